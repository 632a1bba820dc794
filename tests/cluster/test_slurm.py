"""`--cluster slurm` on a real single-node SLURM (conftest): a Sobol' study whose workers are batch jobs submitted by
dask-jobqueue with sbatch survives a worker job cancelled (scancel) in the middle with results byte-identical to
`--jobs 1` and no finished task recomputed; a refused queue is the scheduler's one line (exit 2); a queue that never
starts a job stops after --worker-timeout (exit 3) naming --resume, with every finished task kept, and the study
then resumes on a working queue. Runs the real simulator on a tiny protocol (about 0.15 s a run)."""
import json
import os
import subprocess
import threading
import time

import pytest

from uq.cli import main

# one test SLURM per module (its fixture): under pytest-xdist all of the module's tests go to one worker
pytestmark = pytest.mark.xdist_group("slurm")

STUDY = """
[study]
name = "tiny-sobol"
kind = "sobol"
repetitions = 2
seed = 5
[excitation]
levels = [6.0, 8.0]
eta = { start = 0.97, stop = 0.99, n = 3 }
wait = 0.1
hold = 0.3
sequence = "up"
integrator = "ode3"
[sobol]
n = 4
bootstrap = 20
"""
TOTAL = 4 * (3 + 2) * 2 * 2  # n (k + 2) points x levels x repetitions
DATA = ("runs.csv", "sobol.csv", "variance.csv")
CLUSTER = ["--cluster", "slurm", "--cluster-cores", "1", "--cluster-memory", "1GB", "--cluster-max-jobs", "2",
           "--cluster-walltime", "00:10:00", "--quiet", "--no-figures", "--jobs", "1"]


def data_of(folder):
    return {name: (folder / name).read_bytes() for name in DATA}


def task_times(folder):
    return {p.name: p.stat().st_mtime_ns for p in (folder / "tasks").glob("*.json")}


@pytest.fixture(scope="module")
def study_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "tiny-sobol.toml"
    path.write_text(STUDY)
    return path


@pytest.fixture(scope="module")
def serial(study_file):
    out = study_file.parent / "serial"
    assert main(["sobol", str(study_file), "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"]) == 0
    return out


def test_a_cancelled_worker_job_loses_nothing_and_changes_no_number(on_slurm, study_file, serial, tmp_path):
    out = tmp_path / "out"
    seen: dict = {}

    def cancel_one_worker():
        """When a fifth of the tasks are on disk, scancel one running worker job (as an admin or a node would)."""
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if (out / "tasks").is_dir() and len(task_times(out)) >= TOTAL // 5:
                seen["jobs"] = on_slurm.jobs()
                seen["finished"] = task_times(out)
                subprocess.run(["scancel", seen["jobs"][0]], check=True, env=os.environ)
                return
            time.sleep(0.02)

    killer = threading.Thread(target=cancel_one_worker, daemon=True)
    killer.start()
    t0 = time.monotonic()
    assert main(["sobol", str(study_file), "--out", str(out), *CLUSTER]) == 0
    killer.join(1)
    print(f"\n{TOTAL} tasks on SLURM in {time.monotonic() - t0:.1f} s; job {seen['jobs'][0]} of {seen['jobs']} "
          f"cancelled after {len(seen['finished'])} tasks")
    assert len(seen["finished"]) < TOTAL, "the study finished before the cancel"
    assert data_of(out) == data_of(serial)
    after = task_times(out)
    assert all(after[name] == mtime for name, mtime in seen["finished"].items())  # finished tasks not recomputed
    summary = json.loads((out / "study.json").read_text())["summary"]
    assert summary["tasks"] == summary["ran"] == TOTAL == len(after)
    assert on_slurm.drained()  # every worker job is gone after the study


