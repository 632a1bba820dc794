r"""Direct-simulation searches for the stable orbits that continuation and branch switching may miss (what `ies
orbits` shades as "no stable orbit" must be shown, not assumed).

At every change of stability of a branch (a located crossing or grazing that loses or gains stability, or one that
could not be located: `sim.orbits.continuation.Branch.unlocated`), the orbit SEARCH_OFFSET (in units of the
parameter's scale: 2e-3 in eta) into the unstable side is perturbed along the eigenvector of its largest multiplier
(SEARCH_PERTURBATION of g, scaled units) and simulated for SEARCH_PERIODS periods on the setting's integrator (the
response a stepped sine would settle on there); Newton's method (`sim.orbits.shooting.solve_orbit`, not restricted
to symmetric orbits) then looks for a kT orbit from the end state, k = 1 .. max_period. What it finds is reduced to
its least period, dropped when it lies on a known branch (`known`: same least period, amplitude and largest multiplier
at that parameter value, mirror images alike), and otherwise continued both ways over the range as a branch of its
own, up to where it runs onto a known branch (`sim.orbits.response`). A search that finds nothing says so in one note (the end state's residual), so the shading
is read as "no stable orbit of period <= k T found by continuation and these searches".

Why the unstable side, perturbed: at a symmetry breaking the asymmetric orbits a supercritical pitchfork gives are
stable right beyond the point, and a subcritical one sends the response away to whatever attracts it; either way the
end state of a simulation from the now unstable orbit is what the stepped sine would find. On the rig's first mode
alone at 7.4 this finds the stable asymmetric two-impact orbit beyond the symmetry breaking at eta 0.95527 (also on
the switched branch) and nothing else periodic of period <= 2 T.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.common.errors import SimulationDiverged
from sim.orbits.bifurcations import GAINS, LOSES
from sim.orbits.continuation import Branch, BranchPoint
from sim.orbits.shooting import OrbitNotConverged, PeriodicOrbit, ShootingMap, solve_orbit
from sim.orbits.starts import simulated_state

#: How far into the unstable side the search starts, in units of the parameter's scale (`Parameter.scale`).
SEARCH_OFFSET = 1.0
#: The perturbation along the leading eigenvector (scaled units: g at the walls).
SEARCH_PERTURBATION = 1e-3
#: Excitation periods simulated before Newton's method (the stepped sine's 3 s wait at the rig's 117 Hz: 352).
SEARCH_PERIODS = 400
#: An orbit lies on a known branch when its amplitude (a/a_noabs*) is within KNOWN_AMPLITUDE of the branch's there
#: and log |mu|max within KNOWN_MULTIPLIER (`known`).
KNOWN_AMPLITUDE = 1e-4
KNOWN_MULTIPLIER = 0.05
#: A kT orbit is one of period d T (d dividing k) when its d-period residual is below this (units of g).
PERIOD_RESIDUAL = 1e-7


@dataclass
class Search:
    """One search (module docstring): where it started (the branch, the point of the change of stability and the
    orbit it was simulated from), the orbit it found (None) and what became of it (one line)."""

    branch: Branch
    change: BranchPoint
    start: PeriodicOrbit
    found: PeriodicOrbit | None
    note: str


def stability_changes(branch: Branch) -> list[tuple[BranchPoint, int]]:
    """(point, side) for every change of stability of a branch, side +1 when the unstable orbits follow the point
    in branch order, -1 when they precede it: its located ones (notes LOSES / GAINS), and for each unlocated change
    the bracket's stable end."""
    changes = []
    for point in branch.points:
        if point.note.startswith(LOSES) or f"; {LOSES}" in point.note:
            changes.append((point, 1))
        elif point.note.startswith(GAINS) or f"; {GAINS}" in point.note:
            changes.append((point, -1))
    for unlocated in branch.unlocated:
        before, after = unlocated.before.orbit, unlocated.after.orbit
        if before.stable != after.stable:
            changes.append((unlocated.before, 1) if before.stable else (unlocated.after, -1))
    return changes


def _unstable_orbit(branch: Branch, point: BranchPoint, side: int) -> PeriodicOrbit:
    """The first orbit of the branch SEARCH_OFFSET (scale units) beyond `point` on its unstable side, else the
    farthest one there."""
    par = branch.parameter
    index = next(i for i, p in enumerate(branch.points) if p is point)
    here = par.to_coordinate(par.get(point.orbit.setting))
    chosen = point.orbit
    i = index + side
    while 0 <= i < len(branch.points):
        orbit = branch.points[i].orbit
        chosen = orbit
        if abs(par.to_coordinate(par.get(orbit.setting)) - here) >= SEARCH_OFFSET * par.scale:
            break
        i += side
    return chosen


