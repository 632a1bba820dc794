"""The fourth new-user pass (issue 43): the last tracebacks, silent wrong values refused, work estimated before it
starts, one run per output folder, plain progress lines in logs, and study files of the previous release.

Each bad input ends in one line on stderr with exit code 2 (caught before any work) or 3 (after work, keeping what was
done), no traceback, nothing half-written. The studies here use the Ishigami model or the three-mode model file (runs
of a few hundredths of a simulated second), so the file runs in about a minute.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from uq.cli import main

from tests.support import FAST, one_line

ROOT = Path(__file__).resolve().parents[1]
ISHIGAMI = "[study]\nkind = 'sobol'\nmodel = 'ishigami'\nseed = 5\n[sobol]\nn = {n}\nbootstrap = 20\n"


def ishigami(tmp_path: Path, n: int = 8) -> Path:
    study = tmp_path / "ishigami.toml"
    study.write_text(ISHIGAMI.format(n=n))
    return study


def whole_files(folder: Path) -> None:
    """Every file of a study folder is whole: CSV tables end with their last line, JSON and results.nc read, and
    no temporary file of a write is left."""
    from sim.common.files import read_rows
    from uq.outputs.netcdf import open_results

    assert not [p.name for p in folder.rglob(".*")], "a temporary file of a write is left"
    for path in folder.glob("*.csv"):
        read_rows(path)
    for path in [*folder.glob("*.json"), *(folder / "tasks").glob("*.json")]:
        json.loads(path.read_text())
    if (folder / "results.nc").exists():
        open_results(folder)


# ---- 1. the last tracebacks --------------------------------------------------------------------------------------

def test_resume_over_a_task_file_cut_short_runs_that_task_again_and_says_so(tmp_path, capsys):
    study, out = ishigami(tmp_path), tmp_path / "out"
    assert main(["sobol", str(study), "--out", str(out), "--no-figures", "--quiet"]) == 0
    first = (out / "sobol.csv").read_text()
    tasks = sorted((out / "tasks").glob("*.json"))
    tasks[3].write_text(tasks[3].read_text()[:40])  # a disk that filled up, a copy cut off
    tasks[5].write_text("[1, 2]")  # JSON, but not a task's record
    capsys.readouterr()
    assert main(["sobol", str(study), "--out", str(out), "--no-figures", "--quiet", "--resume"]) == 0
    captured = capsys.readouterr()
    assert "2 run now" in captured.out and "Traceback" not in captured.err
    warnings = [line for line in captured.err.splitlines() if "damaged" in line]
    assert len(warnings) == 1 and "2 stored task file(s)" in warnings[0] and "run again" in warnings[0]
    assert (out / "sobol.csv").read_text() == first  # the same runs, the same numbers


def test_compare_on_an_overview_cut_short_names_the_file_and_the_line(tmp_path, capsys):
    folder = tmp_path / "study"
    folder.mkdir()
    (folder / "study.json").write_text(json.dumps({"study": {"kind": "response", "name": "s"}, "landmarks": {}}))
    (folder / "overview.csv").write_text("level,resonant_mean,regime\n5.3,0.05,SMR\n6.7,0.0")
    one_line(capsys, main(["compare", str(folder), "--out", str(tmp_path / "c")]), 2,
             f"{folder / 'overview.csv'}: line 3 has 2 cells but the header names 3 columns", "cut short")
    (folder / "overview.csv").write_text("level,resonant_mean,regime\n5.3,0.05,SMR\n6.7,0.04,AP")
    one_line(capsys, main(["compare", str(folder), "--out", str(tmp_path / "c")]), 2,
             "line 3 ends without a line end")
    (folder / "overview.csv").write_text("level,resonant_mean,regime\n5.3,0.0\x005,SMR\n")
    one_line(capsys, main(["compare", str(folder), "--out", str(tmp_path / "c")]), 2,
             "in column 'resonant_mean' is not a number")
    assert not (tmp_path / "c").exists()


def test_plot_on_a_table_cut_short_names_the_file_and_the_line(tmp_path, capsys):
    study, out = ishigami(tmp_path), tmp_path / "out"
    assert main(["sobol", str(study), "--out", str(out), "--no-figures", "--quiet"]) == 0
    text = (out / "sobol.csv").read_text()
    (out / "sobol.csv").write_text(text[: text.rindex(",")])
    capsys.readouterr()
    one_line(capsys, main(["plot", str(out)]), 2, f"{out / 'sobol.csv'}: line ", "cut short")


def _interrupting_at(count: int):
    """A profile function that sends this process a real SIGINT at its `count`-th function call."""
    calls = [0]

    def profile(frame, event, arg):
        if event == "call":
            calls[0] += 1
            if calls[0] == count:
                os.kill(os.getpid(), signal.SIGINT)

    return profile, calls


def test_ctrl_c_at_any_point_of_the_final_writes_is_one_line_and_leaves_whole_files(tmp_path, capsys, monkeypatch):
    """A real SIGINT at many points of a study's final writing (the tables, results.nc through HDF5, study.json, the
    figures): always exit 130 with one line, or 0 when it came after the last file; never a traceback; every file
    whole or absent; and the interrupt never fires inside a writer (HDF5, matplotlib's savefig, ...: `atomic_path`),
    where it can leave a library in a state that ends the interpreter with a fatal error: it is held back and
    delivered between files."""
    import uq.engine.execution

    fired_inside_a_writer = []
    writers = {"savefig", "to_netcdf", "write_bytes"}  # matplotlib's, xarray's (HDF5) and the text files' writer

    def interrupt(signum, frame):  # Python's default handler, noting where it fires
        while frame is not None:
            if frame.f_code.co_name in writers:
                fired_inside_a_writer.append(frame.f_code.co_name)
            frame = frame.f_back
        raise KeyboardInterrupt

    monkeypatch.setattr(signal, "default_int_handler", interrupt)
    previous = signal.signal(signal.SIGINT, interrupt)
    study = ishigami(tmp_path)
    analyse = uq.engine.execution.statistics
    counted: dict[str, int] = {}

    def final_writes_profiled(*args, **kwargs):  # the runs are done: profile from here to the end of the command
        sys.setprofile(profile)
        return analyse(*args, **kwargs)

    monkeypatch.setattr(uq.engine.execution, "statistics", final_writes_profiled)
    for k in range(2):  # count only, how many calls the final writes make, once everything is imported
        profile, calls = _interrupting_at(-1)
        try:
            assert main(["sobol", str(study), "--out", str(tmp_path / f"count{k}"), "--quiet"]) == 0
        finally:
            sys.setprofile(None)
    total = calls[0]
    assert total > 10_000
    codes = []
    for k, at in enumerate(sorted({int(total * f) for f in (0.001, 0.01, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7,
                                                             0.8, 0.9, 0.95, 0.99, 0.999, 1.2)})):
        out = tmp_path / f"o{k}"
        profile, calls = _interrupting_at(at)
        capsys.readouterr()
        try:
            code = main(["sobol", str(study), "--out", str(out), "--quiet"])
        finally:
            sys.setprofile(None)
        err = capsys.readouterr().err
        assert "Traceback" not in err and len(err.strip().splitlines()) == (code == 130), (at, err)
        assert code in (0, 130) and (code == 0) == (at > total), (at, code, err)
        whole_files(out)
        codes.append(code)
    signal.signal(signal.SIGINT, previous)
    assert codes.count(130) == len(codes) - 1 and not fired_inside_a_writer


def test_ctrl_c_after_the_command_is_done_is_ignored(tmp_path):
    """Through the process entry (argv from the command line): an interrupt once the exit code is settled, while the
    interpreter shuts down, no longer ends the process with a traceback, "Exception ignored" or a kill by SIGINT."""
    study = ishigami(tmp_path)
    code = ("import os, signal, sys; from uq.cli import main; code = main(); os.kill(os.getpid(), signal.SIGINT); "
            "sys.exit(code)")
    done = subprocess.run([sys.executable, "-c", code, "sobol", str(study), "--out", str(tmp_path / "o"), "--quiet",
                           "--no-figures"], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0 and done.stderr == "", done.stderr


# ---- 4. one run per output folder --------------------------------------------------------------------------------

def _started(command: list[str], lock: Path) -> subprocess.Popen:
    """A real `ies` process (`python -m uq`, from the source tree), once it holds the lock `lock`."""
    import time

    process = subprocess.Popen([sys.executable, "-m", "uq", *command], cwd=ROOT, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120.0
    while not lock.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the first run never took the folder's lock"
        time.sleep(0.05)
    return process


def _second(command: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "uq", *command], cwd=ROOT, capture_output=True, text=True)


def test_two_study_runs_into_one_folder_the_second_is_refused_naming_the_first(tmp_path):
    """Two `ies interval` runs into one --out: the second (with or without --resume) is refused with one line naming
    the first (pid, host, command, start time) while it runs; after it ends the folder is free and the lock gone."""
    import socket

    from sim.common.folder_lock import LOCK_FILE
    from tests.support import AB_PARAMETERS

    study = tmp_path / "slow.toml"
    study.write_text(f"[study]\nkind = 'interval'\nmodel = 'tests.support:sleepy'\nrepetitions = 6\n{AB_PARAMETERS}"
                     "[interval]\ndesigns = ['individual', 'joint']\n")  # 66 runs of 0.25 s
    out = tmp_path / "out"
    command = ["interval", str(study), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]
    first = _started(command, out / LOCK_FILE)
    for extra in ([], ["--resume"]):
        second = _second([*command, *extra])
        assert second.returncode == 2 and len(second.stderr.strip().splitlines()) == 1, second.stderr
        assert f"--out {out} is in use by another run: pid {first.pid} on {socket.gethostname()}" in second.stderr
        assert f"interval {study} --out {out}" in second.stderr and "started 20" in second.stderr
    assert first.wait(timeout=300) == 0, first.communicate()
    assert not (out / LOCK_FILE).exists()
    again = _second([*command, "--resume"])
    assert again.returncode == 0 and "0 run now" in again.stdout, again.stderr


def test_resume_takes_over_from_a_run_that_died(tmp_path):
    """A run killed (SIGKILL: no chance to clean up) leaves its lock file, not its lock: --resume takes the folder over
    at once and finishes the study with the runs the dead one stored."""
    from sim.common.folder_lock import LOCK_FILE
    from tests.support import AB_PARAMETERS

    study = tmp_path / "slow.toml"
    study.write_text(f"[study]\nkind = 'interval'\nmodel = 'tests.support:sleepy'\n{AB_PARAMETERS}[interval]\n"
                     "designs = ['individual', 'joint']\n")
    out = tmp_path / "out"
    command = ["interval", str(study), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]
    first = _started(command, out / LOCK_FILE)
    while len(list((out / "tasks").glob("*.json"))) < 2:
        assert first.poll() is None
    first.kill()
    first.wait()
    assert (out / LOCK_FILE).exists()
    again = _second([*command, "--resume"])
    assert again.returncode == 0, again.stderr
    assert "reused" in again.stdout and not (out / LOCK_FILE).exists()


def test_two_sweeps_with_force_into_one_folder_do_not_race(tmp_path, model_file):
    """`ies sweep --force` twice into one folder: the second is refused while the first runs, and after the first is
    killed a third takes the folder over."""
    from sim.common.folder_lock import LOCK_FILE

    out = tmp_path / "res"
    command = ["sweep", "--level", "6", "--eta", "0.98:1.0:40", "--wait", "20", "--hold", "20", "--reps", "3",
               "--model", model_file, "--out", str(out), "--force"]
    first = _started(command, out / LOCK_FILE)
    second = _second(command)
    assert second.returncode == 2 and f"pid {first.pid}" in second.stderr, second.stderr
    first.kill()
    first.wait()
    third = _second(["sweep", "--level", "6", *FAST, "--model", model_file, "--out", str(out), "--force"])
    assert third.returncode == 0, third.stderr
    assert sorted(p.name for p in out.iterdir()) == ["sweep.csv", "sweep.json"]


# ---- 2. silent wrong values --------------------------------------------------------------------------------------

def test_a_damping_ratio_in_percent_is_read_as_such_and_a_bare_one_above_5_percent_refused(tmp_path, model_file,
                                                                                          capsys):
    base = ["sweep", "--level", "6", *FAST, "--model", model_file, "--json"]
    assert main([*base, "--D", "0.085%"]) == 0
    assert json.loads(capsys.readouterr().out)["D1"] == 0.00085  # the same float as --D 0.00085
    one_line(capsys, main([*base, "--D", "0.085"]), 2, "--D 0.085: 8.5 % is implausible for a damping ratio (above "
             "5 %); did you mean 0.085%? Give the unit, or pass --allow-implausible")
    assert main([*base, "--D", "0.085", "--allow-implausible"]) == 0
    assert json.loads(capsys.readouterr().out)["D1"] == 0.085


def test_implausible_values_in_a_study_file_are_refused_with_the_reading_meant(tmp_path, capsys):
    head = "[study]\nkind = 'interval'\n[excitation]\nlevels = [6.7]\n"
    cases = [("[parameters.D]\nmax = 0.09\n", "[parameters.D] max = 0.09: 9 % is implausible for a damping ratio "
                                              "(above 5 %); did you mean 0.09%?"),
             ("[parameters.g]\nmax = '612 um'\nnominal = 0.6\n", "[parameters.g] nominal = 0.6: 0.6 m is implausible"),
             ("[parameters.k_H]\n[interval]\ndesigns = ['residual']\nfix = { k_H = 350e3 }\n",
              "[interval] fix.k_H = 350000.0: 3.5e+05 N/m^1.5 is implausible")]
    for k, (table, phrase) in enumerate(cases):
        study = tmp_path / f"s{k}.toml"
        study.write_text(head + table)
        one_line(capsys, main(["interval", str(study), "--out", str(tmp_path / f"o{k}")]), 2, f"{study}: {phrase}")
        assert not (tmp_path / f"o{k}").exists()
    from uq.methods import load_study

    study.write_text(head + "[parameters.D]\nmin = '0.075 %'\nmax = '0.09%'\n")
    assert load_study(study).space["D"].max == 0.0009


def test_a_modal_file_whose_walls_stand_still_in_mode_1_is_refused_for_what_it_means(tmp_path, model_file):
    """Through the console script: one line saying the IES sits at a node of the resonance (no numpy RuntimeWarning
    about a division by zero first, no "a_base must be >= 0, got inf")."""
    text = Path(model_file).read_text()
    node = tmp_path / "node.toml"
    node.write_text(text.replace("phi_wall_left = [\n    1.05,", "phi_wall_left = [\n    0.0,")
                    .replace("phi_wall_right = [\n    1.05,", "phi_wall_right = [\n    0.0,"))
    assert node.read_text() != text
    study = tmp_path / "s.toml"
    study.write_text(f"[study]\nkind = 'response'\nmodal_model = '{node}'\n[excitation]\nlevels = [6.7]\n")
    for command in (["sweep", "--level", "6", *FAST, "--model", str(node)], ["response", str(study)]):
        done = subprocess.run([sys.executable, "-m", "uq", *command, "--out", str(tmp_path / "o")], cwd=ROOT,
                              capture_output=True, text=True)
        assert done.returncode == 2 and len(done.stderr.splitlines()) == 1, done.stderr
        assert "the cavity walls do not move in mode 1" in done.stderr and "node of the resonance" in done.stderr
        assert "RuntimeWarning" not in done.stderr and not (tmp_path / "o").exists()


def test_plot_and_compare_name_a_damaged_results_nc(tmp_path, model_file, capsys):
    study = tmp_path / "r.toml"
    study.write_text(f"[study]\nkind = 'response'\nmodal_model = '{model_file}'\nrepetitions = 1\n[excitation]\n"
                     "levels = [6.7]\neta = { start = 0.98, stop = 0.99, n = 2 }\nwait = 0.02\nhold = 0.05\n"
                     "[response]\nfigures = ['fig6']\n")
    out = tmp_path / "out"
    assert main(["response", str(study), "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    data = (out / "results.nc").read_bytes()
    (out / "results.nc").write_bytes(data[: len(data) // 2])
    capsys.readouterr()
    for command in (["plot", str(out), "--out", str(tmp_path / "figs")], ["compare", str(out), "--out",
                                                                          str(tmp_path / "cmp")]):
        one_line(capsys, main(command), 2, f"{out / 'results.nc'} is damaged or cut short",
                 f"rerun `ies response {study} --out {out} --resume`")
    assert not (tmp_path / "figs").exists() and not (tmp_path / "cmp").exists()
    assert main(["response", str(study), "--out", str(out), "--quiet", "--resume", "--no-figures"]) == 0
    assert main(["plot", str(out), "--out", str(tmp_path / "figs")]) == 0  # written again: drawn


# ---- 8. study files of the previous release ----------------------------------------------------------------------

def test_a_pce_study_of_the_previous_release_with_n_runs_and_says_points_is_its_setting(tmp_path, capsys):
    """`[sobol] n = 32` beside method = "pce" (the release before the method registry accepted and ignored it): the
    study runs as then, with one line that `points` is the surrogate's setting; Saltelli's own keys stay refused
    beside the other method."""
    study = tmp_path / "old.toml"
    study.write_text(ISHIGAMI.format(n=32).replace("[sobol]\n", "[sobol]\nmethod = 'pce'\n"))
    assert main(["sobol", str(study), "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if "[sobol] n" in line]
    assert err == [f"warning: {study}: [sobol] n = 32 is not a setting of method = \"pce\" (an earlier release ignored "
                   "it too) and is ignored: its setting is points, here points = 32; remove n or write points = N"]
    meta = json.loads((tmp_path / "o" / "study.json").read_text())
    assert meta["study"]["sobol"]["method"] == "pce" and "n" not in meta["study"]["sobol"]
    study.write_text(ISHIGAMI.format(n=32).replace("[sobol]\n", "[sobol]\npoints = 16\n"))
    one_line(capsys, main(["sobol", str(study), "--out", str(tmp_path / "p")]), 2,
             "[sobol] points only applies to method = \"pce\"")


# ---- 5. logs: one hash, plain progress lines ---------------------------------------------------------------------

def test_progress_in_a_log_is_plain_lines_never_a_bar(tmp_path, capsys, monkeypatch):
    """stderr not a terminal (a log file): the tasks' progress is plain lines, one per PLAIN_EVERY_S (0 here: every
    run), the last saying done; no carriage return, and every other line stands on its own."""
    monkeypatch.setattr("sim.common.progress.PLAIN_EVERY_S", 0.0)
    study = ishigami(tmp_path)
    assert main(["sobol", str(study), "--out", str(tmp_path / "o"), "--no-figures"]) == 0
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = [line for line in err.splitlines() if line.startswith("tasks: ")]
    assert len(lines) == 8 * (3 + 2) + 1 and lines[0].startswith("tasks: 1/40 run (2 %), ")
    assert "left" in lines[0] and lines[-1].startswith("tasks: 40/40 run (100 %), ") and lines[-1].endswith(", done")


def test_short_work_in_a_log_prints_no_progress_at_all(tmp_path):
    """Through the console script into a file, with the default period: a study of seconds writes no progress (and
    no bar's carriage returns) to the log."""
    study = ishigami(tmp_path)
    with open(tmp_path / "log.txt", "w") as log:
        done = subprocess.run([sys.executable, "-m", "uq", "sobol", str(study), "--out", str(tmp_path / "o"),
                               "--no-figures"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=log)
    assert done.returncode == 0
    text = (tmp_path / "log.txt").read_text()
    assert "\r" not in text and "tasks:" not in text and "it/s" not in text


def test_one_hash_names_the_simulators_code_in_version_cache_and_the_kernel_folder(capsys):
    from sim.integration import jit
    from uq.problem.models import IESModel

    assert main(["--version"]) == 0
    line = capsys.readouterr().out.strip()
    version = line.split("simulator code ")[1].rstrip(")")
    assert main(["cache", "--json"]) == 0
    current = [v["folder"] for v in json.loads(capsys.readouterr().out)["versions"] if v["current"]]
    assert current == [f"sim-{version}"] == [jit.cache_folder().name]
    assert IESModel().version() == version  # the code version in every task's key


# ---- 3. work estimated before it starts --------------------------------------------------------------------------

INTERVAL = ("[study]\nkind = 'interval'\nrepetitions = 5\nmodal_model = '{model}'\n[parameters.D]\n[parameters.g]\n"
            "[parameters.k_H]\n[excitation]\nlevels = [5.3, 6.7, 7.4]\neta = {{ start = 0.96, stop = 1.0, n = 21 }}\n"
            "[interval]\ndesigns = ['individual', 'joint']\n")


def test_a_study_estimated_above_an_hour_is_refused_before_its_first_run(tmp_path, model_file, capsys, monkeypatch):
    """The issue's interval study that printed "about 80 h" after its first run: now its time comes from a probe of its
    protocol before any run (here the probe is made to say 1 s per simulated second), and above an hour it is refused
    with the estimate and --allow-large; with --allow-large the estimate is the first line, before the first run."""
    import uq.engine.runner

    monkeypatch.setattr("sim.stepped_sine.cost.probe_cost", lambda *a: 1.0)
    ran = []
    monkeypatch.setattr(uq.engine.runner, "evaluate", lambda *a: ran.append(1) or (_ for _ in ()).throw(
        KeyboardInterrupt))
    study = tmp_path / "big.toml"
    study.write_text(INTERVAL.format(model=model_file))
    out = tmp_path / "out"
    one_line(capsys, main(["interval", str(study), "--out", str(out)]), 2, "cost estimate: 225 run(s) x 2.9 min",
             "on one core", "more than the 1.0 h a command runs without --allow-large", "or pass --allow-large")
    assert not ran and not out.exists()
    assert main(["interval", str(study), "--out", str(out), "--allow-large", "--jobs", "1"]) == 130
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("warning: cost estimate: 225 run(s) x 2.9 min") and len(ran) == 1


def test_a_sobol_study_refused_by_its_run_count_says_its_time(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'sobol'\n[parameters.D]\n[parameters.g]\n[excitation]\nlevels = [6.7]\n")
    one_line(capsys, main(["sobol", str(study), "--n", str(2**17), "--out", str(tmp_path / "o")]), 2,
             "524,288 runs (524,288 parameter points x 1 levels x 1 repetitions, about ", "h on one core)",
             "--allow-large")


def test_reproduce_all_is_refused_above_an_hour_before_its_calibration(tmp_path, capsys, monkeypatch):
    import uq.commands.reproduce

    monkeypatch.setattr("sim.stepped_sine.cost.probe_cost", lambda *a: 1.0)
    monkeypatch.setattr(uq.commands.reproduce, "run_calibration", lambda *a: pytest.fail("calibrated before refusing"))
    out = tmp_path / "out"
    one_line(capsys, main(["reproduce", "all", "--out", str(out)]), 2, "cost estimate: 1255 run(s)",
             "run --quick (minutes), one figure at a time", "--allow-large")
    assert not out.exists()


def test_a_design_is_refused_above_an_hour_before_its_first_run(tmp_path, model_file, capsys, monkeypatch):
    import uq.engine.runner

    monkeypatch.setattr("sim.stepped_sine.cost.probe_cost", lambda *a: 50.0)
    monkeypatch.setattr(uq.engine.runner, "evaluate", lambda *a: pytest.fail("a run before the refusal"))
    study = tmp_path / "design.toml"
    study.write_text(f"[study]\nkind = 'design'\noutput = '{tmp_path / 'out'}'\n[design]\nexcitation = '1.5um'\n"
                     f"clearance = '0.5mm:0.6mm:2'\nradius = '7.92mm'\ncandidates = 1\nreps = 1\nmodel = '{model_file}'\n"
                     "[excitation]\neta = { start = 0.98, stop = 0.99, n = 2 }\n")  # the paper's wait and hold
    one_line(capsys, main(["design", str(study), "--jobs", "1", "--quiet"]), 2, "cost estimate: ", "--allow-large")
    assert not (tmp_path / "out").exists()
