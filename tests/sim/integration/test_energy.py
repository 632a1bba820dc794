"""Energy bookkeeping of the integrators (Sect. 5.5): against the analytic steady state of a damped mode,
the energy balance (a conservation law), an independent DOP853 reference of the dissipation integrals, and
ode3's balance converging with the scheme's order."""
import math

import numpy as np
import pytest

from sim.integration import exact, ode3
from sim.integration.energy import Ledger, stored_energy
from sim.integration.references import reference_run
from sim.hosts.rig import seed_rig_model
from sim.model.system import Impactor, ModalModel, a_base_star, system_arrays

F1 = 117.4


def _single_mode(D: float = 0.01) -> ModalModel:
    return ModalModel(frequencies_hz=[100.0], damping_ratios=[D], phi_wall_left=[1.0], phi_wall_right=[1.0],
                      phi_tip=[1.0], participation=[1.0], source="single mode")


def test_single_damped_mode_dissipates_pi_c_omega_x2_per_period():
    """Steady state of s'' + c s' + w^2 s = a Omega^2 cos(Omega t): pi c Omega X^2 per period, X = |S|."""
    model = _single_mode()
    sys = system_arrays(model, Impactor())._replace(k_H=0.0)
    Omega, a_base = 2 * math.pi * 97.0, 1e-4
    w, D = float(model.omega[0]), 0.01
    S = a_base * Omega**2 / (w**2 - Omega**2 + 2j * D * w * Omega)
    y = np.array([S.real, -Omega * S.imag, 0.0, 0.0])  # the particular solution at phase 0
    ledger = Ledger()
    exact.run_step(y, 10, Omega, a_base, sys, ledger=ledger)
    expected = math.pi * (2 * D * w) * Omega * abs(S) ** 2
    np.testing.assert_allclose(ledger.dissipation[:, 0], expected, rtol=1e-8)
    np.testing.assert_allclose(ledger.input, expected, rtol=1e-8)
    np.testing.assert_allclose(ledger.contact, 0.0)
    assert abs(ledger.balance_error) < 1e-8


@pytest.fixture(scope="module")
def rig():
    model = seed_rig_model()
    return model, system_arrays(model, Impactor()), 7.4 * a_base_star(model)


def _settled(model, sys, a_base, eta, periods=300):
    Omega = eta * float(model.omega[0])
    y = np.zeros(2 * model.n_modes + 2)
    y[-1] = a_base * Omega
    exact.run_step(y, periods, Omega, a_base, sys)
    return y, Omega


@pytest.mark.parametrize("contacts", ["collocation", "dopri5"])
@pytest.mark.parametrize("eta", [0.976, 0.99])  # APR and SMR at a_base/a_base* = 7.4 (Fig. 4)
def test_exact_energy_balance_closes_with_impacts(rig, eta, contacts):
    model, sys, a_base = rig
    y, Omega = _settled(model, sys, a_base, eta)
    e0 = stored_energy(y, sys)
    ledger = Ledger()
    _, impacts = exact.run_step(y, 300, Omega, a_base, sys, ledger=ledger, contacts=contacts)
    assert impacts.sum() > 300  # impacts, damping and forcing all at work
    assert ledger.stored_start == e0 and ledger.stored_end == stored_energy(y, sys)
    assert abs(ledger.balance_error) <= 1e-6
    assert np.all(ledger.dissipation > 0) and np.all(ledger.contact == 0)


def test_exact_dissipation_matches_a_dop853_reference(rig):
    """The per-mode dissipation and the input work over two periods against quadrature of a tight DOP853 solution."""
    model, sys, a_base = rig
    y, Omega = _settled(model, sys, a_base, 0.976)
    T = 2 * math.pi / Omega
    pieces = []
    reference_run(y.copy(), 2 * T, Omega, a_base, sys, rtol=1e-11, pieces=pieces)
    n = model.n_modes
    x, wq = np.polynomial.legendre.leggauss(8)
    diss = np.zeros(n)
    work = 0.0
    for t0, t1, sol in pieces:
        edges = np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / 2e-6)) + 1))
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
        t = (mid[:, None] + half[:, None] * x).ravel()
        wt = (half[:, None] * wq).ravel()
        states = sol(t)
        v = states[n:2 * n]
        diss += (2 * sys.D * sys.omega)[:, None] ** 1 * v**2 @ wt
        power = a_base * Omega**2 * np.cos(Omega * t) * (sys.gamma @ v + sys.m_a * states[2 * n + 1])
        work += power @ wt
    ledger = Ledger()
    exact.run_step(y, 2, Omega, a_base, sys, ledger=ledger)
    total = ledger.input.sum()
    np.testing.assert_allclose(ledger.dissipation.sum(axis=0), diss, rtol=1e-5, atol=1e-7 * total)
    assert ledger.input.sum() == pytest.approx(work, rel=1e-6)


def test_ode3_balance_converges_with_third_order():
    """Without contacts ode3's balance error falls by 2^3 per halving of h (its own quadrature, Sect. 3.2)."""
    model = ModalModel(frequencies_hz=[100.0, 5000.0], damping_ratios=[0.01, 0.02], phi_wall_left=[1.0, 0.5],
                       phi_wall_right=[1.0, 0.5], phi_tip=[1.0, 0.5], participation=[1.0, 0.3])
    sys = system_arrays(model, Impactor())._replace(k_H=0.0)
    errors = []
    for scale in (1.0, 0.5, 0.25):
        y = np.zeros(6)
        y[-1] = 0.3
        ledger = Ledger()
        ode3.run_step(y, 20, 2 * math.pi * 97.0, 2e-3, sys, ledger=ledger, dt_scale=scale)
        errors.append(abs(ledger.balance_error))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    np.testing.assert_allclose(orders, 3.0, atol=0.1)


def test_ode3_reports_its_larger_balance_error_with_impacts(rig):
    model, sys, a_base = rig
    y, Omega = _settled(model, sys, a_base, 0.976)
    errors = []
    for scale in (1.0, 0.5):
        ledger = Ledger()
        ode3.run_step(y.copy(), 30, Omega, a_base, sys, ledger=ledger, dt_scale=scale)
        errors.append(abs(ledger.balance_error))
    assert errors[0] > 1e-4 and errors[1] < errors[0] / 2
