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


def test_tangential_stiffness_under_the_weight(capsys):
    """Appendix C: BEM and Mindlin's 8 G* a at N = m_a g (2.96 kN/mm, 7.4x below the paper's 22 kN/mm); the
    closed form a = (3 N R / (4 E*))^(1/3) with E*, G* of Table 1 computed here."""
    import json
    import math

    assert main(["calibrate", "--tangential", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    N = 0.0177 * 9.81
    E_star = 1 / (0.91 / 207e9 + 0.91 / 102e9)
    G_star = 1 / (1.7 * 2.6 / 207e9 + 1.7 * 2.6 / 102e9)
    a = (3 * N * 7.92e-3 / (4 * E_star)) ** (1 / 3)
    assert data["normal_force"] == pytest.approx(N)
    assert data["contact_radius"] == pytest.approx(a, rel=1e-12)
    assert data["k_t_mindlin"] == pytest.approx(8 * G_star * a, rel=1e-12) == pytest.approx(2.962e6, rel=1e-3)
    assert data["k_t"] == pytest.approx(data["k_t_mindlin"], rel=2e-3)
    assert data["normal_force_for_paper"] / N == pytest.approx((22e6 / data["k_t_mindlin"]) ** 3) == pytest.approx(410, abs=1)
    assert main(["calibrate", "--tangential", "--json", "--normal-force", str(data["normal_force_for_paper"])]) == 0
    at_paper = json.loads(capsys.readouterr().out)
    assert at_paper["k_t_mindlin"] == pytest.approx(22e6, rel=1e-12)
    assert at_paper["k_t"] == pytest.approx(22e6, rel=2e-3)
    assert math.isfinite(at_paper["contact_radius"])
    assert main(["calibrate", "--tangential"]) == 0
    assert "22 kN/mm = 7.43 x Mindlin's" in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["--tangential", "--normal-force", "0"], "--normal-force 0.0 must be"),
    (["--tangential", "--normal-force", "nan"], "--normal-force nan must be"),
    (["--normal-force", "1"], "--normal-force belongs to --tangential"),
    (["--tangential", "crater.ply"], "drop the SCAN file"),
    (["--tangential", "--grid", "2"], "--grid 2"),
])
def test_tangential_bad_input_is_one_line_exit_2(capsys, args, message):
    assert main(["calibrate", *args]) == 2
    captured = capsys.readouterr()
    assert message in captured.err and captured.err.count("\n") == 1 and captured.out == ""
