r"""Pseudo-arclength continuation of periodic orbits in one parameter (eta, level, ...; `sim.orbits.setting`),
with step control, Floquet multipliers at every point and the bifurcations of `sim.orbits.bifurcations`.

Unknowns u = (y / scale, lambda / lambda_scale): the orbit's state at phase 0 in the shooting's scaled units
(g at the walls) and the continuation coordinate (`Parameter.to_coordinate`) in units of `Parameter.scale`, so
that the arclength weighs a change of the state by g like a change of eta by 2e-3 (of the level by 0.2). The
branch is the curve R(u) = 0 of the shooting residual (`sim.orbits.shooting`: G(y) - y for a symmetric orbit,
P_k(y) - y otherwise). From a point u_i with unit tangent t_i (the null vector of [R_y R_lambda], oriented along the
branch):

  predictor  u_p = u_i + h t_i,
  corrector  R(u) = 0 and t_i . (u - u_p) = 0 (Keller's pseudo-arclength), by Newton's method on the
             augmented Jacobian [R_y R_lambda; t_i] taken at u_p (forward differences: half the runs of central
             ones, accurate enough for iterations) and kept (chord) while the residual falls by CHORD_RATE per
             iteration, else taken again at the iterate. R_y by central differences (`ShootingMap.jacobian`,
             2 (2n + 2) runs), R_lambda by central differences in lambda (2 runs). The maps are so nonlinear
             (`sim.orbits.shooting`) that the previous point's Jacobian, even updated by Broyden's rule, makes the
             corrector diverge beyond steps of ~0.01 (measured on the rig at 7.4), while one taken at u_p converges
             in 3-4 iterations at 0.06. A step thus costs two Jacobians: at u_p and at the accepted point (its
             multipliers).

Step control: a step is accepted when the corrector converges (residual below `sim.orbits.shooting.TOLERANCE`)
within MAX_CORRECTOR iterations, moves less than DRIFT h from the predictor and turns the tangent by less than
MAX_TURN (so that the corrector does not jump to a neighbouring branch); otherwise h is halved, down to
`min_step` where the branch ends (its `stop` says so). After an accepted step h grows by 1.5 when the step was
easy (drift below EASY h and turn below EASY rad), up to a ceiling: the last refused step, raised by GROWTH per
accepted point (without it, half the attempts on the rig were refused: steps are limited by the basin of Newton's
method, not by the corrector's effort), and shrinks by 0.7 when it was not (drift above DRIFT h / 2,
turn above MAX_TURN / 2 or more than MAX_CORRECTOR - 3 iterations). The geometry, not the iteration count, sets
the step: the Broyden corrector converges linearly on these strongly nonlinear maps (5-9 iterations at any step,
measured on the rig), and an iteration costs one run against the 2 (2n + 2) of the Jacobian. The last point of a
branch lies on the parameter's bound (the corrector then fixes lambda instead of the arclength).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.orbits.setting import OrbitSetting, Parameter, parameter
from sim.orbits.shooting import (NOISE_FLOOR, TOLERANCE, MapValue, PeriodicOrbit, ShootingMap, fd_step, make_orbit,
                                 newton_matrix)

#: Corrector iterations before a step is refused.
MAX_CORRECTOR = 24
#: A corrected point may lie at most this multiple of the step from its predictor.
DRIFT = 0.5
#: Largest angle between consecutive tangents (rad).
MAX_TURN = 0.35
#: A step was easy (the next one grows) below this drift (multiple of the step) and turn (rad).
EASY = 0.1
#: The corrector keeps its Jacobian while each iteration divides the residual by at least 1 / CHORD_RATE, else
#: takes a new one at the iterate, at most MAX_JACOBIANS times per step (a chord iteration costs one run, a
#: Jacobian 2 (2n + 2): 42 on the rig).
CHORD_RATE = 0.3
MAX_JACOBIANS = 3
#: Halvings of a corrector step whose residual is larger than before it.
BACKTRACK = 4
#: After a refused step, the steps stay below it, the ceiling growing by this factor per accepted point.
GROWTH = 1.1
#: Step in the continuation coordinate (units of the parameter's scale) of the derivative R_lambda.
LAMBDA_STEP = 1e-5
#: The parameters that change the excitation only (one shooting map, retargeted).
EXCITATION = ("eta", "level")
#: Default step control: initial, smallest and largest arclength step (scaled units), most points per branch.
INITIAL_STEP = 0.05
MIN_STEP = 1e-5
MAX_STEP = 0.5
MAX_POINTS = 1500


@dataclass
class BranchPoint:
    """One point of a branch: the orbit, its continuation coordinate (`Parameter.to_coordinate` of the value),
    the unit tangent in the scaled unknowns (length 2n + 3), the bifurcation label of the point ("" for none;
    `sim.orbits.bifurcations`), a note on it, and how well it is located (|mu| - 1 at a multiplier crossing, the
    smallest free-flight gap over g at a grazing; NaN for no label)."""

    orbit: PeriodicOrbit
    coordinate: float
    tangent: np.ndarray
    label: str = ""
    note: str = ""
    location_error: float = math.nan


@dataclass
class Unlocated:
    """A change of stability or of the impacts between two points of a branch that could not be located (`what`:
    one line; `sim.orbits.bifurcations`)."""

    what: str
    before: BranchPoint
    after: BranchPoint

    def __str__(self) -> str:
        return self.what


@dataclass
class Branch:
    """A branch of kT orbits continued in `parameter` (`sim.orbits.setting.Parameter`): its points in the order of
    the arclength, where it came from (`origin`), why it ended (`stop`), and the changes of stability or of the
    impacts between two of its points that could not be located (`unlocated`; not labelled, `sim.orbits.bifurcations`);
    rejoins: for a switched branch that came back through its parent, the parameter values between which it did."""

    parameter: Parameter
    k: int
    symmetric: bool
    points: list[BranchPoint] = field(default_factory=list)
    origin: str = ""
    stop: str = ""
    unlocated: list[Unlocated] = field(default_factory=list)
    rejoins: tuple[float, float] | None = None

    def values(self) -> np.ndarray:
        """The parameter's value at every point."""
        return np.array([self.parameter.get(p.orbit.setting) for p in self.points])


