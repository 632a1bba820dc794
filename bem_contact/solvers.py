"""Frictionless unilateral contact of a gap map with an elastic half-space (seed paper, Sect. 4.1).

Problem (Signorini conditions, a linear complementarity problem). On a regular grid of square
elements of side dx, with initial gap h >= 0 (min h = 0: the bodies just touch), rigid approach
delta and element pressures p, the deformed gap is

    g = h - delta + K p,        p >= 0,  g >= 0,  p * g = 0,

where K is the normal influence operator (Love's rectangle, `bem_contact.influence`). Equivalently
p minimises 0.5 p.K p + p.(h - delta) over p >= 0, whose gradient is g. Under load control the total
force sum(p) dx^2 = W is prescribed instead and delta is read off the solution (the mean of h + K p
over the contact).

Accuracy measures reported with every solution (dimensionless):
  residual = max_i |min(p_i K_ii, g_i)| / delta  (the natural LCP residual, lengths in units of delta;
             K_ii p_i is the element's self-displacement),
  complementarity_error = sum(p |g|) / (sum(p) delta)  (pressure-weighted mean |gap| on the contact).

Only elements with h < delta can touch (K p >= 0 everywhere), so under displacement control every
solver works on the bounding box of {h < delta}; this is exact, not an approximation.

Solvers, by name (see `SOLVERS`):
  "pk"        Polonsky & Keer (1999) constrained conjugate gradients on the zero-padded FFT operator;
              the fast default for any grid, warm-started from x0.
  "al-jacobi" augmented Lagrangian with Jacobi relaxation on the dense matrix (the paper's method):
              p <- max(0, p - (omega / K_ii) g), i.e. a multiplier update with per-element penalty.
  "osqp"      OSQP on the equivalent quadratic program (dense matrix, solution polished).
  "cvxpy"     cvxpy (Clarabel) on the same quadratic program: a reference for small grids.
Dense solvers take load control by a search on delta (Hertz-like steps to bracket, then Brent).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import Callable

import numpy as np

from bem_contact.errors import ContactInputError, ConvergenceError
from bem_contact.influence import ConvolutionOperator, love_kernel


@dataclass(frozen=True)
class SolverInfo:
    """A contact solver: its dense-grid limit (None: any grid), default tolerance and iteration cap."""

    name: str
    max_nodes: int | None
    default_tol: float
    default_maxiter: int
    description: str


SOLVERS: dict[str, SolverInfo] = {
    "pk": SolverInfo("pk", None, 1e-8, 20000, "Polonsky-Keer constrained CG on the FFT operator (any grid)"),
    "al-jacobi": SolverInfo("al-jacobi", 64 * 64, 1e-8, 200000, "augmented Lagrangian, Jacobi relaxation (the paper's method; dense)"),
    "osqp": SolverInfo("osqp", 48 * 48, 1e-8, 200000, "OSQP on the quadratic program (dense)"),
    "cvxpy": SolverInfo("cvxpy", 32 * 32, 1e-5, 500, "cvxpy / Clarabel on the quadratic program (dense reference)"),
}
DEFAULT_SOLVER = "pk"
MAX_ELEMENTS = 4096 * 4096  # the zero-padded FFT operator of a larger map needs > 1 GB


def solver_names() -> list[str]:
    """Names accepted by `solve_contact` (plus "auto")."""
    return ["auto", *SOLVERS]


@dataclass
class ContactResult:
    """Solution of one frictionless contact problem; SI units.

    Attributes:
        pressure: contact pressure per element (Pa), shape of the gap map.
        gap: the initial gap used, shifted so that min(gap) = 0 (m).
        force: total normal force sum(p) dx^2 (N).
        indentation: rigid approach delta from first touch (m).
        contact_area: number of loaded elements times dx^2 (m^2).
        iterations: solver iterations (for load control with a dense solver: summed over the delta search).
        residual, complementarity_error: accuracy measures (dimensionless; see module docstring).
        solver: solver name; converged: residual <= tol; tol: the tolerance asked for.
        dx: grid pitch (m); E_star: contact modulus (Pa).
    """

    pressure: np.ndarray
    gap: np.ndarray
    force: float
    indentation: float
    contact_area: float
    iterations: int
    residual: float
    complementarity_error: float
    solver: str
    converged: bool
    tol: float
    dx: float
    E_star: float
    _operator: ConvolutionOperator = field(repr=False, compare=False, default=None)  # type: ignore[assignment]

    @cached_property
    def displacement(self) -> np.ndarray:
        """Combined normal surface displacement K p (m), positive where the surfaces are pushed apart."""
        return self._operator(self.pressure)

    @property
    def deformed_gap(self) -> np.ndarray:
        """Gap after loading h - delta + K p (m); >= 0 up to the tolerance, 0 on the contact."""
        return self.gap - self.indentation + self.displacement

    @property
    def touches_edge(self) -> bool:
        """True if any element on the border of the map carries pressure (the map is then too small)."""
        p = self.pressure
        return bool((p[0] > 0).any() or (p[-1] > 0).any() or (p[:, 0] > 0).any() or (p[:, -1] > 0).any())


# ---------------------------------------------------------------------------------------------
# shared pieces


@lru_cache(maxsize=8)
def _kernel_table(n: int, m: int, dx: float, E_star: float) -> np.ndarray:
    table = love_kernel(n, m, dx, E_star)
    table.setflags(write=False)
    return table


def normal_operator_cached(shape: tuple[int, int], dx: float, E_star: float, workers: int = 1) -> ConvolutionOperator:
    """Normal operator of a grid, its kernel table cached (a curve reuses it for every indentation)."""
    return ConvolutionOperator(_kernel_table(int(shape[0]), int(shape[1]), float(dx), float(E_star)), workers)


def kkt_measures(p: np.ndarray, g: np.ndarray, self_compliance: float, delta: float) -> tuple[float, float]:
    """(residual, complementarity_error) of a candidate solution, both dimensionless (module docstring)."""
    residual = float(np.max(np.abs(np.minimum(p * self_compliance, g)))) / delta
    total = float(p.sum())
    complementarity = float(np.sum(p * np.abs(g))) / (total * delta) if total > 0 else 0.0
    return residual, complementarity


# Indentations below 1e-12 grid pitches are round-off of the geometry, not contact (they also underflow).
MIN_RELATIVE_INDENTATION = 1e-12


def _validate(gap: np.ndarray, dx: float, E_star: float, indentation, force, solver: str, x0) -> tuple[np.ndarray, str]:
    h = np.asarray(gap, dtype=float)
    if h.ndim != 2 or h.size == 0:
        raise ContactInputError(f"gap map must be a non-empty 2-D array (got shape {h.shape}); give h(x, y) on a regular grid")
    if h.size > MAX_ELEMENTS:
        raise ContactInputError(f"gap map {h.shape[0]}x{h.shape[1]} is too large (at most {MAX_ELEMENTS} elements, e.g. 4096x4096); resample it coarser")
    if not np.isfinite(h).all():
        bad = int((~np.isfinite(h)).sum())
        raise ContactInputError(f"gap map has {bad} non-finite values (NaN/inf); fill or crop the holes before solving")
    if not (isinstance(dx, (int, float, np.floating)) and math.isfinite(dx) and dx > 0):
        raise ContactInputError(f"grid pitch dx = {dx!r} m must be a finite number > 0")
    if not (isinstance(E_star, (int, float, np.floating)) and math.isfinite(E_star) and E_star > 0):
        raise ContactInputError(f"contact modulus E* = {E_star!r} Pa must be a finite number > 0 (steel on brass: 75.09e9)")
    if (indentation is None) == (force is None):
        raise ContactInputError("give exactly one of indentation= (m) or force= (N)")
    for name, value, unit in (("indentation", indentation, "m"), ("force", force, "N")):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ContactInputError(f"{name} = {value!r} {unit} must be a finite number > 0")
    if indentation is not None and indentation < MIN_RELATIVE_INDENTATION * dx:
        raise ContactInputError(
            f"indentation = {indentation!r} m is below the model's length resolution ({MIN_RELATIVE_INDENTATION:g} dx = "
            f"{MIN_RELATIVE_INDENTATION * dx:.3g} m); give a physical indentation"
        )
    if solver == "auto":
        solver = DEFAULT_SOLVER
    if solver not in SOLVERS:
        raise ContactInputError(f"unknown solver {solver!r}; choose one of {', '.join(solver_names())}")
    limit = SOLVERS[solver].max_nodes
    if limit is not None and h.size > limit:
        raise ContactInputError(
            f"grid {h.shape[0]}x{h.shape[1]} ({h.size} elements) is too large for the dense solver {solver!r} "
            f"(at most {limit}); use solver='pk', which handles any grid"
        )
    if x0 is not None and np.shape(x0) != h.shape:
        raise ContactInputError(f"starting pressure x0 has shape {np.shape(x0)}, the gap map {h.shape}; they must match")
    return h - h.min(), solver


def _candidate_box(h: np.ndarray, level: float, margin: int = 0) -> tuple[slice, slice]:
    """Bounding box of the elements with h < level, widened by `margin` elements on each side."""
    rows = np.flatnonzero((h < level).any(axis=1))
    cols = np.flatnonzero((h < level).any(axis=0))
    return (
        slice(max(rows[0] - margin, 0), min(rows[-1] + 1 + margin, h.shape[0])),
        slice(max(cols[0] - margin, 0), min(cols[-1] + 1 + margin, h.shape[1])),
    )


# ---------------------------------------------------------------------------------------------
# Polonsky & Keer constrained conjugate gradients


def polonsky_keer(
    op: ConvolutionOperator,
    h: np.ndarray,
    *,
    delta: float | None = None,
    force: float | None = None,
    area: float,
    x0: np.ndarray | None,
    tol: float,
    maxiter: int,
) -> tuple[np.ndarray, np.ndarray, float, int, float]:
    """Polonsky & Keer (1999, Wear 231:206) CG for the contact LCP on operator `op`.

    Displacement control (delta given): projected CG on 0.5 p.K p + p.(h - delta), p >= 0.
    Load control (force given): the gradient is shifted by its mean over the contact (delta read off)
    and p is rescaled to the load after each step. Returns (p, u = K p, delta, iterations, residual).
    """
    from bem_contact import _pk_kernels as _k  # numba, imported on first use (keeps `ies --help` fast)

    load_control = force is not None
    kii = op.self_compliance
    if x0 is not None and np.any(x0 > 0):
        d = np.maximum(x0, 0.0)
    elif load_control:
        d = np.ones_like(h)
    else:
        d = np.maximum(delta - h, 0.0)
    Kd = op(d)
    if load_control:
        scale = force / (area * d.sum())
    else:
        # exact line search of the energy along d; a useless warm start falls back to the cold one
        scale = float(np.sum(d * (delta - h))) / float(np.sum(d * Kd))
        if not scale > 0:
            d = np.maximum(delta - h, 0.0)
            Kd = op(d)
            scale = float(np.sum(d * (delta - h))) / float(np.sum(d * Kd))
    p = np.ascontiguousarray(scale * d)
    u = np.ascontiguousarray(scale * Kd)
    h = np.ascontiguousarray(h, dtype=float)
    g = np.empty_like(h)
    t = np.zeros_like(h)
    G_old = 1.0
    restart = True
    residual = math.inf
    iterations = 0
    exact = True  # u = K p to round-off; False after cheap incremental updates
    since_exact = 0
    while True:
        if load_control:
            delta = _k.contact_mean(h, u, p)
        worst, G = _k.gap_and_residual(h, u, p, delta, kii, g)
        residual = worst / delta
        if residual <= tol or iterations >= maxiter:
            if exact:
                break
            u, exact, since_exact = np.ascontiguousarray(op(p)), True, 0  # confirm on the exact displacement
            continue
        iterations += 1
        _k.conjugate_direction(g, p, t, 0.0 if restart else G / G_old)
        G_old = G
        Kt = np.ascontiguousarray(op(t))
        rt, gt, st, sk, count = _k.step_sums(Kt, t, g, p)
        if load_control:
            rt -= sk / count * st  # the gradient's mean over the contact is the load multiplier
        # the contact may already be in equilibrium while elements outside penetrate (t = 0): then only
        # load those, with the self-compliance step 1/K_ii (PK's tau would be 0 and the iteration would stall)
        tau = gt / rt if rt > 0 else 0.0
        tau_overlap = tau if tau * kii > 1e-6 else 1.0 / kii
        clipped, overlap, total = _k.update_pressure(p, t, g, tau, tau_overlap)
        restart = overlap > 0
        scale = force / (area * total) if load_control else 1.0
        if scale != 1.0:
            p *= scale
        if restart or clipped or since_exact >= 50:
            u, exact, since_exact = np.ascontiguousarray(op(p)), True, 0
        else:
            _k.linear_update(u, Kt, tau, scale)  # the step was linear: K p_new = K p - tau K t
            exact, since_exact = False, since_exact + 1
    return p, u, float(delta), iterations, residual


# ---------------------------------------------------------------------------------------------
# dense solvers on the candidate elements, in units of delta (lengths) and delta E*/dx (pressures)


def _al_jacobi(K: np.ndarray, b: np.ndarray, x0: np.ndarray | None, tol: float, maxiter: int) -> tuple[np.ndarray, int]:
    """Augmented Lagrangian with Jacobi relaxation: p <- max(0, p - omega g / diag(K)), g = K p + b."""
    diag = np.diag(K).copy()
    # relaxation from the largest eigenvalue of D^-1/2 K D^-1/2 (power iteration); omega < 2/lambda_max converges
    scaled = K / np.sqrt(np.outer(diag, diag))
    v = np.ones(len(b)) / math.sqrt(len(b))
    lam = 1.0
    for _ in range(100):
        w = scaled @ v
        lam_new = float(np.linalg.norm(w))
        v = w / lam_new
        if abs(lam_new - lam) <= 1e-6 * lam_new:
            break
        lam = lam_new
    step = 1.0 / (lam_new * diag)
    p = np.maximum(x0, 0.0) if x0 is not None else np.maximum(-b, 0.0) / diag
    for it in range(1, maxiter + 1):
        g = K @ p + b
        p = np.maximum(p - step * g, 0.0)
        if it % 10 == 0 and np.max(np.abs(np.minimum(p * diag, K @ p + b))) <= tol:
            return p, it
    return p, maxiter


def _osqp(K: np.ndarray, b: np.ndarray, x0: np.ndarray | None, tol: float, maxiter: int) -> tuple[np.ndarray, int]:
    """OSQP (Stellato et al. 2020) on min 0.5 p.K p + b.p, p >= 0, with solution polishing."""
    import osqp
    import scipy.sparse as sp

    n = len(b)
    problem = osqp.OSQP()
    problem.setup(
        P=sp.triu(sp.csc_matrix(K), format="csc"), q=b, A=sp.identity(n, format="csc"),
        l=np.zeros(n), u=np.full(n, np.inf), eps_abs=0.1 * tol, eps_rel=0.1 * tol,
        max_iter=maxiter, polishing=True, verbose=False,
    )
    if x0 is not None:
        problem.warm_start(x=np.maximum(x0, 0.0))
    result = problem.solve(raise_error=False)  # a failed solve is judged by our own residual check
    if result.x is None or not np.all(np.isfinite(result.x)):
        return np.zeros(n), int(result.info.iter)
    return np.maximum(result.x, 0.0), int(result.info.iter)


def _cvxpy(K: np.ndarray, b: np.ndarray, x0: np.ndarray | None, tol: float, maxiter: int) -> tuple[np.ndarray, int]:
    """cvxpy with Clarabel (interior point) on min 0.5 p.K p + b.p, p >= 0."""
    import cvxpy as cp

    p = cp.Variable(len(b), nonneg=True)
    problem = cp.Problem(cp.Minimize(0.5 * cp.quad_form(p, cp.psd_wrap(K)) + b @ p))
    tight = min(1e-10, 0.01 * tol)
    try:
        problem.solve(solver=cp.CLARABEL, max_iter=maxiter, tol_gap_abs=tight, tol_gap_rel=tight, tol_feas=tight)
    except cp.SolverError:
        return np.zeros(len(b)), maxiter
    iterations = int(problem.solver_stats.num_iters or 0)
    if p.value is None:
        return np.zeros(len(b)), iterations
    return np.maximum(np.asarray(p.value, dtype=float), 0.0), iterations


_DENSE: dict[str, Callable[..., tuple[np.ndarray, int]]] = {"al-jacobi": _al_jacobi, "osqp": _osqp, "cvxpy": _cvxpy}


# ---------------------------------------------------------------------------------------------
# the entry point


# A smooth contact ends near h = delta / 2 (exactly so for Hertz); "pk" first solves on this smaller box
# and falls back to the full candidate box only if the check there finds a penetration.
_INNER_LEVEL = 0.6
_INNER_MARGIN = 2


@dataclass(frozen=True)
class _Problem:
    """The settings of one `solve_contact` call, shared by its steps: gap map h (m, min 0), pitch dx (m), E* (Pa),
    solver name, tolerance, iteration cap, FFT threads, and whether a missed tolerance raises."""

    h: np.ndarray
    dx: float
    E_star: float
    solver: str
    tol: float
    maxiter: int
    workers: int
    raise_on_failure: bool


def _solve_on_box(problem: _Problem, delta: float, x0: np.ndarray | None, box: tuple[slice, slice]):
    """Displacement control restricted to `box`; returns (pressure on the box, iterations)."""
    h, dx, E_star, solver, tol, maxiter = (problem.h, problem.dx, problem.E_star, problem.solver, problem.tol,
                                           problem.maxiter)
    rows, cols = box
    hs = h[rows, cols]
    op = normal_operator_cached(h.shape, dx, E_star, problem.workers).restricted(*hs.shape)
    x0s = None if x0 is None else np.asarray(x0, dtype=float)[rows, cols]
    if solver == "pk":
        ps, _, _, iterations, _ = polonsky_keer(op, hs, delta=delta, area=dx * dx, x0=x0s, tol=tol, maxiter=maxiter)
        return ps, iterations
    idx = np.flatnonzero(hs.ravel() < delta)
    unit_p = delta * E_star / dx  # pressures in this unit, lengths in delta: K becomes O(1)
    K = op.dense()[np.ix_(idx, idx)] * (E_star / dx)
    b = (hs.ravel()[idx] - delta) / delta
    start = None if x0s is None else x0s.ravel()[idx] / unit_p
    solution, iterations = _DENSE[solver](K, b, start, tol, maxiter)
    ps = np.zeros(hs.size)
    ps[idx] = solution * unit_p
    return ps.reshape(hs.shape), iterations


def _solve_indentation(problem: _Problem, delta: float, x0: np.ndarray | None):
    """Displacement control; returns (p on the full grid, iterations, residual, complementarity error).

    The accuracy measures are evaluated on the whole candidate box {h < delta}: outside it p = 0 and g > 0."""
    h, dx, E_star, solver, tol = problem.h, problem.dx, problem.E_star, problem.solver, problem.tol
    full = _candidate_box(h, delta)
    op = normal_operator_cached(h.shape, dx, E_star, problem.workers).restricted(full[0].stop - full[0].start, full[1].stop - full[1].start)
    boxes = [full]
    if solver == "pk":
        inner = _candidate_box(h, _INNER_LEVEL * delta, _INNER_MARGIN)
        if (inner[0].stop - inner[0].start) * (inner[1].stop - inner[1].start) < 0.8 * op.shape[0] * op.shape[1]:
            boxes.insert(0, inner)
    p = np.zeros_like(h)
    total = 0
    for box in boxes:
        ps, iterations = _solve_on_box(problem, delta, x0, box)
        total += iterations
        p[...] = 0.0
        p[box] = ps
        g = h[full] - delta + op(p[full])
        residual, complementarity = kkt_measures(p[full], g, op.self_compliance, delta)
        if residual <= tol:
            break
        x0 = p.copy()
    return p, total, residual, complementarity


def _finish(problem: _Problem, p: np.ndarray, delta: float, iterations: int, residual: float,
            complementarity: float) -> ContactResult:
    """The `ContactResult` of pressure p (Pa) at indentation delta (m); ConvergenceError (one line) when the residual
    missed the tolerance and the problem says to raise."""
    h, dx, E_star, solver, tol, maxiter = (problem.h, problem.dx, problem.E_star, problem.solver, problem.tol,
                                           problem.maxiter)
    converged = residual <= tol
    if not converged and problem.raise_on_failure:
        raise ConvergenceError(
            f"solver {solver!r} stopped after {iterations} iterations with residual {residual:.3g} > tol {tol:.3g} "
            f"(maxiter {maxiter}); raise maxiter, loosen tol or use solver='pk'"
        )
    return ContactResult(
        pressure=p, gap=h, force=float(p.sum()) * dx * dx, indentation=float(delta),
        contact_area=float(np.count_nonzero(p > 0)) * dx * dx, iterations=int(iterations), residual=residual,
        complementarity_error=complementarity, solver=solver, converged=converged, tol=tol, dx=float(dx),
        E_star=float(E_star), _operator=normal_operator_cached(h.shape, dx, E_star, problem.workers),
    )


def solve_contact(
    gap: np.ndarray,
    dx: float,
    E_star: float,
    *,
    indentation: float | None = None,
    force: float | None = None,
    solver: str = "auto",
    tol: float | None = None,
    x0: np.ndarray | None = None,
    maxiter: int | None = None,
    raise_on_failure: bool = True,
    workers: int = 1,
) -> ContactResult:
    """Frictionless contact of a gap map pressed onto an elastic half-space (Sect. 4.1; Signorini LCP).

    Args:
        gap: initial separation h(x, y) (m) on a regular grid (axis 0 = x). It is shifted so that
            min(gap) = 0: the indentation is the rigid approach from first touch (for a crater the
            first touch may be on its rim, not at its bottom).
        dx: grid pitch (m), square elements.
        E_star: contact modulus (Pa), `contact_modulus(a, b)`.
        indentation: prescribed rigid approach delta (m), or
        force: prescribed total normal force (N); delta is then read off the solution.
        solver: "auto" (= "pk"), "pk", "al-jacobi", "osqp" or "cvxpy" (`SOLVERS`).
        tol: relative LCP residual to reach (default: the solver's `default_tol`).
        x0: starting pressure (Pa), e.g. the solution at a smaller indentation.
        maxiter: iteration cap (default: the solver's).
        raise_on_failure: if True (default) a solve that misses tol raises ConvergenceError;
            if False the result is returned with converged=False.
        workers: threads for the FFTs.

    Returns:
        ContactResult with pressure (Pa), force (N), indentation (m), area (m^2) and accuracy measures.
    """
    h, solver = _validate(gap, dx, E_star, indentation, force, solver, x0)
    info = SOLVERS[solver]
    tol = info.default_tol if tol is None else float(tol)
    maxiter = info.default_maxiter if maxiter is None else int(maxiter)
    if not (tol > 0):
        raise ContactInputError(f"tol = {tol!r} must be > 0")

    problem = _Problem(h, dx, E_star, solver, tol, maxiter, workers, raise_on_failure)
    if indentation is not None:
        p, iterations, residual, compl = _solve_indentation(problem, float(indentation), x0)
        return _finish(problem, p, float(indentation), iterations, residual, compl)

    if solver == "pk":
        op = normal_operator_cached(h.shape, dx, E_star, workers)
        p, _, delta, iterations, _ = polonsky_keer(
            op, h, force=float(force), area=dx * dx, x0=None if x0 is None else np.asarray(x0, float), tol=tol, maxiter=maxiter
        )
        residual, compl = kkt_measures(p, h - delta + op(p), op.self_compliance, delta)
        return _finish(problem, p, delta, iterations, residual, compl)
    return _solve_force_by_search(problem, float(force), x0)


def _solve_force_by_search(problem: _Problem, W: float, x0: np.ndarray | None) -> ContactResult:
    """Load control for the dense solvers: find delta with F(delta) = W (F increasing, locally ~ delta^1.5)."""
    h, dx, E_star, solver, tol = problem.h, problem.dx, problem.E_star, problem.solver, problem.tol
    # first guess from below: ignoring the elements' interaction, p_i = (delta - h_i) / K_ii over-estimates
    # the force at any delta, so its root under-estimates the indentation (and keeps the first solves small)
    kii = love_kernel(1, 1, dx, E_star)[0, 0]
    levels = np.sort(h.ravel())
    cumulative = np.cumsum(levels)
    counts = np.arange(1, levels.size + 1)
    # on [levels[k], levels[k+1]] the estimate is (counts[k] delta - cumulative[k]) dx^2 / K_ii
    k = int(np.searchsorted((counts * levels - cumulative) * dx * dx / kii, W)) - 1
    delta = (W * kii / (dx * dx) + cumulative[k]) / counts[k]
    state = {"x0": x0, "total": 0}

    def solve_at(d: float):
        p, iterations, residual, compl = _solve_indentation(problem, d, state["x0"])
        state["x0"], state["total"] = p, state["total"] + iterations
        return p, residual, compl, float(p.sum()) * dx * dx

    # bracket the root from below by Hertz-like steps delta (W/F)^(2/3), then Brent's method; the
    # indentation is resolved to tol relative, the accuracy of each solve (F may have kinks: new patches)
    low, high = 0.0, math.inf
    for _ in range(60):
        p, residual, compl, F = solve_at(delta)
        if abs(F / W - 1.0) <= tol:
            return _finish(problem, p, delta, state["total"], residual, compl)
        if F > W:
            high = delta
            break
        low = delta
        delta *= max((W / F) ** (2.0 / 3.0), 1.0 + 1e-3) if F > 0 else 2.0
    if math.isfinite(high):
        from scipy import optimize  # here, not at the top: `ies --help` lists the solvers without loading scipy

        try:
            delta = optimize.brentq(lambda d: solve_at(d)[3] - W, low, high, xtol=0.5 * tol * low if low > 0 else 1e-300,
                                    rtol=max(tol, 4 * np.finfo(float).eps), maxiter=200)
            p, residual, compl, F = solve_at(delta)
        except RuntimeError:
            high = math.inf
    if not math.isfinite(high):
        if problem.raise_on_failure:
            raise ConvergenceError(f"solver {solver!r}: the search for the indentation at force {W:g} N did not converge; use solver='pk'")
        residual = math.inf  # reported as not converged
    return _finish(problem, p, delta, state["total"], residual, compl)
