"""Bad input met on a new user's first day: one line on stderr, exit code 2, no traceback, and nothing created or
overwritten (the new-user pass: unsupported --plot suffixes, bad --jobs / --calibration / --n, units, truncated
scans, --resume into another study, a lost cluster, one repetition)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from uq.cli import main

from tests.support import FAST, STUDIES, refused


def files_in(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*"))


# ---- --plot: checked before any work, for every command that has it ----------------------------------------

@pytest.mark.parametrize("plot, phrase", [("f.xyz", "unsupported figure format '.xyz'"), ("fig", "no file suffix")])
@pytest.mark.parametrize("command", [["sweep", "--level", "6"], ["overview", "--levels", "5,6"], ["calibrate", "--flat"]])
def test_a_plot_file_matplotlib_cannot_write_is_refused_up_front(tmp_path, model_file, capsys, monkeypatch, command,
                                                                 plot, phrase):
    monkeypatch.chdir(tmp_path)
    extra = [*FAST, "--model", model_file, "--out", "res"] if command[0] != "calibrate" else []
    line = refused(capsys, main([*command, *extra, "--plot", plot]), f"argument --plot: '{plot}'", phrase)
    assert ".png" in line and ".pdf" in line  # the supported suffixes are listed
    assert [p.name for p in files_in(tmp_path)] == ["three.toml"]  # no --out folder, no CSV, no figure


# ---- --jobs, --calibration, --n -----------------------------------------------------------------------------

@pytest.mark.parametrize("jobs", ["0", "-5"])
@pytest.mark.parametrize("command", [["interval", str(STUDIES / "fig7-quick.toml")],
                                     ["sobol", str(STUDIES / "sobol.toml")], ["reproduce", "fig7", "--quick"]])
def test_jobs_below_one_is_refused_and_creates_nothing(tmp_path, capsys, command, jobs):
    out = tmp_path / "out"
    refused(capsys, main([*command, "--jobs", jobs, "--out", str(out)]), "argument --jobs", "positive integer")
    assert not out.exists()


def test_sobol_n_zero_is_refused_not_replaced(tmp_path, capsys):
    out = tmp_path / "out"
    refused(capsys, main(["sobol", str(STUDIES / "sobol.toml"), "--n", "0", "--out", str(out)]), "argument --n")
    assert not out.exists()


@pytest.mark.parametrize("content, phrase", [("{}", "has no positive 'k_H'"), ("not json", "is not the JSON")])
def test_a_bad_calibration_file_creates_no_output_folder(tmp_path, capsys, content, phrase):
    calibration = tmp_path / "calib.json"
    calibration.write_text(content)
    out = tmp_path / "out"
    refused(capsys, main(["reproduce", "all", "--quick", "--calibration", str(calibration), "--out", str(out)]), phrase)
    assert not out.exists()


def test_refusals_exit_2_through_the_console_script(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "uq", "sweep", "--level", "6", "--plot", "f.xyz"], capture_output=True,
                          text=True, cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and len(proc.stderr.splitlines()) == 1


# ---- units ---------------------------------------------------------------------------------------------------

def test_g_and_k_H_accept_units(tmp_path, model_file, capsys):
    import json

    assert main(["sweep", "--level", "6", *FAST, "--model", model_file, "--g", "0.6mm", "--k-H", "300e3N/mm^1.5",
                 "--json"]) == 0
    captured = capsys.readouterr()
    impactor = json.loads(captured.out)["impactor"]
    assert impactor["g_m"] == pytest.approx(0.6e-3) and impactor["k_H_N_per_m1p5"] == pytest.approx(300e3 * 1e3**1.5)
    assert captured.err == ""  # plausible: no warning


@pytest.mark.parametrize("option, value, meant", [("--g", "0.58", "did you mean 0.58mm?"),
                                                  ("--k-H", "282e3", "did you mean 282e3N/mm^1.5?"),
                                                  ("--D", "0.085", "did you mean 0.085%?")])
def test_implausible_magnitudes_are_refused_with_the_reading_probably_meant(tmp_path, model_file, capsys, option,
                                                                              value, meant):
    out = tmp_path / "out"
    refused(capsys, main(["sweep", "--level", "6", *FAST, "--model", model_file, "--no-impactor", option, value,
                          "--out", str(out)]), f"{option} {value}: ", meant, "--allow-implausible")
    assert not out.exists()
    assert main(["sweep", "--level", "6", *FAST, "--model", model_file, "--no-impactor", option, value,
                 "--allow-implausible"]) == 0


@pytest.mark.parametrize("option, value", [("--g", "0.58in"), ("--k-H", "282e3 N/cm^1.5")])
def test_unknown_units_are_refused(tmp_path, model_file, capsys, option, value):
    out = tmp_path / "out"
    refused(capsys, main(["sweep", "--level", "6", *FAST, "--model", model_file, option, value, "--out", str(out)]),
            f"argument {option}", "unknown unit")
    assert not out.exists()


def test_study_files_take_units_and_refuse_slips(tmp_path, capsys):
    from uq.errors import StudyError
    from uq.methods import load_study
    from uq.problem.space import K_H_STAR

    path = tmp_path / "s.toml"
    path.write_text("[study]\nkind = 'interval'\n[parameters.g]\nmax = '0.612 mm'\n[parameters.k_H]\n"
                    "max = '428e3 N/mm^1.5'\n[excitation]\nlevels = [6.7]\n")
    study = load_study(path)
    assert study.space["g"].max == pytest.approx(0.612e-3) and study.space["k_H"].max == pytest.approx(428e3 * 1e3**1.5)
    assert capsys.readouterr().err == ""
    path.write_text("[study]\nkind = 'interval'\n[parameters.g]\nnominal = 0.58\nmin = 0.58\nmax = 0.612\n"
                    "[excitation]\nlevels = [6.7]\n")
    with pytest.raises(StudyError, match=r"\[parameters.g\] nominal = 0.58: 0.58 m is implausible for a clearance g "
                                         r"\(above 10 mm\); did you mean 0.58mm\? Give the unit"):
        load_study(path)
    assert load_study(path, allow_implausible=True).space["g"].max == 0.612
    assert K_H_STAR == pytest.approx(282e3 * 1e3**1.5)


# ---- scans ---------------------------------------------------------------------------------------------------

def test_a_truncated_binary_stl_names_the_real_reason(tmp_path, capsys):
    from scans import example_path

    data = Path(example_path("imprint")).read_bytes()
    cut = tmp_path / "cut.stl"
    cut.write_bytes(data[: len(data) // 2])
    refused(capsys, main(["calibrate", str(cut), "--json"]), "truncated or damaged binary STL",
            "announces 16200 triangles (810084 bytes) but the file has 405042 bytes")
    stub = tmp_path / "stub.stl"
    stub.write_bytes(data[:50])
    refused(capsys, main(["calibrate", str(stub)]), "too short for a binary STL")


# ---- one repetition ------------------------------------------------------------------------------------------

def test_one_repetition_says_monotonicity_could_not_be_tested(tmp_path, capsys):
    """One stepped-sine run per point gives no noise estimate: no 'not monotone beyond the noise', nothing
    flagged, and the report says the check could not be made."""
    import csv

    study = tmp_path / "one.toml"
    study.write_text("[study]\nkind = 'interval'\nrepetitions = 1\n[parameters.k_H]\n[parameters.g]\n[excitation]\n"
                     "levels = [7.4]\neta = { start = 0.975, stop = 0.98, n = 2 }\nwait = 0.1\nhold = 0.1\n"
                     "[interval]\ndesigns = ['individual', 'joint']\n")
    assert main(["interval", str(study), "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    captured = capsys.readouterr()
    assert "not monotone" not in captured.err + captured.out
    assert "monotonicity could not be tested" in captured.err
    with open(tmp_path / "o" / "bands.csv", newline="") as fh:
        bands = list(csv.DictReader(fh))
    assert bands and all(r["tested"] == "0" and r["flagged"] == "0" for r in bands)


# ---- --resume into another study -----------------------------------------------------------------------------

AB = "[parameters.a]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n[parameters.b]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n"


def test_resume_refuses_a_folder_of_another_study(tmp_path, capsys):
    first, second = tmp_path / "first.toml", tmp_path / "second.toml"
    head = "[study]\nkind = 'interval'\nmodel = 'uq.problem.test_functions:noisy_linear'\nrepetitions = 2\n"
    first.write_text(head + "seed = 1\n" + AB)
    second.write_text(head + "seed = 2\n" + AB)  # another seed: other results
    out = tmp_path / "o"
    run = ["--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]
    assert main(["interval", str(first), *run]) == 0
    before = {p: p.read_bytes() for p in files_in(out) if p.is_file()}
    capsys.readouterr()
    refused(capsys, main(["interval", str(second), *run, "--resume"]), "holds the tasks of another study ('first'",
            "not of 'second'", "choose another --out")
    assert {p: p.read_bytes() for p in files_in(out) if p.is_file()} == before  # nothing overwritten or added
    assert main(["interval", str(first), *run, "--resume"]) == 0  # the same study continues
    assert "(0 run now, " in capsys.readouterr().out


# ---- a lost Dask scheduler -----------------------------------------------------------------------------------

SLOW_MODEL = '''
import time

def slow_sum(params, level, rep, seed):
    time.sleep(0.2)
    return params["a"] + params["b"] + level
'''


class Cluster:
    """A Dask scheduler and one single-threaded worker as separate processes (`dask scheduler`, `dask worker`)."""

    def __init__(self, folder: Path, env: dict) -> None:
        import json
        import time

        self.file = folder / f"scheduler-{time.monotonic_ns()}.json"
        run = lambda *args: subprocess.Popen([sys.executable, "-m", *args], cwd=folder, env=env,  # noqa: E731
                                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.scheduler = run("distributed.cli.dask_scheduler", "--port", "0", "--no-dashboard",
                             "--scheduler-file", str(self.file))
        for _ in range(600):
            if self.file.is_file() and self.file.stat().st_size:
                break
            time.sleep(0.1)
        self.address = json.loads(self.file.read_text())["address"]
        self.worker = run("distributed.cli.dask_worker", "--scheduler-file", str(self.file), "--nthreads", "1",
                          "--no-dashboard")

    def stop(self) -> None:
        for proc in (self.scheduler, self.worker):
            proc.kill()
            proc.wait()


def test_a_lost_scheduler_is_one_line_and_resume_finishes_the_study(tmp_path):
    pytest.importorskip("distributed")
    import os
    import time

    (tmp_path / "slow_model.py").write_text(SLOW_MODEL)
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'interval'\nmodel = 'slow_model:slow_sum'\nrepetitions = 2\n" + AB +
                     "[excitation]\nlevels = [1.0, 2.0, 3.0]\n[interval]\ndesigns = ['individual', 'joint']\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(Path(__file__).resolve().parents[1])])}
    out = tmp_path / "o"
    command = [sys.executable, "-m", "uq", "interval", str(study), "--out", str(out), "--quiet", "--no-figures"]
    cluster = Cluster(tmp_path, env)
    try:
        proc = subprocess.Popen([*command, "--scheduler", cluster.address], cwd=tmp_path, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        while len(list((out / "tasks").glob("*.json"))) < 5 and proc.poll() is None:
            time.sleep(0.1)
        cluster.scheduler.kill()  # the scheduler dies mid-study
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        cluster.stop()
    assert proc.returncode == 2, stderr
    assert len(stderr.strip().splitlines()) == 1 and "Traceback" not in stderr, stderr
    assert stderr.startswith(f"ies interval: error: lost the Dask scheduler {cluster.address} after ") and "--resume" in stderr
    kept = len(list((out / "tasks").glob("*.json")))
    assert kept >= 5 and not (out / "bands.csv").exists()
    cluster = Cluster(tmp_path, env)  # a new cluster; --resume runs only the missing tasks
    try:
        done = subprocess.run([*command, "--scheduler", cluster.address, "--resume"], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=300)
    finally:
        cluster.stop()
    assert done.returncode == 0, done.stderr
    assert "reused)" in done.stdout and (out / "bands.csv").is_file()
    tasks = int(done.stdout.split(" runs (")[0].splitlines()[-1])
    assert f"({tasks - kept} run now, {kept} reused)" in done.stdout


# ---- ies impacts, ies modal-fit, ies trace ---------------------------------------------------------------------

def _signal_file(folder: Path, text: str) -> Path:
    path = folder / "signal.csv"
    path.write_text(text)
    return path


def _uniform_rows(n: int = 200, fs: float = 51.2e3) -> str:
    t = np.arange(n) / fs
    return "".join(f"{float(ti)!r},{np.sin(ti * 3e4)},{np.cos(ti * 3e4)},{np.sin(ti * 700)},{np.cos(ti * 700)}\n"
                   for ti in t)


def _with_nan(rows: str) -> str:
    """The rows with a_left of the eighth one replaced by nan."""
    lines = rows.splitlines(keepends=True)
    cells = lines[7].split(",")
    lines[7] = ",".join([cells[0], "nan", *cells[2:]])
    return "".join(lines)


HEADER = "t,a_left,a_right,a_tip,v_tip\n"


@pytest.mark.parametrize("content, phrase", [
    ("", "is empty"),
    ("t,a_left,a_tip,v_tip\n0,1,2,3\n1e-5,1,2,3\n", "missing column(s) a_right"),
    (HEADER + _with_nan(_uniform_rows()), "every value must be a finite number"),
    (HEADER + _uniform_rows(20).replace(_uniform_rows(20).splitlines()[5], "oops,1,2,3,4"), "'oops' in column 't'"),
    (HEADER + "".join(reversed(_uniform_rows(20).splitlines(keepends=True))), "t must increase"),
    (HEADER + _uniform_rows(200, 30e3), "sampling rate 30000 Hz is too low for the 20000 Hz high-pass"),
])
@pytest.mark.parametrize("command", [["impacts"], ["modal-fit", "--model", "builtin"]])
def test_bad_signal_files_are_one_line(tmp_path, capsys, content, phrase, command):
    path = _signal_file(tmp_path, content)
    before = files_in(tmp_path)
    refused(capsys, main([command[0], str(path), *command[1:], "--plot", str(tmp_path / "fit.png")] if command[0] ==
                         "modal-fit" else [*command, str(path)]), phrase)
    assert files_in(tmp_path) == before


def test_non_uniform_sampling_is_refused(tmp_path, capsys):
    t = np.arange(300) / 51.2e3
    t[100:] += 0.3 / 51.2e3
    rows = "".join(f"{float(ti)!r},1,2,3\n" for ti in t)
    path = _signal_file(tmp_path, "t,a_left,a_right,a_tip\n" + rows)
    refused(capsys, main(["impacts", str(path)]), "not uniformly sampled")


@pytest.mark.parametrize("args, phrase", [
    (["--model", "nowhere.toml"], "unknown model 'nowhere.toml'"),
    (["--model", "builtin", "--impacts", "none.json"], "--impacts none.json: file not found"),
    (["--model", "builtin", "--threshold", "0.8:1.0"], "needs one threshold factor"),
])
def test_bad_modal_fit_options_are_one_line(tmp_path, capsys, monkeypatch, args, phrase):
    monkeypatch.chdir(tmp_path)
    path = _signal_file(tmp_path, HEADER + _uniform_rows())
    refused(capsys, main(["modal-fit", str(path), *args, "--plot", "fit.png"]), phrase)
    assert [p.name for p in files_in(tmp_path)] == ["signal.csv"]


@pytest.mark.parametrize("args, phrase", [
    (["--fs", "100"], "is below twice the excitation frequency"),
    (["--periods", "0"], "argument --periods"),
    (["--model", "nowhere.toml"], "nowhere.toml"),
])
def test_bad_trace_options_create_nothing(tmp_path, model_file, capsys, monkeypatch, args, phrase):
    monkeypatch.chdir(tmp_path)
    base = ["trace", "--level", "6", "--eta", "0.99", "--wait", "0.02", "--model", model_file, "--out", "res"]
    refused(capsys, main([*base, *args, "--plot", "trace.png"]), phrase)
    assert [p.name for p in files_in(tmp_path)] == ["three.toml"]


# ---- the damped contact law (Eq. 10) ---------------------------------------------------------------------------

@pytest.mark.parametrize("args, phrase", [
    (["--r-cont", "1.2"], "r_cont must lie in (0, 1]"),
    (["--r-cont", "0"], "r_cont must lie in (0, 1]"),
    (["--contact-law", "hertz", "--r-cont", "0.9"], "needs the contact law 'hertz-damped'"),
    (["--r-cont", "0.9"], "has no 'beam_mass_kg'"),  # the three-mode file has no beam mass
])
@pytest.mark.parametrize("command", [["sweep", "--level", "6", *FAST], ["overview", "--levels", "5,6", *FAST],
                                     ["trace", "--level", "6", "--eta", "0.98", "--periods", "2"]])
def test_bad_contact_law_options_create_nothing(tmp_path, model_file, capsys, monkeypatch, command, args, phrase):
    monkeypatch.chdir(tmp_path)
    refused(capsys, main([*command, "--model", model_file, "--out", "res", *args]), phrase)
    assert [p.name for p in files_in(tmp_path)] == ["three.toml"]


# ---- dry friction (Appendix C) ----------------------------------------------------------------------------------

@pytest.mark.parametrize("args, phrase", [
    (["--friction", "-0.1", "--integrator", "ode3"], "the friction coefficient mu must be >= 0"),
    (["--friction", "0.07", "--k-t", "-5", "--integrator", "ode3"], "k_t (N/m) must be a positive number"),
    (["--friction", "0.07", "--integrator", "ode3"], "has no 'phi_floor'"),  # the three-mode file has no floor values
    (["--friction", "0.07"], "in the ode3 integrator only"),
])
@pytest.mark.parametrize("command", [["sweep", "--level", "6", *FAST], ["overview", "--levels", "5,6", *FAST],
                                     ["trace", "--level", "6", "--eta", "0.98", "--periods", "2"]])
def test_bad_friction_options_create_nothing(tmp_path, model_file, capsys, monkeypatch, command, args, phrase):
    monkeypatch.chdir(tmp_path)
    model = ["--model", model_file] if phrase == "has no 'phi_floor'" else []
    refused(capsys, main([*command, *model, "--out", "res", *args]), phrase)
    assert [p.name for p in files_in(tmp_path)] == ["three.toml"]


def test_a_friction_study_on_the_exact_integrator_is_one_line(tmp_path, capsys):
    study = tmp_path / "friction.toml"
    study.write_text("[study]\nkind = 'response'\n[parameters.friction]\nnominal = 0.07\n[excitation]\nlevels = [1.26]\n"
                     "eta = { start = 0.98, stop = 0.99, n = 2 }\nwait = 0.1\nhold = 0.1\n")
    refused(capsys, main(["response", str(study), "--out", str(tmp_path / "o")]), "ode3 integrator only")
    assert not (tmp_path / "o").exists()
