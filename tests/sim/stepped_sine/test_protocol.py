"""The stepped-sine protocol (Sect. 5.1): validation, whole periods, reproducible random streams,
legs vs repetitions, aggregation."""
import math

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.stepped_sine.protocol import SteppedSine, aggregate_runs, run_sweep, sweep
from sim.model.system import Impactor

# short holds keep these tests fast; physics of the hold lengths is tested elsewhere
FAST = dict(eta_start=0.98, eta_stop=1.0, n_eta=3, wait=0.02, hold=0.03)


@pytest.mark.parametrize("bad, message", [
    (dict(n_eta=0), "empty"),
    (dict(eta_start=1.02, eta_stop=0.96), "empty or reversed"),
    (dict(eta_start=1.0, eta_stop=1.0, n_eta=5), "empty or reversed"),
    (dict(eta_start=-1.0), "positive"),
    (dict(sequence="sideways"), "unknown sequence"),
    (dict(hold=0.0), "hold must be positive"),
    (dict(wait=-1.0), "wait"),
    (dict(repetition="both"), "repetition"),
    (dict(perturbation=0.5), "perturbation"),
    (dict(perturb="everywhere"), "perturb must be one of start, each-point"),
    (dict(wait=float("nan")), "finite"),
])
def test_invalid_protocols_are_refused(bad, message):
    with pytest.raises(SimulationInputError, match=message):
        SteppedSine(**(FAST | bad))


def test_hold_shorter_than_one_period_is_refused(three_mode_model):
    protocol = SteppedSine(**(FAST | dict(hold=0.005)))  # T = 8.7 ms at eta = 0.98
    with pytest.raises(SimulationInputError, match="shorter than one excitation period"):
        run_sweep(three_mode_model, Impactor(), 5.0, protocol, seed=0, rep=0)


@pytest.mark.parametrize("level", [0.0, -1.0, float("inf")])
def test_level_must_be_positive(three_mode_model, level):
    with pytest.raises(SimulationInputError, match="level"):
        run_sweep(three_mode_model, Impactor(), level, SteppedSine(**FAST), seed=0, rep=0)


def test_wait_and_hold_are_whole_periods():
    protocol = SteppedSine(wait=3.0, hold=5.0)
    Omega = 2 * math.pi * 117.4
    assert protocol.periods(Omega) == (352, 587)  # Sect. 5.1: 352 and 587 nominal periods


@pytest.mark.parametrize("perturb", ["start", "each-point"])
def test_run_is_reproducible_from_seed_and_rep_in_any_order(three_mode_model, perturb):
    protocol = SteppedSine(**(FAST | dict(sequence="up-down-up", perturb=perturb)))
    b1 = run_sweep(three_mode_model, Impactor(), 6.0, protocol, seed=7, rep=1)
    a = run_sweep(three_mode_model, Impactor(), 6.0, protocol, seed=7, rep=0)
    b2 = run_sweep(three_mode_model, Impactor(), 6.0, protocol, seed=7, rep=1)
    for key in ("eta_actual", "mean", "max", "std", "impacts_per_period"):
        np.testing.assert_array_equal(getattr(b1, key), getattr(b2, key))
    assert not np.array_equal(a.mean, b1.mean)  # another repetition, another perturbation
    np.testing.assert_array_equal(b1.eta, [0.98, 0.99, 1.0, 1.0, 0.99, 0.98, 0.98, 0.99, 1.0])
    np.testing.assert_array_equal(b1.leg, [0, 0, 0, 1, 1, 1, 2, 2, 2])
    if perturb == "start":  # every hold at its nominal frequency
        np.testing.assert_array_equal(b1.eta_actual, b1.eta)
    else:  # the documented law: eta' = eta (1 + U(-p, p)) drawn from default_rng([seed, rep]) in execution order
        rng = np.random.default_rng([7, 1])
        offsets = np.concatenate([rng.uniform(-5e-4, 5e-4, 3) for _ in range(3)])
        np.testing.assert_allclose(b1.eta_actual, b1.eta * (1 + offsets), rtol=0, atol=1e-15)


