"""Appendix B on synthetic data with a known amplitude-dependent damping: the single nonlinear mode finds D(a) within
10 % over the response range, from (a) FRFs made from a known backbone by harmonic balance and (b) the friction
element at the clamp integrated in time (its describing function is the known D(a)); the half-power method is exact
on a linear FRF."""
from __future__ import annotations

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.measured.linearity import LevelRecord, balance_roots, damping_interval, fit_nonlinear_mode, half_power
from sim.measured.synthetic import Iwan, iwan_backbone, shaker_levels

F1 = 117.4
G = 1.43  # phi_tip Gamma of the built-in rig's mode 1
LEVELS = 1.4 * np.array([2.0e-7, 2.7e-7, 4.7e-7, 6.7e-7, 9.4e-7])
STEPS = F1 * np.linspace(0.992, 1.004, 49)
RANGE = np.linspace(0.58e-3, 0.95e-3, 50)


def known_omega(a):
    return 2 * np.pi * F1 * (1 - 0.001 * (a / 1e-3) ** 1.5)


def known_damping(a):
    return 0.0006 + 0.0004 * np.tanh(a / 0.6e-3)


def test_a_known_backbone_is_found_within_10_percent():
    rng = np.random.default_rng(0)
    levels = []
    for a_base in LEVELS:
        amp = np.array([balance_roots(known_omega, known_damping, G, 2 * np.pi * f, a_base, 5e-3).max() for f in STEPS])
        levels.append(LevelRecord(a_base, STEPS, amp * (1 + 0.01 * rng.standard_normal(amp.size)), "known"))
    mode = fit_nonlinear_mode(levels)
    assert np.max(np.abs(mode.damping(RANGE) / known_damping(RANGE) - 1)) < 0.10
    assert np.max(np.abs(mode.omega(RANGE) / known_omega(RANGE) - 1)) < 2e-4
    interval = damping_interval(mode, 0.58e-3, 0.95e-3, (0.3e-3, 1.0e-3))
    assert interval.low == pytest.approx(known_damping(0.58e-3), rel=0.1)
    assert interval.high == pytest.approx(known_damping(0.95e-3), rel=0.1)
    assert interval.low <= interval.nominal <= interval.high and not interval.extrapolated


def test_the_friction_element_at_the_clamp_is_found_within_10_percent():
    iwan = Iwan(2 * np.pi * F1, 1.3555, 0.0045, np.geomspace(0.2e-3, 3e-3, 12))
    tip = shaker_levels(iwan, 0.0006, G / 1.3555, STEPS, LEVELS)
    mode = fit_nonlinear_mode([LevelRecord(a, STEPS, np.abs(tip[i]), "iwan") for i, a in enumerate(LEVELS)])
    omega, D = iwan_backbone(iwan, 0.0006, RANGE)
    assert np.max(np.abs(mode.damping(RANGE) / D - 1)) < 0.10
    assert np.max(np.abs(mode.omega(RANGE) / omega - 1)) < 2e-4


def test_half_power_is_exact_on_a_linear_frf():
    f = F1 * np.linspace(0.99, 1.01, 2001)
    D = 0.0008
    w, wn = 2 * np.pi * f, 2 * np.pi * F1
    amp = np.abs(G * w**2 * 1e-7 / (wn**2 - w**2 + 2j * D * wn * w))
    hp = half_power(LevelRecord(1e-7, f, amp, "linear"))
    assert hp.damping_ratio == pytest.approx(D, rel=2e-3)
    assert hp.frequency_hz == pytest.approx(F1 / np.sqrt(1 - 2 * D**2), rel=1e-6)  # the peak of Omega^2 / |den|


def test_a_range_the_fit_cannot_reach_is_one_line():
    with pytest.raises(SimulationInputError, match="--range"):
        from sim.measured.linearity import NonlinearMode

        damping_interval(NonlinearMode(700.0, (0.0,), 1e-3, (0.0,), 1.0, 1e-3), 1e-3, 0.5e-3, (0.1e-3, 1e-3))


def test_time_records_per_step_give_the_steady_amplitudes(tmp_path):
    """A stepped sine recorded in time (base and tip accelerations, absolute): the fundamental harmonics of each step's
    last periods give a_base and the tip's amplitude relative to the base."""
    from sim.measured.linearity import read_level

    fs, a_base, rows = 8192.0, 5e-7, []
    for f in (116.0, 117.4, 118.0):
        t = np.arange(int(fs * 0.5)) / fs + (len(rows) and rows[-1][0] + 1 / fs)
        w = 2 * np.pi * f
        relative = 2e-4 * f / 117.4 * np.cos(w * t - 0.3)  # the tip's motion relative to the base (m)
        base_acc = -(w**2) * a_base * np.cos(w * t)
        tip_acc = base_acc - w**2 * relative
        rows += list(zip(t, np.full(t.size, f), base_acc, tip_acc))
    path = tmp_path / "steps.csv"
    path.write_text("time_s,frequency_Hz,base_m_s2,tip_m_s2\n" + "\n".join(",".join(repr(float(v)) for v in r)
                                                                           for r in rows) + "\n")
    level = read_level(path)
    assert level.a_base == pytest.approx(a_base, rel=1e-3)
    assert np.allclose(level.amplitude, 2e-4 * level.frequencies_hz / 117.4, rtol=1e-3)
