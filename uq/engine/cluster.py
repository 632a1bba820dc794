"""Studies on a batch cluster: Dask workers submitted as batch jobs through dask-jobqueue (`--cluster slurm`, or
a ``[cluster]`` table in a study file).

`open_cluster(settings)` starts a dask-jobqueue cluster (`SLURMCluster`; PBS, SGE, LSF, OAR, Moab and HTCondor go
through the same code but are untested here), lets it scale adaptively between zero and ``max_jobs`` batch jobs with
the study's queue of tasks, and yields a `distributed.Client` that the existing runner (`uq.engine.runner.run_tasks`: one
future per task, the model sent once, the cache and ``--resume``) uses like any Dask cluster. On exit the jobs are
cancelled and the cluster closed.

Settings come, lowest first, from Dask's own configuration (``~/.config/dask/jobqueue.yaml``, the
``jobqueue.<kind>`` section), the study file's ``[cluster]`` table and the ``--cluster-*`` options: a value left
unset is not passed, so the next source below fills it.

Failures are one line: an unknown kind, dask-jobqueue not installed (naming the ``cluster`` extra), the submit
command (``sbatch``) not on the PATH, a job the batch system refuses (its own message, from SLURM's dry run
``sbatch --test-only`` before anything runs) are `StudyError`s (exit 2);
no worker connected within ``worker_timeout`` seconds (jobs pending in a closed queue, jobs dying at start) is a
`ClusterUnavailable` (exit 3) naming ``--resume``. A worker whose job dies or reaches its walltime loses only the
tasks in flight, which Dask reruns on the other workers while the adaptive cluster submits a replacement job;
every finished task is already on disk.
"""
from __future__ import annotations

import argparse
import math
import shutil
import threading
import time
from contextlib import contextmanager
from typing import Any, Iterator

from uq.errors import ClusterUnavailable, StudyError
from uq.problem.cluster_settings import (
    DEFAULT_MAX_JOBS,
    DEFAULT_WORKER_TIMEOUT,
    KINDS,
    NO_CLUSTER,
    ClusterSettings,
    check_kind,
    check_walltime,
    walltime_seconds,
)

# ---- the command line ------------------------------------------------------------------------------------------

def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not value > 0 or not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text!r}")
    return value


def _walltime_option(text: str) -> str:
    try:
        return check_walltime(text, "--cluster-walltime")
    except StudyError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--cluster-walltime ")) from None


def add_cluster_arguments(parser: argparse.ArgumentParser) -> None:
    """--cluster KIND and its --cluster-* options (every study command that takes --jobs / --scheduler)."""
    from sim.common.options import positive_int

    group = parser.add_argument_group("batch cluster (dask-jobqueue; options win over [cluster] and jobqueue.yaml)")
    group.add_argument("--cluster", metavar="KIND",
                       help=f"submit Dask workers as batch jobs: {', '.join(KINDS)} (tested: slurm); "
                            f"'{NO_CLUSTER}' ignores the study file's [cluster] table")
    group.add_argument("--cluster-cores", type=positive_int, metavar="N",
                       help="cores per job (one worker process each)")
    group.add_argument("--cluster-memory", metavar="SIZE", help="memory per job, e.g. 4GB")
    group.add_argument("--cluster-walltime", type=_walltime_option, metavar="HH:MM:SS", help="time limit per job")
    group.add_argument("--cluster-queue", metavar="NAME", help="queue (SLURM: partition)")
    group.add_argument("--cluster-account", metavar="NAME", help="account (SGE, LSF: project) charged for the jobs")
    group.add_argument("--cluster-max-jobs", type=positive_int, metavar="N",
                       help=f"most jobs at once; the cluster scales between 0 and N with the tasks waiting "
                            f"(default {DEFAULT_MAX_JOBS})")
    group.add_argument("--cluster-directive", action="append", dest="cluster_directives", metavar="LINE",
                       help="an extra job-script directive, e.g. --cluster-directive=--qos=short (repeatable)")
    group.add_argument("--worker-timeout", type=_positive_seconds, metavar="S",
                       help=f"stop (exit 3; rerun with --resume) when no worker is connected for S seconds while "
                            f"tasks wait (default {DEFAULT_WORKER_TIMEOUT:g})")


