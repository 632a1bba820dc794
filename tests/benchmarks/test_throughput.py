"""Throughput of a study's runs through each engine of the runner (issue 26, item 4): bare runs in this process
(`uq.engine.runner.evaluate` in a loop), joblib with 1 and 2 workers, local Dask processes (2 workers) and the SLURM path
(`uq.engine.cluster.open_cluster` on the test SLURM of tests/cluster, 2 one-core jobs).

Per engine: runs per core-second, the CPU time per task (this process and every worker process, from psutil)
and its overhead against the bare runs, the engine's idle background CPU over the same wall time (Dask's
heartbeats and monitors: charged to the tasks when other work on a shared machine stretches the wall time), the
overhead net of it ("net"), and the wall speed-up over the bare runs.
Targets: <= 5 % net CPU overhead per task on local Dask; a wall speed-up >= 1.8 with 2 workers on 2 cores. The machine
may be shared: the CPU overhead is asserted always; the speed-up only when the 1-minute load average before the
run is below 0.5 (else printed with the load). Each engine is warmed up first (worker start, numba's cache
loaded) on other tasks, so the figures are of a running study. Run:
`pytest -m benchmark tests/benchmarks/test_throughput.py -s`.

Each engine runs the same three sets of tasks; the table gives the medians over the three (the shared machine moves
a single set by several per cent). Latest figures: in `tests/benchmarks/README.md`.
"""
import os
import statistics
import time
from types import SimpleNamespace
from pathlib import Path

import psutil
import pytest

from uq.engine.runner import ResultStore, Task, evaluate, prepare_output, run_tasks
from uq.methods import study_from as parse_study

ROOT = Path(__file__).resolve().parents[2]
N_TASKS = 24
N_WARM = 8
REPEATS = 3
#: a small real study: the simulator on a short protocol (about 0.3 CPU s a run; the shipped Sobol' study's runs
#: take about 1 s), long enough that a few ms of bookkeeping per task is a per-cent

STUDY = {"study": {"kind": "sobol", "seed": 3, "repetitions": 1},
         "excitation": {"levels": [6.0, 7.4, 8.0], "eta": {"start": 0.97, "stop": 0.99, "n": 4}, "wait": 0.5,
                        "hold": 1.5, "sequence": "up", "integrator": "ode3"}}
TARGET_OVERHEAD = 0.05
TARGET_SPEEDUP = 1.8


def _load() -> float:
    return os.getloadavg()[0]


def _tasks(study, offset: int, n: int = N_TASKS) -> list[Task]:
    """n distinct tasks (D varied); `offset` keeps warm-up tasks apart from measured ones."""
    space = study.space
    lo, hi = space["D"].min, space["D"].max
    points = [{**space.nominal(), "D": lo + (hi - lo) * (i + offset * N_TASKS) / ((REPEATS + 2) * N_TASKS)}
              for i in range(n)]
    return [Task.make(p, study.levels[i % len(study.levels)], 0) for i, p in enumerate(points)]


def _cpu(pids: list[int]) -> float:
    total = 0.0
    for pid in pids:
        try:
            t = psutil.Process(pid).cpu_times()
            total += t.user + t.system
        except psutil.NoSuchProcess:
            pass
    return total


class Meter:
    """CPU seconds of this process and of `worker_pids()` (sampled before and after), and wall seconds."""

    def __init__(self, worker_pids):
        self.worker_pids = worker_pids

    def __enter__(self):
        self.pids = self.worker_pids()
        self.cpu0, self.wall0, self.load = time.process_time() + _cpu(self.pids), time.perf_counter(), _load()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.wall0
        self.cpu = time.process_time() + _cpu(self.pids) - self.cpu0
        # the engine's background (heartbeats, monitors) over the same wall time, idle: charged to the tasks when
        # other work on a shared machine stretches the wall time
        start = time.process_time() + _cpu(self.pids)
        time.sleep(self.wall if self.pids else 0.0)
        self.idle = time.process_time() + _cpu(self.pids) - start if self.pids else 0.0


def _net(m: Meter, bare_cpu: float) -> float:
    """CPU overhead per task against the bare runs, less the engine's idle background over the same wall time."""
    return (m.cpu - m.idle) / N_TASKS / bare_cpu - 1


def _children() -> list[int]:
    return [p.pid for p in psutil.Process().children(recursive=True)]


@pytest.fixture(scope="module")
def model_and_study():
    study = parse_study(STUDY)
    model = study.make_model().with_rig()
    model.warm_up()
    return model, study


