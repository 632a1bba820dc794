"""Runner: resumable after SIGKILL, identical numbers serially, with --jobs 2 and on a Dask LocalCluster, a dead
worker costs only its unfinished tasks, an unreachable scheduler in one line. Runs the real simulator on a tiny
protocol (short wait and hold)."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from uq.cli import main

ROOT = Path(__file__).resolve().parents[3]
TINY = """
[study]
name = "tiny"
kind = "interval"
repetitions = 2
seed = 11
[excitation]
levels = [6.0, 8.0]
eta = {{ start = 0.97, stop = 0.99, n = 3 }}
wait = {wait}
hold = 0.3
sequence = "up"
integrator = "ode3"
[interval]
designs = ["individual", "joint"]
interior = 1
"""
DATA = ("runs.csv", "points.csv", "bands.csv")


def tiny_study(tmp_path, wait=0.1):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY.format(wait=wait))
    return path


def data_of(folder):
    return {name: (folder / name).read_text() for name in DATA}


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("serial")
    out = tmp / "out"
    assert main(["interval", str(tiny_study(tmp)), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    return out


def test_jobs_2_gives_identical_numbers(serial, tmp_path):
    out = tmp_path / "out"
    assert main(["interval", str(tiny_study(tmp_path)), "--out", str(out), "--jobs", "2", "--quiet",
                 "--no-figures"]) == 0
    assert data_of(out) == data_of(serial)


def test_dask_local_cluster_gives_identical_numbers(serial, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    from uq.engine import runner

    addresses = []
    connect = runner._connect
    monkeypatch.setattr(runner, "_connect", lambda address: addresses.append(address) or connect(address))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        out = tmp_path / "out"
        assert main(["interval", str(tiny_study(tmp_path)), "--out", str(out), "--scheduler",
                     cluster.scheduler_address, "--quiet", "--jobs", "1", "--no-figures"]) == 0
    assert data_of(out) == data_of(serial)
    assert addresses == [cluster.scheduler_address]  # one connection serves the whole study


def test_unreachable_scheduler_is_one_line(tmp_path, capsys):
    pytest.importorskip("distributed")
    code = main(["interval", str(tiny_study(tmp_path)), "--out", str(tmp_path / "o"), "--scheduler",
                 "tcp://127.0.0.1:9", "--quiet", "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in err
    assert len(err.strip().splitlines()) == 1


def test_sigkill_then_resume_runs_only_unfinished_tasks(serial, tmp_path):
    study = tiny_study(tmp_path)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "uq", "interval", str(study), "--out", str(out), "--quiet", "--jobs", "1",
                             "--no-figures"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    tasks = out / "tasks"
    total = 2 * 2 * 8  # reps x levels x points (nominal, D: min/nominal/max, g, k_H: mid and max, corners, ...)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if tasks.is_dir() and len(list(tasks.glob("*.json"))) >= 6:
            break
        time.sleep(0.01)
    assert proc.poll() is None, f"study finished before the kill: {proc.stderr.read().decode()}"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    finished = {p.name: p.stat().st_mtime_ns for p in tasks.glob("*.json")}
    assert 6 <= len(finished)
    assert not (out / "bands.csv").exists()
    for path in tasks.glob("*.json"):  # every finished task file is complete (atomic rename)
        assert json.loads(path.read_text())["outputs"]
    assert main(["interval", str(study), "--out", str(out), "--resume", "--quiet", "--jobs", "1", "--no-figures"]) == 0
    summary = json.loads((out / "study.json").read_text())["summary"]
    assert summary["reused"] == len(finished) and summary["ran"] == summary["tasks"] - len(finished)
    assert all(p.stat().st_mtime_ns == finished[p.name] for p in tasks.glob("*.json") if p.name in finished)
    assert data_of(out) == data_of(serial)  # the resumed outputs equal an uninterrupted run
    assert summary["tasks"] >= total
    assert not list(tasks.glob(".*"))  # the temporary file of the write cut off by the kill is cleared


def test_resume_with_everything_done_runs_nothing(serial, tmp_path, capsys):
    assert main(["interval", str(tiny_study(tmp_path)), "--out", str(serial), "--resume", "--quiet", "--jobs", "1",
                 "--no-figures"]) == 0
    assert "(0 run now" in capsys.readouterr().out


class CountingModel:
    """A toy model that appends its parameter to a log file at every evaluation (to count recomputations)."""

    outputs = ("y",)

    def __init__(self, log: str) -> None:
        self.log = log

    def __call__(self, params, level, rep, seed):
        time.sleep(0.05)
        with open(self.log, "a") as fh:
            fh.write(f"{params['x']:g}\n")
        return {"y": params["x"]}


def test_a_dead_worker_does_not_recompute_finished_tasks(tmp_path):
    """A worker that dies (a batch job at its walltime) must cost only its unfinished tasks: the runner forgets each
    result once it has it, otherwise the scheduler recomputes every finished task the client still holds, and with
    jobs dying at each walltime a study never ends."""
    distributed = pytest.importorskip("distributed")
    from uq.engine.runner import Task, _dispatch

    log = tmp_path / "calls.log"
    pending = [(f"k{i}", Task.make({"x": i}, 1.0, 0)) for i in range(40)]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        finished = []
        for key, task, result in _dispatch(CountingModel(str(log)), pending, 0, 1, client):
            finished.append(key)
            if len(finished) == 10:  # kill the only worker; its nanny starts a new one
                pid = next(iter(client.run(os.getpid).values()))
                os.kill(pid, signal.SIGKILL)
    calls = log.read_text().split()
    assert sorted(finished) == sorted(k for k, _ in pending)
    assert all(calls.count(key[1:]) == 1 for key in finished[:10]), calls  # finished before the kill: run once


def _children(pid: int, marker: str) -> list[int]:
    """Processes whose parent is `pid` and whose command line contains `marker` (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
                if ppid == pid and marker in (entry / "cmdline").read_bytes().decode(errors="replace"):
                    found.append(int(entry.name))
            except (OSError, IndexError, ValueError):
                continue
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers through /proc")
def test_ctrl_c_while_the_workers_start_is_one_line(tmp_path):
    """Ctrl-C (SIGINT to the terminal's process group) while `--jobs 99` workers are still starting: no worker prints
    a traceback, the command says one line and exits 130."""
    study = tiny_study(tmp_path)
    proc = subprocess.Popen([sys.executable, "-m", "uq", "interval", str(study), "--out", str(tmp_path / "out"),
                             "--jobs", "99", "--no-figures"], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None and len(_children(proc.pid, "loky")) < 3:
        time.sleep(0.02)
    assert proc.poll() is None, f"the study ended before its workers started: {proc.stderr.read()}"
    time.sleep(0.3)  # the workers are importing numpy, numba, the simulator
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err[-3000:]
    assert proc.returncode == 130
    assert err.strip().splitlines()[-1] == "ies interval: interrupted; finished results were kept (rerun with --resume)"


def test_ctrl_c_during_a_dask_study_is_one_line(tmp_path):
    """The same on a Dask cluster (here a LocalCluster of worker processes): the client's Ctrl-C cancels its tasks and
    says one line; no traceback from the client or Dask's logging."""
    distributed = pytest.importorskip("distributed")
    study = tiny_study(tmp_path, wait=0.5)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        proc = subprocess.Popen([sys.executable, "-m", "uq", "interval", str(study), "--out", str(tmp_path / "out"),
                                 "--scheduler", cluster.scheduler_address, "--no-figures"], cwd=ROOT,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
        tasks = tmp_path / "out" / "tasks"
        deadline = time.time() + 300
        while time.time() < deadline and proc.poll() is None and len(list(tasks.glob("*.json"))) < 2:
            time.sleep(0.02)
        assert proc.poll() is None, f"the study ended before the interruption: {proc.stderr.read()}"
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err[-3000:]
    assert proc.returncode == 130
    assert err.strip().splitlines()[-1] == "ies interval: interrupted; finished results were kept (rerun with --resume)"