def least_period(orbit: PeriodicOrbit) -> PeriodicOrbit:
    """The orbit as one of its least period: a kT orbit that repeats after d T (d dividing k) solved again as a dT
    orbit (the amplitudes of a kT solve of a T orbit are alike, its multipliers those of P_1^k)."""
    for d in range(1, orbit.k):
        if orbit.k % d:
            continue
        shooting = ShootingMap(orbit.setting, d)
        r, _ = shooting.residual(orbit.state, False)
        if float(np.max(np.abs(r))) < PERIOD_RESIDUAL:
            return solve_orbit(orbit.setting, orbit.state, k=d, symmetric=False)
    return orbit


def known(orbit: PeriodicOrbit, branches: list[Branch], *, k: int | None = None, amplitude: float | None = None,
          max_multiplier: float | None = None, exclude: tuple[Branch, ...] = ()) -> Branch | None:
    """The branch (of `branches`, less `exclude`) on which an orbit lies, or None: one of period k T (default the
    orbit's) on which, between two consecutive points around the orbit's parameter value, the interpolated amplitude
    is within KNOWN_AMPLITUDE of the orbit's and log |mu|max within KNOWN_MULTIPLIER (two different orbits rarely
    agree in both where their curves cross; mirror images agree in both, and count as known). amplitude,
    max_multiplier: the values to compare instead of the orbit's (a switched branch's at its switching point)."""
    k = orbit.k if k is None else k
    amplitude = orbit.amplitude if amplitude is None else amplitude
    log_mu = math.log(max(orbit.max_multiplier if max_multiplier is None else max_multiplier, 1e-300))
    for branch in branches:
        if branch.k != k or not branch.points or any(branch is other for other in exclude):
            continue
        value = branch.parameter.get(orbit.setting)
        values = branch.values()
        amplitudes = np.array([p.orbit.amplitude for p in branch.points])
        mus = np.log(np.maximum([p.orbit.max_multiplier for p in branch.points], 1e-300))
        if values.size == 1:
            values, amplitudes, mus = (np.repeat(a, 2) for a in (values, amplitudes, mus))
        a, b = values[:-1], values[1:]
        around = (np.minimum(a, b) <= value) & (value <= np.maximum(a, b))
        w = np.divide(value - a, b - a, out=np.zeros_like(a), where=b != a)
        close = (np.abs(amplitudes[:-1] + w * np.diff(amplitudes) - amplitude) < KNOWN_AMPLITUDE) & (
            np.abs(mus[:-1] + w * np.diff(mus) - log_mu) < KNOWN_MULTIPLIER)
        if np.any(around & close):
            return branch
    return None


def search(branch: Branch, point: BranchPoint, side: int, max_period: int,
           branches: list[Branch]) -> Search:
    """One search (module docstring) from the change of stability `point` of `branch` towards its unstable `side`,
    for orbits of period <= max_period T not on `branches`."""
    start = _unstable_orbit(branch, point, side)
    par = branch.parameter
    where = f"{par.name} {par.get(start.setting):.5g}"
    end, _ = start.jacobian
    mu, vectors = np.linalg.eig(end)
    v = np.real(vectors[:, int(np.argmax(np.abs(mu)))])
    v /= np.linalg.norm(v) or 1.0
    setting = start.setting
    try:
        y = simulated_state(setting, SEARCH_PERIODS, start.state + SEARCH_PERTURBATION * v * setting.scales())
    except SimulationDiverged as exc:
        return Search(branch, point, start, None, f"search at {where}: the simulation failed ({exc})")
    failures = []
    for k in range(1, max_period + 1):
        try:
            found = least_period(solve_orbit(setting, y, k=k, symmetric=False))
        except (OrbitNotConverged, SimulationDiverged) as exc:
            failures.append(str(exc).split(";")[0].replace("orbits: ", ""))
            continue
        if found.linear:
            return Search(branch, point, start, None, f"search at {where}: the simulation settles on the linear orbit")
        on = known(found, branches)
        if on is not None:
            return Search(branch, point, start, None, f"search at {where}: settles on a known orbit ({on.origin}, "
                                                      f"{found.k} T, a/a_noabs* {found.amplitude:.4f})")
        return Search(branch, point, start, found, f"search at {where}: found {'a stable' if found.stable else 'an unstable'}"
                                                   f" {found.k} T orbit, a/a_noabs* {found.amplitude:.4f}")
    return Search(branch, point, start, None, f"search at {where}: no orbit of period <= {max_period} T from the "
                                              f"state {SEARCH_PERIODS} periods on ({failures[-1] if failures else ''})")


__all__ = ["KNOWN_AMPLITUDE", "KNOWN_MULTIPLIER", "SEARCH_OFFSET", "SEARCH_PERIODS", "SEARCH_PERTURBATION", "Search", "known",
           "least_period", "search", "stability_changes"]
