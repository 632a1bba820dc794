r"""Bifurcations along a branch of periodic orbits (`sim.orbits.continuation`): detection from the Floquet
multipliers, their classification by the path the multipliers take, their location, and branch switching at
symmetry breaking and period doubling.

Multipliers. A symmetric orbit is a fixed point of the half map G (`sim.orbits.shooting`); its multipliers lambda
(of DG) give those of the k-period map, mu = lambda^2. The classified multipliers m are lambda on a symmetric branch
and mu otherwise (`relevant_multipliers`); how many lie outside the unit circle is `outside_count` (beyond OUTSIDE).

Classification by the path (between two accepted points a, b of a branch whose outside counts differ). Complex
multipliers of a real matrix come in conjugate pairs of equal modulus, so the count changes by one exactly when a
real multiplier crosses the circle, by two when a complex pair does:

  one real multiplier through +1     fold when the tangent's parameter component changes sign over [a, b] (a
                                     turning point), else a branch point (a transcritical or pitchfork point of the
                                     map: another branch crosses);
  one real multiplier through -1     on a symmetric branch (lambda of G): symmetry breaking (mu = +1 through an
                                     antisymmetric eigenvector: a pitchfork of P_k from which a pair of mirror-image
                                     asymmetric kT orbits branches); on any other branch: period doubling (a 2kT
                                     orbit branches);
  a complex pair                     Neimark-Sacker (a torus: the door to modulated response), at any angle;
  a jump where an impact appears     grazing: the impacts per k periods change, and with them the map's derivative
  or vanishes                        (the Hertz contact's square-root singularity at zero approach speed), so the
                                     multipliers may jump across the unit circle there; such a jump is a grazing,
                                     never one of the above.

Symmetric orbits have no generic period doubling (mu = -1 needs lambda = +-i, codimension two): they break their
symmetry instead, which is why they are solved with G (the system with P_k would be singular there). The path
matters on nearly conservative hosts: on the rig's first mode alone the complex pair of lambda sits at modulus
0.9998, meets on the negative real axis and splits into two real multipliers, one of which crosses -1; the
multiplier nearest to the circle there is complex a hair before the crossing, and only the count (one multiplier
out) tells a symmetry breaking from a Neimark-Sacker point.

Location. A crossing is located by Brent's method (scipy's brentq) on the arclength s from a, each trial a
pseudo-arclength step from a along its tangent, until |mu| of the crossing multiplier lies within MU_TOLERANCE of 1
(|mu| = |lambda|^2 on a symmetric branch). A real crossing at +-1 is located on det(J -+ I)^(1/n) (J the matrix of
the classified multipliers), a complex pair on log |m| - log OUTSIDE of its modulus: both change sign over [a, b]
and are continuous in s. The determinant, because the multiplier itself is not smooth where it matters: on a lightly
damped host (the rig's first mode alone) the pair collides on the real axis at |lambda| = 0.9998 and one real
multiplier reaches -1 some 3e-9 of arclength later, while near the collision the multipliers move by the square root
of the Jacobian's error. Several crossings in one interval are located one after the other. A grazing is located by
bisection and the secant on the smallest free-flight gap of the orbits without the new impact
(`sim.orbits.shooting.ShootingMap.clearance`: linear in s near a grazing), until that gap is below GRAZING_TOLERANCE
g; the crossings on either side of it are then located apart. The multipliers may jump at a grazing (the Hertz
contact's force is C^1, but near zero approach speed the map's derivative changes within 1e-9 g): the orbits just
beyond it whose Jacobians had to straddle it (`PeriodicOrbit.at_grazing`) or whose |mu|max moves JUMP_RATE times as
fast as before it make up its jump (`_absorb_jump`), and a change of stability inside the jump is the grazing's
(its note: "loses stability at the grazing", with |mu|max on either side), never labelled otherwise. A change that
is not located within LOCATION_STEPS (GRAZING_STEPS) trials, or whose multiplier misses the tolerance, is not
labelled: the branch keeps one line for it in `Branch.unlocated`, and the figure draws no marker. A located point is
inserted into the branch with its label, its `location_error` (| |mu| - 1 |, or the gap over g) and a note: "loses
stability" / "gains stability" when a stable orbit becomes unstable or the reverse (crossings of already unstable
orbits are labelled too: they change the unstable manifold, not the stability).

Branch switching (`switch_branch`): at a located symmetry breaking the new branch is a fixed point of P_k (not of
G) through the point, tangent to the eigenvector v of DG at lambda = -1; at a period doubling one of P_{2k},
tangent to the eigenvector of DP_k at mu = -1. Its first step goes along (v, 0) in the scaled unknowns, and the
pseudo-arclength constraint v . (u - u_p) = 0 keeps the corrector off the old branch (which is orthogonal to v
at the point); that first step is short (SWITCH_STEP) and exempt from the drift and turn limits of the step
control (`sim.orbits.continuation`), since the new branch bends towards the parameter right away. The old branch
also meets that hyperplane (a distance ~ sqrt(step) away), so every point of the new branch is checked against
its parent: its offset v . (parent map(y) - y) (G for a symmetry breaking, P_k for a period doubling; from the
orbit's own run) must exceed PARENT_OFFSET g and keep its sign. A first point on the parent is retried with other
steps and the other direction; a sign change later means that the branch has come back through the parent orbit
(the other end of an asymmetric bridge between two symmetry-breaking points, or the vertex of the pitchfork's
parabola, past which lie the mirror images): the branch ends there.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.orbits.continuation import Branch, BranchPoint, Continuer, Unlocated, continue_branch
from sim.orbits.setting import Parameter
from sim.orbits.setting import parameter as continuation_parameter
from sim.orbits.shooting import MAX_PERIOD_MULTIPLE, PeriodicOrbit, ShootingMap, make_orbit

FOLD = "fold"
SYMMETRY_BREAKING = "symmetry-breaking"
PERIOD_DOUBLING = "period-doubling"
NEIMARK_SACKER = "neimark-sacker"
BRANCH_POINT = "branch-point"
GRAZING = "grazing"
#: Every label of a point (besides "" for none), in the output's words.
LABELS = (FOLD, SYMMETRY_BREAKING, PERIOD_DOUBLING, NEIMARK_SACKER, BRANCH_POINT, GRAZING)
#: The labels at which a new branch is switched to.
SWITCHING = (SYMMETRY_BREAKING, PERIOD_DOUBLING)
LOSES, GAINS = "loses stability", "gains stability"
#: A multiplier counts as outside the unit circle beyond this modulus: the finite-difference multipliers' accuracy
#: (4e-6 relative on the rig, `sim.orbits.shooting`), so that a multiplier hugging the circle within it (a nearly
#: neutral pair on a lightly damped host: the rig's first mode alone keeps |mu| within 2e-5 of 1 near its folds)
#: does not cross back and forth on the finite differences' noise.
OUTSIDE = 1.0 + 1e-5
#: A located crossing: |mu| within this of 1.
MU_TOLERANCE = 1e-4
#: A located grazing: the smallest free-flight gap of the orbit without the new impact below this (units of g).
GRAZING_TOLERANCE = 1e-9
#: Most trials (pseudo-arclength steps) to locate a crossing, and a grazing.
LOCATION_STEPS = 40
GRAZING_STEPS = 80
#: Most crossings located between two accepted points.
MAX_CROSSINGS = 4
#: A crossing next to a grazing is part of the grazing's jump when log |mu|max changes at least this many times as
#: fast as on the grazing's other side (`_absorb_jump`): on the rig's first mode alone |mu| falls from 41.6 to
#: 0.9998 within 2e-7 in eta beyond the grazing at 0.9838 (1e4 times as fast as before it); the toy with the same
#: square-root law (tests/sim/orbits/_toys.py) 1e4.
JUMP_RATE = 100.0
#: A grazing's jump is looked for over this many points of the branch on either side of it.
JUMP_WINDOW = 50
#: The note of a crossing folded into a grazing's jump.
IN_JUMP = "in the multipliers' jump at the grazing"
#: A multiplier counts as real when its imaginary part is below this share of its modulus.
REAL = 1e-9
#: First step off a symmetry-breaking or period-doubling point (scaled units): the new branch's amplitude grows
#: like the square root of the parameter's distance, with a cubic coefficient as large as the maps' derivatives
#: (on the rig a step of 1e-3 along the eigenvector already leaves Newton's basin, 1e-4 converges); the other
#: first steps tried when the first lands on the parent branch.
SWITCH_STEP = 1e-4
SWITCH_STEPS = (SWITCH_STEP, 1e-3, 1e-5)
#: A switched branch's orbit lies off its parent when its offset (module docstring) exceeds this (units of g):
#: the parent's own residual is below 1e-7 (`sim.orbits.shooting.NOISE_FLOOR`), the new branch's first point
#: ~2 SWITCH_STEP away.
PARENT_OFFSET = 1e-6


def relevant_multipliers(orbit: PeriodicOrbit) -> np.ndarray:
    """The multipliers whose crossings are classified: lambda of G for a symmetric orbit, mu of P_k otherwise; a
    linear orbit's neutral sphere (the two multipliers at 1) left out."""
    m = orbit.half_multipliers if orbit.symmetric else orbit.multipliers
    if orbit.linear:
        m = m[np.abs(m - 1.0) > 1e-6]
    return m


