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
3. Branch switching at up to `switches` symmetry-breaking and period-doubling points (period multiple at most
   `max_period`), those with the fewest unstable multipliers first (the ones nearest to a stable orbit), and
   the new branches continued with detection too (not switched again).
4. The linear orbits (no impact, the sphere at rest where the walls do not reach it) on LINEAR_POINTS values of
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
from sim.orbits.setting import OrbitSetting, parameter
from sim.orbits.shooting import MAX_PERIOD_MULTIPLE, OrbitNotConverged, PeriodicOrbit, solve_orbit
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


@dataclass
class OrbitResponse:
    """The periodic orbits of one excitation level against eta, or of one eta against the level (module docstring).

    base: the setting the parameter is varied from; parameter: "eta" or "level"; bounds: its range; branches:
    the impacting branches (the start's first, then the switched ones); linear: the linear orbits (a branch without
    continuation; None where there are none); impacts: False when the walls never reach the sphere over the range;
    notes: what was tried and did not work (one line each).
    """

    base: OrbitSetting
    parameter: str
    bounds: tuple[float, float]
    branches: list[Branch] = field(default_factory=list)
    linear: Branch | None = None
    impacts: bool = True
    notes: list[str] = field(default_factory=list)

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
        failures = []
        for k in range(1, max_period + 1):
            try:
                return solve_orbit(setting, y, k=k, symmetric=False)
            except (OrbitNotConverged, SimulationDiverged) as exc:
                failures.append(f"k = {k}: {exc}")
        raise OrbitNotConverged(f"orbits: no periodic orbit of period <= {max_period} T near the simulated state at "
                                f"{name} {value:g} ({failures[-1].split(': ', 2)[-1]})")
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
                   at: float | None = None, max_period: int = 2, switches: int = 2,
                   restitution: float = DEFAULT_RESTITUTION,
                   progress: Callable[[], None] | None = None) -> OrbitResponse:
    """The periodic orbits of `base` with the parameter `name` ("eta" or "level") over `bounds` (module docstring).
    start: one of STARTS; at: the parameter value to start at (None: the start's own choice); max_period: the
    largest period multiple k of a switched branch (1..MAX_PERIOD_MULTIPLE); switches: branch switchings at most;
    restitution: the slow flow's r for the slow-flow start; progress: called once per accepted point."""
    if name not in ("eta", "level"):
        raise SimulationInputError(f"orbits: the response is continued in eta or the level, not {name!r}")
    lo, hi = check_range(name, bounds)
    if start not in STARTS:
        raise SimulationInputError(f"orbits: unknown start {start!r}; choose one of {', '.join(STARTS)}")
    if isinstance(max_period, bool) or not isinstance(max_period, int) or not 1 <= max_period <= MAX_PERIOD_MULTIPLE:
        raise SimulationInputError(f"orbits: the largest period multiple must be an integer in 1..{MAX_PERIOD_MULTIPLE}, "
                                   f"got {max_period!r}")
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
    first = continue_branch(orbit, name, (lo, hi), direction=1.0, origin=f"{start} start", detect=detect,
                            progress=progress)
    if not first.stop.startswith("closed loop"):
        back = continue_branch(orbit, name, (lo, hi), direction=-1.0, detect=detect, progress=progress)
        first.points = back.points[:0:-1] + first.points
        first.stop = f"{back.stop} / {first.stop}"
    result.branches.append(first)
    candidates = [p for p in first.points if p.label in (SYMMETRY_BREAKING, PERIOD_DOUBLING)
                  and (p.label == SYMMETRY_BREAKING or 2 * p.orbit.k <= max_period)]
    candidates.sort(key=lambda p: (outside_count(p.orbit), p.orbit.max_multiplier))
    for point in candidates[:max(0, int(switches))]:
        try:
            result.branches.append(switch_branch(point, name, (lo, hi), progress=progress))
        except (OrbitNotConverged, SimulationDiverged, SimulationInputError) as exc:
            result.notes.append(f"switching at the {point.label} at {name} {par.get(point.orbit.setting):.5g}: {exc}")
    return result


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
