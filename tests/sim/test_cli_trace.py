"""`ies trace`: the recorded stretch is the stepped-sine point of `ies sweep`, its columns are the integrator's
states at the sample instants, and the outputs (CSV, JSON, figure, `ies plot`) are complete or absent."""
import json
import math

import numpy as np
import pytest

from sim.hosts.modal_file import save_modal_model
from sim.stepped_sine.protocol import SteppedSine, run_sweep
from sim.model.system import Impactor
from sim.analysis.trace import COLUMNS, record_trace
from uq.cli import main

FAST = ["--wait", "0.05", "--hold", "0.05"]


@pytest.fixture
def model_file(tmp_path, three_mode_model):
    return str(save_modal_model(three_mode_model, tmp_path / "three.toml"))


def test_trace_json_csv_plot_and_redraw(tmp_path, model_file, capsys):
    out, plot = tmp_path / "trace", tmp_path / "fig4.png"
    assert main(["trace", "--level", "6", "--eta", "0.99", "--periods", "4", *FAST, "--model", model_file,
                 "--out", str(out), "--json", "--plot", str(plot)]) == 0
    data = json.loads(capsys.readouterr().out)
    f_exc = 0.99 * 117.4
    M = round(51200 / f_exc)
    assert data["samples_per_period"] == M and data["fs"] == pytest.approx(M * f_exc, rel=1e-12)
    assert data["fs_requested"] == 51200 and data["periods"] == 4 and len(data["amplitudes"]) == 4
    assert data["mean"] == pytest.approx(np.mean(data["amplitudes"])) and data["max"] == max(data["amplitudes"])
    assert data["impacts"] and {"t", "wall", "impulse"} <= set(data["impacts"][0])
    # the impact list is the integrator's exact records: one per contact onset, each onset between the samples
    # where the sampled contact force switches on
    assert data["impacts_source"] == "integrator" and len(data["impacts"]) == sum(data["onsets_per_period"])
    assert {"duration", "approach_speed", "sphere_before", "sphere_after", "higher_release"} <= set(data["impacts"][0])
    assert all(0 <= i["t"] <= 4 / f_exc and i["wall"] in ("left", "right") for i in data["impacts"])
    assert abs(data["balance_error"]) < 1e-6
    table = np.genfromtxt(out / "trace.csv", delimiter=",", names=True)
    assert table.dtype.names == COLUMNS and table.size == 4 * M + 1
    np.testing.assert_allclose(np.diff(table["t"]), 1 / data["fs"], rtol=1e-9)
    # the per-period |c_1| of the sampled q_tip (rectangle rule, exact for harmonics below M/2) against the
    # kernel's exact quadrature: the CSV holds the states at the sample instants
    force = np.abs(table["f_left"]) + np.abs(table["f_right"])
    first = data["impacts"][0]
    k = int(first["t"] * data["fs"])  # the sample interval of the first onset
    assert force[k] == 0 or k == 0
    q = table["q_tip"][:-1].reshape(4, M)
    c1 = np.abs(2 / M * (q * np.exp(-2j * np.pi * np.arange(M) / M)).sum(axis=1))
    np.testing.assert_allclose(c1 / data["a_noabs"], data["amplitudes"], rtol=1e-3)
    assert json.loads((out / "trace.json").read_text())["amplitudes"] == data["amplitudes"]
    assert plot.stat().st_size > 1000
    assert main(["plot", str(out), "--format", "png"]) == 0
    assert (out / "trace.png").stat().st_size > 1000
    assert not [p for p in tmp_path.rglob(".*")], "temporary files left behind"


def test_trace_text_output(tmp_path, model_file, capsys):
    assert main(["trace", "--level", "6", "--eta", "0.99", "--periods", "2", *FAST, "--model", model_file,
                 "--fs", "20e3", "--out", str(tmp_path / "t")]) == 0
    text = capsys.readouterr().out
    assert "samples per period" in text and "requested 20000 Hz" in text and "wrote" in text