def outside_count(orbit: PeriodicOrbit) -> int:
    """How many multipliers lie outside the unit circle (`relevant_multipliers`, pairs counted twice)."""
    return int(np.sum(np.abs(relevant_multipliers(orbit)) > OUTSIDE))


def _by_modulus(orbit: PeriodicOrbit) -> np.ndarray:
    """The relevant multipliers by decreasing modulus."""
    m = relevant_multipliers(orbit)
    return m[np.argsort(-np.abs(m), kind="stable")]


def _power(orbit: PeriodicOrbit) -> int:
    """mu = m^power: 2 for lambda of a symmetric orbit, else 1."""
    return 2 if orbit.symmetric else 1


def _impacts(point: BranchPoint) -> int:
    return int(np.sum(point.orbit.impacts))


@dataclass
class _Trials:
    """The points a location computed, by their arclength s from its start point (for the brackets)."""

    start: BranchPoint
    continuer: Continuer
    points: dict[float, BranchPoint] = field(default_factory=dict)

    def at(self, s: float) -> BranchPoint:
        """The point at arclength s from the start (SimulationDiverged where the corrector fails)."""
        if s not in self.points:
            outcome = self.continuer.advance(self.start, None, s, strict=False)
            if outcome is None:
                raise SimulationDiverged("orbits: no orbit at this arclength")
            self.points[s] = outcome[0]
        return self.points[s]


