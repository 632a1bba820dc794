"""The simulator's reference (sim.integration.references.reference_run, scipy DOP853 with contact events) checked
against the analytic rigid-wall Hertz impact."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import gamma as gamma_fn

from sim.integration.references import reference_run
from sim.model.system import Impactor, ModalModel, system_arrays


def test_reference_reproduces_the_hertz_impact_on_a_rigid_wall():
    """The reference itself: restitution 1 and the analytic contact time
    t_c = 2 sqrt(pi) Gamma(7/5) / Gamma(9/10) delta_max / v0 (= 2.9432 delta_max / v0)."""
    model = ModalModel(frequencies_hz=[100.0], damping_ratios=[0.01], phi_wall_left=[0.0], phi_wall_right=[0.0],
                       phi_tip=[1.0], participation=[1.0])
    sys = system_arrays(model, Impactor())
    v0 = 0.5
    y0 = np.array([0.0, 0.0, sys.g - 1e-5, v0])
    y, onsets, releases, speeds = reference_run(y0, 1e-3, 2 * math.pi * 1000.0, 0.0, sys)
    delta_max = (5 * sys.m_a * v0**2 / (4 * sys.k_H)) ** 0.4
    t_c = 2 * math.sqrt(math.pi) * gamma_fn(1.4) / gamma_fn(0.9) * delta_max / v0
    assert releases[0] - onsets[0] == pytest.approx(t_c, rel=1e-9)
    assert abs(y[3]) == pytest.approx(v0, rel=1e-10)
