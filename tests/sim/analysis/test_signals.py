"""Signal files and simulated traces (sim.analysis.signals): reading with validation, the columns of a simulated trace
against the analytic solution of Eq. 7 and the contact law, and the simulator's own contact list."""
import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.analysis.signals import make_signal, read_signal, simulated_contacts, simulated_signal
from sim.model.system import Impactor, contact_forces, system_arrays

TRACE_HEADER = "t,q_tip,v_tip,a_tip,q_wall_left,q_wall_right,a_left,a_right,q_sphere,f_left,f_right"


def write_csv(path, header, rows):
    path.write_text(header + "\n" + "\n".join(",".join(str(v) for v in row) for row in rows) + "\n")
    return path


def test_reads_the_requested_columns_and_ignores_the_others(tmp_path):
    fs = 51200.0
    t = np.arange(100) / fs
    rows = [(repr(float(ti)), 1.0 * i, "nan", -2.0 * i) for i, ti in enumerate(t)]
    path = tmp_path / "s.csv"
    path.write_text("# measured on rig 2\n\n t , a_left, note ,a_right\n" + "\n".join(",".join(map(str, r)) for r in rows))
    signal = read_signal(path, ("a_right", "a_left"))
    assert signal.fs == pytest.approx(fs, rel=1e-12)
    assert signal.duration == pytest.approx(100 / fs, rel=1e-12)
    np.testing.assert_array_equal(signal["a_left"], np.arange(100.0))
    np.testing.assert_array_equal(signal["a_right"], -2.0 * np.arange(100))
    with pytest.raises(SimulationInputError, match="no column 'note'"):
        signal["note"]


def test_reads_a_trace_file_with_all_its_columns(tmp_path):
    names = TRACE_HEADER.split(",")
    t = np.arange(20) * 2e-5
    rows = [[ti] + [k * i for k in range(1, len(names))] for i, ti in enumerate(t)]
    signal = read_signal(write_csv(tmp_path / "trace.csv", TRACE_HEADER, rows), ("v_tip", "a_left", "a_right", "a_tip"))
    assert set(signal.columns) == {"v_tip", "a_left", "a_right", "a_tip"}
    np.testing.assert_array_equal(signal["a_tip"], 3.0 * np.arange(20))


def good_rows(n=20, dt=2e-5):
    return [[i * dt, 0.1 * i, 0.2 * i] for i in range(n)]


@pytest.mark.parametrize("case, content, expected", [
    ("empty file", "", "is empty"),
    ("only comments", "# nothing\n\n", "is empty"),
    ("header only", "t,a_left,a_right\n", "no data rows"),
    ("missing column", "t,a_left\n" + "\n".join(f"{i * 2e-5},1" for i in range(20)), "missing column(s) a_right"),
    ("duplicated column", "t,a_left,a_left,a_right\n" + "\n".join(f"{i * 2e-5},1,1,1" for i in range(20)), "more than once"),
    ("text cell", "t,a_left,a_right\n" + "\n".join(f"{i * 2e-5},{'abc' if i == 7 else 1},1" for i in range(20)),
     "'abc' in column 'a_left' at data row 8 is not a number"),
    ("empty cell", "t,a_left,a_right\n" + "\n".join(f"{i * 2e-5},{'' if i == 7 else 1},1" for i in range(20)), "must be a number"),
    ("NaN", "t,a_left,a_right\n" + "\n".join(f"{i * 2e-5},{'nan' if i == 7 else 1},1" for i in range(20)), "'a_left' is nan at data row 8"),
    ("inf", "t,a_left,a_right\n" + "\n".join(f"{i * 2e-5},1,{'inf' if i == 3 else 1}" for i in range(20)), "'a_right' is inf at data row 4"),
    ("decreasing t", "t,a_left,a_right\n" + "\n".join(f"{(i if i != 5 else 3.5) * 2e-5},1,1" for i in range(20)), "t must increase"),
    ("repeated t", "t,a_left,a_right\n" + "\n".join(f"{(i if i != 5 else 4) * 2e-5},1,1" for i in range(20)), "t must increase"),
    ("non-uniform t", "t,a_left,a_right\n" + "\n".join(f"{(i if i < 10 else i + 0.5) * 2e-5},1,1" for i in range(20)), "not uniformly sampled"),
    ("too short", "t,a_left,a_right\n0,1,1\n2e-5,1,1\n", "at least 8"),
])
def test_bad_files_give_one_line(tmp_path, case, content, expected):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(SimulationInputError) as info:
        read_signal(path, ("a_left", "a_right"))
    message = str(info.value)
    assert expected in message and "\n" not in message and "bad.csv" in message


def test_missing_folder_and_binary_files_give_one_line(tmp_path):
    for path, expected in ((tmp_path / "nothing.csv", "not found"), (tmp_path, "is a folder")):
        with pytest.raises(SimulationInputError, match=expected):
            read_signal(path, ("a_left",))
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"\xff\xfe\x00\x81" * 10)
    with pytest.raises(SimulationInputError, match="not a text"):
        read_signal(binary, ("a_left",))