class _Found(Exception):
    """Raised inside brentq when a trial meets the location's tolerance."""

    def __init__(self, s: float) -> None:
        super().__init__(s)
        self.s = s


def _relevant_matrix(orbit: PeriodicOrbit) -> np.ndarray:
    """The scaled matrix whose eigenvalues are `relevant_multipliers`: DG = -DF_half (symmetric) or DP_k."""
    end, half = orbit.jacobian
    return -half if orbit.symmetric else end


def _crossing(trials: _Trials, s_a: float, s_b: float, index: int, real: float | None) -> float | None:
    """The arclength in (s_a, s_b) where the index-th largest multiplier crosses the circle (module docstring:
    Location), or None when it is not located. real: +-1 for a real multiplier crossing there, None for a complex
    pair. A real crossing is located on det(J - real I) (its n-th root, with its sign): a polynomial in the
    Jacobian's entries, smooth where the multiplier itself is not (just after two real multipliers have split off a
    complex pair its computed value is as uncertain as the square root of the Jacobian's error); a complex pair on
    log |m| of its modulus, less log OUTSIDE."""

    def test(s: float) -> float:
        point = trials.at(s)
        m = _by_modulus(point.orbit)
        if real is None:
            crossing = m[index]
        else:
            on_axis = m[np.abs(m.imag) <= REAL * np.abs(m)]
            crossing = on_axis[np.argmin(np.abs(on_axis - real))] if on_axis.size else m[index]
        if abs(abs(crossing) ** _power(point.orbit) - 1.0) < MU_TOLERANCE and 0.0 < s:
            raise _Found(s)
        if real is None:
            return math.log(max(abs(crossing), 1e-300)) - math.log(OUTSIDE)
        J = _relevant_matrix(point.orbit)
        sign, logdet = np.linalg.slogdet(J - real * np.eye(J.shape[0]))
        return float(sign * math.exp(logdet / J.shape[0]))

    try:
        f_a, f_b = test(s_a), test(s_b)
        if f_a * f_b > 0:
            return None
        brentq(test, s_a, s_b, xtol=1e-15 * max(s_b, 1e-300), maxiter=LOCATION_STEPS)
    except _Found as found:
        return found.s
    except (SimulationDiverged, RuntimeError, ValueError):
        return None
    return None


