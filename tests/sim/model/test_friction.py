"""Appendix C's elastic Coulomb (Jenkins) element: the closed-form phase solver (sim.model.friction) against the
independent DOP853 reference with stick/slip events (sim.integration.references.jenkins_reference), the analytic pure-stick
response, the loop area of the force-displacement hysteresis and the force at the transitions."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from sim.common.errors import SimulationInputError
from sim.model.friction import JenkinsElement, floor_driven_response, floor_values
from sim.integration.references import cantilever_like_model, jenkins_reference
from sim.hosts.rig import seed_rig_model
from sim.model.system import SPHERE_MASS

ELEMENT = JenkinsElement()  # 22 kN/mm, mu = 0.07, N = m_a g
OMEGA = 2 * math.pi * 117.4
PERIOD = 2 * math.pi / OMEGA


def floor_amplitude(ratio: float) -> float:
    """Floor amplitude (m) whose acceleration amplitude is `ratio` times mu g."""
    return ratio * ELEMENT.mu * 9.81 / OMEGA**2


@pytest.fixture(scope="module", params=[2.0, 20.0], ids=["stick-slip", "mostly-slip"])
def case(request):
    X = floor_amplitude(request.param)
    pieces: list = []
    reference = jenkins_reference(ELEMENT.k_t, ELEMENT.slip_force, SPHERE_MASS, X, OMEGA, 3 * PERIOD, pieces=pieces)
    closed = floor_driven_response(ELEMENT, SPHERE_MASS, X, OMEGA, 3 * PERIOD)
    return X, reference, closed, pieces


def test_closed_form_phases_match_the_reference(case):
    X, reference, closed, _ = case
    assert len(closed.transitions) == len(reference["transitions"]) >= 10
    for (t, kind, sign), (t_ref, kind_ref, sign_ref) in zip(closed.transitions, reference["transitions"]):
        assert (kind, sign) == (kind_ref, sign_ref)
        assert t == pytest.approx(t_ref, abs=1e-11)
    assert abs(closed.u - reference["u"]) < 1e-6 * X
    assert abs(closed.z - reference["z"]) < 1e-6 * X
    assert closed.dissipated == pytest.approx(reference["dissipated"], rel=1e-8)


def test_reference_is_converged(case):
    X, reference, _, _ = case
    looser = jenkins_reference(ELEMENT.k_t, ELEMENT.slip_force, SPHERE_MASS, X, OMEGA, 3 * PERIOD, rtol=1e-10)
    assert abs(looser["u"] - reference["u"]) < 1e-8 * X
    assert looser["dissipated"] == pytest.approx(reference["dissipated"], rel=1e-8)


def test_force_is_continuous_at_the_transitions(case):
    _, reference, _, _ = case
    for (before, after), (_, kind, sign) in zip(reference["forces"], reference["transitions"]):
        assert after == pytest.approx(before, abs=1e-9 * ELEMENT.slip_force)
        if kind == "slip":
            assert before == pytest.approx(sign * ELEMENT.slip_force, rel=1e-9)


def test_dissipated_energy_per_cycle_is_the_hysteresis_loop_area(case):
    """Between two slip -> stick transitions of the same sign the elongation w is the same, so the integral of
    k_t w du (u = x - x_f) over that cycle equals the slider's dissipated energy."""
    X, reference, _, pieces = case
    ends = [t for t, kind, sign in reference["transitions"] if kind == "stick" and sign > 0]
    t_a, t_b = ends[0], ends[1]

    def state(t):
        for t0, t1, sol, _, _ in pieces:
            if t0 <= t <= t1:
                return sol(t)
        raise AssertionError(t)

    def power(t):  # k_t w (x' - x_f')
        y = state(t)
        return ELEMENT.k_t * (y[0] - y[2]) * (y[1] + X * OMEGA * math.sin(OMEGA * t))

    dissipated = state(t_b)[3] - state(t_a)[3]
    assert dissipated > 0
    area = 0.0
    for t0, t1, sol, _, _ in pieces:
        lo, hi = max(t0, t_a), min(t1, t_b)
        if hi > lo:
            area += quad(power, lo, hi, limit=2000, epsabs=1e-10 * dissipated, epsrel=1e-10)[0]
    assert area == pytest.approx(dissipated, rel=1e-6)


def test_pure_stick_is_the_analytic_forced_oscillator():
    """Below the slip limit (floor acceleration 0.3 mu g) nothing slips and, from rest, the elongation is
    w = P (cos(Omega t) - cos(w_t t)), P = X Omega^2 / (w_t^2 - Omega^2)."""
    X = floor_amplitude(0.3)
    t_end = 0.5 * PERIOD
    reference = jenkins_reference(ELEMENT.k_t, ELEMENT.slip_force, SPHERE_MASS, X, OMEGA, t_end)
    closed = floor_driven_response(ELEMENT, SPHERE_MASS, X, OMEGA, t_end)
    w_t = math.sqrt(ELEMENT.k_t / SPHERE_MASS)
    P = X * OMEGA**2 / (w_t**2 - OMEGA**2)
    analytic = P * (math.cos(OMEGA * t_end) - math.cos(w_t * t_end))
    assert reference["transitions"] == [] and closed.transitions == []
    assert reference["dissipated"] == 0.0 and closed.dissipated == 0.0
    assert reference["u"] - reference["z"] == pytest.approx(analytic, abs=1e-7 * P)  # w = x - p: cancellation
    assert closed.u - closed.z == pytest.approx(analytic, abs=1e-9 * P)


@pytest.mark.parametrize("kwargs, words", [
    ({"mu": -0.1}, "mu must be >= 0"), ({"k_t": 0.0}, "k_t (N/m, e.g. 22e6) must be > 0"),
    ({"k_t": -22e6}, "must be > 0"), ({"k_t": math.nan}, "must be > 0"), ({"normal_force": 0.0}, "normal force"),
    ({"mu": True}, "mu must be"),
])
def test_bad_friction_parameters_are_one_line(kwargs, words):
    with pytest.raises(SimulationInputError) as err:
        JenkinsElement(**kwargs)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_friction_needs_the_floor_point():
    assert JenkinsElement(mu=0.0).slip_force == 0.0
    assert np.array_equal(floor_values(seed_rig_model()), seed_rig_model().phi_floor)
    with pytest.raises(SimulationInputError, match="has no 'phi_floor'") as err:
        floor_values(cantilever_like_model(), "model.toml")
    assert "model.toml" in str(err.value) and "\n" not in str(err.value)
    assert ELEMENT.slip_elongation == pytest.approx(0.07 * SPHERE_MASS * 9.81 / 22e6)