def test_make_signal_checks_arrays():
    t = np.arange(10) * 1e-5
    with pytest.raises(SimulationInputError, match="has 9 values but t has 10"):
        make_signal(t, {"v_tip": np.zeros(9)})
    with pytest.raises(SimulationInputError, match="missing column"):
        make_signal(t, {"v_tip": np.zeros(10)}, required=("a_tip",))
    signal = make_signal(t, {"v_tip": np.ones(10)})
    with pytest.raises(ValueError):
        signal["v_tip"][0] = 2.0  # read-only


def test_trace_accelerations_follow_the_equations_of_motion(three_mode_model):
    """Without contact each mode is the particular harmonic solution of Eq. 7 plus a damped free vibration,
    both in closed form: the trace's absolute accelerations must be phi^T s'' + q_base''."""
    model = three_mode_model
    sys = system_arrays(model, Impactor(clearance=1.0))  # the sphere never reaches a wall
    Omega, a_base, M = 0.97 * model.omega[0], 2e-6, 600
    w, D, gamma = model.omega, model.damping_ratios, model.participation
    S = gamma * a_base * Omega**2 / (w**2 - Omega**2 + 2j * D * w * Omega)
    lam = -D * w + 1j * w * np.sqrt(1 - D**2)
    C = np.array([1e-5 - 2e-6j, 3e-7 + 1e-7j, -2e-8j])
    t = np.arange(2 * M + 1) * (2 * np.pi / Omega / M)
    harmonic, free = np.exp(1j * Omega * t)[:, None], np.exp(lam * t[:, None])
    s = (S * harmonic + C * free).real
    v = (1j * Omega * S * harmonic + C * lam * free).real
    acc = (-Omega**2 * S * harmonic + C * lam**2 * free).real
    states = np.column_stack([s, v, np.zeros(t.size), np.zeros(t.size)])
    trace = simulated_signal(states, M, Omega, a_base, sys)
    base = -a_base * Omega**2 * np.cos(Omega * t)
    for column, phi in (("a_tip", model.phi_tip), ("a_left", model.phi_wall_left), ("a_right", model.phi_wall_right)):
        expected = acc @ phi + base
        np.testing.assert_allclose(trace[column], expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    np.testing.assert_allclose(trace["v_tip"], v @ model.phi_tip, rtol=1e-14)
    np.testing.assert_allclose(trace["q_tip"], s @ model.phi_tip, rtol=1e-14)
    assert not trace["f_left"].any() and not trace["f_right"].any()
    assert trace.fs == pytest.approx(M * Omega / (2 * np.pi), rel=1e-12)


def test_trace_forces_follow_the_contact_law(three_mode_model):
    sys = system_arrays(three_mode_model, Impactor())
    rng = np.random.default_rng(4)
    states = np.zeros((40, 8))
    states[:, :3] = rng.normal(0.0, 4e-4, (40, 3))
    states[:, 6] = rng.normal(0.0, 5e-4, 40)
    trace = simulated_signal(states, 40, 700.0, 1e-6, sys)
    expected = np.array([contact_forces(row[:3], row[6], sys) for row in states])
    assert np.count_nonzero(expected[:, 0]) > 3 and np.count_nonzero(expected[:, 1]) > 3
    np.testing.assert_allclose(trace["f_left"], expected[:, 0], rtol=1e-13)
    np.testing.assert_allclose(trace["f_right"], expected[:, 1], rtol=1e-13)


def test_contacts_are_the_changes_of_the_sphere_velocity(three_mode_model):
    """Absolute sphere velocity piecewise constant with a left contact over two intervals and a right one."""
    sys = system_arrays(three_mode_model, Impactor())
    M, Omega, a_base = 100, 700.0, 3e-6
    velocity = np.full(M + 1, 0.3)
    velocity[11] = 0.5
    velocity[12:] = 0.8
    velocity[31:] = 0.1
    phase = 2 * np.pi * np.arange(M + 1) / M
    states = np.zeros((M + 1, 8))
    states[:, 7] = velocity + a_base * Omega * np.sin(phase)  # u_a' = q_a' - q_base'
    contacts = simulated_contacts(states, M, Omega, a_base, sys, t0=1.0)
    step = 2 * np.pi / Omega / M
    np.testing.assert_allclose(contacts.times, 1.0 + np.array([10.5, 30.5]) * step, rtol=1e-14)
    assert contacts.walls == ("left", "right")
    np.testing.assert_allclose(contacts.impulses, sys.m_a * np.array([0.5, -0.7]), rtol=1e-12)
    np.testing.assert_array_equal(contacts.first, [10, 30])
    np.testing.assert_array_equal(contacts.last, [11, 30])


@pytest.mark.timeout(600)
def test_contacts_of_a_rig_trace_agree_with_the_integrators_count():
    """Every onset the integrator counts is a velocity change in the samples; chattering within one sample
    interval merges into one contact."""
    from tests.sim._traces import rig_trace

    trace = rig_trace()
    contacts = trace.contacts
    assert 0.95 * trace.onsets <= contacts.times.size <= trace.onsets
    assert set(contacts.walls) == {"left", "right"}
    assert np.all(contacts.first <= contacts.last) and np.all(np.diff(contacts.times) > 0)
    assert np.all((contacts.impulses > 0) == (np.array(contacts.walls) == "left"))