def _label(orbit: PeriodicOrbit, real: float | None, turned: bool) -> tuple[str, int]:
    """(label, how many multipliers crossed) of a located crossing: `real` +-1 for a real multiplier (the outside
    count changed by one), None for a complex pair; `turned` True when the tangent's parameter component changed
    sign over the interval (module docstring: Classification)."""
    if real is None:
        return NEIMARK_SACKER, 2
    if real > 0:
        return (FOLD if turned else BRANCH_POINT), 1
    return (SYMMETRY_BREAKING if orbit.symmetric else PERIOD_DOUBLING), 1


def _location_error(orbit: PeriodicOrbit, index: int, real: float | None) -> float:
    """|mu| - 1 of the crossing multiplier at a located point (the real one nearest to `real`, or the index-th)."""
    m = _by_modulus(orbit)
    if real is not None:
        on_axis = m[np.abs(m.imag) <= REAL * np.abs(m)]
        if on_axis.size:
            return float(abs(abs(on_axis[np.argmin(np.abs(on_axis - real))]) ** _power(orbit) - 1.0))
    return float(abs(abs(m[index]) ** _power(orbit) - 1.0))


def _crossings(continuer: Continuer, a: BranchPoint, b: BranchPoint, branch: Branch) -> list[BranchPoint]:
    """The located crossings between a and b (same impacts; module docstring), in arclength order."""
    found: list[BranchPoint] = []
    target = outside_count(b.orbit)
    turned = bool(np.sign(a.tangent[-1]) != np.sign(b.tangent[-1]))
    current = a
    for _ in range(MAX_CROSSINGS):
        count = outside_count(current.orbit)
        if count == target:
            break
        total = float(np.linalg.norm(continuer.unknowns(b.orbit) - continuer.unknowns(current.orbit)))
        trials = _Trials(current, continuer, {0.0: current, total: b})
        index = count if target > count else count - 1
        outside = b if target > count else current  # the end where the crossing multiplier is out
        m = _by_modulus(outside.orbit)[index]
        real = None if (abs(target - count) >= 2 and abs(m.imag) > REAL * abs(m)) else math.copysign(1.0, m.real)
        s = _crossing(trials, 0.0, total, index, real) if total > 0 else None
        if s is None:
            branch.unlocated.append(Unlocated(f"{count} -> {target} multipliers outside the unit circle between "
                                              f"{_where(branch, current)} and {_where(branch, b)} (not located)",
                                              current, b))
            break
        point = trials.points[s]
        label, crossed = _label(point.orbit, real, turned)
        if label == FOLD:
            turned = False  # one turning point per interval
        after = count + crossed if target > count else count - crossed
        point.label = label
        point.location_error = _location_error(point.orbit, index, real)
        point.note = LOSES if count == 0 and after > 0 else GAINS if after == 0 and count > 0 else ""
        found.append(point)
        beyond = [t for t in sorted(trials.points) if t > s and outside_count(trials.points[t].orbit) == after]
        current = trials.points[beyond[0]] if beyond else b
        if current is b:
            if after != target:
                branch.unlocated.append(Unlocated(f"{after} -> {target} multipliers outside the unit circle between "
                                                  f"{_where(branch, point)} and {_where(branch, b)} (not located)",
                                                  point, b))
            break
    if turned and not any(p.label == FOLD for p in found) and outside_count(a.orbit) == target:
        found.extend(_fold_without_crossing(continuer, a, b, branch))
    return found


