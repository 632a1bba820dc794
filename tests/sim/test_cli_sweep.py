"""`ies sweep` and `ies overview`: JSON keys, atomic output, and bad input as one line without traceback."""
import json
import subprocess
import sys

import numpy as np
import pytest

from sim.hosts.modal_file import save_modal_model
from uq.cli import main

FAST = ["--eta", "0.98:1.0:3", "--wait", "0.02", "--hold", "0.03", "--reps", "2"]


@pytest.fixture
def model_file(tmp_path, three_mode_model):
    return str(save_modal_model(three_mode_model, tmp_path / "three.toml"))


def test_sweep_json_out_and_plot(tmp_path, model_file, capsys):
    out = tmp_path / "result"
    plot = tmp_path / "fig5.png"
    code = main(["sweep", "--level", "6", *FAST, "--model", model_file, "--json", "--out", str(out), "--plot", str(plot)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("eta", "mean", "max", "resonant_mean", "resonant_max", "regime", "impacts_per_period", "wall_time_s",
                "mean_lo", "mean_hi", "max_lo", "max_hi", "protocol"):
        assert key in data
    assert data["eta"] == pytest.approx([0.98, 0.99, 1.0])
    assert data["resonant_mean"] == pytest.approx(max(data["mean"]))
    assert data["n_samples"] == 2 and data["protocol"]["integrator"] == "exact"
    assert data["protocol"]["start"] == "base-velocity"  # the default initial conditions (sim.stepped_sine.protocol)
    table = np.genfromtxt(out / "sweep.csv", delimiter=",", names=True, dtype=None, encoding=None)
    np.testing.assert_allclose(table["mean"], data["mean"], rtol=1e-12)
    assert json.loads((out / "sweep.json").read_text())["resonant_max"] == pytest.approx(data["resonant_max"])
    assert plot.stat().st_size > 1000
    assert not [p for p in tmp_path.rglob(".*")], "temporary files left behind"


def test_sweep_table_output(model_file, capsys):
    assert main(["sweep", "--level", "6", *FAST, "--model", model_file]) == 0
    text = capsys.readouterr().out
    assert "resonant mean" in text and "eta" in text


def test_overview_json_and_out(tmp_path, model_file, capsys):
    out = tmp_path / "ov"
    code = main(["overview", "--levels", "4,6", *FAST, "--model", model_file, "--json", "--out", str(out),
                 "--plot", str(tmp_path / "fig6.pdf")])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["levels"] == [4.0, 6.0] and len(data["resonant_mean"]) == 2 and len(data["regime"]) == 2
    assert (out / "overview.csv").read_text().startswith("level,resonant_mean")
    assert (tmp_path / "fig6.pdf").exists()


@pytest.mark.parametrize("args, message", [
    (["--D", "1.5"], "D must lie in (0, 1)"),
    (["--D", "0"], "D must lie in (0, 1)"),
    (["--g", "0"], "clearance g must be a positive number"),
    (["--g=-1e-3"], "clearance g must be a positive number"),
    (["--k-H", "0"], "k_H must be a positive number"),
    (["--level", "0"], "level a_base/a_base* must be positive"),
    (["--level=-2"], "level a_base/a_base* must be positive"),
    (["--eta", "1.02:0.96:31"], "empty or reversed"),
    (["--eta", "0.96:1.02:0"], "empty"),
    (["--eta", "0.96-1.02"], "START:STOP:N"),
    (["--hold", "0.001"], "shorter than one excitation period"),
    (["--integrator", "ode3", "--dt-scale", "10"], "too large for ode3 stability"),
    (["--integrator", "rk4"], "unknown integrator"),
])
def test_bad_input_is_one_line_exit_2(tmp_path, model_file, capsys, args, message):
    out = tmp_path / "never"
    base = ["sweep", "--level", "6", *FAST, "--model", model_file, "--out", str(out)]
    # later options win in argparse, so the bad value overrides the good default
    code = main(base + args)
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (out / "sweep.csv").exists()


@pytest.mark.parametrize("command", [["sweep", "--level", "6"], ["overview", "--levels", "5,6"]])
@pytest.mark.parametrize("args", [["--integrator", "rk4"], ["--reps", "0"]])
def test_bad_input_leaves_no_out_folder(tmp_path, model_file, capsys, command, args):
    """Inputs only the simulation rejects (after --out was created): the new folder is removed again, a
    folder that existed before is kept."""
    out = tmp_path / "new" / "out"
    assert main([*command, *FAST, "--model", model_file, "--out", str(out), *args]) == 2
    assert not out.exists()
    kept = tmp_path / "kept"
    kept.mkdir()
    assert main([*command, *FAST, "--model", model_file, "--out", str(kept), *args]) == 2
    assert kept.is_dir()
    capsys.readouterr()


def test_malformed_model_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("frequencies_hz = [117.4, 'x']\n")
    assert main(["sweep", "--level", "6", *FAST, "--model", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and len(err.strip().splitlines()) == 1


def test_bad_overview_levels(model_file, capsys):
    for levels, message in (("6,0", "must be positive"), ("8:2:4", "empty or reversed"), ("a,b", "must be a level a_base/a_base* like 7.4 or a base amplitude")):
        assert main(["overview", "--levels", levels, *FAST, "--model", model_file]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1


def test_diverging_simulation_exits_3_without_traceback(model_file):
    """An absurd level drives the walls through the sphere within a step: numerical failure, exit 3, one
    line (through a real process)."""
    proc = subprocess.run([sys.executable, "-m", "uq", "sweep", "--level", "1e6", *FAST, "--model", model_file],
                          capture_output=True, text=True)
    assert proc.returncode == 3
    assert "numerical failure" in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_no_impactor_waits_15_s_by_default_and_reaches_a_noabs(tmp_path, three_mode_model, capsys):
    """Sect. 5.1: 15 s wait without the IES; at eta = 1 the response is a_noabs* (Nominal D* = the model's)."""
    path = str(save_modal_model(three_mode_model, tmp_path / "m.toml"))
    code = main(["sweep", "--level", "2", "--eta", "1:1:1", "--hold", "0.2", "--reps", "1", "--perturbation", "0",
                 "--model", path, "--no-impactor", "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["protocol"]["wait"] == 15.0
    assert data["resonant_mean"] == pytest.approx(1.0, rel=5e-3)
    assert data["regime"] == "linear"


def test_the_linear_response_at_default_settings_is_the_analytic_one(capsys):
    """`ies sweep --no-impactor --level 1 --eta 0.999:1.001:21` with every other default (built-in rig, 5 runs with
    perturbed starts, 15 s wait) is the analytic frequency response of Eq. 7 within 0.5 % at every point, though
    the grid (step 1e-4) lies inside the perturbation (+-5e-4) and the peak's half-power width (+-8.5e-4)."""
    from sim.stepped_sine.measures import linear_tip_amplitude
    from sim.hosts.rig import seed_rig_model
    from sim.model.system import a_base_star, a_noabs_star

    assert main(["sweep", "--no-impactor", "--level", "1", "--eta", "0.999:1.001:21", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    model = seed_rig_model(n_modes=9)
    a_base = a_base_star(model)
    exact = linear_tip_amplitude(model, np.array(data["eta"]) * model.omega[0], a_base) / a_noabs_star(model, a_base)
    np.testing.assert_allclose(data["mean"], exact, rtol=5e-3)
    assert data["resonant_mean"] == pytest.approx(1.0, rel=5e-3) and data["eta_resonant_mean"] == pytest.approx(1.0)


def test_every_spread_contains_its_value(tmp_path, model_file, capsys):
    """lo <= value <= hi in sweep.csv and overview.csv, for every point and level (resonant levels included)."""
    out = tmp_path / "ov"
    assert main(["overview", "--levels", "3,4,5,6", "--eta", "0.97:1.0:7", "--wait", "0.05", "--hold", "0.05",
                 "--reps", "3", "--model", model_file, "--out", str(out)]) == 0
    capsys.readouterr()
    table = np.genfromtxt(out / "overview.csv", delimiter=",", names=True, dtype=None, encoding=None)
    for name in ("resonant_mean", "resonant_max"):
        assert np.all(table[f"{name}_lo"] <= table[name]) and np.all(table[name] <= table[f"{name}_hi"])
    for sweep in json.loads((out / "overview.json").read_text())["sweeps"]:
        for name in ("mean", "max"):
            assert np.all(np.array(sweep[f"{name}_lo"]) <= sweep[name]) and np.all(np.array(sweep[name]) <= sweep[f"{name}_hi"])


def test_sweep_lyapunov_adds_the_exponent_and_dynamics_per_eta(tmp_path, model_file, capsys):
    """--lyapunov: each hold's exponent (mean over the samples) and dynamics as sweep.csv columns beside the regime,
    the exponents of every visit in sweep.json, a column in the printed table; a hold too short is refused in one
    line naming the hold needed."""
    out = tmp_path / "res"
    args = ["sweep", "--level", "6", "--eta", "0.98:1.0:3", "--wait", "0.05", "--hold", "0.8", "--reps", "2",
            "--model", model_file, "--lyapunov", "--out", str(out)]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "lyapunov/T  dynamics" in printed
    import csv

    with (out / "sweep.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert all(r["dynamics"] in ("periodic", "quasi-periodic", "chaotic") for r in rows)
    data = json.loads((out / "sweep.json").read_text())
    samples = np.array(data["lyapunov_samples"], dtype=float)
    assert samples.shape == (2, 3)
    assert [float(r["lyapunov_per_period"]) for r in rows] == pytest.approx(np.mean(samples, axis=0), rel=1e-12)
    code = main([*args[:8], "0.3", *args[9:-2], "--out", str(tmp_path / "short")])
    err = capsys.readouterr().err
    assert code == 2 and "--lyapunov takes each hold's exponent" in err and "--hold" in err
    assert not (tmp_path / "short").exists()
