"""The shooting's finite-difference monodromy matrices (sim.orbits.shooting) against the variational equations of
Eqs. 3-7 integrated by scipy's DOP853 alongside the state, restarted at every contact onset and release (the vector
field is C^1 across them for the Hertz law: no saltation term), over half a period and a whole one."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from sim.model.system import SystemArrays
from sim.orbits.shooting import ShootingMap


def variational_run(y0: np.ndarray, times: list[float], Omega: float, a_base: float,
                    sys: SystemArrays) -> list[np.ndarray]:
    """The transition matrices dy(t)/dy0 at `times` (s) of Eqs. 3-7 with the Hertz law (Eq. 4), by DOP853 (rtol
    1e-11) on the state and its variational equations, restarted at the contact events."""
    n = sys.omega.size
    m = 2 * n + 2
    w2, c = sys.omega**2, 2 * sys.D * sys.omega
    k = sys.k_H

    def parts(y):
        s, u = y[:n], y[2 * n]
        dl = sys.phi_l @ s - u - sys.g
        dr = sys.phi_r @ s - u + sys.g
        return dl, dr

    def rhs(t, z):
        y, Phi = z[:m], z[m:].reshape(m, m)
        dl, dr = parts(y)
        fl = k * dl**1.5 if dl > 0 else 0.0
        fr = -k * (-dr) ** 1.5 if dr < 0 else 0.0
        kl = 1.5 * k * math.sqrt(dl) if dl > 0 else 0.0  # d f_l / d delta_l
        kr = 1.5 * k * math.sqrt(-dr) if dr < 0 else 0.0  # d f_r / d delta_r
        acc = a_base * Omega**2 * math.cos(Omega * t)
        out = np.empty_like(z)
        out[:n] = y[n:2 * n]
        out[n:2 * n] = -c * y[n:2 * n] - w2 * y[:n] - sys.phi_l * fl - sys.phi_r * fr + sys.gamma * acc
        out[2 * n] = y[2 * n + 1]
        out[2 * n + 1] = (fl + fr) / sys.m_a + acc
        A = np.zeros((m, m))
        A[:n, n:2 * n] = np.eye(n)
        A[n:2 * n, :n] = -np.diag(w2) - kl * np.outer(sys.phi_l, sys.phi_l) - kr * np.outer(sys.phi_r, sys.phi_r)
        A[n:2 * n, n:2 * n] = -np.diag(c)
        A[n:2 * n, 2 * n] = kl * sys.phi_l + kr * sys.phi_r
        A[2 * n, 2 * n + 1] = 1.0
        A[2 * n + 1, :n] = (kl * sys.phi_l + kr * sys.phi_r) / sys.m_a
        A[2 * n + 1, 2 * n] = -(kl + kr) / sys.m_a
        out[m:] = (A @ Phi).ravel()
        return out

    def left(t, z):
        return parts(z[:m])[0]

    def right(t, z):
        return parts(z[:m])[1]

    left.terminal = right.terminal = True
    scale = np.concatenate([np.full(n, sys.g), np.full(n, sys.g * sys.omega.max()), [sys.g, sys.g * sys.omega.max()]])
    atol = np.concatenate([scale * 1e-13, np.full(m * m, 1e-11)])
    z = np.concatenate([y0, np.eye(m).ravel()])
    t, out = 0.0, []
    for target in times:
        while t < target:
            sol = solve_ivp(rhs, (t, target), z, method="DOP853", rtol=1e-11, atol=atol, events=(left, right),
                            first_step=1e-8)
            z, t_new = sol.y[:, -1].copy(), sol.t[-1]
            if sol.status == 1:  # step just past the event so that it does not fire again at once
                sol = solve_ivp(rhs, (t_new, min(t_new + 1e-9, target)), z, method="DOP853", rtol=1e-11, atol=atol)
                z, t_new = sol.y[:, -1].copy(), sol.t[-1]
            t = t_new
        out.append(z[m:].reshape(m, m).copy())
    return out


@pytest.mark.slow
@pytest.mark.parametrize("which, tolerance", [("stable_rig_orbit", 1e-6), ("nominal_rig_orbit", 1e-4)])
def test_finite_differences_match_the_variational_equations(which, tolerance, request):
    """The rig with two impacts per period, its orbits at 7.4 / 0.95 with the higher modes damped (stable) and
    nominal (|mu| ~ 12, the ringing higher modes): the central differences' DF_half and DP_1 agree with the
    variational equations to `tolerance` of the matrices' largest entry (measured 2e-8 and 4e-6), the multipliers'
    moduli to `tolerance` too."""
    orbit = request.getfixturevalue(which)
    s = orbit.setting
    sys = s.system()
    half_ref, end_ref = variational_run(orbit.state, [s.period / 2, s.period], s.Omega, s.a_base, sys)
    scale = s.scales()
    to_scaled = lambda M: M * scale[None, :] / scale[:, None]  # noqa: E731
    end, half = ShootingMap(s).jacobian(orbit.state)
    for fd, ref in ((half, to_scaled(half_ref)), (end, to_scaled(end_ref))):
        assert np.max(np.abs(fd - ref)) < tolerance * np.max(np.abs(ref))
    mu_ref = np.sort(np.abs(np.linalg.eigvals(to_scaled(end_ref))))
    assert np.sort(np.abs(np.linalg.eigvals(end))) == pytest.approx(mu_ref, rel=tolerance)
