"""The similarity-law predictor (`sim.reduced.similarity`) on analytic stand-ins for the simulator, whose switch and
levels are known exactly: the bisection finds each reference's switch within its resolution, the law interpolates a
switch linear in log kappa and in D_1 exactly, bounds stay bounds, and the response is read on the right side of the
switch. (Its agreement with the full simulator: tests/benchmarks/test_slow_flow_switch.py.)"""
import math

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.reduced.similarity import Outcome, kappa, own_levels, reference_curves, reference_kappas


def switch_of(k, D):
    """A switch level linear in log2 kappa and in D (the shape measured on the rig: +0.5 level per factor 2 in kappa)."""
    return 5.0 + 0.5 * math.log2(k / 1e5) + 2000.0 * (D - 0.00085)


def stand_in(references, calls):
    """An evaluate whose reference i is SMR (value 0.05) below switch_of and APR (0.2 + 0.02 level) from it on."""
    def evaluate(batch):
        calls.append(len(batch))
        out = []
        for i, level in batch:
            s = switch_of(*references[i])
            out.append(Outcome(1.0 if level >= s else 0.0, 0.05 if level < s else 0.2 + 0.02 * level))
        return out
    return evaluate


REFERENCES = [(1e5, 0.00075), (4e5, 0.00075), (1e5, 0.0009), (4e5, 0.0009)]


def test_each_reference_switch_is_bisected_to_the_resolution_in_few_batches():
    calls = []
    law = reference_curves(stand_in(REFERENCES, calls), REFERENCES, own_levels(1.5, 12.0), resolution=0.25)
    for curve, (k, D) in zip(law.curves, REFERENCES):
        s = curve.switch()
        assert s.kind == "found" and s.width <= 0.25 + 1e-12
        assert abs(s.level - switch_of(k, D)) <= 0.5 * s.width + 1e-12
    grid = own_levels(1.5, 12.0)
    assert calls[0] == len(REFERENCES) * len(grid[::2])  # every other level of the grid (its top among them)
    below = sum(x < switch_of(k, D) for k, D in REFERENCES for x in grid[1::2])  # the rest only below each switch
    assert calls[1] <= below + len(REFERENCES) and sum(calls) < len(REFERENCES) * len(grid) + 4 * len(REFERENCES)
    assert len(calls) <= 5 and all(n <= len(REFERENCES) for n in calls[2:])  # then <= 3 bisection steps


@pytest.mark.parametrize("k, D", [(2e5, 0.0008), (1.3e5, 0.00085), (3.9e5, 0.0009)])
def test_the_law_interpolates_a_switch_linear_in_log_kappa_and_D(k, D):
    law = reference_curves(stand_in(REFERENCES, []), REFERENCES, own_levels(1.5, 12.0), resolution=0.01)
    assert law.switch(k, D).level == pytest.approx(switch_of(k, D), abs=0.01)
    # outside the references it is clamped to the nearest
    assert law.switch(1e7, 0.0009).level == pytest.approx(switch_of(4e5, 0.0009), abs=0.01)


def test_the_response_is_read_on_its_side_of_the_switch():
    law = reference_curves(stand_in(REFERENCES, []), REFERENCES, own_levels(1.5, 12.0), resolution=0.01)
    k, D = 2e5, 0.00085
    s = switch_of(k, D)
    assert law.value(k, D, s - 0.3) == pytest.approx(0.05)  # SMR side, although one reference is APR there
    assert law.value(k, D, 10.0) == pytest.approx(0.2 + 0.02 * 10.0)
    below, above = law.jump(k, D)
    assert below == pytest.approx(0.05) and above == pytest.approx(0.2 + 0.02 * s, abs=0.02)
    assert not law.is_apr(k, D, s - 0.1) and law.is_apr(k, D, s + 0.1)


def test_a_reference_without_a_switch_makes_the_prediction_a_lower_bound():
    references = [(1e5, 0.00085), (1e7, 0.00085)]  # the second switches at 8.3, beyond a grid ending at 6
    law = reference_curves(stand_in(references, []), references, own_levels(1.5, 6.0))
    assert law.curves[1].switch().kind == "above" and law.curves[1].switch().level == pytest.approx(6.0)
    assert law.switch(1e6, 0.00085).kind == "above" and not law.switch(1e6, 0.00085).exists
    assert law.switch(1e5, 0.00085).kind == "found"
    apr_everywhere = [(1e3, 0.00085)]  # switches at 1.7: APR from the grid's 2.0 on
    law = reference_curves(stand_in(apr_everywhere, []), apr_everywhere, own_levels(2.0, 6.0))
    assert law.switch(1e3, 0.00085).kind == "below"


def test_the_switch_is_the_first_from_below():
    """An APR level below the first SMR one (a rattle below the onset of impacts) does not count, an SMR island far
    above the switch does not move it, and an APR level inside the SMR part is the switch: a design must stay below
    it."""
    def evaluate(batch):
        return [Outcome(1.0 if level < 0.8 or 6.0 <= level < 15.0 or level >= 17.0 else 0.0, 0.1)
                for _, level in batch]
    law = reference_curves(evaluate, [(1e5, 0.00085)], own_levels(0.6, 20.0))
    assert law.switch(1e5, 0.00085).level == pytest.approx(6.0, abs=0.13)
    def noisy(batch):
        return [Outcome(1.0 if level >= 6.0 or abs(level - 3.0) < 0.2 else 0.0, 0.1) for _, level in batch]
    law = reference_curves(noisy, [(1e5, 0.00085)], [2.0, 3.0, 4.0, 5.0, 7.0, 8.0])
    assert law.switch(1e5, 0.00085).level == pytest.approx(2.9, abs=0.13)


def test_grids_and_kappas():
    assert kappa(4.0, 0.25) == pytest.approx(2.0)
    levels = own_levels(0.5, 12.0)
    assert levels[0] == 0.5 and levels[-1] == 12.0 and max(np.diff(np.log(levels))) <= math.log(1.2) + 0.02
    assert reference_kappas(1.0, 1.04) == [pytest.approx(math.sqrt(1.04))]
    ks = reference_kappas(1.0, 10.0, 2.5)
    assert ks[0] == pytest.approx(1.0) and ks[-1] == pytest.approx(10.0) and max(np.diff(np.log(ks))) <= math.log(2.5)
    with pytest.raises(SimulationInputError):
        reference_curves(lambda batch: [], [], [1.0])
    with pytest.raises(SimulationInputError):
        own_levels(2.0, 1.0)
