"""Measures of Sect. 5: a_noabs*, the analytic frequency response without impactor, the regime, Eq. B.1."""
import math

import numpy as np
import pytest

from sim.stepped_sine.measures import (APR, LINEAR, SMR, classify_regime, hold_measures, linear_tip_amplitude,
                          physical_amplitude)
from sim.stepped_sine.protocol import SteppedSine, sweep
from sim.model.system import ModalModel, Nominal, a_base_star, a_noabs_star


def test_single_mode_resonance_is_a_noabs_star():
    """One mode: |H(omega_1)| = phi_tip gamma a_base / (2 D) exactly (Sect. 5)."""
    model = ModalModel([117.4], [0.00085], [1.3], [1.3], [1.25], [1.1])
    a_base = 1e-6
    assert linear_tip_amplitude(model, model.omega[0], a_base) == pytest.approx(a_noabs_star(model, a_base), rel=1e-12)


def test_without_impactor_resonant_level_is_one_and_response_is_the_analytic_frf(three_mode_model):
    """Stepped sine without impactor, paper's 15 s wait: resonant mean = 1 within
    0.5 %, and every point on the analytic frequency response of the modal model."""
    nominal = Nominal(D1=float(three_mode_model.damping_ratios[0]))
    protocol = SteppedSine(eta_start=0.996, eta_stop=1.004, n_eta=5, wait=15.0, hold=0.5, perturbation=0.0)
    result = sweep(three_mode_model, None, 3.0, protocol, reps=1, seed=0, nominal=nominal)
    assert result.resonant_mean == pytest.approx(1.0, rel=5e-3)
    assert result.eta_resonant_mean == pytest.approx(1.0)
    a_base = 3.0 * a_base_star(three_mode_model, nominal)
    expected = linear_tip_amplitude(three_mode_model, result.eta * three_mode_model.omega[0], a_base)
    expected /= a_noabs_star(three_mode_model, a_base, nominal)
    np.testing.assert_allclose(result.mean, expected, rtol=2e-3)
    np.testing.assert_allclose(result.max, expected, rtol=3e-3)
    assert result.regime == LINEAR and not result.impacts_per_period.any()


def test_hold_measures_and_regimes():
    periodic = hold_measures(np.full(50, 2e-3), np.full(50, 2), 4e-3)
    assert (periodic.mean, periodic.max, periodic.cv, periodic.impacts_per_period) == (0.5, 0.5, 0.0, 2.0)
    t = np.arange(600)
    modulated = hold_measures(1e-3 * (1.5 + np.sin(2 * math.pi * t / 100)), np.ones(600), 1e-3)
    assert modulated.mean == pytest.approx(1.5) and modulated.max == pytest.approx(2.5, rel=1e-3)
    assert modulated.cv == pytest.approx(1 / (1.5 * math.sqrt(2)), rel=1e-3)
    assert classify_regime(periodic.cv, 2.0) == APR
    assert classify_regime(modulated.cv, 1.0) == SMR
    assert classify_regime(0.0, 0.0) == LINEAR
    assert list(classify_regime(np.array([0.01, 0.5, 0.5]), np.array([1.0, 1.0, 0.0]))) == [APR, SMR, LINEAR]


def test_equation_b1_reconstructs_the_physical_amplitude(three_mode_model):
    """a = (a/a_noabs*) (a_base/a_base*) (phi_tip/phi_c) g*: consistent with a_noabs* and a_base*."""
    nominal = Nominal()
    level, normalised = 6.7, 0.08
    a_base = level * a_base_star(three_mode_model, nominal)
    direct = normalised * a_noabs_star(three_mode_model, a_base, nominal)
    assert physical_amplitude(normalised, level, three_mode_model, nominal) == pytest.approx(direct, rel=1e-12)