class Continuer:
    """The arclength machinery of one branch family: a base setting, the parameter (a name of
    `sim.orbits.setting.PARAMETERS` or a `Parameter`), the period multiple k and whether orbits are solved as
    symmetric ones (module docstring). `evaluations` counts the integrator runs. map_factory(setting, k, system=...)
    builds the map (`ShootingMap`; another map with its interface for systems other than Eqs. 3-7: the toy systems
    of the bifurcation tests)."""

    def __init__(self, base: OrbitSetting, parameter_name: str | Parameter, k: int, symmetric: bool, *,
                 map_factory: Callable[..., ShootingMap] = ShootingMap) -> None:
        self.base = base
        self.parameter = parameter_name if isinstance(parameter_name, Parameter) else parameter(parameter_name)
        self.k = k
        self.symmetric = symmetric
        self.scale = base.scales()
        self.n = self.scale.size
        self.map_factory = map_factory
        self._maps: dict[float, ShootingMap] = {}
        self._map: ShootingMap | None = None
        self._map_key = math.nan
        self._system = base.system()
        self.evaluations = 0
        self.fd_step: float | None = None  # the Jacobians' step, chosen at the branch's first point (`fd_step`)

    # -- the unknowns ---------------------------------------------------------------------------------------
    def unknowns(self, orbit: PeriodicOrbit) -> np.ndarray:
        """u = (y / scale, lambda / lambda_scale) of an orbit."""
        lam = self.parameter.to_coordinate(self.parameter.get(orbit.setting))
        return np.concatenate([orbit.state / self.scale, [lam / self.parameter.scale]])

    def coordinate(self, u: np.ndarray) -> float:
        """The continuation coordinate lambda of u."""
        return float(u[-1]) * self.parameter.scale

    def shooting(self, coordinate: float) -> ShootingMap:
        """The shooting map at the continuation coordinate (cached for the last few); SimulationDiverged where the
        coordinate gives no valid setting (a Newton step far off: the corrector then backtracks or refuses)."""
        key = float(coordinate)
        if self.parameter.name in EXCITATION:  # one map, moved to each excitation (the system stays)
            if self._map is None:
                self._map = self.map_factory(self._setting(key), self.k, system=self._system)
                self._map_key = key
            elif self._map_key != key:
                self._map.retarget(self._setting(key))
                self._map_key = key
            chosen = self._map
        else:
            if key not in self._maps:
                if len(self._maps) > 8:
                    self._maps.pop(next(iter(self._maps)))
                self._maps[key] = self.map_factory(self._setting(key), self.k)
            chosen = self._maps[key]
        if self.fd_step is not None:
            chosen.fd_step = self.fd_step
        return chosen

    def _setting(self, key: float) -> OrbitSetting:
        """The setting at the continuation coordinate `key`; SimulationDiverged where it is not a valid one."""
        try:
            return self.parameter.set(self.base, self.parameter.from_coordinate(key))
        except (SimulationInputError, OverflowError) as exc:
            raise SimulationDiverged(f"orbits: {self.parameter.name} out of range in a Newton step ({exc})") from None

    def residual(self, u: np.ndarray) -> tuple[np.ndarray, MapValue]:
        """The scaled shooting residual at u (SimulationDiverged where the integrator fails)."""
        shooting = self.shooting(self.coordinate(u))
        before = shooting.evaluations
        r, value = shooting.residual(u[:-1] * self.scale, self.symmetric)
        self.evaluations += shooting.evaluations - before
        return r, value

    def jacobian(self, u: np.ndarray, base: tuple[np.ndarray, MapValue] | None = None
                 ) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
        """([R_y R_lambda] (n x (n + 1)), the map's scaled (DP_k, DF_half)) at u, by central differences, or by
        forward differences from base = (residual, map value) at u when given (the corrector's iterations)."""
        lam = self.coordinate(u)
        shooting = self.shooting(lam)
        before = shooting.evaluations
        end, half = shooting.jacobian(u[:-1] * self.scale, base=None if base is None else base[1],
                                      one_side=base is None)  # the corrector's iterations: plain differences
        self.evaluations += shooting.evaluations - before
        du = np.zeros_like(u)
        du[-1] = LAMBDA_STEP
        r_plus, _ = self.residual(u + du)
        A = np.empty((self.n, self.n + 1))
        A[:, :-1] = newton_matrix(end, half, self.symmetric)
        if base is None:
            r_minus, _ = self.residual(u - du)
            A[:, -1] = (r_plus - r_minus) / (2.0 * LAMBDA_STEP)
        else:
            A[:, -1] = (r_plus - base[0]) / LAMBDA_STEP
        return A, (end, half)

    @staticmethod
    def tangent(A: np.ndarray, previous: np.ndarray | None, direction: float = 1.0) -> np.ndarray:
        """The unit null vector of A (n x (n + 1)) nearest to `previous`: the solution of [A; previous] t = [0; 1]
        (near a branch point, where A has two null directions, it keeps to the branch being followed); without a
        previous tangent the last right singular vector, with the sign of `direction` in its parameter component."""
        if previous is not None:
            try:
                t = np.linalg.solve(np.vstack([A, previous]), np.append(np.zeros(A.shape[0]), 1.0))
                if np.all(np.isfinite(t)) and np.linalg.norm(t) > 0:
                    return t / np.linalg.norm(t)
            except np.linalg.LinAlgError:
                pass
            _, _, vt = np.linalg.svd(A)
            return vt[-1] if float(vt[-1] @ previous) >= 0 else -vt[-1]
        _, _, vt = np.linalg.svd(A)
        t = vt[-1]
        return t if t[-1] * direction >= 0 else -t

    # -- points -------------------------------------------------------------------------------------------
    def point(self, u: np.ndarray, value: MapValue, previous: np.ndarray | None, direction: float = 1.0,
              label: str = "", jacobian: tuple | None = None) -> tuple[BranchPoint, np.ndarray]:
        """The `BranchPoint` at the converged u (multipliers, pattern, tangent) and its augmented Jacobian rows (from
        `jacobian` = (A, (DP_k, DF_half)) when given, else new)."""
        A, jac = jacobian if jacobian is not None else self.jacobian(u)
        lam = self.coordinate(u)
        shooting = self.shooting(lam)
        before = shooting.evaluations
        orbit = make_orbit(shooting, u[:-1] * self.scale, self.symmetric, value, jac)
        self.evaluations += shooting.evaluations - before
        t = self.tangent(A, previous, direction)
        return BranchPoint(orbit, lam, t, label), A

    def start(self, orbit: PeriodicOrbit, direction: float = 1.0,
              tangent: np.ndarray | None = None) -> tuple[BranchPoint, np.ndarray]:
        """The first point of a branch through a converged orbit, its tangent along `direction` (+1: increasing
        parameter) or `tangent` when given (branch switching), and its augmented Jacobian rows."""
        u = self.unknowns(orbit)
        if self.fd_step is None:
            shooting = self.shooting(self.coordinate(u))
            before = shooting.evaluations
            self.fd_step = fd_step(shooting, orbit.state, self.symmetric)
            shooting.fd_step = self.fd_step
            self.evaluations += shooting.evaluations - before
        r, value = self.residual(u)
        A, jac = self.jacobian(u)
        shooting = self.shooting(self.coordinate(u))
        orb = make_orbit(shooting, u[:-1] * self.scale, self.symmetric, value, jac)
        t = tangent if tangent is not None else self.tangent(A, None, direction)
        return BranchPoint(orb, self.coordinate(u), t / np.linalg.norm(t)), A

    def correct(self, u_pred: np.ndarray, t: np.ndarray, *,
                fix_coordinate: float | None = None) -> tuple[np.ndarray, MapValue, int] | None:
        """Newton's method from u_pred on R(u) = 0 and t . (u - u_pred) = 0 (or lambda = fix_coordinate): the
        augmented Jacobian [R_y R_lambda; t] taken at u_pred and kept (chord) while the residual falls by
        1 / CHORD_RATE per iteration, else taken again at the iterate (at most MAX_JACOBIANS times). Returns (u,
        value, iterations) or None when it fails."""
        n = self.n
        last = np.zeros(n + 1)
        if fix_coordinate is None:
            last[:] = t
        else:
            last[-1] = 1.0
        u = u_pred.copy()
        if fix_coordinate is not None:
            u[-1] = fix_coordinate / self.parameter.scale
        try:
            r, value = self.residual(u)
            B = np.vstack([self.jacobian(u, (r, value))[0], last])
        except SimulationDiverged:
            return None
        H = np.append(r, 0.0)
        norm = float(np.max(np.abs(r)))
        jacobians, fresh = 1, True  # fresh: B was taken at the current iterate
        iteration = 0
        while iteration < MAX_CORRECTOR:
            if norm < TOLERANCE:
                return u, value, iteration
            iteration += 1
            try:
                du = np.linalg.solve(B, -H)
            except np.linalg.LinAlgError:
                return None
            damping = 1.0
            while True:  # backtracking: half steps while the residual grows (at most BACKTRACK halvings)
                u_new = u + damping * du
                try:
                    r_new, value_new = self.residual(u_new)
                    norm_new = float(np.max(np.abs(r_new)))
                except SimulationDiverged:
                    norm_new = math.inf
                if norm_new < norm or damping < 0.5**BACKTRACK:
                    break
                damping *= 0.5
            if not norm_new < norm:  # no descent along this Newton direction: a new Jacobian here, or give up
                if norm < NOISE_FLOOR and fresh:
                    return u, value, iteration  # as far as the map's noise allows
                if fresh or jacobians >= MAX_JACOBIANS:
                    return None
                try:
                    B = np.vstack([self.jacobian(u, (H[:-1], value))[0], last])
                except SimulationDiverged:
                    return None
                jacobians, fresh = jacobians + 1, True
                continue
            H_new = np.append(r_new, float(last @ (u_new - u_pred)) if fix_coordinate is None
                              else (u_new[-1] - fix_coordinate / self.parameter.scale))
            fresh = False
            if norm_new > CHORD_RATE * norm and norm_new >= TOLERANCE and jacobians < MAX_JACOBIANS:
                try:
                    B = np.vstack([self.jacobian(u_new, (r_new, value_new))[0], last])
                except SimulationDiverged:
                    return None
                jacobians, fresh = jacobians + 1, True
            u, H, value, norm = u_new, H_new, value_new, norm_new
        return (u, value, iteration) if norm < TOLERANCE else None

    def predict(self, history: list[np.ndarray], t: np.ndarray, h: float) -> np.ndarray:
        """The predictor at arclength h beyond the last of `history` (the unknowns of the branch's last points):
        the quadratic through the last three at their chord lengths when there are three, else the tangent."""
        u0 = history[-1]
        if len(history) < 3:
            return u0 + h * t
        um2, um1 = history[-3], history[-2]
        s1 = float(np.linalg.norm(um1 - um2))
        s2 = s1 + float(np.linalg.norm(u0 - um1))
        s = s2 + h
        if s1 <= 0.0 or s2 <= s1 or h > 3.0 * (s2 - s1):
            return u0 + h * t
        weights = (s - s1) * (s - s2) / (s1 * s2), s * (s - s2) / (s1 * (s1 - s2)), s * (s - s1) / (s2 * (s2 - s1))
        return weights[0] * um2 + weights[1] * um1 + weights[2] * u0

    def advance(self, current: BranchPoint, A: np.ndarray | None, h: float, *, fix_coordinate: float | None = None,
                history: list[np.ndarray] | None = None, strict: bool = True) -> tuple[BranchPoint, np.ndarray, int] | None:
        """One predictor-corrector step of length h from `current`: (point, its augmented Jacobian rows, +1 if the step
        was easy, -1 if hard, else 0), or None if refused (module docstring)."""
        u0 = self.unknowns(current.orbit)
        t = current.tangent
        u_pred = self.predict(history or [u0], t, h)
        if fix_coordinate is not None:
            u_pred = u0 + (fix_coordinate / self.parameter.scale - u0[-1]) / t[-1] * t
        corrected = self.correct(u_pred, t, fix_coordinate=fix_coordinate)
        if corrected is None:
            return None
        u, value, iterations = corrected
        if strict and float(np.linalg.norm(u - u_pred)) > DRIFT * abs(h) + 1e-9 and fix_coordinate is None:
            return None
        try:
            point, A_new = self.point(u, value, t)
        except SimulationDiverged:
            return None
        turn = math.acos(min(1.0, float(point.tangent @ t)))
        if strict and turn > MAX_TURN:
            return None
        drift = float(np.linalg.norm(u - u_pred)) / abs(h) if h else 0.0
        easy = drift < EASY and turn < EASY
        hard = drift > DRIFT / 2.0 or turn > MAX_TURN / 2.0 or iterations > MAX_CORRECTOR - 3
        return point, A_new, (1 if easy else (-1 if hard else 0))


