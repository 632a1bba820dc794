r"""The frequency response of the periodic orbits at one level (continuation in eta) and the level curve at one eta
(continuation in the level): starts, the branches, branch switching, and the linear orbits (Sects. 5.2, 5.3 of the
seed paper, seen through the periodic solutions instead of stepped sines).

What is computed (`orbit_response`):
1. A start (`sim.orbits.starts`): "slow-flow" (default) carries the slow flow's symmetric two-impact orbit to the
   full model through the higher modes' damping (tried at up to START_TRIES parameter values of the range where
   the slow flow has one, from the low end); "simulation" runs the integrator SIMULATION_PERIODS periods from the
   stepped sine's start at `at` and solves for a kT orbit (k = 1 .. max_period) from there; "linear" starts at
   the linear orbit (only where the walls do not reach the sphere).
2. The start's branch, continued both ways over the range (once when it closes on itself).
3. Branch switching at every located symmetry-breaking and period-doubling point of every branch (period multiple
   at most `max_period`; at most `switches` switchings when given), the new branches continued with detection too
   and switched in turn, each up to where it comes back through its parent or runs onto a known branch; a point
   whose new branch is already there (`sim.orbits.searches.known`, or a switched branch came back through it) is
   not switched again.
4. At every change of stability of every branch, a direct simulation from the perturbed orbit on its unstable side
   and Newton's method from its end state for a kT orbit, k <= max_period (`sim.orbits.searches`): what it finds
   that no branch has is continued both ways as a branch of its own, up to where it runs onto a known one (and
   switched and searched from in turn).
   Steps 3 and 4 are one list of tasks, the searches first, then the switchings by their point's unstable multipliers
   (nearest to a stable orbit first), within GROWTH_RUNS map runs and MAX_BRANCHES branches: deterministic work, so
   that one level stays within its 30 s on the rig; what is left undone is said in `notes`.
5. The linear orbits (no impact, the sphere at rest where the walls do not reach it) on LINEAR_POINTS values of
   the range where they exist: they are unstable in the frictionless model (a sphere given any speed drifts into
   a wall: the multiplier 1 of its free flight is a Jordan block), but they are the response a sphere at rest
   would keep. Impacting orbits may coexist with them (the sphere's own motion drives the walls). Where no start
   converges and the linear response never reaches the clearance, the level has only these (`impacts` False).

`parameter_branch` follows the two-impact orbit in any other parameter (the higher modes' damping, r_cont, k_H) with
its bifurcations: where it loses stability, how, where it ends (the fidelity report's stability boundary).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.orbits.bifurcations import PERIOD_DOUBLING, SYMMETRY_BREAKING, detect, outside_count, switch_branch
from sim.orbits.continuation import Branch, BranchPoint, continue_branch
from sim.orbits.searches import known, search, stability_changes
from sim.orbits.setting import OrbitSetting, parameter
from sim.orbits.shooting import MAX_PERIOD_MULTIPLE, OrbitNotConverged, PeriodicOrbit, ShootingMap, solve_orbit
from sim.orbits.starts import (DEFAULT_RESTITUTION, linear_orbit, linear_wall_amplitude, simulated_state,
                               slow_flow_candidates, slow_flow_orbit, stepped_sine_state)

#: The starts of `orbit_response` (module docstring).
STARTS = ("slow-flow", "simulation", "linear")
#: Parameter values tried for the slow-flow start, and the grid they are picked from.
START_TRIES = 4
START_GRID = 21
#: Periods the "simulation" start runs before solving (the stepped sine's 3 s wait at the rig's 117 Hz: 352).
SIMULATION_PERIODS = 400
#: Values of the range at which the linear orbits are computed.
LINEAR_POINTS = 41
#: The range eta may span (the primary resonance and well beyond: the orbits near it are what is asked for).
ETA_BOUNDS = (0.5, 2.0)
#: Most branches of one response (the start's, the switched ones and the searches' finds).
MAX_BRANCHES = 16
#: A switching point lies where a switched branch came back through its parent within this share of the parameter's
#: scale (`_reached`).
REJOIN = 0.01
#: Map runs (`sim.orbits.shooting.ShootingMap.runs`) for the switchings and searches of one response, beyond its
#: first branch (steps 3-4): about 12 s of CPU on the rig (0.1 ms a run), the most promising first (`_grow`).
GROWTH_RUNS = 100_000
#: Most points of a switched branch (its stop says so when it is reached), and fewer when the budget's rest
#: (GROWTH_RUNS) would not pay for them at RUNS_PER_POINT map runs a point (measured on the rig at 7.4: 130-170): on the
#: rig the asymmetric branches from the two-impact orbit's symmetry breakings are all unstable (|mu| 3-5000) and wind
#: through folds in a few 1e-4 of eta, a bridge between two symmetry breakings taking 240-360 points, a branch up to
#: a thousand.
SWITCHED_POINTS = 400
RUNS_PER_POINT = 150


@dataclass
class StartAttempt:
    """One Newton's method of a failed "simulation" start: the period multiple k, the simulated state it started from
    and its last iterate (SI; None when the integrator failed at once), that iterate's residual (units of g) and why
    it stopped."""

    k: int
    start: np.ndarray
    last: np.ndarray | None
    residual: float
    why: str


class StartFailed(OrbitNotConverged):
    """The "simulation" start found no orbit: `attempts` (`StartAttempt`, one per k) at `setting`, for the record
    `ies orbits` writes (`sim.orbits.tables.write_start_attempts`)."""

    def __init__(self, message: str, attempts: list[StartAttempt], setting: OrbitSetting) -> None:
        super().__init__(message)
        self.attempts = attempts
        self.setting = setting


@dataclass
class OrbitResponse:
    """The periodic orbits of one excitation level against eta, or of one eta against the level (module docstring).

    base: the setting the parameter is varied from; parameter: "eta" or "level"; bounds: its range; branches:
    the impacting branches (the start's first, then the switched ones); linear: the linear orbits (a branch without
    continuation; None where there are none); impacts: False when the walls never reach the sphere over the range;
    notes: what was tried and did not work, and what each search found (one line each); searches: the direct
    simulations at the changes of stability (`sim.orbits.searches.Search`).
    """

    base: OrbitSetting
    parameter: str
    bounds: tuple[float, float]
    branches: list[Branch] = field(default_factory=list)
    linear: Branch | None = None
    impacts: bool = True
    notes: list[str] = field(default_factory=list)
    searches: list = field(default_factory=list)

    @property
    def all_branches(self) -> list[Branch]:
        """The impacting branches and the linear one (if any)."""
        return self.branches + ([self.linear] if self.linear is not None else [])


def check_range(name: str, bounds: tuple[float, float]) -> tuple[float, float]:
    """A continuation range (lo < hi, both positive; eta inside ETA_BOUNDS); one line otherwise."""
    lo, hi = (float(b) for b in bounds)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise SimulationInputError(f"orbits: the {name} range {lo:g}:{hi:g} is empty or not positive; give LO:HI with "
                                   "0 < LO < HI, e.g. 0.95:1.0")
    if name == "eta" and not (ETA_BOUNDS[0] <= lo and hi <= ETA_BOUNDS[1]):
        raise SimulationInputError(f"orbits: the eta range {lo:g}:{hi:g} leaves {ETA_BOUNDS[0]:g}..{ETA_BOUNDS[1]:g} (the "
                                   "primary resonance's neighbourhood, where the orbits of period <= 8 T are)")
    return lo, hi


def _linear_branch(base: OrbitSetting, name: str, lo: float, hi: float) -> Branch | None:
    """The linear orbits at LINEAR_POINTS values of [lo, hi] where the walls do not reach the sphere (or None)."""
    par = parameter(name)
    branch = Branch(par, 1, False, origin="linear solution")
    for value in np.linspace(lo, hi, LINEAR_POINTS):
        setting = par.set(base, float(value))
        if linear_wall_amplitude(setting) >= setting.impactor.clearance:
            continue
        orbit = linear_orbit(setting)
        branch.points.append(BranchPoint(orbit, par.to_coordinate(float(value)), np.zeros(orbit.state.size + 1)))
    return branch if branch.points else None


def _start(base: OrbitSetting, name: str, lo: float, hi: float, how: str, *, at: float | None, max_period: int,
           restitution: float, notes: list[str], progress: Callable[[], None] | None) -> PeriodicOrbit | None:
    """The starting orbit (module docstring, step 1), or None with the reasons in `notes`."""
    par = parameter(name)
    if how == "linear":
        value = at if at is not None else lo
        return linear_orbit(par.set(base, value))
    if how == "simulation":
        value = at if at is not None else 0.5 * (lo + hi)
        setting = par.set(base, value)
        if name == "eta":  # an up-sweep from the range's low end, as the stepped sine reaches the point
            y = stepped_sine_state(setting, lo)
        else:
            y = simulated_state(setting, SIMULATION_PERIODS)
        attempts = []
        for k in range(1, max_period + 1):
            try:
                return solve_orbit(setting, y, k=k, symmetric=False)
            except (OrbitNotConverged, SimulationDiverged) as exc:
                attempts.append(StartAttempt(k, y.copy(), getattr(exc, "state", None), getattr(exc, "residual", math.nan),
                                             str(exc).split(";")[0].replace("orbits: ", "")))
        best = min(attempts, key=lambda a: a.residual if math.isfinite(a.residual) else math.inf)
        raise StartFailed(f"orbits: no periodic orbit of period <= {max_period} T near the state a stepped sine "
                          f"reaches at {name} {value:g} (best: k = {best.k}, residual {best.residual:.2e} g); the response "
                          "there may not settle on a periodic orbit (ies trace --lyapunov tells); try --start slow-flow, "
                          "another --at, or a larger --max-period", attempts, setting)
    grid = [at] if at is not None else list(np.linspace(lo, hi, START_GRID))
    grid = [v for v in grid if slow_flow_candidates(par.set(base, float(v)), restitution)]
    if len(grid) > START_TRIES:  # spread over where the slow flow has an orbit, from the low end
        grid = [grid[i] for i in np.linspace(0, len(grid) - 1, START_TRIES).round().astype(int)]
    tried = 0
    for value in grid:
        setting = par.set(base, float(value))
        tried += 1
        try:
            return slow_flow_orbit(setting, restitution=restitution, progress=progress)
        except (OrbitNotConverged, SimulationDiverged) as exc:
            notes.append(f"slow-flow start at {name} {value:.5g}: {str(exc).split(';')[0]}")
    if tried == 0:
        notes.append(f"the slow flow (r = {restitution:g}) has no two-impact orbit for {name} in {lo:g}:{hi:g}")
    return None


def orbit_response(base: OrbitSetting, name: str, bounds: tuple[float, float], *, start: str = "slow-flow",
                   at: float | None = None, max_period: int = 2, switches: int | None = None, searches: bool = True,
                   restitution: float = DEFAULT_RESTITUTION, budget: int = GROWTH_RUNS,
                   progress: Callable[[], None] | None = None) -> OrbitResponse:
    """The periodic orbits of `base` with the parameter `name` ("eta" or "level") over `bounds` (module docstring).
    start: one of STARTS; at: the parameter value to start at (None: the start's own choice); max_period: the
    largest period multiple k of a switched or found branch (1..MAX_PERIOD_MULTIPLE); switches: branch switchings
    at most (None: every located one); searches: the direct simulations at the changes of stability; restitution:
    the slow flow's r for the slow-flow start; budget: map runs for the switchings and searches (steps 3-4);
    progress: called once per accepted point."""
    if name not in ("eta", "level"):
        raise SimulationInputError(f"orbits: the response is continued in eta or the level, not {name!r}")
    lo, hi = check_range(name, bounds)
    if start not in STARTS:
        raise SimulationInputError(f"orbits: unknown start {start!r}; choose one of {', '.join(STARTS)}")
    if isinstance(max_period, bool) or not isinstance(max_period, int) or not 1 <= max_period <= MAX_PERIOD_MULTIPLE:
        raise SimulationInputError(f"orbits: the largest period multiple must be an integer in 1..{MAX_PERIOD_MULTIPLE}, "
                                   f"got {max_period!r}")
    if isinstance(budget, bool) or not isinstance(budget, int) or budget < 0:
        raise SimulationInputError(f"orbits: the budget is a number of map runs >= 0, got {budget!r}")
    if at is not None and not lo <= at <= hi:
        raise SimulationInputError(f"orbits: the start's {name} {at:g} lies outside the range {lo:g}:{hi:g}")
    par = parameter(name)
    result = OrbitResponse(base, name, (lo, hi))
    result.linear = _linear_branch(base, name, lo, hi)
    orbit = _start(base, name, lo, hi, start, at=at, max_period=max_period, restitution=restitution,
                   notes=result.notes, progress=progress)
    if orbit is None:
        reach = max(linear_wall_amplitude(par.set(base, float(v))) for v in np.linspace(lo, hi, START_GRID))
        if reach < base.impactor.clearance:
            result.impacts = False
            result.notes.append(f"no impacting orbit found, and the linear response never reaches the sphere for {name} "
                                f"in {lo:g}:{hi:g} (largest wall motion {reach / base.impactor.clearance:.3g} g): the "
                                "response is the linear one")
        return result
    if orbit.linear and start != "linear":
        result.notes.append("the start converged to the linear orbit (no impacts)")
    result.branches.append(_both_ways(orbit, name, (lo, hi), f"{start} start", progress))
    _grow(result, max_period=max_period, switches=switches, searches=searches, budget=budget, progress=progress)
    return result


def _joins(name: str, others: list[Branch] | None) -> Callable[[BranchPoint], str | None]:
    """A stop for `continue_branch`: the branch ends one point after the first that lies on one of `others`
    (`sim.orbits.searches.known`), that point kept. Call `.reset()` before another continuation."""
    joined: list[str] = []

    def joins(point: BranchPoint) -> str | None:
        if joined:
            return joined.pop()
        other = known(point.orbit, others) if others else None
        if other is not None:
            joined.append(f"joins the branch {other.origin} at {name} = {parameter(name).get(point.orbit.setting):.6g}")
        return None

    joins.reset = joined.clear  # type: ignore[attr-defined]
    return joins


def _both_ways(orbit: PeriodicOrbit, name: str, bounds: tuple[float, float], origin: str,
               progress: Callable[[], None] | None, others: list[Branch] | None = None) -> Branch:
    """The branch through `orbit` continued up and then down over `bounds` (once when it closes on itself), each way
    up to where it runs onto one of `others` (`_joins`)."""
    joins = _joins(name, others)
    branch = continue_branch(orbit, name, bounds, direction=1.0, origin=origin, detect=detect, progress=progress,
                             stop=joins)
    if not branch.stop.startswith("closed loop"):
        joins.reset()
        back = continue_branch(orbit, name, bounds, direction=-1.0, detect=detect, progress=progress, stop=joins)
        branch.points = back.points[:0:-1] + branch.points
        branch.unlocated = back.unlocated + branch.unlocated
        branch.stop = f"{back.stop} / {branch.stop}"
    return branch


def _switching_points(branch: Branch, max_period: int) -> list[BranchPoint]:
    """The located symmetry-breaking and period-doubling points of a branch at which a branch of period <=
    max_period T bifurcates."""
    return [p for p in branch.points if p.label == SYMMETRY_BREAKING and p.orbit.symmetric
            or p.label == PERIOD_DOUBLING and 2 * p.orbit.k <= max_period]


def _reached(point: BranchPoint, branches: list[Branch]) -> bool:
    """Whether a switched branch already came back through its parent at this point (`Branch.rejoins`, within
    REJOIN of the parameter's scale: the located point and the branch's passage through its parent are both within
    ~1e-6 of the bifurcation in eta)."""
    par = branches[0].parameter
    value = par.to_coordinate(par.get(point.orbit.setting))
    for branch in branches:
        if branch.rejoins is not None and branch.k == point.orbit.k:
            a, b = sorted(par.to_coordinate(v) for v in branch.rejoins)
            if a - REJOIN * par.scale <= value <= b + REJOIN * par.scale:
                return True
    return False


def _grow(result: OrbitResponse, *, max_period: int, switches: int | None, searches: bool,
          progress: Callable[[], None] | None, budget: int = GROWTH_RUNS) -> None:
    """Steps 3 and 4 of the module docstring on `result`'s branches, appending the new ones: one list of tasks, the
    searches at changes of stability first, then the switchings by their point's unstable multipliers (the nearest
    to a stable orbit first), each new branch's tasks added as it comes, within `budget` map runs."""
    name, (lo, hi) = result.parameter, result.bounds
    par = parameter(name)
    tasks: list[tuple[tuple, int, str, Branch, BranchPoint, int]] = []
    searched: set[tuple[int, int, float]] = set()  # (branch, side, where in scale units) of the searches made
    switched, skipped, budget_from = 0, [], ShootingMap.runs

    def add(branch: Branch) -> None:
        for point in _switching_points(branch, max_period):
            tasks.append(((1, outside_count(point.orbit), point.orbit.max_multiplier), len(tasks), "switch", branch,
                          point, 0))
        for point, side in (stability_changes(branch) if searches else []):
            tasks.append(((0, 0, 0.0), len(tasks), "search", branch, point, side))

    for branch in result.branches:
        add(branch)
    while tasks:
        tasks.sort(key=lambda task: task[:2])
        _, _, kind, branch, point, side = tasks.pop(0)
        where = f"{name} {par.get(point.orbit.setting):.5g}"
        if kind == "switch":
            k = point.orbit.k * (2 if point.label == PERIOD_DOUBLING else 1)
            power = 2 if point.label == PERIOD_DOUBLING else 1
            if _reached(point, result.branches) or known(point.orbit, result.branches, k=k, exclude=(branch,),
                                                         max_multiplier=point.orbit.max_multiplier ** power):
                continue  # the branch it would give is there already
            if switches is not None and switched >= switches:
                result.notes.append(f"not switched at the {point.label} at {where} (--switches {switches})")
                continue
        else:
            key = (id(branch), side, round(par.to_coordinate(par.get(point.orbit.setting)) / par.scale))
            if key in searched:  # one search per branch, side and scale unit of the parameter
                continue
            searched.add(key)
        if ShootingMap.runs - budget_from >= budget or len(result.branches) >= MAX_BRANCHES:
            skipped.append(f"{'the ' + point.label if kind == 'switch' else 'a search'} at {where}")
            continue
        if kind == "switch":
            try:
                left = (budget - (ShootingMap.runs - budget_from)) // RUNS_PER_POINT
                new = switch_branch(point, name, (lo, hi), max_points=int(max(10, min(SWITCHED_POINTS, left))),
                                    progress=progress,
                                    also_stop=_joins(name, [b for b in result.branches if b is not branch]))
            except (OrbitNotConverged, SimulationDiverged, SimulationInputError) as exc:
                result.notes.append(f"switching at the {point.label} at {where}: {exc}")
                continue
            switched += 1
        else:
            outcome = search(branch, point, side, max_period, result.branches)
            result.searches.append(outcome)
            result.notes.append(outcome.note)
            if outcome.found is None:
                continue
            new = _both_ways(outcome.found, name, (lo, hi), f"simulation from {par.name} = "
                             f"{par.get(outcome.start.setting):.6g}", progress, others=list(result.branches))
        result.branches.append(new)
        add(new)
    if skipped:
        result.notes.append(f"not done ({len(skipped)}; the response's {budget:,} map runs for switchings and "
                            f"searches (--budget), or its {MAX_BRANCHES} branches, were spent): {', '.join(skipped)}")


