"""Running study tasks with joblib (local processes) or a Dask cluster, with an on-disk result store.

A task is one model evaluation: (parameter values, excitation level, repetition). Its key is the
SHA-256 of the task, the model's settings, the study seed and the model's code version, so a stored
result is reused only for exactly the same computation. Every result is written to its own JSON file
(atomically) by the controlling process as soon as it arrives; an interrupted study therefore keeps
every finished task, and `--resume` runs only the missing ones.

Determinism: a task's random stream depends only on (seed, rep) (sim.stepped_sine.protocol contract), results are
stored as JSON floats (exact round trip), and they are collected by key, never by arrival order: the
same study gives identical numbers serially, with `--jobs N` and on Dask.
"""
from __future__ import annotations

import functools
import hashlib
import io
import json
import logging
import math
import os
import signal
import sys
import time
from contextlib import contextmanager
from dataclasses import asdict, is_dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Mapping, Sequence

from sim.common.files import write_text
from sim.common.folder_lock import lock_folder, unlock_folder
from uq.errors import StudyError
from uq.problem.tasks import Task


def describe_model(model: Any) -> Any:
    """The model's settings as plain data (part of every task key)."""
    if hasattr(model, "describe"):
        return model.describe()
    if is_dataclass(model):
        return {"class": type(model).__name__, **{k: v for k, v in asdict(model).items()}}
    return repr(model)


def _keyer(model: Any, seed: int, version: str) -> Callable[[Task], str]:
    """Key function with the study-wide part (model settings, seed, version) hashed once."""
    common = hashlib.sha256(json.dumps({"seed": seed, "model": describe_model(model), "version": version},
                                       sort_keys=True, default=str).encode())

    def key(task: Task) -> str:
        digest = common.copy()
        digest.update(json.dumps([task.params, task.level, task.rep]).encode())
        return digest.hexdigest()

    return key