def cluster_settings(args: argparse.Namespace, table: ClusterSettings | None) -> ClusterSettings | None:
    """The batch cluster a command runs on: the --cluster-* options over the study file's [cluster] table; None
    when neither asks for one, with --cluster none, or when --scheduler names a running Dask scheduler."""
    kind = getattr(args, "cluster", None)
    options = [getattr(args, name, None) for name in ("cluster_cores", "cluster_memory", "cluster_walltime",
                                                      "cluster_queue", "cluster_account", "cluster_max_jobs",
                                                      "cluster_directives", "worker_timeout")]
    if kind is not None and getattr(args, "scheduler", None):
        raise StudyError("--cluster and --scheduler exclude each other: give one")
    if kind == NO_CLUSTER or getattr(args, "scheduler", None):
        return None
    if kind is not None:
        check_kind(kind)
    elif table is None:
        if any(v is not None for v in options):
            raise StudyError("--cluster-* options need --cluster KIND (e.g. --cluster slurm) or a [cluster] table")
        return None
    given = ClusterSettings(kind or table.kind, *options[:6],
                            None if options[6] is None else tuple(options[6]), options[7])
    return given.over(table) if table is not None and (kind is None or kind == table.kind) else given


# ---- running ---------------------------------------------------------------------------------------------------

def _job_class(kind: str) -> Any:
    check_kind(kind)
    try:
        import dask_jobqueue
    except ImportError:
        raise StudyError(f"--cluster {kind} needs dask-jobqueue: pip install 'ies-workbench[cluster]'") from None
    return getattr(dask_jobqueue, KINDS[kind][0])