def _fold_without_crossing(continuer: Continuer, a: BranchPoint, b: BranchPoint, branch: Branch) -> list[BranchPoint]:
    """A turning point whose multiplier at +1 did not change the outside count (it came back within the interval):
    located by Brent's method on the tangent's parameter component, labelled when a real multiplier lies within
    MU_TOLERANCE of +1 there."""
    total = float(np.linalg.norm(continuer.unknowns(b.orbit) - continuer.unknowns(a.orbit)))
    trials = _Trials(a, continuer, {0.0: a, total: b})

    def at_one(point: BranchPoint) -> float:
        m = relevant_multipliers(point.orbit)
        real = m[np.abs(m.imag) <= REAL * np.abs(m)].real
        return float(np.min(np.abs(real ** _power(point.orbit) - 1.0))) if real.size else math.inf

    def test(s: float) -> float:
        point = trials.at(s)
        if at_one(point) < MU_TOLERANCE and s > 0:
            raise _Found(s)
        return float(point.tangent[-1])

    try:
        brentq(test, 0.0, total, xtol=1e-14 * total, maxiter=LOCATION_STEPS)
    except _Found as found:
        point = trials.points[found.s]
        point.label, point.location_error = FOLD, at_one(point)
        return [point]
    except (SimulationDiverged, RuntimeError, ValueError):
        pass
    branch.unlocated.append(Unlocated(f"turning point between {_where(branch, a)} and {_where(branch, b)} (not "
                                      "located)", a, b))
    return []


def _grazing(continuer: Continuer, a: BranchPoint, b: BranchPoint,
             branch: Branch) -> tuple[BranchPoint, BranchPoint] | None:
    """(the orbit at the grazing on the side without the new impact, the first one with it) between a and b, whose
    impacts differ (module docstring: Location), or None when it is not located (then one line in
    `branch.unlocated`)."""
    total = float(np.linalg.norm(continuer.unknowns(b.orbit) - continuer.unknowns(a.orbit)))
    trials = _Trials(a, continuer, {0.0: a, total: b})
    a_free = _impacts(a) < _impacts(b)
    side_a = _impacts(a)

    def gap(point: BranchPoint) -> float:
        return continuer.shooting(point.coordinate).clearance(point.orbit.state)

    lo, hi = 0.0, total  # lo: a's side (a's impacts), hi: b's side
    free: list[tuple[float, float]] = []  # (s, gap) of the free side's trials, newest last
    first_gap = gap(a if a_free else b)
    free.append((0.0 if a_free else total, first_gap))
    for _ in range(GRAZING_STEPS):
        s_free, g_free = free[-1]
        if g_free < GRAZING_TOLERANCE:
            free_point = trials.points[s_free]
            other = trials.points[hi if a_free else lo]
            free_point.label, free_point.location_error = GRAZING, g_free
            break
        if len(free) >= 2 and free[-1][1] != free[-2][1]:  # the secant on the free side's gap, aimed just short
            (s1, g1), (s2, g2) = free[-2], free[-1]
            s = s2 + (0.3 * GRAZING_TOLERANCE - g2) * (s2 - s1) / (g2 - g1)
        else:
            s = 0.5 * (lo + hi)
        width = hi - lo
        s = min(max(s, lo + 1e-3 * width), hi - 1e-3 * width) if width > 0 else s
        if not (lo < s < hi):
            s = 0.5 * (lo + hi)
        try:
            point = trials.at(s)
        except SimulationDiverged:
            branch.unlocated.append(Unlocated(f"impacts change between {_where(branch, a)} and {_where(branch, b)} "
                                              "(grazing not located: no orbit found between them)", a, b))
            return None
        if _impacts(point) == side_a:
            lo = s
        else:
            hi = s
        if (_impacts(point) == side_a) == a_free:
            free.append((s, gap(point)))
        elif len(free) >= 2:
            free = free[-1:]  # the secant overshot: bisect once, then aim again from the nearest free point
    else:
        smallest = min(g for _, g in free)
        branch.unlocated.append(Unlocated(f"impacts change between {_where(branch, a)} and {_where(branch, b)} "
                                          f"(grazing not located: smallest gap {smallest:.1e} g)", a, b))
        return None
    free_point.note = f"{_impacts(a)} -> {_impacts(b)} impacts per {a.orbit.k} T"
    return (free_point, other) if a_free else (other, free_point)