def test_the_trace_is_the_hold_of_the_sweeps_point(three_mode_model):
    """Lead-in and wait as in `ies sweep` (the same `visit_points`), recording an observer: with a hold of
    exactly the recorded periods, the sweep's measures of that point and the trace's are the same numbers,
    also at the last point of a down-sweep."""
    impactor = Impactor()
    T = 2 * math.pi / (0.985 * three_mode_model.omega[0])
    protocol = SteppedSine(eta_start=0.985, eta_stop=0.99, n_eta=2, sequence="down", wait=0.05, hold=6 * T)
    swept = run_sweep(three_mode_model, impactor, 6.0, protocol, seed=3, rep=0)
    trace = record_trace(three_mode_model, impactor, 6.0, protocol, periods=6, seed=3)
    assert trace.eta == swept.eta[-1] == 0.985 and swept.hold_periods[-1] == 6
    a = trace.normalised_amplitudes
    assert a.mean() == swept.mean[-1] and a.max() == swept.max[-1]
    assert trace.impacts.mean() == swept.impacts_per_period[-1] > 0


@pytest.mark.parametrize("args, phrase", [
    (["--fs", "150"], "--fs 150 Hz is below twice the excitation frequency"),
    (["--periods", "0"], "--periods"),
    (["--eta", "0.99:0.98:3"], "empty or reversed"),
])
def test_bad_trace_settings_write_nothing(tmp_path, model_file, capsys, args, phrase):
    base = ["trace", "--level", "6", "--eta", "0.99", *FAST, "--model", model_file, "--out", str(tmp_path / "t")]
    code = main([*base, *args]) if "--eta" not in args else main([*base[:3], *args, *base[5:]])
    err = capsys.readouterr().err
    assert code == 2 and phrase in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "t").exists()


def test_lyapunov_and_poincare_of_a_trace(tmp_path, model_file, capsys):
    """--lyapunov (default 400 periods) and --poincare: the exponent with its convergence over the record in the
    JSON, the dynamics, the section's points (one per period and the last state) and poincare.png written; the host
    alone (--no-impactor) gives mode 1's decay -2 pi D_1 / eta per period and says the host is linear."""
    out = tmp_path / "t"
    assert main(["trace", "--level", "6", "--eta", "0.99", "--lyapunov", "--poincare", "--fs", "4000", *FAST,
                 "--model", model_file, "--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["periods"] == 400 and (out / "poincare.png").is_file()
    assert len(data["lyapunov_convergence"]) == 400 - data["lyapunov_transient_periods"]
    assert data["lyapunov_convergence"][-1] == pytest.approx(np.mean(data["lyapunov_convergence"][-1:]), rel=1e-12)
    assert data["dynamics"] in ("periodic", "quasi-periodic", "chaotic") and data["lyapunov_linear_host"] is None
    assert len(data["poincare"]["q_tip"]) == 401 and len(data["poincare"]["frequency_per_period"]) == 201
    host = tmp_path / "host"
    assert main(["trace", "--level", "6", "--eta", "0.99", "--lyapunov", "--periods", "200", "--fs", "4000", *FAST,
                 "--no-impactor", "--model", model_file, "--out", str(host)]) == 0
    printed = capsys.readouterr().out
    assert "the host alone is linear" in printed and "periodic" in printed
    data = json.loads((host / "trace.json").read_text())
    assert data["lyapunov_per_period"] == pytest.approx(-2 * math.pi * 0.00085 / data["eta_actual"], rel=0.01)
    assert data["lyapunov_linear_host"] == pytest.approx(-2 * math.pi * 0.00085 / data["eta_actual"], rel=1e-12)


@pytest.mark.parametrize("args, phrase", [
    (["--lyapunov", "--periods", "20"], ("at least 80 excitation periods", "got --periods 20", "give --periods 80")),
    (["--poincare", "--periods", "1"], ("at least 8 periods", "got --periods 1", "give --periods 8")),
])
def test_a_record_too_short_for_the_nature_is_refused(tmp_path, model_file, capsys, args, phrase):
    """One line naming the length needed, exit 2, nothing written."""
    out = tmp_path / "t"
    code = main(["trace", "--level", "6", "--eta", "0.99", *FAST, "--model", model_file, "--out", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert all(words in err for words in phrase), err
    assert not out.exists()
