"""The synthetic measurement set: the friction element's describing function against a direct integration of its
hysteresis loop (an independent route: the Jenkins elements driven through a cycle X cos(theta) and the first harmonic
of their force taken numerically), and the time-integrated stepped sine against the describing function."""
from __future__ import annotations

import numpy as np
import pytest

from sim.measured.synthetic import Iwan, iwan_backbone, shaker_levels

IWAN = Iwan(2 * np.pi * 117.4, 1.3555, 0.0045, np.geomspace(0.2e-3, 3e-3, 12))


def loop_harmonic(iwan: Iwan, X: float, n: int = 20000) -> tuple[float, float]:
    """(in-phase stiffness, energy lost per cycle) of the Iwan element driven through s = X cos(theta), from its
    force over the second of two cycles (the first sets the sliders)."""
    theta = np.linspace(0, 4 * np.pi, 2 * n, endpoint=False)
    s = X * np.cos(theta)
    z = np.zeros(iwan.slips.size)
    force = np.zeros(theta.size)
    for i, si in enumerate(s):
        stretch = si - z
        z = np.where(np.abs(stretch) > iwan.slip_modal, si - np.sign(stretch) * iwan.slip_modal, z)
        force[i] = iwan.stiffness * np.sum(si - z)
    f, th, ds = force[n:], theta[n:], np.gradient(s)[n:]
    in_phase = 2 * np.mean(f * np.cos(th)) / X
    return in_phase, float(np.sum(f * ds))


@pytest.mark.parametrize("a", [0.1e-3, 0.5e-3, 1.0e-3, 3.0e-3])
def test_the_describing_function_is_the_hysteresis_loops_first_harmonic(a):
    X = a / IWAN.phi_tip
    k_loop, lost = loop_harmonic(IWAN, X)
    omega, D = iwan_backbone(IWAN, 0.0, np.array([a]))
    w2_lin = IWAN.omega_1**2 * (1 - IWAN.kappa)
    assert omega[0] ** 2 == pytest.approx(w2_lin + k_loop, rel=1e-6)
    assert 2 * D[0] * omega[0] == pytest.approx(lost / (np.pi * omega[0] * X**2), rel=1e-3, abs=1e-4)


def test_the_time_integration_meets_the_describing_function_near_resonance():
    """Away from the small amplitudes the friction's higher harmonics are weak: the time-integrated response of each
    step agrees with the describing function's harmonic balance within 1 %."""
    from sim.measured.linearity import balance_roots

    steps = 117.4 * np.array([0.996, 1.0, 1.002])
    a_base = 9.4e-7
    gamma = 1.0573
    tip = shaker_levels(IWAN, 0.0006, gamma, steps, np.array([a_base]))[0]
    grid = np.geomspace(1e-7, 1e-2, 600)
    w, D = iwan_backbone(IWAN, 0.0006, grid)
    for f, x in zip(steps, tip):
        roots = balance_roots(lambda a: np.interp(a, grid, w), lambda a: np.interp(a, grid, D),
                              IWAN.phi_tip * gamma, 2 * np.pi * f, a_base, 1e-2)
        assert abs(x) == pytest.approx(roots.max(), rel=0.01)
