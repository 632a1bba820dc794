"""Impact records and the scattering measures (Sect. 5.5, Eq. D.1, Appendix D): the collision of a sphere with a
single-mode host (r -> 1: nothing to scatter into), the 9-mode rig (r < 1), and the records, r and the energy
share after impacts against an independent DOP853 solution (scipy, restarted at the contact events) at
a_base/a_base* = 7.4, eta = 0.976."""
import math

import numpy as np
import pytest

from sim.integration import exact
from sim.integration.energy import Ledger
from sim.stepped_sine.measures import modal_restitution, point_measures, scattering_measures, significant_impacts
from sim.integration.references import reference_run
from sim.hosts.rig import seed_rig_model
from sim.model.system import Impactor, ModalModel, Nominal, a_base_star, a_noabs_star, system_arrays


def _single_mode_restitution(phi: float) -> tuple[float, float]:
    """(median r, 90 % range of r) of a 100 Hz host of modal mass 1 / phi^2 with the rig's sphere, impacts
    of about 70 us (<< 10 ms), driven near resonance."""
    model = ModalModel(frequencies_hz=[100.0], damping_ratios=[0.002], phi_wall_left=[phi], phi_wall_right=[phi],
                       phi_tip=[phi], participation=[1 / phi])
    sys = system_arrays(model, Impactor(clearance=0.5e-3))
    Omega = 2 * math.pi * 99.0
    a_base = 6 * a_base_star(model, Nominal(D1=0.002, clearance=0.5e-3))
    y = np.zeros(4)
    y[-1] = a_base * Omega
    exact.run_step(y, 400, Omega, a_base, sys)
    ledger = Ledger()
    exact.run_step(y, 200, Omega, a_base, sys, ledger=ledger)
    r = modal_restitution(ledger.impacts, ledger.fundamental("tip"), Omega)
    lo, hi = np.percentile(r, [5, 95])
    return scattering_measures(ledger).restitution, hi - lo


def test_restitution_of_a_single_mode_host_tends_to_one():
    """Elastic collision of two masses: the relative velocity reverses, and q_tip,mod' at the impact is the
    midpoint of the host's velocity jump up to the host's higher harmonics, which vanish with m_a / M."""
    results = [_single_mode_restitution(phi) for phi in (1.0, 0.3, 0.1)]  # M = 1, 11, 100 kg
    medians = np.array([r for r, _ in results])
    spreads = np.array([s for _, s in results])
    assert np.all(np.abs(medians - 1.0) < 1e-3)
    assert abs(medians[-1] - 1.0) < 1e-4
    assert np.all(np.diff(spreads) < 0) and spreads[-1] < 5e-3


@pytest.fixture(scope="module")
def rig_apr():
    """The rig at 7.4 / eta 0.976 after 400 periods (almost periodic, Fig. 4a)."""
    model = seed_rig_model()
    sys = system_arrays(model, Impactor())
    a_base = 7.4 * a_base_star(model)
    Omega = 0.976 * float(model.omega[0])
    y = np.zeros(2 * model.n_modes + 2)
    y[-1] = a_base * Omega
    exact.run_step(y, 400, Omega, a_base, sys)
    return model, sys, a_base, Omega, y


def test_rig_scatters_restitution_below_one(rig_apr):
    model, sys, a_base, Omega, y0 = rig_apr
    ledger = Ledger()
    amplitudes, impacts = exact.run_step(y0.copy(), 300, Omega, a_base, sys, ledger=ledger)
    m = point_measures(amplitudes, impacts, a_noabs_star(model, a_base), ledger)
    s = m.scattering
    assert ledger.dropped == 0 and ledger.impacts.size == impacts.sum()
    assert 0.5 < s.restitution_wall < 0.98
    assert 0.0 < s.higher_mode_energy_share < 0.5 and 0.0 < s.higher_mode_energy_share_mean < 0.5
    assert s.dissipation_higher_modes > s.dissipation_fundamental > 0 and s.dissipation_contact == 0
    assert s.significant_impacts_per_period <= m.impacts_per_period
    # impulse = the sphere's momentum change (Eq. 3)
    np.testing.assert_allclose(ledger.impacts["impulse"], sys.m_a * np.abs(
        ledger.impacts["sphere_after"] - ledger.impacts["sphere_before"]), rtol=1e-12)


def test_significant_impacts_ignore_grazes():
    records = np.zeros(6, dtype=Ledger().impacts.dtype)
    records["period"] = [0, 0, 1, 1, 2, 2]
    records["impulse"] = [0.03, 1e-6, 0.028, 0.031, 0.002, 0.0035]  # two grazes (< 0.1 of ~0.03)
    assert significant_impacts(records).tolist() == [True, False, True, True, False, True]


