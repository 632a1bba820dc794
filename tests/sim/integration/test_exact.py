"""The exact free-flight integrator against references that are not our own code: scipy's
solve_ivp (DOP853, rtol 1e-12, restarted at every contact event), the analytic harmonic response, the
rigid-wall Hertz impact (restitution 1), energy conservation, and the paper's ode3 at dt/8."""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from sim.integration import dopri5, exact, flight, ode3
from sim.common.errors import SimulationInputError
from sim.hosts.rig import seed_rig_model
from sim.model.system import Impactor, a_base_star, system_arrays

from sim.integration.references import cantilever_like_model, rebound_error, reference_run, ringing_energy_drift

N9 = 9


def _particular_state(sys, Omega, a_base):
    """y at phase 0 on the steady harmonic response of the linear structure (sphere centred, at rest)."""
    S = sys.gamma * a_base * Omega**2 / (sys.omega**2 - Omega**2 + 2j * sys.D * sys.omega * Omega)
    n = sys.omega.size
    y = np.zeros(2 * n + 2)
    y[:n] = S.real
    y[n:2 * n] = -Omega * S.imag
    return y, S


def test_free_flight_is_the_analytic_harmonic_response(three_mode_model):
    """On the particular solution every period's |c_1| is |phi_tip^T S| (Eq. 9, particular part) exactly."""
    sys = system_arrays(three_mode_model, Impactor(clearance=1.0))  # clearance never reached
    Omega = 0.98 * three_mode_model.omega[0]
    y, S = _particular_state(sys, Omega, 2e-6)
    y0 = y.copy()
    amplitudes, impacts = exact.run_step(y, 5, Omega, 2e-6, sys)
    assert np.all(impacts == 0)
    np.testing.assert_allclose(amplitudes, abs(sys.phi_tip @ S), rtol=1e-12)
    np.testing.assert_allclose(y, y0, rtol=1e-10, atol=1e-12 * np.abs(y0).max())


def test_free_flight_transient_and_fourier_match_scipy(three_mode_model):
    """A transient (homogeneous + particular, all modes): state and per-period c_1 vs DOP853 + quad."""
    sys = system_arrays(three_mode_model, Impactor(clearance=1.0))
    Omega = 0.97 * three_mode_model.omega[0]
    a_base = 3e-6
    y = np.zeros(2 * 3 + 2)
    y[:3] = [2e-4, -3e-6, 1e-7]
    y[3:6] = [0.05, -0.02, 0.03]
    y[6:] = [1e-4, 0.01]
    y0 = y.copy()
    T = 2 * math.pi / Omega
    amplitudes, _ = exact.run_step(y, 2, Omega, a_base, sys)
    from scipy.integrate import solve_ivp

    def rhs(t, v):
        acc = a_base * Omega**2 * math.cos(Omega * t)
        return np.concatenate([v[3:6], -2 * sys.D * sys.omega * v[3:6] - sys.omega**2 * v[:3] + sys.gamma * acc,
                               [v[7], acc]])

    sol = solve_ivp(rhs, (0, 2 * T), y0, method="DOP853", rtol=1e-12, atol=1e-18, dense_output=True)
    np.testing.assert_allclose(y, sol.y[:, -1], rtol=1e-8, atol=1e-12)
    for p in range(2):
        q = lambda t: sys.phi_tip @ sol.sol(t)[:3]  # noqa: E731
        re = quad(lambda t: q(t) * math.cos(Omega * t), p * T, (p + 1) * T, limit=200, epsabs=1e-16)[0]
        im = quad(lambda t: q(t) * math.sin(Omega * t), p * T, (p + 1) * T, limit=200, epsabs=1e-16)[0]
        assert amplitudes[p] == pytest.approx(2 / T * math.hypot(re, im), rel=1e-8)


