"""Where a study runs: a study file's [cluster] table (and, through `uq.engine.cluster.cluster_settings`, the
--cluster-* options) as `ClusterSettings`, checked with one-line errors; `uq.engine.cluster` opens the cluster.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, fields, replace
from typing import Any, Mapping

from uq.errors import StudyError

#: kind -> (dask-jobqueue class, submit command, keyword the batch system's account/project goes to)
KINDS: dict[str, tuple[str, str, str | None]] = {
    "slurm": ("SLURMCluster", "sbatch", "account"),
    "pbs": ("PBSCluster", "qsub", "account"),
    "sge": ("SGECluster", "qsub", "project"),
    "lsf": ("LSFCluster", "bsub", "project"),
    "oar": ("OARCluster", "oarsub", "project"),
    "moab": ("MoabCluster", "msub", "account"),
    "htcondor": ("HTCondorCluster", "condor_submit", None),
}


#: the kinds tested on a real batch system (tests/cluster: a single-node SLURM)
TESTED_KINDS = ("slurm",)


#: --cluster none: run locally even when the study file has a [cluster] table
NO_CLUSTER = "none"


_WALLTIME = re.compile(r"^(?:(\d+)-)?(?:(\d+):)?(\d+):(\d+)$")


@dataclass(frozen=True)
class ClusterSettings:
    """What a study's batch jobs ask for. None: not set here (Dask's jobqueue.yaml, then dask-jobqueue decide).

    cores: cores per job (one single-threaded worker process each); memory: per job, e.g. "4GB"; walltime:
    "HH:MM:SS" or "D-HH:MM:SS"; queue: the queue / SLURM partition; account: the account (SLURM, PBS) or project
    (SGE, LSF) charged; max_jobs: most jobs at once (adaptive scaling stays at or below it); directives: extra
    lines for the job script's header (e.g. "--qos=short"); worker_timeout: seconds without any connected worker,
    while tasks wait, before the study stops (exit 3, rerun with --resume).
    """

    kind: str = "slurm"
    cores: int | None = None
    memory: str | None = None
    walltime: str | None = None
    queue: str | None = None
    account: str | None = None
    max_jobs: int | None = None
    directives: tuple[str, ...] | None = None
    worker_timeout: float | None = None

    def over(self, below: "ClusterSettings") -> "ClusterSettings":
        """These settings, with every unset value taken from `below` (the explicit ones win)."""
        return replace(below, **{f.name: getattr(self, f.name) for f in fields(self)
                                 if getattr(self, f.name) is not None})


#: defaults where neither the options, the study file nor Dask's configuration set a value
DEFAULT_MAX_JOBS = 4


DEFAULT_WORKER_TIMEOUT = 600.0  # s


def check_kind(kind: str) -> str:
    """`kind` if dask-jobqueue knows it, else a one-line StudyError listing the kinds."""
    if kind not in KINDS:
        raise StudyError(f"unknown cluster kind '{kind}'; known: {', '.join(KINDS)} (tested: "
                         f"{', '.join(TESTED_KINDS)}), or '{NO_CLUSTER}' to run locally")
    return kind


def check_walltime(value: str, where: str) -> str:
    if not isinstance(value, str) or not _WALLTIME.match(value):
        raise StudyError(f"{where} must be a time like \"01:30:00\" (HH:MM:SS) or \"1-00:00:00\", got {value!r}")
    return value


def walltime_seconds(walltime: str) -> int | None:
    """A walltime "D-HH:MM:SS" / "HH:MM:SS" / "MM:SS" in seconds; None when it has another form."""
    match = _WALLTIME.match(str(walltime))
    if match is None:
        return None
    days, hours, minutes, seconds = (int(g or 0) for g in match.groups())
    return ((days * 24 + hours) * 60 + minutes) * 60 + seconds


def parse_cluster_table(table: Mapping[str, Any]) -> ClusterSettings:
    """A study file's [cluster] table (keys: kind, cores, memory, walltime, queue, account, max_jobs, directives,
    worker_timeout) as settings; a wrong key or value is a one-line StudyError naming it."""
    known = {f.name for f in fields(ClusterSettings)}
    for key in table:
        if key not in known:
            raise StudyError(f"unknown key '{key}' in [cluster]; known: {', '.join(sorted(known))}")
    values: dict[str, Any] = {"kind": table.get("kind", "slurm")}
    if not isinstance(values["kind"], str):
        raise StudyError(f"[cluster] kind must be a string, got {values['kind']!r}")
    check_kind(values["kind"])
    for key in ("cores", "max_jobs"):
        if key in table:
            v = table[key]
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise StudyError(f"[cluster] {key} must be a positive integer, got {v!r}")
            values[key] = v
    for key in ("memory", "queue", "account"):
        if key in table:
            if not isinstance(table[key], str) or not table[key]:
                raise StudyError(f"[cluster] {key} must be a non-empty string, got {table[key]!r}")
            values[key] = table[key]
    if "walltime" in table:
        values["walltime"] = check_walltime(table["walltime"], "[cluster] walltime")
    if "directives" in table:
        d = table["directives"]
        if not isinstance(d, list) or not all(isinstance(x, str) for x in d):
            raise StudyError(f"[cluster] directives must be a list of strings, e.g. [\"--qos=short\"], got {d!r}")
        values["directives"] = tuple(d)
    if "worker_timeout" in table:
        v = table["worker_timeout"]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0:
            raise StudyError(f"[cluster] worker_timeout must be a positive number of seconds, got {v!r}")
        values["worker_timeout"] = float(v)
    return ClusterSettings(**values)