def test_a_perturbed_start_leaves_the_linear_response_unbiased(three_mode_model):
    """Without the IES every run ends up on the analytic frequency response (Eq. 7) whatever its perturbed start:
    after the lead-in at eta_0 (1 + e), each point waits 15 s (Sect. 5.1) and holds at its nominal frequency."""
    from sim.stepped_sine.measures import linear_tip_amplitude
    from sim.model.system import a_base_star, a_noabs_star

    protocol = SteppedSine(eta_start=0.999, eta_stop=1.001, n_eta=5, wait=15.0, hold=1.0, perturbation=5e-3)
    result = sweep(three_mode_model, None, 1.0, protocol, reps=3, seed=0)
    a_base = a_base_star(three_mode_model)
    exact = linear_tip_amplitude(three_mode_model, result.eta * three_mode_model.omega[0], a_base)
    np.testing.assert_allclose(result.mean, exact / a_noabs_star(three_mode_model, a_base), rtol=2e-4)
    assert np.ptp(result.mean_samples, axis=0).max() < 1e-4  # the runs' transients from their starts have decayed


def test_each_point_perturbation_is_reported_at_the_frequencies_simulated(three_mode_model):
    """perturb = "each-point": every sample is interpolated back onto the grid from its simulated frequencies, so
    the average follows the analytic response (within 1 % on the linear peak, half-power width +-8.5e-4, grid
    step 5e-4, offsets +-1e-4: linear interpolation cuts the peak's top); averaging at the nominal frequencies
    would lower the peak by twice as much."""
    from sim.stepped_sine.measures import linear_tip_amplitude
    from sim.model.system import a_base_star, a_noabs_star

    protocol = SteppedSine(eta_start=0.996, eta_stop=1.004, n_eta=17, wait=15.0, hold=1.0, perturbation=1e-4,
                           perturb="each-point")
    runs = [run_sweep(three_mode_model, None, 1.0, protocol, seed=0, rep=r) for r in range(3)]
    result = aggregate_runs(runs)
    a_base = a_base_star(three_mode_model)
    scale = a_noabs_star(three_mode_model, a_base)
    exact = linear_tip_amplitude(three_mode_model, result.eta * three_mode_model.omega[0], a_base) / scale
    inner = slice(1, -1)  # at the grid's ends the nearest simulated point stands in
    np.testing.assert_allclose(result.mean[inner], exact[inner], rtol=1e-2)
    at_nominal = np.mean([r.mean for r in runs], axis=0)  # what reporting at the nominal frequencies would give
    assert np.abs(result.mean[inner] / exact[inner] - 1).max() < 0.5 * np.abs(at_nominal[inner] / exact[inner] - 1).max()
    for run in runs:
        simulated = linear_tip_amplitude(three_mode_model, run.eta_actual * three_mode_model.omega[0], a_base) / scale
        np.testing.assert_allclose(run.mean, simulated, rtol=2e-4)  # each point is the response at eta_actual


def test_the_spread_of_a_resonant_level_contains_it(three_mode_model):
    """lo <= value <= hi for every point's mean and max and for the resonant levels: the resonant level's samples
    are the repetitions at its eta, whose average it is."""
    protocol = SteppedSine(**(FAST | dict(eta_start=0.97, n_eta=6)))
    result = sweep(three_mode_model, Impactor(), 4.0, protocol, reps=4, seed=2)
    for name in ("mean", "max"):
        assert np.all(getattr(result, f"{name}_lo") <= getattr(result, name))
        assert np.all(getattr(result, name) <= getattr(result, f"{name}_hi"))
        lo, hi, se = result.resonant_spread(name)
        level = getattr(result, f"resonant_{name}")
        samples = getattr(result, f"resonant_{name}_samples")
        assert lo <= level <= hi and se > 0
        assert level == pytest.approx(samples.mean(), rel=1e-14)
        assert se == pytest.approx(samples.std(ddof=1) / 2, rel=1e-12)
    single = aggregate_runs([run_sweep(three_mode_model, Impactor(), 4.0, protocol, seed=2, rep=0)])
    assert math.isnan(single.resonant_spread("mean")[2])  # one sample: no noise estimate