def test_fourier_coefficient_through_impacts_matches_scipy():
    """With impacts (the contact force's Fourier integral in play): per-period |c_1| against quad of the
    DOP853 reference, piece by piece between the contact events."""
    sys = system_arrays(cantilever_like_model(), Impactor(clearance=1e-4))  # a few impacts per period
    Omega = 2 * math.pi * 1000.0
    T = 2 * math.pi / Omega
    y0 = np.zeros(2 * N9 + 2)
    y0[2 * N9] = -sys.g + 2e-5  # 20 um from the left wall, closing at 0.3 m/s
    y0[2 * N9 + 1] = -0.3
    a_base = 2e-5
    pieces = []
    y_ref, onsets, _, _ = reference_run(y0, 3 * T, Omega, a_base, sys, pieces=pieces)
    y = y0.copy()
    amplitudes, impacts = exact.run_step(y, 3, Omega, a_base, sys)
    assert impacts.sum() == onsets.size >= 6
    print(f"\nimpacts per period {impacts.tolist()}")
    for p in range(3):
        re = im = 0.0
        for t0, t1, sol in pieces:
            a, b = max(t0, p * T), min(t1, (p + 1) * T)
            if b > a:
                q = lambda t: sys.phi_tip @ sol(t)[:N9]  # noqa: E731
                re += quad(lambda t: q(t) * math.cos(Omega * t), a, b, limit=400, epsabs=1e-18)[0]
                im += quad(lambda t: q(t) * math.sin(Omega * t), a, b, limit=400, epsabs=1e-18)[0]
        assert amplitudes[p] == pytest.approx(2 / T * math.hypot(re, im), rel=1e-7)


@pytest.mark.parametrize("v0", [0.1, 0.5, 1.0])
def test_rebound_error_at_most_ode3_at_dt_over_8(v0):
    """Acceptance: per-impact error (rebound velocity) <= that of ode3 at dt/8, against DOP853."""
    err_exact = rebound_error(v0, lambda y, s, Om, a: exact.run_step(y, 1, Om, a, s))
    err_ode3 = rebound_error(v0, lambda y, s, Om, a: ode3.run_step(y, 1, Om, a, s, dt_scale=1 / 8))
    print(f"\nv0 = {v0} m/s: exact {err_exact:.2e}, ode3 dt/8 {err_ode3:.2e}")
    assert err_exact <= err_ode3
    assert err_exact < 1e-7


def test_rigid_wall_restitution_work_precision(rigid_wall_model):
    """Hertz impact on a rigid wall: restitution 1 (analytic) to 1e-9 at tight tolerance, and the error
    falls at least like work^-4 under tolerance refinement (onset and release steps included)."""
    sys = system_arrays(rigid_wall_model, Impactor())
    v0 = 0.5
    y0 = np.array([0.0, 0.0, sys.g - 1e-5, v0])
    Omega = 2 * math.pi * 1000.0
    errors, work = [], []
    for rtol in (1e-7, 1e-8, 1e-9, 1e-10):
        y = y0.copy()
        stats = {}
        exact.run_step(y, 1, Omega, 0.0, sys, rtol=rtol, stats=stats)
        errors.append(abs(abs(y[3]) - v0) / v0)
        work.append(stats["contact_steps"] + stats["rejected_steps"] + stats["release_iterations"])
    slope = np.polyfit(np.log(work), np.log(errors), 1)[0]
    print(f"\nrigid wall: DOPRI5 steps {work}, restitution errors {['%.1e' % e for e in errors]}, slope {slope:.2f}")
    assert errors[-1] < 1e-9
    assert slope < -4.0


def test_observed_order_of_the_contact_step():
    """Fixed steps through a closed contact (9 modes, 20 us inside the contact) against DOP853:
    the log-log fit of the error against the step gives the Dormand-Prince order 5."""
    sys = system_arrays(cantilever_like_model(), Impactor())
    y0 = np.zeros(2 * N9 + 2)
    y0[2 * N9] = -sys.g - 5e-6  # 5 um into the left wall ...
    y0[2 * N9 + 1] = -0.3  # ... and still closing at 0.3 m/s
    Omega = 2 * math.pi * 50e3  # one "period" = 20 us, all of it in contact
    y_ref, onsets, releases, _ = reference_run(y0, 2 * math.pi / Omega, Omega, 0.0, sys)
    assert releases.size == 0
    steps, errors = [], []
    for n_steps in (8, 16, 32, 64):
        h = 2 * math.pi / Omega / n_steps
        y = y0.copy()
        exact.run_step(y, 1, Omega, 0.0, sys, fixed_contact_step=h)
        steps.append(h)
        errors.append(np.max(np.abs(y - y_ref) / np.maximum(np.abs(y_ref), 1e-3 * np.abs(y_ref).max())))
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    print(f"\ncontact step: h {['%.2e' % h for h in steps]} s, errors {['%.1e' % e for e in errors]}, order {order:.2f}")
    assert 4.5 < order < 6.0


