"""`ies calibrate`: JSON, summary, plot, and one-line errors with nothing half-written."""
import json
import subprocess
import sys

import pytest

from uq.cli import main

FAST = ["--flat", "--grid", "32", "--points", "6"]


def test_json_has_the_promised_keys_in_si_units(capsys):
    assert main(["calibrate", "--json", *FAST]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("k_H", "k_H_star", "k_H_ratio", "k_H_error", "fit_residual", "grid", "solver"):
        assert key in data
    assert data["k_H_star"] == pytest.approx(282e3 * 1e3**1.5, rel=2e-3)  # N/m^1.5
    assert abs(data["k_H_ratio"] - 1) < 5e-3 and data["k_H_error"] > 0
    assert data["grid"] == 32 and data["solver"] == "pk" and len(data["forces"]) == 6


def test_summary_and_plot(tmp_path, capsys):
    figure = tmp_path / "k_H.png"
    assert main(["calibrate", *FAST, "--plot", str(figure)]) == 0
    out = capsys.readouterr().out
    assert "k_H/k_H*" in out and "N/mm^1.5" in out
    assert figure.stat().st_size > 1000
    assert [p.name for p in tmp_path.iterdir()] == ["k_H.png"]


def test_dense_solver_on_a_small_grid(capsys):
    assert main(["calibrate", "--flat", "--json", "--grid", "16", "--points", "3", "--solver", "al-jacobi", "--side-mm", "2.5"]) == 0
    assert json.loads(capsys.readouterr().out)["solver"] == "al-jacobi"


@pytest.mark.parametrize(
    "args, message",
    [
        (["--grid", "0"], "grid"),
        (["--grid", "64", "--solver", "cvxpy"], "solver='pk'"),
        (["--delta-min-um", "-1"], "delta"),
        (["--delta-min-um", "50"], "delta"),
        (["--points", "1"], "points"),
        (["--side-mm", "0"], "side"),
        (["--side-mm", "0.5", "--grid", "32"], "edge"),
        (["--grid", "100000"], "too large"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, args, message):
    figure = tmp_path / "fig.png"
    assert main(["calibrate", "--flat", "--plot", str(figure), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ies calibrate: error:") and message in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not any(tmp_path.iterdir())


def test_plot_into_a_missing_folder_is_refused(tmp_path, capsys):
    assert main(["calibrate", *FAST, "--plot", str(tmp_path / "nope" / "fig.png")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_numerical_failure_exits_3(monkeypatch, capsys):
    from bem_contact import solvers

    monkeypatch.setitem(solvers.SOLVERS, "pk", solvers.SolverInfo("pk", None, 1e-9, 1, "capped"))
    assert main(["calibrate", *FAST]) == 3
    assert "numerical failure" in capsys.readouterr().err


def test_subprocess_has_no_traceback():
    proc = subprocess.run([sys.executable, "-m", "uq", "calibrate", "--grid", "-3"], capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