def parameter_branch(setting: OrbitSetting, name: str, bounds: tuple[float, float], *,
                     restitution: float = DEFAULT_RESTITUTION, direction: float = -1.0,
                     progress: Callable[[], None] | None = None) -> Branch:
    """The symmetric two-impact orbit of `setting` continued in any parameter of `sim.orbits.setting.PARAMETERS`
    (the higher modes' damping, r_cont, k_H, eta, the level) over `bounds`, with its bifurcations located and
    labelled: where it loses stability, how, and where it turns back. For "higher_damping" the branch starts from
    the slow flow at the upper bound (Newton's method reaches it there, `sim.orbits.starts`) and runs down (the
    homotopy of `slow_flow_orbit`, kept whole); otherwise from the setting's orbit (`slow_flow_orbit`) along
    `direction` (+1: increasing)."""
    lo, hi = sorted(float(b) for b in bounds)
    if name == "higher_damping":
        start = slow_flow_orbit(replace(setting, higher_damping=hi), restitution=restitution, damping=(1.0,))
        return continue_branch(start, name, (lo, hi), direction=-1.0, origin="slow flow at the higher damping",
                               detect=detect, progress=progress)
    start = slow_flow_orbit(setting, restitution=restitution, progress=progress)
    return continue_branch(start, name, (lo, hi), direction=direction, origin="slow-flow start", detect=detect,
                           progress=progress)