@pytest.mark.benchmark
def test_throughput_of_each_engine(model_and_study, tmp_path, monkeypatch, capsys):
    model, study = model_and_study
    rows = {}

    def measure(name, run, pids=_children, cores=1):
        run(_tasks(study, 1, N_WARM), tmp_path / f"{name}-warm")  # warm-up: workers started, kernels loaded
        meters = []
        for repeat in range(REPEATS):
            with Meter(pids) as m:
                run(_tasks(study, 2 + repeat), tmp_path / f"{name}-{repeat}")
            meters.append(m)
        rows[name] = (SimpleNamespace(**{field: statistics.median(getattr(m, field) for m in meters)
                                         for field in ("cpu", "idle", "wall", "load")}), cores)

    def bare(tasks, folder):
        for task in tasks:
            evaluate(model, task, study.seed)

    def engine(jobs=1, client=None):
        def run(tasks, folder):
            store = ResultStore(prepare_output(folder, resume=False))
            run_tasks(model, tasks, study.seed, store, jobs=jobs, client=client, progress=False)
        return run

    measure("bare", bare, pids=list)
    measure("joblib, 1 worker", engine(1), pids=list)
    measure("joblib, 2 workers", engine(2), cores=2)
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            distributed.Client(lc) as client:
        measure("Dask local, 2 processes", engine(client=client),
                pids=lambda: list(client.run(os.getpid).values()), cores=2)
    slurm_note = _slurm_row(measure, engine, tmp_path, monkeypatch)

    bare_cpu = rows["bare"][0].cpu / N_TASKS
    bare_wall = rows["bare"][0].wall
    lines = [f"{N_TASKS} runs of {bare_cpu:.3f} CPU s each (bare); 2 cores; medians of {REPEATS} sets",
             (f"{'engine':26s} {'runs/core-s':>11s} {'CPU s/task':>10s} {'overhead':>8s} {'idle CPU':>8s} "
              f"{'net':>7s} {'wall s':>7s} {'speed-up':>8s} {'load':>5s}")]
    for name, (m, cores) in rows.items():
        lines.append(f"{name:26s} {N_TASKS / (m.wall * cores):11.2f} {m.cpu / N_TASKS:10.4f} "
                     f"{m.cpu / N_TASKS / bare_cpu - 1:+8.1%} {m.idle:8.2f} {_net(m, bare_cpu):+7.1%} {m.wall:7.2f} "
                     f"{bare_wall / m.wall:8.2f} {m.load:5.2f}")
    with capsys.disabled():
        print("\n" + "\n".join(lines) + (f"\n{slurm_note}" if slurm_note else ""))
    assert _net(rows["Dask local, 2 processes"][0], bare_cpu) <= TARGET_OVERHEAD
    for name in ("joblib, 2 workers", "Dask local, 2 processes"):
        m = rows[name][0]
        if m.load < 0.5:
            assert bare_wall / m.wall >= TARGET_SPEEDUP, name


def _slurm_row(measure, engine, tmp_path, monkeypatch) -> str:
    """The SLURM path's row (2 one-core jobs), or why there is none."""
    try:
        import dask

        from tests.cluster._slurm import LocalSlurm, SlurmUnavailable
        from uq.engine.cluster import open_cluster
        from uq.problem.cluster_settings import ClusterSettings
    except ImportError as exc:
        return f"SLURM path not measured: {exc}"
    try:
        slurm = LocalSlurm(tmp_path / "slurm").start()
    except SlurmUnavailable as exc:
        return f"SLURM path not measured: {exc}"
    try:
        monkeypatch.setenv("SLURM_CONF", slurm.env()["SLURM_CONF"])
        monkeypatch.setenv("PYTHONPATH", str(ROOT))
        (tmp_path / "logs").mkdir()
        settings = ClusterSettings("slurm", cores=1, memory="1GB", walltime="00:10:00", max_jobs=2, worker_timeout=120)
        with dask.config.set({"jobqueue.slurm.log-directory": str(tmp_path / "logs")}), \
                open_cluster(settings) as client:
            client.cluster.adapt(minimum_jobs=2, maximum_jobs=2)  # two jobs throughout, idle phases included

            def both_workers() -> list[int]:
                client.wait_for_workers(2, timeout=120)
                return list(client.run(os.getpid).values())

            measure("SLURM, 2 one-core jobs", engine(client=client), pids=both_workers, cores=2)
    finally:
        slurm.stop()
    return ""