def test_energy_conserved_over_1000_impacts():
    """No damping (D = 1e-15), no excitation: modal + sphere (+ contact) energy within 1e-6 over >= 1000 impacts.

    Collocated contacts conserve it to ~1e-10 per impact; the drift comes from the contacts that fall back
    to the Dormand-Prince pair (5-10 % in this ringing, undamped case; 2 % in the rig's sweeps) and
    depends on rtol and on the (chaotic) trajectory: 3e-7 to 9e-7 at 1e-10, 6e-9 to 3e-7 at the default 1e-11
    (tests/benchmarks/test_exact_energy.py)."""
    drift, impacts, _ = ringing_energy_drift()
    print(f"\n{impacts} impacts: relative energy change {drift:.2e}")
    assert drift < 1e-6


def test_release_is_located_when_the_first_guess_ends_short():
    """Regression: the release search gave up (and released at the end of a regular step, 1e-5 errors per
    impact) whenever its first trial step ended still closed; it must converge onto c = 0 from either side."""
    sys = system_arrays(cantilever_like_model(), Impactor())
    Omega = 2 * math.pi * 1000.0
    cst, _ = exact._prepare(Omega, 0.0, sys, 48, 1e-7, 0.5 / sys.omega.max())
    n = N9
    Y = np.zeros(flight.state_layout(n).size)
    Y[2 * n] = -sys.g - 1e-7  # 0.1 um into the left wall ...
    Y[2 * n + 1] = 0.2  # ... opening at 0.2 m/s: the release is ~0.5 us ahead
    work = dopri5.work(Y.size, np.zeros(len(flight.COUNT), dtype=np.int64))
    dopri5.rhs(1.0, 0.0, Y, work.K[0], cst, work.book)
    guess = 0.3e-6  # ends short of the release
    for first_guess in (guess, 3 * guess):
        Ynew = work.end
        s, err, found = dopri5.locate_release(Y, flight.Phase(0.0, 1.0, 0.0), first_guess, 4e-6, flight.RELEASE, True,
                                              work, cst)
        c_left = flight.closing(Ynew, s, cst)[0]
        assert found and err <= 1.0
        assert abs(c_left) <= exact.GAP_TOLERANCE * sys.g
        assert s == pytest.approx(0.5e-6, rel=0.01)


def _graze_setup(eps):
    """Walls on their harmonic response, sphere at rest (absolute) where the right wall's excursion
    reaches it by eps * |W_r| half a period later: a graze of indentation ~ eps |W_r| (tens of um to pm)."""
    model = cantilever_like_model()
    sys = system_arrays(model, Impactor())
    Omega = 0.9 * model.omega[0]
    a_base = 2e-6
    y, S = _particular_state(sys, Omega, a_base)
    Wr = sys.phi_r @ S + a_base  # right wall relative to the sphere: c_r = -Re(Wr e^{i Omega t}) + z - g
    z = sys.g - abs(Wr) * (1 - eps)  # z = q_a, constant in free flight
    y[2 * N9] = z - a_base  # u_a = z - a_base cos(Omega t)
    return sys, y, Omega, a_base


@pytest.mark.parametrize("eps", [1e-2, 1e-4, 1e-6])
def test_grazing_contacts_are_not_missed(eps):
    """Grazes of decreasing depth: contact count equals DOP853-with-events and is >= ode3 at dt/8."""
    sys, y0, Omega, a_base = _graze_setup(eps)
    periods = 3
    y = y0.copy()
    _, imp_exact = exact.run_step(y, periods, Omega, a_base, sys)
    y = y0.copy()
    _, imp_ode3 = ode3.run_step(y, periods, Omega, a_base, sys, dt_scale=1 / 8)
    _, onsets, _, _ = reference_run(y0, periods * 2 * math.pi / Omega, Omega, a_base, sys)
    print(f"\neps {eps:g}: exact {imp_exact.sum()}, ode3 dt/8 {imp_ode3.sum()}, DOP853 events {onsets.size}")
    assert imp_exact.sum() >= 1
    assert imp_exact.sum() == onsets.size
    assert imp_exact.sum() >= imp_ode3.sum()


def test_record_rows_are_the_states_at_the_sample_instants(three_mode_model):
    sys = system_arrays(three_mode_model, Impactor())
    Omega = 0.99 * three_mode_model.omega[0]
    y = np.zeros(8)
    y[0] = 6e-4  # large enough for impacts
    y_plain = y.copy()
    record = np.zeros((3 * 4 + 1, 8))
    amp, imp = exact.run_step(y, 3, Omega, 5e-6, sys, record, rtol=1e-10)
    np.testing.assert_allclose(record[-1], y, rtol=1e-12, atol=1e-15)
    assert imp.sum() > 0
    # recording observes: the states at the period ends are the same, bit for bit, whether 1 or 4 states per
    # period are recorded
    ends = np.zeros((3 + 1, 8))
    exact.run_step(y_plain, 3, Omega, 5e-6, sys, ends, rtol=1e-10)
    np.testing.assert_array_equal(record[::4], ends)