def _energies(state, sys):
    n = sys.omega.size
    e = 0.5 * (state[n:2 * n] ** 2 + (sys.omega * state[:n]) ** 2)
    return e[0], e[1:].sum()


def test_records_r_and_energy_share_match_a_dop853_solution(rig_apr):
    """One period (three impacts; the response is chaotic, the two solutions part by a factor ~10 per impact
    from ~1e-12): onsets and releases, sphere velocities, modal energies, c_1 of the tip and hence r of Eq. D.1,
    all from scipy's DOP853 (rtol 1e-11, its dense output, quadrature for c_1) against the ledger."""
    model, sys, a_base, Omega, y0 = rig_apr
    T = 2 * math.pi / Omega
    periods = 1
    pieces = []
    _, onsets, releases, _ = reference_run(y0.copy(), periods * T, Omega, a_base, sys, rtol=1e-11, pieces=pieces)

    def state(t):
        for t0, t1, sol in pieces:
            if t0 <= t <= t1:
                return sol(t)
        raise AssertionError(t)

    n = model.n_modes
    x, w = np.polynomial.legendre.leggauss(12)
    c1 = np.zeros(periods, dtype=complex)
    for t0, t1, sol in pieces:  # c_1 = (2/T) int q_tip e^{-i Omega t} dt, per period
        bounds = [k * T for k in range(1, periods) if t0 < k * T < t1]  # no quadrature cell across a period's end
        edges = np.union1d(np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / 5e-6)) + 1)), bounds)
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
        t = (mid[:, None] + half[:, None] * x).ravel()
        q = sys.phi_tip @ sol(t)[:n]
        p = np.minimum(np.repeat((mid / T).astype(int), x.size), periods - 1)
        np.add.at(c1, p, 2 / T * q * np.exp(-1j * Omega * t) * (half[:, None] * w).ravel())
    ledger = Ledger()
    exact.run_step(y0.copy(), periods, Omega, a_base, sys, ledger=ledger)
    rec = ledger.impacts
    assert rec.size == onsets.size == releases.size
    np.testing.assert_allclose(ledger.fundamental("tip"), c1, rtol=1e-8)
    t_on = rec["period"] * T + rec["t_onset"]
    np.testing.assert_allclose(t_on, onsets, atol=1e-10)
    np.testing.assert_allclose(t_on + rec["duration"], releases, atol=1e-10)
    for i in range(rec.size):  # the reference's state at the ledger's instants
        before, after = state(t_on[i]), state(t_on[i] + rec["duration"][i])
        assert rec["sphere_before"][i] == pytest.approx(before[2 * n + 1], abs=1e-8)  # m/s (approach ~1 m/s)
        assert rec["sphere_after"][i] == pytest.approx(after[2 * n + 1], abs=1e-8)
        e1, eh = _energies(after, sys)
        assert rec["fundamental_release"][i] == pytest.approx(e1, rel=1e-8)
        assert rec["higher_release"][i] == pytest.approx(eh, rel=1e-7)
        p = int(rec["period"][i])
        v_mod = lambda t: np.real(1j * Omega * c1[p] * np.exp(1j * Omega * (t - p * T)))  # noqa: E731
        r_ref = -(v_mod(t_on[i] + rec["duration"][i]) - after[2 * n + 1]) / (v_mod(t_on[i]) - before[2 * n + 1])
        assert modal_restitution(rec[i:i + 1], ledger.fundamental("tip"), Omega)[0] == pytest.approx(r_ref, rel=1e-6)


def test_uq_model_outputs_the_scattering_measures():
    """`uq.problem.models.IESModel` outputs every scattering measure at the resonant mean's eta; a study names the ones
    it bands (`[study] outputs`); an unknown name is one StudyError line."""
    from uq.errors import StudyError
    from uq.problem.models import make_model

    model = make_model("ies", protocol=dict(eta_start=0.97, eta_stop=0.99, n_eta=3, wait=0.3, hold=0.3),
                       outputs=("mean", "restitution_wall"))
    assert model.banded_outputs == ("mean", "restitution_wall")
    records = []
    for rep in range(2):
        out = model({"D": 0.00085, "g": 0.58e-3, "k_H": 282e3 * 1e3**1.5}, 7.4, rep, 1)
        records.append({"outputs": {k: v for k, v in out.items() if k != "trace"}, "trace": out["trace"], "error": ""})
    summary = model.aggregate(records)
    res = model.sweep_result(records)
    at = res.eta == res.eta_resonant_mean
    for name in ("restitution_wall", "significant_impacts_per_period", "higher_mode_energy_share", "balance_error"):
        assert summary[name][0] == pytest.approx(float(res.scattering[name][at][0]))
    assert abs(summary["balance_error"][0]) < 1e-6
    with pytest.raises(StudyError, match="unknown output"):
        make_model("ies", outputs=("bogus",))