def _stable_beside(point: BranchPoint, after: bool) -> bool:
    """Whether the orbits just after (or before) a point of a branch are stable: for a located crossing from its
    note (LOSES: stable before it, GAINS: stable after it; none: unstable on both sides), else its own orbit's."""
    if point.label and point.label != GRAZING:
        return point.note == (GAINS if after else LOSES)
    return point.orbit.stable


def _absorb_jump(continuer: Continuer, sequence: list[BranchPoint], i: int, branch: Branch) -> None:
    """Fold the changes of stability in the multipliers' jump at the located grazing sequence[i] into it (module
    docstring). The reference: the nearest orbit without the new impact whose Jacobian did not straddle the
    grazing (`PeriodicOrbit.at_grazing`), and its own rate of change of log |mu|max (at least 1 per unit of
    arclength). The jump: the orbits with the new impact out to the last one that either straddled the grazing
    too or whose log |mu|max differs from the reference's at least JUMP_RATE times as fast. Its located crossings
    lose their label (note IN_JUMP), its unlocated changes are dropped, and the grazing's note says whether the
    orbits lose or gain stability across it, with |mu|max on either side. `sequence`: the branch's points in
    arclength order."""
    graze = sequence[i]
    out = 1 if i + 1 < len(sequence) and _impacts(sequence[i + 1]) != _impacts(graze) else -1
    inside = lambda j: 0 <= j < len(sequence)  # noqa: E731
    if not inside(i + out):
        return
    impacting = _impacts(sequence[i + out])
    distance = lambda p, q: float(np.linalg.norm(continuer.unknowns(p.orbit) - continuer.unknowns(q.orbit)))  # noqa: E731
    log_mu = lambda p: math.log(max(p.orbit.max_multiplier, 1e-300))  # noqa: E731
    free = [j for j in range(i, -1, -1) if inside(j)] if out > 0 else [j for j in range(i, len(sequence))]
    free = [j for j in free if _impacts(sequence[j]) == _impacts(graze) and not sequence[j].orbit.at_grazing
            and not (sequence[j].label and sequence[j].label != GRAZING)][:2]
    reference = sequence[free[0]] if free else graze
    free_rate = 1.0
    if len(free) == 2 and distance(reference, sequence[free[1]]) > 0:
        other = sequence[free[1]]
        free_rate = max(free_rate, abs(log_mu(reference) - log_mu(other)) / distance(reference, other))
    walk, j = [], i + out
    while inside(j) and _impacts(sequence[j]) == impacting and sequence[j].label != GRAZING and len(walk) < JUMP_WINDOW:
        walk.append(j)
        j += out

    def in_jump(point: BranchPoint) -> bool:
        d = distance(reference, point)
        return point.orbit.at_grazing or d > 0 and abs(log_mu(point) - log_mu(reference)) / d >= JUMP_RATE * free_rate

    fast = [j for j in walk if in_jump(sequence[j])]
    jump = walk[:walk.index(fast[-1]) + 1] if fast else []
    for j in jump:
        point = sequence[j]
        if point.label:
            point.label, point.note, point.location_error = "", IN_JUMP, math.nan
    members = {id(sequence[j]) for j in [i, *jump]} | {id(reference)}
    branch.unlocated[:] = [u for u in branch.unlocated if not {id(u.before), id(u.after)} <= members]
    beyond = jump[-1] + out if jump else i + out
    if not (inside(beyond) and _impacts(sequence[beyond]) == impacting):
        beyond -= out
    beyond_point = sequence[beyond]
    if beyond_point.label:  # a crossing right past the jump: the orbits before it
        stable_beyond = _stable_beside(beyond_point, out < 0)
    else:
        stable_beyond = beyond_point.orbit.stable
    was, now = (reference.orbit.stable, stable_beyond) if out > 0 else (stable_beyond, reference.orbit.stable)
    mu = (reference.orbit.max_multiplier, beyond_point.orbit.max_multiplier)[::1 if out > 0 else -1]
    graze.note = graze.note.split("; ")[0]
    if was != now:
        graze.note += f"; {LOSES if was else GAINS} at the grazing (|mu|max {mu[0]:.4g} -> {mu[1]:.4g})"