def _closes(continuer: Continuer, first: BranchPoint, previous: BranchPoint, new: BranchPoint) -> bool:
    """True when the step previous -> new passes the branch's first point (within a tenth of the step, tangents
    alike): the branch is a closed curve and has been gone round once."""
    a, b, c = (continuer.unknowns(p.orbit) for p in (previous, new, first))
    ab = b - a
    length = float(np.linalg.norm(ab))
    if length == 0.0 or float(new.tangent @ first.tangent) < 0.8:
        return False
    s = min(max(float((c - a) @ ab) / length**2, 0.0), 1.0)
    return float(np.linalg.norm(a + s * ab - c)) < 0.1 * length


def continue_branch(start: PeriodicOrbit, parameter_name: str | Parameter, bounds: tuple[float, float], *,
                    direction: float = 1.0, tangent: np.ndarray | None = None, step: float = INITIAL_STEP,
                    min_step: float = MIN_STEP, max_step: float = MAX_STEP, max_points: int = MAX_POINTS,
                    origin: str = "",
                    detect: Callable[["Continuer", Branch, BranchPoint, BranchPoint, np.ndarray], list] | None = None,
                    progress: Callable[[], None] | None = None,
                    stop: Callable[[BranchPoint], str | None] | None = None,
                    map_factory: Callable[..., ShootingMap] = ShootingMap) -> Branch:
    """Continue the branch through `start` in the parameter `parameter_name` (or a `Parameter`) between `bounds`
    (parameter values) along `direction` (+1 increasing) or along `tangent` (scaled unknowns; branch switching), with
    the step control of the module docstring. `detect(continuer, branch, previous, new, A_previous)` may insert
    located bifurcation points between two accepted points and returns them (`sim.orbits.bifurcations.detect`);
    `stop(point)` ends the branch before the first point for which it returns a reason (that becomes `Branch.stop`);
    map_factory: as `Continuer`."""
    par = parameter_name if isinstance(parameter_name, Parameter) else parameter(parameter_name)
    lo, hi = sorted(float(b) for b in bounds)
    value = par.get(start.setting)
    if not lo <= value <= hi:
        raise SimulationInputError(f"orbits: the start's {par.name} = {value:g} lies outside the range {lo:g}:{hi:g}")
    continuer = Continuer(start.setting, par, start.k, start.symmetric, map_factory=map_factory)
    current, A = continuer.start(start, direction, tangent)
    branch = Branch(par, start.k, start.symmetric, [current], origin=origin)
    lam_lo, lam_hi = par.to_coordinate(lo), par.to_coordinate(hi)
    h = step
    ceiling = max_step
    while True:
        if len(branch.points) >= max_points:
            branch.stop = f"{max_points} points"
            break
        lam = current.coordinate
        t_lam = current.tangent[-1] * par.scale
        predicted = lam + h * t_lam
        target = None
        if predicted > lam_hi or predicted < lam_lo:
            target = lam_hi if predicted > lam_hi else lam_lo
            if abs(target - lam) < 1e-12:
                branch.stop = f"{par.name} bound"
                break
        history = [continuer.unknowns(p.orbit) for p in branch.points[-3:]]
        # the first step off a branch point may turn sharply (the new branch is a parabola in the parameter there)
        strict = tangent is None or len(branch.points) > 1
        outcome = continuer.advance(current, A, h, fix_coordinate=target, history=history, strict=strict)
        if outcome is None:
            ceiling = h  # the next steps stay below the step that failed (it rises again by GROWTH per point)
            h *= 0.5
            if h < min_step:
                branch.stop = (f"step below {min_step:g} at {par.name} = "
                               f"{par.from_coordinate(current.coordinate):.6g} (no convergence)")
                break
            continue
        new, A_new, ease = outcome
        found = detect(continuer, branch, current, new, A) if detect is not None else []
        reason = None
        for point in [*found, new]:
            reason = stop(point) if stop is not None else None
            if reason:
                break
            branch.points.append(point)
        if progress is not None:
            progress()
        if reason:
            branch.stop = reason
            break
        if len(branch.points) > 10 and _closes(continuer, branch.points[0], current, new):
            branch.stop = "closed loop (an isola: the branch came back to its start)"
            break
        current, A = new, A_new
        if target is not None:
            branch.stop = f"{par.name} bound"
            break
        ceiling = min(max_step, ceiling * GROWTH)
        h = min(ceiling, h * 1.5) if ease > 0 else (h * 0.7 if ease < 0 else h)
    return branch