class ResultStore:
    """One JSON file per finished task under ``folder/tasks``; writes are atomic."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder) / "tasks"

    def _path(self, key: str) -> Path:
        return self.folder / f"{key}.json"

    def has(self, key: str) -> bool:
        return self._path(key).is_file()

    def count(self) -> int:
        return sum(1 for _ in self.folder.glob("*.json")) if self.folder.is_dir() else 0

    def save(self, key: str, task: Task, result: Mapping[str, Any]) -> None:
        record = {"key": key, "params": dict(task.params), "level": task.level, "rep": task.rep, **result}
        write_text(self._path(key), json.dumps(record, sort_keys=True, allow_nan=True))

    def load(self, key: str) -> dict:
        return json.loads(self._path(key).read_text())

    def read(self, key: str) -> dict | None:
        """The stored record of `key`; None when there is none, or when its file is damaged (cut short, not a task's
        JSON, another task's record: a disk that filled up, a copy cut off), which is then removed so that the task
        runs again (`run_tasks` says so)."""
        path = self._path(key)
        try:
            record = json.loads(path.read_bytes())
        except FileNotFoundError:
            return None
        except (OSError, ValueError):  # json.JSONDecodeError and UnicodeDecodeError are ValueErrors
            record = None
        if isinstance(record, dict) and record.get("key") == key and {"outputs", "error"} <= set(record):
            return record
        path.unlink(missing_ok=True)
        return None


def check_writable(folder: str | Path) -> Path:
    """Create `folder` (and parents) and prove a file can be written in it, else a one-line StudyError."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".probe-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise StudyError(f"cannot write to output folder {folder} ({reason}); choose another --out") from None
    return folder


#: the file in OUT/tasks naming the study whose tasks the folder holds: its name, then its key
STUDY_MARK = "STUDY.txt"


def prepare_output(folder: str | Path, *, resume: bool, study: tuple[str, str] | None = None) -> Path:
    """Create the output folder, check it can be written and take its lock (`sim.common.folder_lock`: a second run
    into a folder in use is refused with one line naming the other run; `release_output` gives it back when the
    run's last file is written); refuse to overwrite finished results, and refuse `resume` into a folder that holds
    the tasks of another study. `study`: (name, key) of the study to run (`uq.engine.execution.study_key`), kept in
    OUT/tasks/STUDY.txt."""
    folder = Path(folder)
    store = ResultStore(folder)
    check_writable(store.folder)
    lock_folder(folder)  # before the folder's tasks are looked at: another run may be adding to them
    try:
        if not resume and store.count():
            raise StudyError(f"output folder {folder} already holds task results; pass --resume to continue that study "
                             "or choose another --out")
        mark = store.folder / STUDY_MARK
        if resume and study is not None and mark.is_file():
            name, key = (mark.read_text().splitlines() + ["", ""])[:2]
            if key != study[1] and store.count():
                raise StudyError(f"output folder {folder} holds the tasks of another study ('{name}', key {key[:12]}), "
                                 f"not of '{study[0]}' (key {study[1][:12]}); --resume continues only the same study: "
                                 "choose another --out")
        if study is not None:
            write_text(mark, f"{study[0]}\n{study[1]}\n")
        for stale in store.folder.glob(".*.json"):  # a temporary file of a write cut off by SIGKILL
            stale.unlink(missing_ok=True)
    except BaseException:
        unlock_folder(folder)
        raise
    return folder


def release_output(folder: str | Path) -> None:
    """Give back the lock `prepare_output` took on `folder` (nothing if this process holds none)."""
    unlock_folder(folder)


def evaluate(model: Callable, task: Task, seed: int) -> dict:
    """Run one task; a diverged simulation or non-finite output is recorded as a failed run."""
    from sim.common.errors import SimulationDiverged

    start = time.perf_counter()
    try:
        outputs = dict(model(dict(task.params), task.level, task.rep, seed))
        trace = outputs.pop("trace", None)
        error = ""
        bad = [k for k, v in outputs.items() if not math.isfinite(v) and k in getattr(model, "banded_outputs", ())]
        if bad:
            error = f"non-finite output(s) {', '.join(bad)}"
    except (SimulationDiverged, FloatingPointError, ZeroDivisionError) as exc:
        outputs, trace = {name: float("nan") for name in getattr(model, "outputs", ())}, None
        error = f"{type(exc).__name__}: {exc}"
    record = {"outputs": outputs, "error": error, "seconds": time.perf_counter() - start}
    if trace is not None:
        record["trace"] = trace
    return record


def _same(value: Any) -> Any:
    return value


def _run_one(model: Callable, key: str, task: Task, seed: int) -> tuple[str, dict]:
    return key, evaluate(model, task, seed)


@contextmanager
def dask_client(scheduler: str | None, client: Any = None) -> Iterator[Any]:
    """The Dask client of a study, connected once for all its tasks: `client` as given, else a connection to
    `scheduler` (an unreachable address is a one-line StudyError; closed on exit), else None (local).
    While it is open, the distributed library's own log lines stay quiet: a lost scheduler is reported once,
    by `run_tasks`."""
    if client is not None or scheduler is None:
        yield client
        return
    own = _connect(scheduler)
    logging.disable(logging.ERROR)  # distributed logs (with tracebacks) every failed reconnection attempt
    try:
        yield own
    finally:
        try:
            own.close(timeout=5)
        except (OSError, TimeoutError):  # a lost scheduler cannot be told goodbye
            pass
        finally:
            logging.disable(logging.NOTSET)


def _connect(address: str):
    """A distributed.Client for `address`, or a one-line StudyError when it cannot be reached."""
    try:
        from distributed import Client
    except ImportError:
        raise StudyError("--scheduler needs dask.distributed: pip install 'ies-workbench[cluster]'") from None
    try:
        return Client(address, timeout="5s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise StudyError(f"cannot reach the Dask scheduler at {address} ({type(exc).__name__}); "
                         "check the address (e.g. tcp://HOST:8786) and that the scheduler is running") from None


#: what starting local worker processes costs (s): on C cores they win when the serial work exceeds this x C / (C - 1).
#: Measured on the 2-core development machine shared with other work (a response study of 2-128 runs, --jobs 1
#: against 2): below about 20 s of serial work --jobs 2 took 8-12 s longer; at 63 runs (about 75 s serial) it
#: took 62 s against 73 s; at 127 runs the two were within the load's noise (81 and 94 s). The break-even lies near
#: 60 s of serial work, hence 30 s.
PARALLEL_OVERHEAD_S = 30.0


def choose_jobs(jobs: int | None, work_s: float, cores: int | None = None, stream: Any = None) -> int:
    """Worker processes for `work_s` seconds of remaining serial work: `jobs` as given (a warning line on `stream`,
    stderr, when it exceeds the cores: the runs then compete for them), or with None one per core when the work
    outweighs the workers' start (PARALLEL_OVERHEAD_S), else 1 (in this process)."""
    cores = cores or os.cpu_count() or 1
    stream = stream or sys.stderr
    if jobs is not None:
        if jobs > cores:
            stream.write(f"warning: --jobs {jobs} is more than the {cores} CPU core(s): the runs compete for them and "
                         f"take longer, not less; use --jobs {cores} or leave it out\n")
        return jobs
    if cores == 1:
        return 1
    return cores if work_s > PARALLEL_OVERHEAD_S * cores / (cores - 1) else 1


#: what a study's cost estimate or refusal suggests (`check_cost`)
LESS_WORK = "ask for fewer levels, repetitions or points, a shorter wait or hold, or run it on a cluster (--cluster)"


def pending_tasks(model: Any, tasks: Sequence[Task], seed: int, folder: str | Path) -> list[Task]:
    """The tasks of `tasks` (each once) whose result is not stored in `folder`'s task store (`ResultStore`)."""
    keyer = _keyer(model, seed, model.version())
    store = ResultStore(folder)
    return list({keyer(task): task for task in tasks if not store.has(keyer(task))}.values())


def workers_for(jobs: int | None, serial_s: float, client: Any = None) -> int:
    """The processes that will share work of `serial_s` seconds: the Dask cluster's threads, --jobs, or
    `choose_jobs`'s choice."""
    if client is not None:
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:  # noqa: BLE001 - a cluster that cannot say (yet): counted as one
            return 1
    if jobs is not None:
        return jobs
    return choose_jobs(None, serial_s, stream=io.StringIO())


def check_cost(model: Any, tasks: Sequence[Task], *, jobs: int | None = None, client: Any = None,
               allow_large: bool = False, quiet: bool = False) -> Any:
    """The cost estimate of `tasks` before the first runs (`sim.stepped_sine.cost`: runs x the seconds of one run,
    measured here by a probe of the model's protocol at their levels, on the workers that will run them): said in one
    line when long (with `quiet` only above half an hour), refused (one line naming the estimate and --allow-large)
    above an hour. None for a model that
    cannot be probed (no `seconds_per_run`: the first run is timed instead) or work too small to be worth it."""
    from collections import Counter

    from sim.stepped_sine.cost import check_estimate, estimate

    if not tasks or not hasattr(model, "seconds_per_run"):
        return None
    runs_at = Counter(task.level for task in tasks)
    per_run = model.seconds_per_run(list(runs_at), len(tasks))
    if per_run is None:
        return None
    serial = estimate(runs_at, per_run).serial_s
    work = estimate(runs_at, per_run, workers=workers_for(jobs, serial, client))
    check_estimate(work, LESS_WORK, allow_large=allow_large, quiet=quiet)
    return work


def run_tasks(model: Callable, tasks: Sequence[Task], seed: int, store: ResultStore, *, jobs: int | None = 1,
              scheduler: str | None = None, progress: bool = True, client: Any = None,
              expected_s: float | None = None) -> tuple[dict[Task, dict], int]:
    """Run every task whose result is not in `store` (or whose stored file is damaged: removed and run again, said
    in one warning line, `ResultStore.read`); return all results by task and how many ran now.

    jobs: local worker processes (joblib/loky; 1 = in this process; None: `choose_jobs` after timing the first task
    in this process). expected_s: the seconds of one run estimated before (`check_cost`); the first run's time says
    what the rest will take where there was no estimate, or where it is far off (`sim.stepped_sine.cost.first_run_line`).
    scheduler: a Dask scheduler address (`client` may be passed instead, e.g. in tests): every task is submitted
    to the cluster, whatever its size. Each result is saved as it arrives, so an interruption (Ctrl-C, a killed
    process, a lost scheduler) loses only the tasks in flight; a lost scheduler is one StudyError line that names
    `--resume`.
    """
    from sim.common.progress import progress as report

    if jobs is not None and jobs < 1:
        raise StudyError(f"--jobs must be >= 1, got {jobs}")
    version = model.version()
    keyer = _keyer(model, seed, version)
    keys = {task: keyer(task) for task in tasks}
    records: dict[str, dict] = {}
    unique: dict[str, Task] = {}
    damaged = []
    for task, key in keys.items():
        if key in unique or key in records:
            continue
        present = store.has(key)
        record = store.read(key) if present else None
        if record is None:
            unique[key] = task
            if present:
                damaged.append(key)
        else:
            records[key] = record
    if damaged:
        sys.stderr.write(f"warning: {len(damaged)} stored task file(s) in {store.folder} were damaged (cut short or not "
                         f"a task's record, e.g. {damaged[0]}.json) and were removed; they run again\n")
    pending = list(unique.items())
    total = len(set(keys.values()))
    bar = report(total, "tasks", "run", initial=total - len(pending), enabled=progress)
    try:
        if scheduler is not None and client is None:
            with dask_client(scheduler) as own:
                _run_and_store(model, pending, seed, jobs, own, store, bar, total, expected_s=expected_s)
        else:
            _run_and_store(model, pending, seed, jobs, client, store, bar, total, expected_s=expected_s)
    finally:
        bar.close()
    records.update((key, store.load(key)) for key, _ in pending)
    return {task: records[key] for task, key in keys.items()}, len(pending)


def _run_and_store(model: Callable, pending: list[tuple[str, Task]], seed: int, jobs: int | None, client: Any,
                   store: ResultStore, bar: Any, total: int, *, expected_s: float | None) -> None:
    """Save each result as it arrives; a lost Dask scheduler becomes one StudyError line."""
    from sim.stepped_sine.cost import first_run_line

    done = total - len(pending)
    if client is None and pending:  # locally the first task runs here: its time sizes the rest
        key, task = pending[0]
        started = time.perf_counter()
        store.save(key, task, evaluate(model, task, seed))
        done += 1
        bar.update(1)
        pending = pending[1:]
        per_run = time.perf_counter() - started
        jobs = choose_jobs(jobs, len(pending) * per_run) if pending else 1
        line = first_run_line(len(pending), per_run, expected_s, jobs)
        if line:
            bar.write(f"{line}; interrupt with Ctrl-C and rerun with --resume to go on", file=sys.stderr)
    try:
        for key, task, result in _dispatch(model, pending, seed, jobs, client):
            store.save(key, task, result)
            done += 1
            bar.update(1)
    except Exception as exc:
        if client is None or client.status == "running":
            raise
        address = getattr(client.scheduler, "address", "") or "the scheduler"
        raise StudyError(f"lost the Dask scheduler {address} after {done} of {total} tasks ({type(exc).__name__}); "
                         f"the finished tasks are kept in {store.folder}: start the scheduler (and workers) again "
                         "and rerun the same command with --resume") from None


def _start_workers_deaf_to_ctrl_c() -> None:
    """Have loky (joblib's local processes) start its workers with SIGINT blocked, as loky starts its own resource
    tracker: the signal mask survives fork and exec, so a Ctrl-C in the terminal reaches only this process, which
    stops the pool (its workers end by SIGTERM) and prints one line (`uq.cli`). Without it every worker that is still
    importing when Ctrl-C comes prints its own traceback (13 of them, 220 lines, with --jobs 99 on 2 cores).
    Installed once per process around loky's one call that starts a worker (`fork_exec`, right at the spawn: the
    standard library's resource tracker unblocks SIGINT on its way there); where it or `pthread_sigmask` is missing,
    nothing changes."""
    try:
        from joblib.externals.loky.backend import fork_exec as module
    except ImportError:
        return
    spawn = getattr(module, "fork_exec", None)
    if spawn is None or getattr(spawn, "sigint_blocked", False) or not hasattr(signal, "pthread_sigmask"):
        return

    @functools.wraps(spawn)
    def spawn_deaf(*args: Any, **kwargs: Any) -> Any:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            return spawn(*args, **kwargs)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)  # a Ctrl-C meanwhile is delivered here, now

    spawn_deaf.sigint_blocked = True
    module.fork_exec = spawn_deaf