def _cluster_kwargs(settings: ClusterSettings) -> dict[str, Any]:
    """dask-jobqueue keywords for the settings that are set; the rest come from jobqueue.yaml or its defaults."""
    import dask

    kind = settings.kind
    config = dask.config.get(f"jobqueue.{kind}", default={}) or {}
    cores = settings.cores or config.get("cores") or 1
    kw: dict[str, Any] = {"cores": cores, "memory": settings.memory or config.get("memory") or f"{2 * cores}GB",
                          "processes": config.get("processes") or cores,  # single-threaded tasks: a process a core
                          "silence_logs": "critical",
                          # the dashboard on a free port unless the configuration names one (no port-in-use warning)
                          "scheduler_options": {"dashboard_address": ":0", **(config.get("scheduler-options") or {})}}
    if kind not in ("htcondor",):
        if settings.walltime is not None:
            kw["walltime"] = settings.walltime
        if settings.queue is not None:
            kw["queue"] = settings.queue
    if settings.account is not None and KINDS[kind][2]:
        kw[KINDS[kind][2]] = settings.account
    if settings.directives is not None:
        kw["job_extra_directives"] = list(settings.directives)
    walltime = kw.get("walltime") or config.get("walltime")
    if walltime and (walltime_seconds(walltime) or 0) > 180:
        # retire a worker before its job's walltime (its tasks move to other workers, none cut off)
        margin = max(60, walltime_seconds(walltime) // 20)
        kw["worker_extra_args"] = [*(config.get("worker-extra-args") or []),
                                   "--lifetime", f"{walltime_seconds(walltime) - margin}s", "--lifetime-stagger", "30s"]
    return kw


#: kind -> the submit command's dry run, which checks a job script against the queues without submitting it
PREFLIGHT = {"slurm": ["sbatch", "--test-only"]}


def _preflight(kind: str, script: str) -> None:
    """Show the worker job script to the batch system's dry run (SLURM: sbatch --test-only); a refusal (unknown
    partition, account, limits) is a StudyError with the scheduler's own first error line. Kinds without a dry run
    (all but SLURM) are not checked here: a refused job then shows as no worker within the worker timeout."""
    import subprocess
    import tempfile

    if kind not in PREFLIGHT:
        return
    with tempfile.NamedTemporaryFile("w", suffix=".sh", prefix="ies-worker-") as fh:
        fh.write(script)
        fh.flush()
        proc = subprocess.run([*PREFLIGHT[kind], fh.name], capture_output=True, text=True)
    if proc.returncode:
        lines = [line.strip() for line in (proc.stderr + proc.stdout).splitlines() if line.strip()]
        first = next((line for line in lines if "error" in line.lower()), lines[0] if lines else "no message")
        raise StudyError(f"the batch system refused the worker job: {first}")


class _Watchdog(threading.Thread):
    """Closes the client (ending the runner's wait) when no worker has been connected for `timeout` seconds."""

    def __init__(self, cluster: Any, client: Any, timeout: float) -> None:
        super().__init__(daemon=True, name="ies-cluster-watchdog")
        self.cluster, self.client, self.timeout = cluster, client, timeout
        self.fired = False
        self._stop = threading.Event()

    def run(self) -> None:
        last_seen = time.monotonic()
        while not self._stop.wait(0.25):
            if self.cluster.scheduler_info.get("workers"):
                last_seen = time.monotonic()
            elif time.monotonic() - last_seen > self.timeout:
                self.fired = True
                try:
                    self.client.close(timeout=5)
                except Exception:  # noqa: BLE001 - the client is being given up either way
                    pass
                return

    def stop(self) -> None:
        self._stop.set()


@contextmanager
def open_cluster(settings: ClusterSettings) -> Iterator[Any]:
    """A dask-jobqueue cluster of `settings.kind` scaling adaptively from 0 to max_jobs jobs, and a Client to it.

    Checks before anything runs: dask-jobqueue importable, the submit command on the PATH, the job script accepted
    by the batch system's dry run (SLURM; else its message, one line). While the study runs, a watchdog stops it
    (ClusterUnavailable, exit 3) when no worker is connected for worker_timeout seconds. On exit every job is
    cancelled."""
    job_class = _job_class(settings.kind)
    submit = KINDS[settings.kind][1]
    if shutil.which(submit) is None:
        raise StudyError(f"--cluster {settings.kind}: `{submit}` is not on the PATH; run on a login node of the "
                         "cluster (or load its batch-system module)")
    from distributed import Client

    max_jobs = settings.max_jobs or DEFAULT_MAX_JOBS
    timeout = settings.worker_timeout or DEFAULT_WORKER_TIMEOUT
    try:
        cluster = job_class(**_cluster_kwargs(settings))
    except ValueError as exc:  # dask-jobqueue's own check of the settings (e.g. a bad memory string)
        raise StudyError(f"--cluster {settings.kind}: {str(exc).splitlines()[0]}") from None
    watchdog = None
    try:
        _preflight(settings.kind, cluster.job_script())
        cluster.adapt(minimum_jobs=0, maximum_jobs=max_jobs, wait_count=10, interval="1s")
        client = Client(cluster)
        watchdog = _Watchdog(cluster, client, timeout)
        watchdog.start()
        try:
            yield client
        except StudyError:
            if watchdog.fired:
                raise ClusterUnavailable(
                    f"no worker of the {settings.kind} cluster was connected for {timeout:g} s (jobs pending or "
                    f"failing: see `squeue`/`qstat` and the jobs' logs); the finished tasks are kept: rerun the same "
                    "command with --resume") from None
            raise
        except Exception as exc:
            if type(exc).__name__ == "KilledWorker":  # a task on which `allowed-failures` workers died in a row
                raise ClusterUnavailable(f"workers kept dying while running one task ({exc}); the finished tasks "
                                         "are kept: check the jobs' memory and walltime, then rerun with "
                                         "--resume") from None
            raise
        finally:
            watchdog.stop()
            try:
                client.close(timeout=10)
            except Exception:  # noqa: BLE001 - closed by the watchdog already, or the scheduler is gone
                pass
    finally:
        try:
            cluster.close(timeout=30)
        except Exception:  # noqa: BLE001 - jobs already gone; nothing more to cancel
            pass
