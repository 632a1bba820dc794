"""Simulated traces of the built-in rig for the signal-analysis tests (tests/sim/analysis/test_impacts.py,
test_modal_fit.py, test_sim_signals.py): the states of the exact integrator recorded at ~51.2 kHz.

The almost periodic response at a_base/a_base* = 7.4, eta = 0.976 (Sect. 5.5, Figs. 4a-b and 9) is not
reached from rest; it is prepared by a down-sweep from eta = 0.99 (8 s per step), as in
tests/benchmarks/test_exact_speed.py.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from sim.integration import exact
from sim.hosts.rig import seed_rig_model
from sim.analysis.signals import Signal, SimulatedContacts, simulated_contacts, simulated_signal
from sim.model.system import Impactor, ModalModel, SystemArrays, a_base_star, system_arrays

LEVEL = 7.4
#: Samples per excitation period: fs = M Omega / (2 pi) = 51.2 kHz at eta = 0.976.
SAMPLES_PER_PERIOD = 447


@dataclass(frozen=True)
class Trace:
    signal: Signal
    states: np.ndarray
    contacts: SimulatedContacts
    model: ModalModel
    system: SystemArrays
    Omega: float
    a_base: float
    onsets: int  # contact onsets the integrator counted while recording


@lru_cache(maxsize=4)
def rig_trace(eta: float = 0.976, periods: int = 50, down_from: float | None = 0.99) -> Trace:
    """The rig's response recorded over `periods` excitation periods after a down-sweep from `down_from`
    (None: from rest, 3 s settling)."""
    model = seed_rig_model(n_modes=9)
    system = system_arrays(model, Impactor())
    a_base = LEVEL * a_base_star(model)
    y = np.zeros(2 * model.n_modes + 2)
    steps = np.arange(down_from, eta + 1e-9, -0.004) if down_from is not None else []
    for step_eta in steps:
        Omega = step_eta * model.omega[0]
        exact.run_step(y, int(round(8.0 * Omega / (2 * np.pi))), Omega, a_base, system)
    Omega = eta * model.omega[0]
    if down_from is None:
        exact.run_step(y, int(round(3.0 * Omega / (2 * np.pi))), Omega, a_base, system)
    M = SAMPLES_PER_PERIOD
    states = np.empty((periods * M + 1, y.size))
    _, onsets = exact.run_step(y, periods, Omega, a_base, system, states)
    return Trace(simulated_signal(states, M, Omega, a_base, system), states,
                 simulated_contacts(states, M, Omega, a_base, system), model, system, Omega, a_base,
                 int(onsets.sum()))
