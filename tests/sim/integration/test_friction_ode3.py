"""Dry friction (Appendix C) inside the paper's integrator (ode3): the sphere on a floor that moves with the base
(a host whose floor value is 0) against the closed-form stick/slip solution (`sim.model.friction.floor_driven_response`)
and the independent DOP853 reference with events (`sim.integration.references.jenkins_reference`), the located transitions'
order of convergence, the energy bookkeeping with friction on a rig point, mu = 0 as exactly no friction, and the
exact integrator's refusal."""
from __future__ import annotations

import math

import numpy as np
import pytest

from sim.integration import exact, ode3
from sim.integration.energy import Ledger
from sim.common.errors import SimulationInputError
from sim.model.friction import GRAVITY, JenkinsElement, floor_driven_response
from sim.integration.references import jenkins_reference
from sim.hosts.rig import seed_rig_model
from sim.model.system import SPHERE_MASS, Impactor, ModalModel, a_base_star, system_arrays

OMEGA = 2 * math.pi * 117.4
MU = 0.07
FLOOR_IS_BASE = ModalModel(frequencies_hz=np.array([100.0]), damping_ratios=np.array([0.01]),
                           phi_wall_left=np.array([0.0]), phi_wall_right=np.array([0.0]), phi_tip=np.array([1.0]),
                           participation=np.array([0.0]), source="a host whose floor moves with the base",
                           phi_floor=np.array([0.0]))


def floor_run(factor: float, dt_scale: float, periods: int = 3) -> tuple[np.ndarray, Ledger, float]:
    """The sphere from rest on the floor moved as X cos(Omega t) with a floor acceleration of factor mu g, by ode3
    (the walls 1 mm away are never reached); returns (final state, ledger, X)."""
    X = factor * MU * GRAVITY / OMEGA**2
    sys = system_arrays(FLOOR_IS_BASE, Impactor(clearance=1e-3, friction=MU))
    y = np.zeros(4)
    ledger = Ledger()
    ode3.run_step(y, periods, OMEGA, X, sys, ledger=ledger, dt_scale=dt_scale)
    return y, ledger, X


@pytest.mark.parametrize("factor", [2.0, 20.0])
def test_stick_slip_matches_the_closed_form_and_the_scipy_reference(factor):
    """Displacement within 1e-6 of X at dt/400 (13 transitions in three periods), dissipated energy within 1e-5,
    and the same against DOP853 with located events (an independent solver)."""
    y, ledger, X = floor_run(factor, 0.0025)
    T3 = 3 * 2 * math.pi / OMEGA
    closed = floor_driven_response(JenkinsElement(), SPHERE_MASS, X, OMEGA, T3)
    scipy_ref = jenkins_reference(22e6, MU * SPHERE_MASS * GRAVITY, SPHERE_MASS, X, OMEGA, T3)
    print(f"\n{factor} mu g: u error {(y[2] - closed.u) / X:.1e} X, dissipation {ledger.friction.sum() / closed.dissipated - 1:.1e}, "
          f"{len(closed.transitions)} transitions")
    for ref_u, ref_v, ref_e in ((closed.u, closed.v, closed.dissipated), (scipy_ref["u"], scipy_ref["xd"], scipy_ref["dissipated"])):
        assert abs(y[2] - ref_u) <= 1e-6 * X
        assert abs(y[3] - ref_v) <= 1e-6 * X * OMEGA
        assert ledger.friction.sum() == pytest.approx(ref_e, rel=1e-5)
    assert len(closed.transitions) >= 10


def test_located_transitions_keep_the_order_of_the_scheme():
    """Halving the step divides the displacement error by >= 4 (third order expected; a transition smoothed or
    taken at the step points instead would leave first or second order)."""
    T3 = 3 * 2 * math.pi / OMEGA
    X = 2.0 * MU * GRAVITY / OMEGA**2
    closed = floor_driven_response(JenkinsElement(), SPHERE_MASS, X, OMEGA, T3)
    errors = [abs(floor_run(2.0, s)[0][2] - closed.u) for s in (0.02, 0.01, 0.005)]
    print(f"\nerrors / X: {[f'{e / X:.2e}' for e in errors]}")
    assert errors[1] <= errors[0] / 4 and errors[2] <= errors[1] / 4


def test_energy_balance_closes_with_friction_on_the_rig():
    """The rig at level 1.26 (the sphere sticks and slips on the floor, Appendix C): the ledger's balance error,
    which includes the slider's dissipation and the spring's energy, falls with the step like the scheme's."""
    model = seed_rig_model(9)
    errors = []
    for dt_scale in (0.5, 0.25):
        sys = system_arrays(model, Impactor(friction=MU))
        y = np.zeros(20)
        a_base = 1.26 * a_base_star(model)
        ode3.run_step(y, 30, 0.99 * model.omega[0], a_base, sys, dt_scale=dt_scale)
        ledger = Ledger()
        ode3.run_step(y, 20, 0.99 * model.omega[0], a_base, sys, ledger=ledger, dt_scale=dt_scale)
        errors.append(abs(ledger.balance_error))
        assert ledger.friction.sum() > 0
    print(f"\nrig 1.26 with friction: balance errors {errors}")
    assert errors[1] < errors[0] / 4


def test_no_friction_is_bit_for_bit_the_model_without_it():
    model = seed_rig_model(9)
    a_base = 7.4 * a_base_star(model)
    results = []
    for impactor in (Impactor(), Impactor(friction=0.0, k_t=5e6)):
        y = np.zeros(20)
        ledger = Ledger()
        amplitudes, _ = ode3.run_step(y, 20, 0.985 * model.omega[0], a_base, system_arrays(model, impactor), ledger=ledger)
        results.append((amplitudes, y, ledger.periods))
    for a, b in zip(*results):
        assert np.array_equal(a, b)


def test_the_exact_integrator_refuses_friction():
    sys = system_arrays(seed_rig_model(9), Impactor(friction=MU))
    with pytest.raises(SimulationInputError, match="ode3 integrator only"):
        exact.run_step(np.zeros(20), 1, OMEGA, 1e-6, sys)


@pytest.mark.parametrize("kwargs, phrase", [({"friction": -0.1}, "mu must be >= 0"), ({"k_t": -1.0}, "k_t (N/m)")])
def test_bad_friction_parameters(kwargs, phrase):
    with pytest.raises(SimulationInputError, match=phrase.replace("(", r"\(").replace(")", r"\)")):
        Impactor(**kwargs)
