"""PreparedExact (sim.integration.prepared) is exact.run_step bit for bit, after other runs and a new excitation."""
from __future__ import annotations

import numpy as np

from sim.integration.exact import run_step
from sim.hosts.rig import seed_rig_model
from sim.integration.prepared import PreparedExact
from sim.model.system import Impactor, a_base_star, system_arrays


def test_prepared_runs_are_run_step_bit_for_bit():
    """The rig at 7.4 / eta 0.976 from a rattling state (contacts by collocation and Dormand-Prince, carried from
    contact to contact): PreparedExact after runs from other states and at another excitation gives exact.run_step's
    states, records, amplitudes and impact counts bit for bit."""
    model = seed_rig_model(9)
    sys = system_arrays(model, Impactor())
    a_base, Omega = 7.4 * a_base_star(model), 0.976 * float(model.omega[0])
    start = np.zeros(2 * model.n_modes + 2)
    start[-1] = a_base * Omega
    run_step(start, 100, Omega, a_base, sys)
    prepared = PreparedExact(2, Omega * 1.01, a_base, sys, samples=2)
    for shift in (1e-4, -2e-4):
        prepared.advance(start * (1 + shift))
    prepared.retarget(Omega, a_base)
    y = start.copy()
    amplitudes, impacts, record = prepared.advance(y)
    assert impacts.sum() >= 2
    y_ref = start.copy()
    record_ref = np.empty((5, y.size))
    amplitudes_ref, impacts_ref = run_step(y_ref, 2, Omega, a_base, sys, record_ref)
    assert np.array_equal(y, y_ref) and np.array_equal(record, record_ref)
    assert np.array_equal(amplitudes, amplitudes_ref) and np.array_equal(impacts, impacts_ref)
