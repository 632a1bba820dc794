"""Bifurcations (sim.orbits.bifurcations) told apart and located on toy maps whose answers are known in closed form
(tests/sim/orbits/_toys.py), each run through the orbits' own continuation, detection and branch switching: the
label from the multipliers' path, the location within its tolerance (|mu| within 1e-4 of 1, the grazing condition
within 1e-9), the new branches against their closed forms."""
from __future__ import annotations

import numpy as np
import pytest

from sim.orbits.bifurcations import GAINS, GRAZING, IN_JUMP, LOSES, MU_TOLERANCE, detect, switch_branch
from sim.orbits.continuation import continue_branch
from sim.orbits.shooting import make_orbit

from tests.sim.orbits._toys import A, EDGE, P, ToyMap, ToySetting


def branch_of(kind: str, p: float, x: float, bounds: tuple[float, float], direction: float, symmetric: bool = False):
    orbit = make_orbit(ToyMap(ToySetting(kind, p)), np.array([x, 0.0]), symmetric)
    return continue_branch(orbit, P, bounds, direction=direction, detect=detect, map_factory=ToyMap)


def labelled(branch):
    return [p for p in branch.points if p.label]


@pytest.mark.parametrize("kind, start, direction, label, note, symmetric", [
    ("fold", (0.25, 0.5), -1.0, "fold", LOSES, False),               # x = sqrt(p) stable, turns at p = 0
    ("transcritical", (-0.3, 0.0), 1.0, "branch-point", LOSES, False),  # x = 0: multiplier 1 + p, no turn
    ("period-doubling", (-0.3, 0.0), 1.0, "period-doubling", LOSES, False),
    ("symmetric", (-0.3, 0.0), 1.0, "symmetry-breaking", LOSES, True),
    ("neimark-sacker", (-0.3, 0.0), 1.0, "neimark-sacker", LOSES, False),
])
def test_each_bifurcation_is_labelled_by_its_path_and_located(kind, start, direction, label, note, symmetric):
    """One labelled point per toy, at p = 0 (each toy's closed form), its multiplier within MU_TOLERANCE of the unit
    circle and of the closed form's multiplier there."""
    branch = branch_of(kind, *start, (-0.3, 0.3), direction, symmetric)
    (point,) = labelled(branch)
    assert (point.label, point.note) == (label, note)
    p = point.orbit.setting.p
    assert point.location_error < MU_TOLERANCE
    if kind == "fold":  # multiplier 1 - 2x on x^2 = p: |1 - 2 sqrt(p)| within 1e-4 of 1
        assert abs(point.orbit.state[0]) < MU_TOLERANCE and abs(p) < MU_TOLERANCE**2
    else:  # multipliers of modulus 1 + p (|(1 + p)^2 - 1| for the half map's square)
        assert abs(p) < MU_TOLERANCE
    assert not branch.unlocated


@pytest.mark.parametrize("kind, symmetric, k", [("period-doubling", False, 2), ("symmetric", True, 1)])
def test_switching_finds_the_new_branch_of_the_closed_form(kind, symmetric, k):
    """The 2-cycle of the period doubling (x^2 = p, period 2) and the asymmetric pair of the symmetry breaking
    (x^2 = p of P = G o G, period 1), stable, to the continuation's tolerance over the fixed point's conditioning; the
    switched branch is a branch of its own (none of its orbits on the parent: x = 0)."""
    branch = branch_of(kind, -0.3, 0.0, (-0.3, 0.3), 1.0, symmetric)
    (point,) = labelled(branch)
    new = switch_branch(point, P, (-0.3, 0.3), map_factory=ToyMap)
    assert new.k == k and not new.symmetric and len(new.points) > 5
    x = np.array([q.orbit.state[0] for q in new.points[1:]])
    p = np.array([q.orbit.setting.p for q in new.points[1:]])
    # Newton's residual (1e-9) over the fixed point's conditioning 1 / |P' - 1| = 1 / (4 x^2) moves x^2 - p by 1e-9 / 2x
    assert np.all(np.abs(x) > 0) and np.all(np.abs(x**2 - p) < 10 * 1e-9 / (2 * np.abs(x)))
    assert all(q.orbit.stable for q in new.points[1:])


def test_a_jump_at_a_grazing_is_a_grazing_not_a_period_doubling():
    """The grazing toy: its multiplier jumps from A = 0.5 to -1.5 within 1e-4 beyond the edge, through -1 on the way.
    Going up the impact appears, going down it vanishes: each way one grazing, located where the fixed point meets
    the edge (p = EDGE (1 - A)) to the grazing condition's 1e-9, saying the stability is lost (gained) at it; the
    crossing of -1 inside the jump is not labelled."""
    for direction, start, note in ((1.0, (0.0, 0.0), LOSES), (-1.0, (0.4, 0.48 + 2e-4 / 7.5), GAINS)):
        branch = branch_of("grazing", *start, (0.0, 0.4), direction)
        (point,) = labelled(branch)
        assert point.label == GRAZING and f"; {note} at the grazing" in point.note
        assert 0.0 < point.location_error < 1e-9
        assert EDGE - point.orbit.state[0] < 1e-9
        assert point.orbit.setting.p == pytest.approx(EDGE * (1 - A), abs=1e-8)
        assert any(p.note == IN_JUMP for p in branch.points)
        assert not branch.unlocated


def test_an_unlocated_change_is_not_labelled(monkeypatch):
    """With the location given too few trials, the period doubling is not located: no label, one line in the
    branch's `unlocated` naming the interval."""
    import sim.orbits.bifurcations as bifurcations

    monkeypatch.setattr(bifurcations, "LOCATION_STEPS", 1)
    monkeypatch.setattr(bifurcations, "MU_TOLERANCE", 1e-14)
    branch = branch_of("period-doubling", -0.3, 0.0, (-0.3, 0.3), 1.0)
    assert not labelled(branch)
    (unlocated,) = branch.unlocated
    assert str(unlocated).startswith("0 -> 1 multipliers outside the unit circle between p ")
    assert "(not located)" in str(unlocated)
