r"""Bifurcations along a branch of periodic orbits (`sim.orbits.continuation`): detection from the Floquet
multipliers and the tangent, location, labels, and branch switching at symmetry breaking and period doubling.

Multipliers. A symmetric orbit is a fixed point of the half map G (`sim.orbits.shooting`); its multipliers lambda
(of DG) give those of the k-period map, mu = lambda^2. Where a multiplier leaves or enters the unit circle:

  on a symmetric branch (lambda):       +1 fold (of the symmetric orbit),
                                         -1 symmetry breaking (mu = +1 through an antisymmetric eigenvector: a
                                            pitchfork of P_k from which an asymmetric pair of kT orbits branches),
                                         e^{+-i theta} Neimark-Sacker (a torus: the door to modulated response);
  on any other branch (mu of P_k):      +1 fold (or branch point), -1 period doubling (a 2kT orbit branches),
                                         e^{+-i theta} Neimark-Sacker.

Symmetric orbits have no generic period doubling (mu = -1 needs lambda = +-i, codimension two): they break their
symmetry instead, which is why they are solved with G (the system with P_k would be singular there).

Detection between two accepted points a, b of a branch:
* fold: the parameter component of the tangent changes sign (exact for a quadratic turning point);
* a multiplier crossing: the number of multipliers outside the unit circle (pairs counted twice) changes; the
  crossing is located by the secant method on log |m| of the multiplier nearest to the circle, from a by
  pseudo-arclength steps along a's tangent, to |log |m|| < LOCATION_TOLERANCE or LOCATION_STEPS steps; its label
  comes from that multiplier at the located point: real and positive (+1 without a fold: a branch point), real
  and negative (-1), or one of a complex pair (Neimark-Sacker, at any angle);
* grazing (an impact appears or vanishes): the number of contact onsets over the k periods changes; located
  by bisection to LOCATION_STEPS halvings.
A located point is inserted between a and b with its label. Crossings of already unstable orbits are labelled
too (they change the orbit's unstable manifold, not its stability); `loses_stability` marks the ones where a
stable orbit becomes unstable.

Branch switching (`switch_branch`): at a symmetry breaking point the new branch is a fixed point of P_k (not of
G) through the point, tangent to the eigenvector v of DG at lambda = -1; at a period doubling one of P_{2k},
tangent to the eigenvector of DP_k at mu = -1. Its first step goes along (v, 0) in the scaled unknowns, and the
pseudo-arclength constraint v . (u - u_p) = 0 keeps the corrector off the old branch (which is orthogonal to v
at the point); that first step is short (SWITCH_STEP) and exempt from the drift and turn limits of the step
control (`sim.orbits.continuation`), since the new branch bends towards the parameter right away.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from sim.common.errors import SimulationInputError
from sim.orbits.continuation import Branch, BranchPoint, Continuer, continue_branch
from sim.orbits.setting import parameter as continuer_parameter
from sim.orbits.shooting import MAX_PERIOD_MULTIPLE, PeriodicOrbit, ShootingMap, make_orbit

FOLD = "fold"
SYMMETRY_BREAKING = "symmetry-breaking"
PERIOD_DOUBLING = "period-doubling"
NEIMARK_SACKER = "neimark-sacker"
BRANCH_POINT = "branch-point"
GRAZING = "grazing"
#: Every label of a point (besides "" for none), in the output's words.
LABELS = (FOLD, SYMMETRY_BREAKING, PERIOD_DOUBLING, NEIMARK_SACKER, BRANCH_POINT, GRAZING)
#: A multiplier counts as outside the unit circle beyond this modulus (the finite differences' accuracy).
OUTSIDE = 1.0 + 1e-6
#: Location of a crossing: |log |m|| below this, or this many secant / bisection steps.
LOCATION_TOLERANCE = 1e-3
LOCATION_STEPS = 5
#: A multiplier counts as real when its imaginary part is below this share of its modulus.
REAL = 1e-9
#: First step off a symmetry-breaking or period-doubling point (scaled units): the new branch's amplitude grows
#: like the square root of the parameter's distance, with a cubic coefficient as large as the maps' derivatives
#: (on the rig a step of 1e-3 along the eigenvector already leaves Newton's basin, 1e-4 converges).
SWITCH_STEP = 1e-4


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


def nearest_to_circle(orbit: PeriodicOrbit) -> complex:
    """The multiplier (`relevant_multipliers`) nearest to the unit circle in |log |m||."""
    m = relevant_multipliers(orbit)
    return complex(m[np.argmin(np.abs(np.log(np.abs(m) + 1e-300)))])


def crossing_label(orbit: PeriodicOrbit, multiplier: complex) -> str:
    """The label of a multiplier crossing the unit circle at `orbit` (module docstring): a real one (a real matrix'
    eigenvalue without an imaginary part) at +1 or -1, else a complex pair: Neimark-Sacker, whatever its angle (the
    slow pair of the rig's orbits crosses at angles of 0.1 rad)."""
    if abs(multiplier.imag) > REAL * abs(multiplier):
        return NEIMARK_SACKER
    if multiplier.real > 0:
        return BRANCH_POINT
    return SYMMETRY_BREAKING if orbit.symmetric else PERIOD_DOUBLING


def _insert(continuer: Continuer, previous: BranchPoint, new: BranchPoint, A: np.ndarray, total: float,
            test: Callable[[BranchPoint], float], secant: bool) -> BranchPoint | None:
    """The point between `previous` (s = 0) and `new` (s = total, arclength) where test changes sign, by the
    secant method (Illinois' variant of regula falsi) or bisection on s, each trial a pseudo-arclength step from
    `previous` along its tangent; the trial with the smallest |test| (None if no step converges)."""
    lo, hi = 0.0, total
    f_lo, f_hi = test(previous), test(new)
    best, best_f = None, math.inf
    side = 0
    for _ in range(LOCATION_STEPS):
        if secant and f_hi != f_lo:
            s = hi - f_hi * (hi - lo) / (f_hi - f_lo)
            s = min(max(s, lo + 0.01 * (hi - lo)), hi - 0.01 * (hi - lo))
        else:
            s = 0.5 * (lo + hi)
        outcome = continuer.advance(previous, A, s, strict=False)
        if outcome is None:
            return best
        point = outcome[0]
        f = test(point)
        if abs(f) < best_f:
            best, best_f = point, abs(f)
        if secant and abs(f) < LOCATION_TOLERANCE:
            return point
        if (f > 0) == (f_lo > 0):
            lo, f_lo = s, f
            if side == -1:
                f_hi *= 0.5  # Illinois: the end that stays gets half its weight
            side = -1
        else:
            hi, f_hi = s, f
            if side == 1:
                f_lo *= 0.5
            side = 1
    return best


def detect(continuer: Continuer, branch: Branch, previous: BranchPoint, new: BranchPoint,
           A: np.ndarray) -> list[BranchPoint]:
    """The located bifurcation points between two accepted points of a branch (module docstring), in the order of
    the arclength; `new` gets the fold label when the fold lies at it. The callback of `continue_branch`."""
    found: list[BranchPoint] = []
    u0 = continuer.unknowns(previous.orbit)
    total = float(np.linalg.norm(continuer.unknowns(new.orbit) - u0))
    if total == 0.0:
        return found
    if np.sign(previous.tangent[-1]) != np.sign(new.tangent[-1]) and previous.tangent[-1] != 0.0:
        # the turning point: the parameter component of the tangent through zero
        point = _insert(continuer, previous, new, A, total, lambda p: float(p.tangent[-1]), secant=True)
        if point is not None:
            point.label = FOLD
            found.append(point)
    if outside_count(previous.orbit) != outside_count(new.orbit):
        point = _insert(continuer, previous, new, A, total,
                        lambda p: math.log(abs(nearest_to_circle(p.orbit))), secant=True)
        if point is not None:
            point.label = crossing_label(point.orbit, nearest_to_circle(point.orbit))
            stable_before, stable_after = previous.orbit.stable, new.orbit.stable
            point.note = ("loses stability" if stable_before and not stable_after else
                          "gains stability" if stable_after and not stable_before else "")
            found.append(point)
    if int(np.sum(previous.orbit.impacts)) != int(np.sum(new.orbit.impacts)):
        before = int(np.sum(previous.orbit.impacts))
        point = _insert(continuer, previous, new, A, total,
                        lambda p: 1.0 if int(np.sum(p.orbit.impacts)) == before else -1.0, secant=False)
        if point is not None:
            point.label = GRAZING
            point.note = f"{before} -> {int(np.sum(new.orbit.impacts))} impacts per {new.orbit.k} T"
            found.append(point)
    found.sort(key=lambda p: float(np.linalg.norm(continuer.unknowns(p.orbit) - u0)))
    return found


def switch_branch(point: BranchPoint, parameter_name: str, bounds: tuple[float, float], *,
                  step: float = SWITCH_STEP, max_points: int = 1500, progress: Callable[[], None] | None = None,
                  detect_bifurcations: bool = True) -> Branch:
    """The branch that bifurcates at a symmetry breaking or period doubling `point` (module docstring), continued
    in `parameter_name` within `bounds`. SimulationInputError for another label or a period multiple beyond
    MAX_PERIOD_MULTIPLE."""
    orbit = point.orbit
    end, half = orbit.jacobian
    if point.label == SYMMETRY_BREAKING and orbit.symmetric:
        lam, vectors = np.linalg.eig(-half)
        k, origin = orbit.k, "symmetry breaking"
    elif point.label == PERIOD_DOUBLING:
        lam, vectors = np.linalg.eig(end)
        k, origin = 2 * orbit.k, "period doubling"
    else:
        raise SimulationInputError(f"orbits: no branch switching at a point labelled {point.label!r}")
    if k > MAX_PERIOD_MULTIPLE:
        raise SimulationInputError(f"orbits: period doubling to {k} T exceeds the largest period multiple "
                                   f"{MAX_PERIOD_MULTIPLE}")
    v = np.real(vectors[:, int(np.argmin(np.abs(lam + 1.0)))])
    v /= np.linalg.norm(v)
    shooting = ShootingMap(orbit.setting, k)
    start = make_orbit(shooting, orbit.state, False)
    tangent = np.append(v, 0.0)
    par = continuer_parameter(parameter_name)
    where = f"{par.name} = {par.get(orbit.setting):.6g}"
    return continue_branch(start, parameter_name, bounds, tangent=tangent, step=step, max_points=max_points,
                           origin=f"{origin} at {where}", progress=progress,
                           detect=detect if detect_bifurcations else None)


def loses_stability(branch: Branch) -> list[BranchPoint]:
    """The located points of a branch where a stable orbit becomes unstable (or the reverse), in branch order."""
    return [p for p in branch.points if p.note in ("loses stability", "gains stability")]


__all__ = ["BRANCH_POINT", "FOLD", "GRAZING", "LABELS", "NEIMARK_SACKER", "PERIOD_DOUBLING", "SYMMETRY_BREAKING",
           "crossing_label", "detect", "loses_stability", "nearest_to_circle", "outside_count", "relevant_multipliers",
           "switch_branch"]
