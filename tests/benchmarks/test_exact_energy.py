"""Energy conservation of the exact integrator at its defaults (issue 5, Acceptance: within 1e-6 over 1000
impacts without damping or excitation), next to the tighter fall-back tolerance the default test uses and
to last session's default (every contact by Dormand-Prince at rtol 1e-7).

Run: pytest -m benchmark tests/benchmarks/test_exact_energy.py -s
"""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from sim import exact
from sim.system import Impactor, ModalModel, system_arrays

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
from test_exact_reference import cantilever_like_model  # noqa: E402

pytestmark = pytest.mark.benchmark
N9 = 9


def _drift(**options):
    """Relative energy change over >= 1000 impacts (undamped beam, sphere launched at 0.5 m/s), and the
    kernel's counters."""
    base = cantilever_like_model(undamped=True)
    model = ModalModel(frequencies_hz=base.frequencies_hz, damping_ratios=np.full(N9, 1e-15),
                       phi_wall_left=base.phi_wall_left, phi_wall_right=base.phi_wall_right,
                       phi_tip=base.phi_tip, participation=base.participation)
    s = system_arrays(model, Impactor())

    def energy(y):
        x, v, u, ud = y[:N9], y[N9:2 * N9], y[2 * N9], y[2 * N9 + 1]
        dl = s.phi_l @ x - u - s.g
        dr = s.phi_r @ x - u + s.g
        contact = 0.4 * s.k_H * (max(dl, 0.0) ** 2.5 + max(-dr, 0.0) ** 2.5)
        return 0.5 * v @ v + 0.5 * (s.omega**2 * x) @ x + 0.5 * s.m_a * ud**2 + contact

    y = np.zeros(2 * N9 + 2)
    y[2 * N9 + 1] = 0.5
    e0 = energy(y)
    impacts = 0
    stats = {}
    while impacts < 1000:
        _, imp = exact.run_step(y, 20, 2 * math.pi * 100.0, 0.0, s, stats=stats, **options)
        impacts += int(imp.sum())
    return abs(energy(y) - e0) / e0, impacts, stats


def test_energy_over_1000_impacts_at_the_defaults():
    rows = {"defaults (collocation, fall-backs at rtol 1e-11)": {},
            "fall-backs at rtol 1e-10": {"rtol": 1e-10},
            "Dormand-Prince contacts at rtol 1e-7": {"contacts": "dopri5", "rtol": 1e-7}}
    print()
    drifts = {}
    for label, options in rows.items():
        drift, impacts, stats = _drift(**options)
        drifts[label] = drift
        print(f"  {label:50s}: relative energy change {drift:.1e} over {impacts} impacts "
              f"({stats['collocation_fallbacks']} of {stats['contacts']} contacts fell back)")
    assert drifts["defaults (collocation, fall-backs at rtol 1e-11)"] < 1e-6
