"""Force-indentation curve and the Hertzian spring constant k_H of a gap map (seed paper, Sect. 4.1, Fig. 3c).

The curve f(delta) is computed by the contact solver for each prescribed approach delta (from first
touch), warm-starting each solve from the previous pressure. k_H is the ordinary least-squares fit of
f = k_H delta^1.5 (Eq. 4) to the curve: k_H = sum(f delta^1.5) / sum(delta^3), which weights the large
indentations reached in the simulations, as a fit to Fig. 3c does. The numerical error bar is the
change of k_H under grid refinement: |k_H(n) - k_H(n/2)| on the same physical domain. For Love's
elements the error falls about as dx^2, so this bar over-estimates the error of k_H(n) by about 3x:
deliberately conservative, because it enters an uncertainty study.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from bem_contact.errors import ContactInputError
from bem_contact.solvers import DEFAULT_SOLVER, solve_contact
from sim.model.materials import hertz_constant_of

GapMaker = Callable[[int], tuple[np.ndarray, float]]


@dataclass(frozen=True)
class ForceCurve:
    """Force-indentation curve on one grid: deltas (m), forces (N), contact areas (m^2), solver statistics."""

    deltas: np.ndarray
    forces: np.ndarray
    areas: np.ndarray
    iterations: int
    max_residual: float
    grid: tuple[int, int]
    dx: float


@dataclass(frozen=True)
class Calibration:
    """k_H of a gap map with its numerical error bar (Sect. 4.1, Fig. 3c); SI units.

    Attributes:
        k_H: fitted Hertzian spring constant (N/m^1.5) on the fine grid.
        k_H_error: |k_H(grid) - k_H(grid/2)| (N/m^1.5), the numerical error bar.
        fit_residual: ||f - k_H delta^1.5|| / ||f|| (-): how Hertzian the curve is.
        deltas, forces: the fine-grid curve (m, N); curve, coarse: both curves in full.
        grid: fine grid size n (elements across); coarse_k_H: k_H on the grid n // 2.
        solver: solver name; k_H_star, k_H_ratio: Eq. 8 and k_H / k_H_star when R was given.
    """

    k_H: float
    k_H_error: float
    fit_residual: float
    deltas: np.ndarray
    forces: np.ndarray
    grid: int
    solver: str
    coarse_k_H: float
    curve: ForceCurve
    coarse: ForceCurve
    k_H_star: float | None = None
    k_H_ratio: float | None = None

    def summary(self) -> dict[str, Any]:
        """Plain, JSON-ready summary (SI units: k_H in N/m^1.5, deltas in m, forces in N)."""
        return {
            "k_H": self.k_H,
            "k_H_star": self.k_H_star,
            "k_H_ratio": self.k_H_ratio,
            "k_H_error": self.k_H_error,
            "fit_residual": self.fit_residual,
            "grid": self.grid,
            "coarse_grid": self.coarse.grid[0],
            "coarse_k_H": self.coarse_k_H,
            "dx": self.curve.dx,
            "solver": self.solver,
            "iterations": self.curve.iterations + self.coarse.iterations,
            "max_residual": max(self.curve.max_residual, self.coarse.max_residual),
            "deltas": self.deltas,
            "forces": self.forces,
            "contact_areas": self.curve.areas,
        }


def fit_k_H(deltas: np.ndarray, forces: np.ndarray) -> tuple[float, float]:
    """Least-squares k_H of f = k_H delta^1.5 (N/m^1.5) and the relative residual ||f - fit|| / ||f||."""
    d15 = np.asarray(deltas, dtype=float) ** 1.5
    f = np.asarray(forces, dtype=float)
    k = float(np.dot(f, d15) / np.dot(d15, d15))
    return k, float(np.linalg.norm(f - k * d15) / np.linalg.norm(f))


def _check_deltas(deltas) -> np.ndarray:
    d = np.asarray(deltas, dtype=float).ravel()
    if d.size < 2:
        raise ContactInputError(f"need at least 2 indentations for a k_H fit (got {d.size}); for example 2e-6 to 40e-6 m")
    if not (np.isfinite(d).all() and (d > 0).all()):
        raise ContactInputError("indentations must be finite and > 0 (m), measured from first touch")
    return np.sort(d)


def force_curve(
    gap: np.ndarray,
    dx: float,
    E_star: float,
    deltas,
    *,
    solver: str = "auto",
    tol: float | None = None,
    workers: int = 1,
    on_solve: Callable[[], None] | None = None,
) -> ForceCurve:
    """Forces (N) at the approaches `deltas` (m) for one gap map, each solve warm-started from the last.

    `on_solve()` is called after each solve (progress display). Raises ContactInputError if the contact
    reaches the edge of the map (the domain is then too small).
    """
    d = _check_deltas(deltas)
    forces = np.empty_like(d)
    areas = np.empty_like(d)
    pressure = None
    iterations = 0
    max_residual = 0.0
    for i, delta in enumerate(d):
        result = solve_contact(gap, dx, E_star, indentation=float(delta), solver=solver, tol=tol, x0=pressure, workers=workers)
        if result.touches_edge:
            raise ContactInputError(
                f"at indentation {delta * 1e6:.3g} um the contact reaches the edge of the {gap.shape[0]}x{gap.shape[1]} "
                "gap map; use a larger domain or smaller indentations"
            )
        forces[i], areas[i], pressure = result.force, result.contact_area, result.pressure
        iterations += result.iterations
        max_residual = max(max_residual, result.residual)
        if on_solve is not None:
            on_solve()
    return ForceCurve(d, forces, areas, iterations, max_residual, tuple(np.shape(gap)), float(dx))


def calibrate_k_H(
    gap_at: GapMaker,
    grid: int,
    E_star: float,
    deltas,
    *,
    solver: str = "auto",
    R: float | None = None,
    tol: float | None = None,
    workers: int = 1,
    on_solve: Callable[[], None] | None = None,
) -> Calibration:
    """Calibrate k_H of any gap map (flat wall, scanned crater) with a grid-refinement error bar (Sect. 4.1).

    Args:
        gap_at: gap_at(n) -> (gap (m), dx (m)): the gap map sampled on n elements across the same domain.
        grid: fine grid size n (>= 8); the error bar uses n // 2.
        E_star: contact modulus (Pa).
        deltas: approaches from first touch (m), e.g. np.linspace(2e-6, 40e-6, 20).
        solver: solver name (see `bem_contact.solvers.SOLVERS`); R: sphere radius (m) for k_H* (Eq. 8).
        tol: LCP residual per solve (default: the solver's); workers: FFT threads.
        on_solve: called after each of the 2 x len(deltas) solves (progress display).
    """
    if not (isinstance(grid, (int, np.integer)) and grid >= 8):
        raise ContactInputError(f"grid = {grid!r} must be a whole number >= 8 (the error bar uses grid // 2)")
    if R is not None and not (math.isfinite(R) and R > 0):
        raise ContactInputError(f"sphere radius R = {R!r} m must be a finite number > 0")
    curves = []
    for n in (grid, grid // 2):
        gap, dx = gap_at(n)
        curves.append(force_curve(gap, dx, E_star, deltas, solver=solver, tol=tol, workers=workers, on_solve=on_solve))
    fine, coarse = curves
    k, residual = fit_k_H(fine.deltas, fine.forces)
    k_coarse, _ = fit_k_H(coarse.deltas, coarse.forces)
    k_star = ratio = None
    if R is not None:
        k_star = hertz_constant_of(R, E_star)  # Eq. 8 with E* given directly
        ratio = k / k_star
    return Calibration(
        k_H=k, k_H_error=abs(k - k_coarse), fit_residual=residual, deltas=fine.deltas, forces=fine.forces,
        grid=int(grid), solver=DEFAULT_SOLVER if solver == "auto" else solver, coarse_k_H=k_coarse,
        curve=fine, coarse=coarse, k_H_star=k_star, k_H_ratio=ratio,
    )
