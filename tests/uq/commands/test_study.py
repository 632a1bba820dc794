"""`ies sobol`, `ies interval` and `ies reproduce` end to end on analytic and noisy models."""
import csv
import json

import numpy as np
import pytest

from tests.support import AB_PARAMETERS
from uq.cli import main

AB = AB_PARAMETERS


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_sobol_command_on_ishigami(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\nseed = 5\n[sobol]\nbootstrap = 300\n")
    assert main(["sobol", str(study), "--n", "512", "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1"]) == 0
    res = {r["parameter"]: r for r in rows(tmp_path / "o" / "sobol.csv")}
    V = 7**2 / 8 + 0.1 * np.pi**4 / 5 + 0.1**2 * np.pi**8 / 18 + 0.5
    exact_S1 = {"x1": 0.5 * (1 + 0.1 * np.pi**4 / 5) ** 2 / V, "x2": 7**2 / 8 / V, "x3": 0.0}
    for name, s1 in exact_S1.items():
        assert abs(float(res[name]["S1"]) - s1) <= max(float(res[name]["S1_conf"]), 5e-3)
    for suffix in ("png", "pdf"):
        assert (tmp_path / "o" / f"sobol.{suffix}").stat().st_size > 1000
    meta = json.loads((tmp_path / "o" / "study.json").read_text())
    assert meta["study"]["sobol"]["n"] == 512 and meta["summary"]["base_sample"] == 512  # what ran: --n over the file


def test_sobol_bad_sample_size_writes_nothing(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n")
    assert main(["sobol", str(study), "--n", "100", "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "power of two" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_noisy_model_noise_share_and_no_false_flags(tmp_path):
    from uq.engine.execution import run_study
    from uq.methods import load_study

    text = "[study]\nkind = '{kind}'\nmodel = 'uq.problem.test_functions:noisy_linear'\nrepetitions = {reps}\nseed = 3\n" + AB
    path = tmp_path / "i.toml"
    path.write_text(text.format(kind="interval", reps=8) + "[interval]\ndesigns = ['individual', 'joint']\ninterior = 3\n")
    res = run_study(load_study(path), out=tmp_path / "i", progress=False)
    assert all(res.summary["monotone"].values()), res.warnings  # noise does not trip the check
    band = {r["design"]: r for r in rows(tmp_path / "i" / "bands.csv")}
    assert float(band["joint"]["lower"]) == pytest.approx(1.0, abs=4 * 0.2 / np.sqrt(8))  # level 1 + 0
    assert float(band["joint"]["upper"]) == pytest.approx(4.0, abs=4 * 0.2 / np.sqrt(8))  # level 1 + 1 + 2
    path.write_text(text.format(kind="sobol", reps=4) + "[sobol]\nn = 128\n")
    res = run_study(load_study(path), out=tmp_path / "s", progress=False)
    # Var(ybar) = Var(a + 2 b) + sigma^2 / r = 5/12 + 0.01; noise share = 0.01 / (5/12 + 0.01)
    share = float(rows(tmp_path / "s" / "variance.csv")[0]["noise_share"])
    assert share == pytest.approx(0.01 / (5 / 12 + 0.01), rel=0.25)


def test_failed_runs_are_reported_not_hidden(tmp_path, capsys):
    path = tmp_path / "f.toml"
    path.write_text("[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:failing'\nrepetitions = 2\n" + AB + "[sobol]\nn = 32\n")
    assert main(["sobol", str(path), "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    err = capsys.readouterr().err
    assert "runs failed" in err and "not analysed" in err and "no finite run" in err
    runs = rows(tmp_path / "o" / "runs.csv")
    assert any(r["error"].startswith("SimulationDiverged") for r in runs)
    summary = rows(tmp_path / "o" / "variance.csv")[0]
    assert summary["message"] and summary["noise_share"] == "nan"


def test_interval_command_writes_data_then_figures(tmp_path):
    path = tmp_path / "i.toml"
    path.write_text("[study]\nkind = 'interval'\nmodel = 'ishigami'\n[parameters.x1]\nnominal = 0.5\nmin = 0.2\n"
                    "max = 1.0\n[interval]\ndesigns = ['individual', 'joint']\n")
    assert main(["interval", str(path), "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1"]) == 0
    for name in ("runs.csv", "points.csv", "bands.csv", "study.json", "individual-variation.png",
                 "individual-variation.pdf", "joint-variation.png", "joint-variation.pdf"):
        assert (tmp_path / "o" / name).is_file(), name
    meta = json.loads((tmp_path / "o" / "study.json").read_text())
    assert meta["study"]["parameters"]["x1"]["max"] == 1.0 and meta["code_version"]


def test_reproduce_rejects_bad_calibration(tmp_path, capsys):
    bad = tmp_path / "calib.json"
    bad.write_text("{\"k_H_ratio\": 1.5}")
    assert main(["reproduce", "fig7", "--quick", "--calibration", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "has no positive 'k_H'" in err and len(err.strip().splitlines()) == 1


def test_calibrated_k_H_becomes_the_upper_bound():
    from uq.commands.reproduce import study_file
    from uq.problem.study import with_calibration
    from uq.problem.space import K_H_STAR
    from uq.methods import load_study

    study = load_study(study_file("fig8", quick=True))
    cal = with_calibration(study, 1.48 * K_H_STAR)
    assert cal.space["k_H"].max == pytest.approx(1.48 * K_H_STAR)
    assert cal.settings["fix"]["k_H"] == pytest.approx(1.25 * K_H_STAR)
    low = with_calibration(study, 1.1 * K_H_STAR)  # below the paper's best estimate: use the midpoint
    assert low.settings["fix"]["k_H"] == pytest.approx(1.05 * K_H_STAR)


def tiny_reproduction(tmp_path, monkeypatch, extra=""):
    """`ies reproduce` on a tiny simulator study (k_H varied, one level, two frequencies) instead of the shipped ones."""
    import uq.commands.reproduce as reproduce

    tiny = tmp_path / "tiny.toml"
    tiny.write_text("[study]\nkind = 'interval'\nrepetitions = 1\n[parameters.k_H]\n[excitation]\nlevels = [7.4]\n"
                    "eta = { start = 0.975, stop = 0.98, n = 2 }\nwait = 0.1\nhold = 0.1\n" + extra)
    monkeypatch.setattr(reproduce, "study_file", lambda figure, quick: tiny)


def test_reproduce_uses_the_calibrated_k_H(tmp_path, monkeypatch, capsys):
    """`ies reproduce` end to end on a tiny simulator study: calibrated k_H bound, data, figures, trends."""
    from uq.problem.space import K_H_STAR

    tiny_reproduction(tmp_path, monkeypatch, "integrator = 'ode3'\n[interval]\ninterior = 0\n")
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps({"k_H": 1.5 * K_H_STAR}))
    out = tmp_path / "o"
    assert main(["reproduce", "fig7", "--calibration", str(calib), "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    text = capsys.readouterr().out
    assert "= 1.500 k_H*" in text and "dk_H (max-min)/nominal" in text
    assert "largest influence first" in text or "influence not ranked" in text
    meta = json.loads((out / "fig7" / "study.json").read_text())
    assert meta["study"]["parameters"]["k_H"]["max"] == pytest.approx(1.5 * K_H_STAR)
    assert (out / "fig7" / "fig7.pdf").is_file() and not (out / "fig7" / "nominal-levels.png").exists()
    assert "monotonicity could not be tested for individual:k_H/mean" in text  # one repetition


def test_reproduce_bad_integrator_writes_nothing(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["reproduce", "all", "--quick", "--integrator", "rk99", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "unknown integrator 'rk99'" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_reproduce_unreachable_scheduler_fails_before_the_calibration(tmp_path, capsys):
    pytest.importorskip("distributed")
    out = tmp_path / "o"
    assert main(["reproduce", "all", "--quick", "--scheduler", "tcp://127.0.0.1:9", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the Dask scheduler" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_reproduce_calibrates_in_process(tmp_path, monkeypatch, capsys):
    """Without --calibration FILE the front door's calibration (bem_contact.pipeline.calibrate_default, the shipped
    crater) runs in this process; its JSON is kept in OUT/calibration.json and bounds k_H."""
    from uq.problem.space import K_H_STAR

    tiny_reproduction(tmp_path, monkeypatch, "[interval]\ninterior = 0\ndesigns = ['joint']\n")
    out = tmp_path / "o"
    assert main(["reproduce", "fig8", "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    calibration = json.loads((out / "calibration.json").read_text())
    assert calibration["k_H_ratio"] == pytest.approx(1.521051, abs=1e-6)  # `ies calibrate` in the README
    assert f"= {calibration['k_H'] / K_H_STAR:.3f} k_H* (upper bound of k_H)" in capsys.readouterr().out
    meta = json.loads((out / "fig8" / "study.json").read_text())
    assert meta["study"]["parameters"]["k_H"]["max"] == pytest.approx(calibration["k_H"])


def test_a_failed_calibration_is_one_warning_and_keeps_table_2(tmp_path, capsys):
    from scans.errors import ScanError
    from uq.commands.reproduce import run_calibration

    def broken():
        raise ScanError("paper_crater.ply: the file is empty")

    assert run_calibration(broken, tmp_path) is None
    err = capsys.readouterr().err
    assert err == "warning: the calibration failed (ScanError: paper_crater.ply: the file is empty); using Table 2's k_H bounds\n"
    assert not list(tmp_path.iterdir())
