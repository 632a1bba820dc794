"""The shooting (sim.orbits.shooting) against references that are not the shooting itself: the analytic frequency
response, the slow flow's exact orbit of the one-mode Newton model, direct simulations from the orbits (stable ones
stay, unstable ones depart at the rate of their largest multiplier), the paper's ode3 scheme at a quarter of its step,
and the variational equations of Eqs. 3-7 integrated by scipy's DOP853 alongside the state, restarted at every contact
onset and release (the vector field is C^1 across them for the Hertz law: no saltation term), against the
finite-difference monodromy matrices."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from sim.integration.exact import run_step
from sim.model.contact_law import restitution, xi_of_r_cont
from sim.model.system import Impactor, SystemArrays
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import ShootingMap, solve_orbit
from sim.orbits.starts import linear_state, slow_flow_candidates, slow_flow_state
from sim.reduced.slow_flow import exact_orbit, periodic_orbits, slow_flow_model
from sim.stepped_sine.measures import linear_tip_amplitude

from tests.sim.orbits._systems import DAMPED, departure_rate


def test_linear_limit_is_the_analytic_frequency_response(rig):
    """A clearance the response never reaches: Newton's method from a perturbed state finds the linear orbit, whose
    amplitude and state are the analytic frequency response (Eq. 7) to 1e-8."""
    setting = OrbitSetting(rig, Impactor(clearance=0.05), 7.4, 0.985)
    exact = linear_state(setting)
    n = rig.n_modes
    start = exact.copy()
    start[:2 * n] *= 1.02  # the host off its orbit; the sphere at rest (its position is free: no impact)
    orbit = solve_orbit(setting, start, symmetric=False)
    assert orbit.linear and not orbit.stable  # the free sphere: a Jordan block at 1
    frf = linear_tip_amplitude(rig, setting.Omega, setting.a_base)
    assert orbit.amplitude_m == pytest.approx(frf, rel=1e-8)
    assert np.max(np.abs(orbit.state[:2 * n] - exact[:2 * n]) / setting.scales()[:2 * n]) < 1e-8
    host = np.sort(np.abs(orbit.multipliers))[:-2]  # the host's multipliers: exp(-D_j omega_j T) in pairs
    expected = np.sort(np.repeat(np.exp(-rig.damping_ratios * rig.omega * setting.period), 2))
    assert host == pytest.approx(expected, rel=1e-5)


def test_one_mode_newton_like_contact_is_the_slow_flows_exact_orbit(newton_like):
    """One mode with the damped law at r_cont = 0.8 and a stiff contact (100 k_H*): the symmetric two-impact orbit and
    its stability are those of the one-mode Newton model's exact orbit (`sim.reduced.slow_flow.exact_orbit`, rigid
    walls, restitution r = restitution(xi(r_cont)) on the mode's mass) within 1 %."""
    model, impactor, r_cont = newton_like
    r = restitution(float(xi_of_r_cont(r_cont)))
    reference_model = slow_flow_model(model, impactor, r)
    for eta, stable in ((0.95, True), (0.97, False)):
        guess = sorted(periodic_orbits(reference_model, 7.4, eta), key=lambda o: -o.A_wall)[0]
        reference = exact_orbit(reference_model, 7.4, eta, guess)
        setting = OrbitSetting(model, impactor, 7.4, eta)
        orbit = solve_orbit(setting, slow_flow_state(setting, guess))
        assert orbit.symmetric and orbit.pattern == "RL"
        assert orbit.amplitude == pytest.approx(reference.normalised, rel=0.01)
        assert orbit.stable == reference.stable == stable
        largest = max(abs(m) for m in reference.multipliers)
        assert float(np.abs(orbit.half_multipliers[0])) == pytest.approx(largest, rel=0.02)


def test_a_stable_orbit_stays_on_it(stable_rig_orbit):
    """The rig's stable two-impact orbit (higher modes damped) as the initial state of a direct simulation: the
    state at every period start stays on it to 1e-6 (relative to g) over 200 periods, and so does the amplitude."""
    orbit = stable_rig_orbit
    s = orbit.setting
    sys = s.system()
    y = orbit.state.copy()
    record = np.empty((201, y.size))
    amplitudes, impacts = run_step(y, 200, s.Omega, s.a_base, sys, record)
    deviation = np.max(np.abs(record - orbit.state) / s.scales())
    assert deviation < 1e-6
    assert np.all(impacts == 2)
    assert np.max(np.abs(amplitudes / orbit.amplitude_m - 1.0)) < 1e-6


def test_an_unstable_orbit_departs_at_the_rate_of_its_largest_multiplier(newton_like, rig, nominal_rig_orbit):
    """A perturbation along the dominant eigenvector grows per period by the largest multiplier |mu| (within
    10 %): the one-mode orbit at 0.97 (real mu = lambda^2), the rig's orbit at 0.97 with the higher modes damped,
    and the nominal rig's at 0.95 (a complex pair: the growth of the perturbation's coordinates in the plane of the
    pair's eigenvector, on which the linearised map is |mu| times a rotation)."""
    model, impactor, _ = newton_like
    cases = [nominal_rig_orbit]
    setting = OrbitSetting(model, impactor, 7.4, 0.97)
    cases.append(solve_orbit(setting, slow_flow_state(setting, slow_flow_candidates(setting, 0.8)[0])))
    setting = OrbitSetting(rig, Impactor(), 7.4, 0.97, higher_damping=DAMPED)
    cases.append(solve_orbit(setting, slow_flow_state(setting, slow_flow_candidates(setting)[0])))
    for orbit in cases:
        assert not orbit.stable
        end, _ = orbit.jacobian
        mu, vectors = np.linalg.eig(end)
        i = int(np.argmax(np.abs(mu)))
        real = abs(mu[i].imag) < 1e-9 * abs(mu[i])
        basis = (np.real(vectors[:, [i]]) if real else np.column_stack([np.real(vectors[:, i]), np.imag(vectors[:, i])]))
        basis /= np.linalg.norm(basis[:, 0])
        periods = int(np.ceil(np.log(1e5) / np.log(abs(mu[i]))))  # grows by 1e5 from 1e-10: still linear
        rate = departure_rate(orbit.setting, orbit.state, basis, periods)
        assert rate == pytest.approx(abs(mu[i]), rel=0.10), (orbit.setting.eta, rate, mu[i])


def test_ode3_at_a_quarter_of_its_step_finds_the_same_orbit(stable_rig_orbit):
    """The paper's scheme (ode3) at a quarter of its step converges to the same orbit: amplitude within 0.1 %."""
    orbit = stable_rig_orbit
    setting = replace(orbit.setting, integrator="ode3", dt_scale=0.25)
    other = solve_orbit(setting, orbit.state)
    assert other.amplitude == pytest.approx(orbit.amplitude, rel=1e-3)
    assert other.stable and other.impacts_per_period == 2


def test_a_symmetric_orbits_multipliers_are_the_half_maps_squared(stable_rig_orbit):
    """At a symmetric orbit P = G o G: DP (finite differences of the full map) equals DG^2 to the differences'
    accuracy, so the multipliers mu = lambda^2 (`sim.orbits.shooting.multipliers`)."""
    end, half = stable_rig_orbit.jacobian
    square = half @ half
    assert np.max(np.abs(end - square)) < 1e-4 * np.max(np.abs(end))
    mu = np.sort_complex(np.linalg.eigvals(end))
    assert np.sort(np.abs(mu)) == pytest.approx(np.sort(np.abs(stable_rig_orbit.multipliers)), abs=1e-4)
    assert ShootingMap(stable_rig_orbit.setting).size == 20


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
