"""sim.stepped_sine.batch: many runs in one call, each identical to the single run with the same (seed, rep)."""
import numpy as np
import pytest

from sim.stepped_sine.batch import BatchJob, aggregate_batch, batch_jobs, run_batch
from sim.common.errors import SimulationInputError
from sim.stepped_sine.protocol import SteppedSine, aggregate_runs, run_sweep
from sim.model.system import Impactor

PROTOCOL = SteppedSine(eta_start=0.98, eta_stop=1.0, n_eta=2, wait=0.5, hold=0.05, integrator="exact")
FIELDS = ("eta_actual", "mean", "max", "min", "std", "impacts_per_period")


def _same(run_a, run_b):
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(run_a, name), getattr(run_b, name), err_msg=name)


def test_batch_equals_single_runs_serial_and_parallel(three_mode_model):
    jobs = batch_jobs([{}, {"k_H": 1.25 * Impactor().k_H, "g": 0.6e-3, "D": 0.0009}], levels=[7.4], reps=2)
    assert len(jobs) == 4
    serial = run_batch(three_mode_model, PROTOCOL, jobs, seed=3)
    parallel = run_batch(three_mode_model, PROTOCOL, jobs[::-1], seed=3, n_jobs=2)[::-1]
    for job, run_s, run_p in zip(jobs, serial, parallel):
        model = three_mode_model if job.D is None else three_mode_model.with_damping(job.D)
        impactor = Impactor(clearance=job.g or Impactor().clearance, k_H=job.k_H or Impactor().k_H)
        single = run_sweep(model, impactor, job.level, PROTOCOL, seed=3, rep=job.rep)
        _same(run_s, single)
        _same(run_p, single)
    assert np.any(serial[0].impacts_per_period > 0)


def test_aggregate_batch_groups_by_parameters_and_level(three_mode_model):
    jobs = batch_jobs([{}], levels=[5.0, 7.4], reps=2)
    runs = run_batch(three_mode_model, PROTOCOL, jobs, seed=1)
    results = aggregate_batch(jobs, runs)
    assert len(results) == 2
    key = (jobs[0].params, 7.4)
    expected = aggregate_runs([r for j, r in zip(jobs, runs) if j.level == 7.4])
    np.testing.assert_array_equal(results[key].mean, expected.mean)
    assert results[key].n_runs == 2


def test_integrator_override_and_ode3(three_mode_model):
    job = [BatchJob(level=7.4, rep=0)]
    run = run_batch(three_mode_model, PROTOCOL, job, seed=0, integrator="ode3")[0]
    assert run.protocol.integrator == "ode3"


@pytest.mark.parametrize("call, message", [
    (lambda m: run_batch(m, PROTOCOL, [], seed=0), "no jobs"),
    (lambda m: batch_jobs([{"q": 1.0}], [7.4], 1), "unknown parameter"),
    (lambda m: batch_jobs([{}], [7.4], 0), "reps"),
    (lambda m: run_batch(m, PROTOCOL, [BatchJob(level=7.4, rep=0, D=2.0)], seed=0), "D must lie"),
    (lambda m: run_batch(m, PROTOCOL, [BatchJob(level=7.4, rep=0, g=-1.0)], seed=0), "clearance"),
])
def test_bad_batch_input_is_one_line(three_mode_model, call, message):
    with pytest.raises(SimulationInputError, match=message) as info:
        call(three_mode_model)
    assert "\n" not in str(info.value)