def test_a_refused_queue_is_the_schedulers_one_line(on_slurm, study_file, tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["sobol", str(study_file), "--out", str(out), *CLUSTER, "--cluster-queue", "nosuch"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "refused the worker job" in err and "invalid partition specified: nosuch" in err
    assert not out.exists()  # nothing written


def test_no_worker_in_time_stops_naming_resume_and_keeps_finished_tasks(on_slurm, study_file, serial, tmp_path,
                                                                         capsys):
    import shutil

    out = tmp_path / "out"
    shutil.copytree(serial / "tasks", out / "tasks")  # a study half done: half of its tasks on disk
    for path in sorted((out / "tasks").glob("*.json"))[::2]:
        path.unlink()
    kept = task_times(out)
    # partition "closed" is DOWN: sbatch accepts the job, which stays pending
    code = main(["sobol", str(study_file), "--out", str(out), *CLUSTER, "--cluster-queue", "closed",
                 "--worker-timeout", "4", "--resume"])
    err = capsys.readouterr().err
    assert code == 3 and len(err.strip().splitlines()) == 1, err
    assert "no worker of the slurm cluster was connected for 4 s" in err and "--resume" in err
    assert task_times(out) == kept and not (out / "sobol.csv").exists()
    assert on_slurm.drained()  # the pending job was cancelled
    assert main(["sobol", str(study_file), "--out", str(out), *CLUSTER, "--resume"]) == 0
    assert data_of(out) == data_of(serial)
    summary = json.loads((out / "study.json").read_text())["summary"]
    assert summary["reused"] == len(kept) and summary["ran"] == TOTAL - len(kept)


WALLTIME_STUDY = STUDY.replace("hold = 0.3", "hold = 3.0").replace("n = 4", "n = 32")
WALLTIME_TOTAL = 32 * (3 + 2) * 2 * 2


@pytest.mark.long
def test_a_worker_job_killed_at_its_walltime_loses_nothing(on_slurm, tmp_path):
    """One worker job at a time with a 1-minute walltime (SLURM's smallest) and about 2 min of work: SLURM kills the
    first job at its time limit (JobState TIMEOUT), the cluster submits another, and the study finishes with every
    task once and the tasks finished before the kill untouched. (Above 3 min of walltime the workers retire before
    it instead, `uq.engine.cluster`.) About 3 min: run with `pytest -m long tests/cluster`."""
    study = tmp_path / "walltime.toml"
    study.write_text(WALLTIME_STUDY)
    out = tmp_path / "out"
    env = {**os.environ, **on_slurm.env()}
    seen: dict = {"states": {}}

    def watch():
        """Record each worker job's state until the study ends, and the tasks on disk when the first job ends."""
        while not seen.get("done"):
            for job in on_slurm.jobs():
                seen["states"].setdefault(job, "RUNNING")
            for job in seen["states"]:
                text = subprocess.run(["scontrol", "show", "job", job], env=env, capture_output=True, text=True).stdout
                state = text.split("JobState=")[1].split()[0] if "JobState=" in text else seen["states"][job]
                if state == "TIMEOUT" and "finished" not in seen:
                    seen["finished"] = task_times(out)
                seen["states"][job] = state
            time.sleep(0.5)

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    t0 = time.monotonic()
    options = [o if o != "00:10:00" else "00:01:00" for o in CLUSTER]
    options[options.index("--cluster-max-jobs") + 1] = "1"
    assert main(["sobol", str(study), "--out", str(out), *options]) == 0
    seen["done"] = True
    watcher.join(5)
    print(f"\n{WALLTIME_TOTAL} tasks in {time.monotonic() - t0:.0f} s; worker jobs and their states: {seen['states']}; "
          f"{len(seen.get('finished', {}))} tasks finished when the first job timed out")
    assert "TIMEOUT" in seen["states"].values() and len(seen["states"]) >= 2
    after = task_times(out)
    assert 0 < len(seen["finished"]) < WALLTIME_TOTAL == len(after)
    assert all(after[name] == mtime for name, mtime in seen["finished"].items())
    summary = json.loads((out / "study.json").read_text())["summary"]
    assert summary["tasks"] == summary["ran"] == WALLTIME_TOTAL and summary["failed_runs"] == 0
    assert on_slurm.drained()