def _where(branch: Branch, point: BranchPoint) -> str:
    return f"{branch.parameter.name} {branch.parameter.get(point.orbit.setting):.6g}"


def _between(continuer: Continuer, branch: Branch, a: BranchPoint, b: BranchPoint) -> list[BranchPoint]:
    """The located grazings and crossings between a and b in arclength order (a or b itself when it is one)."""
    if _impacts(a) != _impacts(b):
        grazing = _grazing(continuer, a, b, branch)
        if grazing is None:
            return []
        before, after = grazing  # the located pair: a's side's orbit, then b's side's
        return [*_between(continuer, branch, a, before), before, after, *_between(continuer, branch, after, b)]
    if outside_count(a.orbit) != outside_count(b.orbit) or (
            np.sign(a.tangent[-1]) != np.sign(b.tangent[-1]) and a.tangent[-1] != 0.0):
        return _crossings(continuer, a, b, branch)
    return []


def detect(continuer: Continuer, branch: Branch, previous: BranchPoint, new: BranchPoint,
           A: np.ndarray | None = None) -> list[BranchPoint]:
    """The located bifurcation points between two accepted points of a branch (module docstring), in the order of
    the arclength, with the grazings' jumps folded in (`_absorb_jump`, over the last JUMP_WINDOW points). The
    callback of `continue_branch`; a located end point is labelled in place instead of returned."""
    found = [p for p in _between(continuer, branch, previous, new) if p is not previous and p is not new]
    if any(p.label == GRAZING for p in (*branch.points[-JUMP_WINDOW:], *found, new)):
        sequence = [*branch.points, *found, new]
        for i in range(max(0, len(sequence) - len(found) - 1 - JUMP_WINDOW), len(sequence)):
            if sequence[i].label == GRAZING:
                _absorb_jump(continuer, sequence, i, branch)
    return found


def parent_residual(orbit: PeriodicOrbit, parent: str) -> np.ndarray:
    """G(y) - y (parent "symmetric": the branch was switched at a symmetry breaking) or P_k(y) - y with k half the
    orbit's (parent "half-period": at a period doubling), scaled (units of g), from the orbit's own run
    (`half_state`): zero on the parent branch (module docstring)."""
    image = -orbit.half_state if parent == "symmetric" else orbit.half_state
    return (image - orbit.state) / orbit.setting.scales()


