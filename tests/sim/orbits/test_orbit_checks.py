"""The periodic orbits (sim.orbits) against references that are not the shooting itself: the analytic frequency
response, the slow flow's exact orbit of the one-mode Newton model, direct simulations from the orbits (stable ones
stay, unstable ones depart at the rate of their largest multiplier), the stepped sine where it settles, and the
paper's ode3 scheme at a quarter of its step."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from sim.integration.exact import run_step
from sim.integration.prepared import PreparedExact
from sim.model.contact_law import restitution, xi_of_r_cont
from sim.model.system import Impactor
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import ShootingMap, solve_orbit
from sim.orbits.starts import linear_state, slow_flow_candidates, slow_flow_state
from sim.reduced.slow_flow import exact_orbit, periodic_orbits, slow_flow_model
from sim.stepped_sine.measures import linear_tip_amplitude

from conftest import DAMPED, departure_rate


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


def test_where_the_stepped_sine_is_almost_periodic_it_is_on_a_stable_orbit(rig):
    """Mode 1 alone with the damped law (r_cont = 0.86, nominal k_H): the stepped sine (up from 0.94, 3 s wait, 2 s
    hold) is almost periodic at eta 0.96 and 0.965 with two impacts per period. The orbits found by continuation in
    eta from a stepped-sine start at 0.966 are stable there, and their amplitude is the stepped sine's per-period
    amplitude within 1 %. (They are asymmetric: the symmetric two-impact orbit has lost its stability below 0.96;
    this branch doubles its period near 0.969.)"""
    from sim.model.contact_law import ContactLaw
    from sim.orbits.response import orbit_response
    from sim.stepped_sine.protocol import SteppedSine, run_sweep

    from conftest import one_mode

    model, impactor = one_mode(rig), Impactor(contact_law=ContactLaw("hertz-damped", 0.86))
    sweep = run_sweep(model, impactor, 7.4, SteppedSine(eta_start=0.94, eta_stop=0.97, n_eta=7, wait=3.0, hold=2.0,
                                                        perturbation=0.0), seed=0, rep=0)
    response = orbit_response(OrbitSetting(model, impactor, 7.4, 0.966), "eta", (0.955, 0.966), start="simulation",
                              at=0.966, max_period=1, switches=0)
    branch = response.branches[0]
    etas = branch.values()
    for eta, mean, std in zip(sweep.eta[-3:-1], sweep.mean[-3:-1], sweep.std[-3:-1]):
        assert std / mean < 0.01
        nearest = branch.points[int(np.argmin(np.abs(etas - eta)))].orbit
        orbit = solve_orbit(replace(nearest.setting, eta=float(eta)), nearest.state, symmetric=False)
        assert orbit.stable and not orbit.symmetric and orbit.impacts_per_period == 2
        assert orbit.amplitude == pytest.approx(mean, rel=0.01)


def test_the_two_impact_orbit_loses_stability_where_the_slow_flow_says(rig):
    """The same host: continued in eta, the symmetric two-impact orbit loses its stability through a located
    Neimark-Sacker point between 0.955 and 0.96, where the one-mode Newton model's exact orbit is stable and
    unstable (`sim.reduced.slow_flow.exact_orbit`, r = the law's restitution)."""
    from sim.model.contact_law import ContactLaw
    from sim.orbits.response import orbit_response

    from conftest import one_mode

    model, impactor = one_mode(rig), Impactor(contact_law=ContactLaw("hertz-damped", 0.86))
    r = restitution(float(xi_of_r_cont(0.86)))
    reference = slow_flow_model(model, impactor, r)
    stable = {}
    for eta in (0.955, 0.96):
        guess = sorted(periodic_orbits(reference, 7.4, eta), key=lambda o: -o.A_wall)[0]
        stable[eta] = exact_orbit(reference, 7.4, eta, guess).stable
    assert stable == {0.955: True, 0.96: False}
    response = orbit_response(OrbitSetting(model, impactor, 7.4, 0.95), "eta", (0.95, 0.97), switches=0,
                              restitution=r)
    lost = [p for p in response.branches[0].points if p.note == "loses stability"]
    assert len(lost) == 1 and lost[0].label == "neimark-sacker"
    assert 0.955 < lost[0].orbit.setting.eta < 0.96
    assert abs(abs(complex(lost[0].orbit.half_multipliers[0])) - 1.0) < 1e-2 or any(
        abs(abs(m) - 1.0) < 1e-2 for m in lost[0].orbit.half_multipliers)


def test_prepared_runs_are_run_step_bit_for_bit(stable_rig_orbit):
    """PreparedExact after other runs and a new excitation gives exact.run_step's numbers bit for bit."""
    s = stable_rig_orbit.setting
    sys = s.system()
    prepared = PreparedExact(2, s.Omega * 1.01, s.a_base, sys, samples=2)
    for shift in (1e-4, -2e-4):
        prepared.advance(stable_rig_orbit.state * (1 + shift))
    prepared.retarget(s.Omega, s.a_base)
    y = stable_rig_orbit.state.copy()
    amplitudes, impacts, record = prepared.advance(y)
    y_ref = stable_rig_orbit.state.copy()
    record_ref = np.empty((5, y.size))
    amplitudes_ref, impacts_ref = run_step(y_ref, 2, s.Omega, s.a_base, sys, record_ref)
    assert np.array_equal(y, y_ref) and np.array_equal(record, record_ref)
    assert np.array_equal(amplitudes, amplitudes_ref) and np.array_equal(impacts, impacts_ref)


def test_a_symmetric_orbits_multipliers_are_the_half_maps_squared(stable_rig_orbit):
    """At a symmetric orbit P = G o G: DP (finite differences of the full map) equals DG^2 to the differences'
    accuracy, so the multipliers mu = lambda^2 (`sim.orbits.shooting.multipliers`)."""
    end, half = stable_rig_orbit.jacobian
    square = half @ half
    assert np.max(np.abs(end - square)) < 1e-4 * np.max(np.abs(end))
    mu = np.sort_complex(np.linalg.eigvals(end))
    assert np.sort(np.abs(mu)) == pytest.approx(np.sort(np.abs(stable_rig_orbit.multipliers)), abs=1e-4)
    assert ShootingMap(stable_rig_orbit.setting).size == 20
