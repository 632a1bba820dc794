"""The response's nature (sim.stepped_sine.dynamics) against references that are not the estimator: the linear host's
analytic decay, a stable periodic orbit's Floquet multiplier (from the shooting's monodromy matrix), the rig's chaotic
response that stays chaotic with a longer record and tighter contacts, and the classification's cases."""
from __future__ import annotations

import math

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.hosts.rig import seed_rig_model
from sim.integration.integrators import get_integrator
from sim.model.system import Impactor, a_base_star
from sim.stepped_sine.dynamics import (CHAOTIC, MIN_PERIODS, PERIODIC, QUASI_PERIODIC, Lyapunov, check_record, classify,
                                       largest_lyapunov, linear_host_exponent, one_period, periodicity, poincare,
                                       state_scales)
from sim.stepped_sine.protocol import SteppedSine, simulated_system, visit_points


@pytest.fixture(scope="module")
def rig():
    return seed_rig_model(9)


def stepped_sine_state(model, impactor, level, eta):
    """The state a stepped sine up from 0.96 (10 points) reaches at eta, with (sys, a_base, Omega) there."""
    sys = simulated_system(model, impactor)
    a_base = level * a_base_star(model)
    y = np.zeros(2 * model.n_modes + 2)
    for *_, Omega in visit_points(model, sys, a_base, SteppedSine(eta_start=0.96, eta_stop=eta, n_eta=10), y,
                                  seed=0, rep=0):
        pass
    return y, sys, a_base, Omega


def test_the_host_alone_decays_at_mode_ones_damping(rig):
    """Without the sphere the host is linear: its largest exponent is mode 1's decay over a period,
    -D_1 omega_1 T = -2 pi D_1 / eta, within 1 % (measured: 4e-6 relative over 400 periods)."""
    y, sys, a_base, Omega = stepped_sine_state(rig, None, 7.4, 0.978)
    eta = Omega / float(rig.omega[0])
    result = largest_lyapunov(one_period(get_integrator("exact"), Omega, a_base, sys), y, 400,
                              state_scales(rig, sys.g), host_only=True)
    expected = -2.0 * math.pi * float(rig.damping_ratios[0]) / eta
    assert linear_host_exponent(rig, eta) == pytest.approx(expected, rel=1e-12)
    assert result.per_period == pytest.approx(expected, rel=0.01)
    assert result.converged and result.host_only


def test_a_stable_orbit_decays_at_its_largest_multiplier(rig):
    """On the rig's stable two-impact orbit (7.4 / 0.95, higher modes damped 100-fold; its leading multipliers a
    complex pair of modulus 0.9765, from the shooting's monodromy matrix) the exponent is ln |mu|max per period
    within 10 % (measured: within 1 % over 200-800 periods)."""
    from sim.orbits.setting import OrbitSetting
    from sim.orbits.shooting import solve_orbit
    from sim.orbits.starts import slow_flow_candidates, slow_flow_state

    setting = OrbitSetting(rig, Impactor(), 7.4, 0.95, higher_damping=100.0)
    orbit = solve_orbit(setting, slow_flow_state(setting, slow_flow_candidates(setting)[0]))
    assert orbit.stable
    run = one_period(get_integrator("exact"), setting.Omega, setting.a_base, setting.system())
    result = largest_lyapunov(run, orbit.state, 400, setting.scales())
    assert result.per_period == pytest.approx(math.log(orbit.max_multiplier), rel=0.10)
    states = []
    largest_lyapunov(run, orbit.state, MIN_PERIODS, setting.scales(), on_period=lambda i, y, a, n: states.append(y))
    assert periodicity(np.array(states), setting.scales()) == 1
    assert classify(result, 1, 2.0) == PERIODIC


def test_the_rigs_response_at_7_4_is_chaotic_and_stays_so(rig):
    """The rig at 7.4 / eta 0.978 (the stepped sine's almost periodic response): a positive exponent of 5-9 per
    period, three standard errors clear of zero; with the record doubled and with every contact taken by
    Dormand-Prince at a hundred times tighter tolerance it stays positive and agrees within the errors (and 10 %)."""
    y, sys, a_base, Omega = stepped_sine_state(rig, Impactor(), 7.4, 0.978)
    scale = state_scales(rig, sys.g)
    runs = {"record": (one_period(get_integrator("exact"), Omega, a_base, sys), 400),
            "doubled": (one_period(get_integrator("exact"), Omega, a_base, sys), 800),
            "tighter": (one_period(get_integrator("exact"), Omega, a_base, sys, rtol=1e-13, contacts="dopri5"), 400)}
    results = {name: largest_lyapunov(run, y, n, scale) for name, (run, n) in runs.items()}
    for name, result in results.items():
        assert 5.0 < result.per_period < 9.0 and result.per_period > 3 * result.standard_error, name
        assert classify(result, None, 3.0) == CHAOTIC
    reference = results["record"]
    for name in ("doubled", "tighter"):
        other = results[name]
        spread = 3 * math.hypot(reference.standard_error, other.standard_error) + 0.1 * reference.per_period
        assert abs(other.per_period - reference.per_period) < spread, name


def test_a_record_too_short_is_refused_naming_the_length_needed():
    with pytest.raises(SimulationInputError, match=f"at least {MIN_PERIODS} excitation periods.*--periods 20"):
        check_record(20)
    assert check_record(MIN_PERIODS) == MIN_PERIODS


def test_classify_and_periodicity_on_constructed_cases():
    """Each branch of the classification, and the least period of states that repeat after 1, 3 or never."""
    def lyapunov(value, error):
        return Lyapunov(per_period=value, standard_error=error, periods=100, transient=25, growth=np.zeros(100),
                        running=np.zeros(75), converged=True, periods_needed=100)

    assert classify(lyapunov(0.5, 0.01), None, 2.0) == CHAOTIC
    assert classify(lyapunov(0.005, 0.0001), None, 2.0) == QUASI_PERIODIC  # below CHAOS_FLOOR: zero for a torus
    assert classify(lyapunov(1e-4, 1e-3), None, 2.0) == QUASI_PERIODIC
    assert classify(lyapunov(-0.02, 1e-3), None, 2.0) == PERIODIC
    assert classify(lyapunov(1e-4, 1e-3), 3, 2.0) == PERIODIC
    assert classify(lyapunov(0.5, 0.01), None, 0.0) == PERIODIC  # no contact: the linear response
    scale = np.ones(2)
    assert periodicity(np.tile([[1.0, 2.0]], (40, 1)), scale) == 1
    assert periodicity(np.tile([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]], (20, 1)), scale) == 3
    phases = np.arange(60) * (math.sqrt(2.0) - 1.0) * 2 * math.pi
    assert periodicity(np.column_stack([np.cos(phases), np.sin(phases)]), scale) is None


def test_the_spectrum_of_a_period_two_amplitude_is_one_line(rig):
    """Amplitudes that alternate (a 2T response): all the spectrum's power at half a cycle per period."""
    states = np.zeros((64, 2 * rig.n_modes + 2))
    amplitudes = np.where(np.arange(64) % 2, 1.1, 0.9)
    data = poincare(states, amplitudes, rig, 700.0, 1.0)
    assert data["frequency_per_period"][np.argmax(data["amplitude_spectrum"])] == 0.5
    assert np.sum(data["amplitude_spectrum"][:-1]) < 1e-20