RECORD_STALL_STATE = Path(__file__).parents[1] / "data" / "record_stall_state.npy"


def _stall_case():
    """The rig at 7.4 / eta 0.976 from a state whose period has contacts across record instants at M = 447
    (a contact phase stopped at a record instant used to restart with zero length there, for ever)."""
    model = seed_rig_model(9)
    sys = system_arrays(model, Impactor())
    return np.load(RECORD_STALL_STATE), 0.976 * model.omega[0], 7.4 * a_base_star(model), sys


@pytest.mark.timeout(120)
def test_recording_through_contacts_neither_stalls_nor_perturbs():
    y0, Omega, a_base, sys = _stall_case()
    M = 447
    y_plain, y_rec = y0.copy(), y0.copy()
    record = np.empty((2 * M + 1, y0.size))
    amp_plain, imp_plain = exact.run_step(y_plain, 2, Omega, a_base, sys)
    amp_rec, imp_rec = exact.run_step(y_rec, 2, Omega, a_base, sys, record)
    # an observer: the same trajectory, bit for bit
    np.testing.assert_array_equal(amp_rec, amp_plain)
    np.testing.assert_array_equal(imp_rec, imp_plain)
    np.testing.assert_array_equal(y_rec, y_plain)
    assert imp_rec.sum() >= 6
    np.testing.assert_allclose(record[-1], y_plain, rtol=1e-12, atol=1e-12 * np.abs(record).max())


def test_recorded_states_inside_contacts_match_scipy():
    """Each recorded row inside a contact, and the first after it, against DOP853 (rtol 1e-12, restarted at
    every contact event, `sim.integration.references.reference_run`) from the last recorded row before the contact (free
    flight: exact). The rows inside are as accurate as the integrator's own state after the contact."""
    y0, Omega, a_base, sys = _stall_case()
    M = 447
    record = np.empty((M + 1, y0.size))
    exact.run_step(y0.copy(), 1, Omega, a_base, sys, record)
    n = sys.omega.size
    left = record[:, :n] @ sys.phi_l - record[:, 2 * n] - sys.g
    right = record[:, :n] @ sys.phi_r - record[:, 2 * n] + sys.g
    in_contact = set(np.flatnonzero((left > 0) | (right < 0)))
    after = {i + 1 for i in in_contact} - in_contact
    assert len(in_contact) >= 10 and len(after) >= 4
    dt = 2 * math.pi / Omega / M
    scale = np.abs(record).max(axis=0)  # per component: mode 9 is small
    errors = {}
    for i in sorted(in_contact | after):
        start = i - 1
        while start in in_contact:
            start -= 1
        expected = reference_run(record[start], i * dt, Omega, a_base, sys, t0=start * dt)[0]
        errors[i] = (np.abs(record[i] - expected) / scale).max()
    inside = max(errors[i] for i in in_contact)
    outside = max(errors[i] for i in after)
    print(f"\n{len(in_contact)} rows in contact: largest relative error {inside:.1e} (after the contacts {outside:.1e})")
    assert inside < 3 * outside
    assert inside < 2e-8


def test_registry_and_contract(three_mode_model):
    from sim.integration.integrators import get_integrator

    run_step = get_integrator("exact")
    assert run_step is exact.run_step
    sys = system_arrays(three_mode_model, Impactor())
    amplitudes, impacts = run_step(np.zeros(8), 2, 700.0, 1e-6, sys, None)
    assert amplitudes.shape == (2,) and impacts.dtype == np.int64


@pytest.mark.parametrize("kwargs, message", [
    (dict(n_periods=0), "n_periods"),
    (dict(Omega=-1.0), "Omega"),
    (dict(a_base=float("nan")), "a_base"),
    (dict(rtol=0.5), "rtol"),
    (dict(y=np.zeros(3)), "state y"),
])
def test_bad_input_one_line(three_mode_model, kwargs, message):
    sys = system_arrays(three_mode_model, Impactor())
    args = dict(y=np.zeros(8), n_periods=1, Omega=700.0, a_base=1e-6)
    args.update(kwargs)
    extra = {"rtol": args.pop("rtol")} if "rtol" in args else {}
    with pytest.raises(SimulationInputError, match=message) as info:
        exact.run_step(args["y"], args["n_periods"], args["Omega"], args["a_base"], sys, **extra)
    assert "\n" not in str(info.value)