def switch_branch(point: BranchPoint, parameter_name: str | Parameter, bounds: tuple[float, float], *,
                  step: float | None = None, max_points: int = 1500, progress: Callable[[], None] | None = None,
                  detect_bifurcations: bool = True, map_factory: Callable[..., ShootingMap] = ShootingMap,
                  also_stop: Callable[[BranchPoint], str | None] | None = None) -> Branch:
    """The branch that bifurcates at a located symmetry breaking or period doubling `point` (module docstring),
    continued in `parameter_name` within `bounds`; it ends where it comes back through its parent orbit, or where
    `also_stop` (as `continue_branch`'s stop) says. SimulationInputError for another label or a period multiple
    beyond MAX_PERIOD_MULTIPLE; SimulationDiverged when no first step leaves the parent branch."""
    orbit = point.orbit
    end, half = orbit.jacobian
    if point.label == SYMMETRY_BREAKING and orbit.symmetric:
        lam, vectors = np.linalg.eig(-half)
        k, origin, parent = orbit.k, "symmetry breaking", "symmetric"
    elif point.label == PERIOD_DOUBLING:
        lam, vectors = np.linalg.eig(end)
        k, origin, parent = 2 * orbit.k, "period doubling", "half-period"
    else:
        raise SimulationInputError(f"orbits: no branch switching at a point labelled {point.label!r}")
    if k > MAX_PERIOD_MULTIPLE:
        raise SimulationInputError(f"orbits: period doubling to {k} T exceeds the largest period multiple "
                                   f"{MAX_PERIOD_MULTIPLE}")
    v = np.real(vectors[:, int(np.argmin(np.abs(lam + 1.0)))])
    v /= np.linalg.norm(v)
    shooting = map_factory(orbit.setting, k)
    start = make_orbit(shooting, orbit.state, False)
    par = parameter_name if isinstance(parameter_name, Parameter) else continuation_parameter(parameter_name)
    where = f"{par.name} = {par.get(orbit.setting):.6g}"
    parent_name = "symmetric orbit" if parent == "symmetric" else f"{orbit.k} T orbit"
    for sign in (1.0, -1.0):
        for first in ((step,) if step is not None else SWITCH_STEPS):
            last: list = []  # the last accepted point's residual and parameter value

            def stop(p: BranchPoint, last: list = last) -> str | None:
                r, value = parent_residual(p.orbit, parent), par.get(p.orbit.setting)
                if not last and np.max(np.abs(r)) < PARENT_OFFSET:
                    return "on the parent"
                if last and float(r @ last[0]) < 0.0:  # r turned round: the branch passed through its parent
                    last.append(value)
                    return f"rejoins the {parent_name} between {par.name} = {last[1]:.6g} and {value:.6g}"
                last[:] = [r, value]
                return also_stop(p) if also_stop is not None else None

            branch = continue_branch(start, par, bounds, tangent=np.append(sign * v, 0.0), step=first,
                                     max_points=max_points, origin=f"{origin} at {where}", progress=progress,
                                     detect=detect if detect_bifurcations else None, stop=stop,
                                     map_factory=map_factory)
            if len(branch.points) > 1 and branch.stop != "on the parent":
                branch.rejoins = (last[1], last[2]) if len(last) == 3 else None
                return branch
    raise SimulationDiverged(f"orbits: every first step off the {origin} at {where} fell back onto the parent branch")


__all__ = ["BRANCH_POINT", "FOLD", "GAINS", "GRAZING", "IN_JUMP", "LABELS", "LOSES", "NEIMARK_SACKER", "PERIOD_DOUBLING",
           "SWITCHING", "SYMMETRY_BREAKING", "detect", "outside_count", "parent_residual", "relevant_multipliers",
           "switch_branch"]