def test_legs_as_repetitions_or_pooled_per_run(three_mode_model):
    legs = SteppedSine(**(FAST | dict(sequence="up-down-up", repetition="leg")))
    pooled = SteppedSine(**(FAST | dict(sequence="up-down-up", repetition="run")))
    run_l = run_sweep(three_mode_model, Impactor(), 6.0, legs, seed=3, rep=0)
    run_p = run_sweep(three_mode_model, Impactor(), 6.0, pooled, seed=3, rep=0)
    np.testing.assert_array_equal(run_l.mean, run_p.mean)  # same stream, same simulation
    by_leg = aggregate_runs([run_l])
    by_run = aggregate_runs([run_p])
    assert by_leg.n_samples == 3 and by_run.n_samples == 1
    # equal holds: the pooled mean is the average of the legs' means; the pooled max is the largest max
    np.testing.assert_allclose(by_run.mean, by_leg.mean, rtol=1e-12)
    np.testing.assert_allclose(by_run.max, by_leg.max_hi, rtol=1e-12)
    assert np.all(by_leg.mean_lo <= by_leg.mean) and np.all(by_leg.mean <= by_leg.mean_hi)


def test_sweep_equals_aggregate_of_single_runs(three_mode_model):
    protocol = SteppedSine(**FAST)
    result = sweep(three_mode_model, Impactor(), 6.0, protocol, reps=2, seed=11)
    runs = [run_sweep(three_mode_model, Impactor(), 6.0, protocol, seed=11, rep=r) for r in range(2)]
    manual = aggregate_runs(runs[::-1])  # order of the runs does not matter
    np.testing.assert_allclose(result.mean, manual.mean, rtol=1e-14)
    np.testing.assert_allclose(result.max, manual.max, rtol=1e-14)
    assert result.resonant_mean == pytest.approx(manual.resonant_mean, rel=1e-14)
    assert result.resonant_mean == pytest.approx(result.mean.max())
    assert result.resonant_max == pytest.approx(result.max.max())
    assert result.regime == result.regime_per_eta[int(np.argmax(result.mean))]
    data = result.to_dict()
    for key in ("eta", "mean", "max", "resonant_mean", "resonant_max", "regime", "impacts_per_period", "wall_time_s"):
        assert key in data


def test_aggregate_refuses_mixed_levels(three_mode_model):
    protocol = SteppedSine(**FAST)
    runs = [run_sweep(three_mode_model, Impactor(), level, protocol, seed=0, rep=0) for level in (5.0, 6.0)]
    with pytest.raises(SimulationInputError, match="share"):
        aggregate_runs(runs)
    with pytest.raises(SimulationInputError, match="no runs"):
        aggregate_runs([])


def test_unknown_integrator_is_one_line(three_mode_model):
    protocol = SteppedSine(**(FAST | dict(integrator="euler")))
    with pytest.raises(SimulationInputError, match="unknown integrator 'euler'; available"):
        run_sweep(three_mode_model, Impactor(), 6.0, protocol, seed=0, rep=0)


def test_start_with_base_velocity_keeps_the_impactor_active_off_resonance(three_mode_model):
    """From rest, far below resonance, the walls never reach the sphere (linear response); started with the
    base's peak velocity (the default) the frictionless sphere drifts into a wall and keeps rattling
    (Appendix C)."""
    common = dict(eta_start=0.96, eta_stop=0.96, n_eta=1, wait=0.5, hold=0.2, perturbation=0.0)
    rest = run_sweep(three_mode_model, Impactor(), 3.0, SteppedSine(**common, start="rest"), seed=0, rep=0)
    moving = run_sweep(three_mode_model, Impactor(), 3.0, SteppedSine(**common), seed=0, rep=0)
    assert rest.impacts_per_period[0] == 0
    assert moving.impacts_per_period[0] > 0
    with pytest.raises(SimulationInputError, match="start must be one of"):
        SteppedSine(start="sideways")
