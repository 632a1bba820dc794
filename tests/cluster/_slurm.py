"""A single-node SLURM on this machine for tests: controller and node daemon on localhost, configured in a
temporary folder, from Debian's `slurm-wlm` (and `munge` where the version has no `auth/none`).

`LocalSlurm(folder).start()` writes slurm.conf and cgroup.conf, starts the daemons and waits for the node to be
idle; `env()` is what a client (sbatch, scancel, squeue, dask-jobqueue) needs in its environment; `stop()` ends
every daemon it started, by its process id. `start()` raises `SlurmUnavailable` with the reason when the daemons
cannot run here (missing packages, no root, a daemon that exits).
"""
from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

#: where Debian puts the plugins; auth/none (no munge needed) exists up to SLURM 23.02
PLUGIN_DIRS = (Path("/usr/lib/x86_64-linux-gnu/slurm-wlm"), Path("/usr/lib/aarch64-linux-gnu/slurm-wlm"),
               Path("/usr/lib/slurm"), Path("/usr/lib64/slurm"))


class SlurmUnavailable(RuntimeError):
    """The daemons cannot start on this machine; the message says why."""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _has_plugin(name: str) -> bool:
    return any((d / f"{name}.so").is_file() for d in PLUGIN_DIRS)


class LocalSlurm:
    """Controller (slurmctld) and node daemon (slurmd) of a one-node cluster named after this host."""

    def __init__(self, folder: Path, cpus: int | None = None) -> None:
        self.folder = Path(folder)
        self.cpus = cpus or os.cpu_count() or 1
        self.node = socket.gethostname().split(".")[0]
        self.conf = self.folder / "slurm.conf"
        self.pids: list[int] = []

    def env(self) -> dict[str, str]:
        """Environment for the SLURM client commands: this cluster's configuration."""
        return {"SLURM_CONF": str(self.conf)}

    def _auth(self) -> list[str]:
        if _has_plugin("auth_none") and _has_plugin("cred_none"):
            return ["AuthType=auth/none", "CredType=cred/none"]
        if shutil.which("munged") is None:
            raise SlurmUnavailable("this SLURM has no auth/none and munge is not installed (apt-get install munge)")
        key, sock = self.folder / "munge.key", self.folder / "munge.socket"
        key.write_bytes(os.urandom(1024))
        key.chmod(0o400)
        proc = subprocess.run(["munged", "--force", f"--key-file={key}", f"--socket={sock}",
                               f"--pid-file={self.folder / 'munged.pid'}", f"--log-file={self.folder / 'munged.log'}",
                               f"--seed-file={self.folder / 'munged.seed'}"], capture_output=True, text=True)
        if proc.returncode:
            raise SlurmUnavailable(f"munged did not start: {proc.stderr.strip() or proc.stdout.strip()}")
        self._remember("munged.pid")
        return ["AuthType=auth/munge", "CredType=cred/munge", f"AuthInfo=socket={sock}"]

    def _remember(self, pidfile: str, wait: float = 10.0) -> None:
        """Keep the process id a daemon writes to `pidfile` (the file may exist a moment before its content)."""
        path = self.folder / pidfile
        deadline = time.monotonic() + wait
        while time.monotonic() < deadline:
            text = path.read_text().split() if path.is_file() else []
            if text:
                self.pids.append(int(text[0]))
                return
            time.sleep(0.05)
        raise SlurmUnavailable(f"{pidfile} stayed empty for {wait:g} s; the daemon did not start")

    def write_config(self) -> None:
        for sub in ("state", "spool", "logs"):
            (self.folder / sub).mkdir(parents=True, exist_ok=True)
        f = self.folder
        lines = [
            "ClusterName=iestest", f"SlurmctldHost={self.node}(127.0.0.1)",
            f"SlurmctldPort={_free_port()}", f"SlurmdPort={_free_port()}", *self._auth(),
            "SlurmUser=root", "SlurmdUser=root", f"StateSaveLocation={f / 'state'}", f"SlurmdSpoolDir={f / 'spool'}",
            f"SlurmctldPidFile={f / 'slurmctld.pid'}", f"SlurmdPidFile={f / 'slurmd.pid'}",
            f"SlurmctldLogFile={f / 'slurmctld.log'}", f"SlurmdLogFile={f / 'slurmd.log'}",
            "ProctrackType=proctrack/linuxproc", "TaskPlugin=task/none", "SelectType=select/cons_tres",
            "SelectTypeParameters=CR_Core_Memory", "JobAcctGatherType=jobacct_gather/none",
            "AccountingStorageType=accounting_storage/none", "MpiDefault=none", "ReturnToService=2",
            "SchedulerType=sched/backfill", "SchedulerParameters=sched_interval=1", "InactiveLimit=0",
            "MinJobAge=30", "KillWait=2", "OverTimeLimit=0", "MessageTimeout=10",
            f"NodeName={self.node} NodeAddr=127.0.0.1 CPUs={self.cpus} RealMemory=4000 State=UNKNOWN",
            f"PartitionName=debug Nodes={self.node} Default=YES MaxTime=60 State=UP",
            f"PartitionName=closed Nodes={self.node} MaxTime=60 State=DOWN",
        ]
        self.conf.write_text("\n".join(lines) + "\n")
        # read by slurmd only with cgroup plugins; the linuxproc/none plugins above need no cgroup hierarchy
        (f / "cgroup.conf").write_text("CgroupPlugin=autodetect\nIgnoreSystemd=yes\n")

    def start(self, timeout: float = 30.0) -> "LocalSlurm":
        """Write the configuration, start the daemons, wait for the node to be idle (SlurmUnavailable if not)."""
        missing = [cmd for cmd in ("slurmctld", "slurmd", "sbatch", "scancel", "sinfo") if shutil.which(cmd) is None]
        if missing:
            raise SlurmUnavailable(f"SLURM is not installed ({', '.join(missing)} missing; apt-get install slurm-wlm)")
        if os.geteuid() != 0:
            raise SlurmUnavailable("a test SLURM needs root to start slurmd")
        self.write_config()
        env = {**os.environ, **self.env()}
        for daemon, pidfile in (("slurmctld", "slurmctld.pid"), ("slurmd", "slurmd.pid")):
            args = [daemon, "-i"] if daemon == "slurmctld" else [daemon]
            proc = subprocess.run(args, env=env, capture_output=True, text=True)
            if proc.returncode:
                self.stop()
                raise SlurmUnavailable(f"{daemon} did not start: {(proc.stderr or proc.stdout).strip()[:200]}")
            try:
                self._remember(pidfile)
            except SlurmUnavailable:
                self.stop()
                raise
        deadline = time.monotonic() + timeout
        state = ""
        while time.monotonic() < deadline:
            state = subprocess.run(["sinfo", "-h", "-p", "debug", "-o", "%t"], env=env, capture_output=True,
                                   text=True).stdout.strip()
            if state == "idle":
                return self
            time.sleep(0.2)
        log = (self.folder / "slurmd.log").read_text()[-300:] if (self.folder / "slurmd.log").is_file() else ""
        self.stop()
        raise SlurmUnavailable(f"the node did not become idle within {timeout:g} s (state {state!r}); {log}")

    def jobs(self) -> list[str]:
        """Ids of the jobs queued or running."""
        out = subprocess.run(["squeue", "-h", "-o", "%i"], env={**os.environ, **self.env()}, capture_output=True,
                             text=True).stdout
        return out.split()

    def drained(self, timeout: float = 20.0) -> bool:
        """True once no job is queued or running (a cancelled job takes a moment to leave the queue)."""
        deadline = time.monotonic() + timeout
        while self.jobs():
            if time.monotonic() > deadline:
                return False
            time.sleep(0.2)
        return True

    def stop(self) -> None:
        """Cancel every job, then end the daemons this object started (by process id)."""
        if self.conf.is_file():
            subprocess.run(["scancel", "--full", "-u", "root"], env={**os.environ, **self.env()}, capture_output=True)
        for pid in reversed(self.pids):
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                continue
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:
                try:
                    os.kill(pid, 0)
                except ProcessLookupError:
                    break
                time.sleep(0.05)
        self.pids.clear()