def _dispatch(model: Callable, pending: list[tuple[str, Task]], seed: int, jobs: int,
              client: Any) -> Iterable[tuple[str, Task, dict]]:
    """(key, task, result) of every pending task as it finishes: in this process (jobs 1, no client), in `jobs`
    local processes (joblib/loky) or on a Dask cluster (`client`: one future per task, the model sent once)."""
    if not pending:
        return
    by_key = {k: t for k, t in pending}
    if client is not None:
        from distributed import as_completed

        # the model is sent once, as the result of a task rather than scattered data: when the workers holding it
        # die (a batch job cancelled or out of walltime) the scheduler recomputes it, while scattered data is lost
        remote_model = client.submit(_same, model, pure=False)
        keys, tasks = zip(*pending)
        # one graph update for all tasks (client.map) rather than one message per task
        waiting = set(client.map(_run_one, [remote_model] * len(keys), keys, tasks, [seed] * len(keys), pure=False))
        try:
            for future in as_completed(list(waiting)):
                key, result = future.result()
                # forget a finished task at once: a result the client still holds lives on a worker, and when that
                # worker's job ends the scheduler recomputes it (every finished task, again and again at each
                # walltime); the result is on disk from here on
                waiting.discard(future)
                future.release()
                yield key, by_key[key], result
        finally:
            if client.status == "running" and waiting:
                client.cancel(list(waiting))
        return
    if jobs == 1:
        for key, task in pending:
            yield key, task, evaluate(model, task, seed)
        return
    from joblib import Parallel, delayed

    _start_workers_deaf_to_ctrl_c()
    calls = (delayed(_run_one)(model, key, task, seed) for key, task in pending)
    for key, result in Parallel(n_jobs=jobs, return_as="generator_unordered", batch_size=1)(calls):
        yield key, by_key[key], result
