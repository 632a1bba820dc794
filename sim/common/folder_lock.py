"""One run per output folder: the lock file OUT/.ies-lock, held by the run that writes into OUT.

A run takes the lock before it looks at what the folder holds and keeps it until its last file is written; a second
run into the same folder is refused with one line naming the first (pid, host, command, start time), whatever it
says (--force, --resume). Two runs into one folder would otherwise both run every task, or race for the same files.

The lock is an advisory lock on the file (``fcntl.flock``), which the system drops when its process ends, however it
ends. A run that died (killed, out of memory, a power cut) leaves the file but not the lock: the next run takes it over
at once, so ``--resume`` continues a finished or dead run and never waits for anything. Where the file system has no
flock (some network file systems) the file's content decides: its run is alive when it ran on this host and a process
with its pid and start time still runs (`Holder.alive`); a run of another host cannot be checked from here, and the
line says how to remove its file.

Within one process the lock is re-entrant (a study of sub-studies, `ies reproduce` and its figures' studies).
"""
from __future__ import annotations

import errno
import json
import os
import socket
import sys
import time
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Iterator

from sim.common.errors import SimulationInputError

#: the lock file in an output folder
LOCK_FILE = ".ies-lock"
#: held locks of this process: folder (absolute) -> [file descriptor, holds]
_HELD: dict[Path, list[int]] = {}
#: errors of a file system without flock
_NO_FLOCK = (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL)


@dataclass(frozen=True)
class Holder:
    """The run that holds a folder: its pid, host, command line, start time (local, ISO) and its process's start
    time in clock ticks since boot (Linux /proc; 0 elsewhere), which tells it from a later process with its pid."""

    pid: int
    host: str
    command: str
    started: str
    ticks: int = 0

    @staticmethod
    def this_process() -> "Holder":
        name = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python"
        return Holder(os.getpid(), socket.gethostname(), " ".join([name, *sys.argv[1:]]),
                      time.strftime("%Y-%m-%d %H:%M:%S"), _start_ticks(os.getpid()))

    def alive(self) -> bool:
        """Whether this run may still be going: on this host, a process with its pid (and, where known, its start
        time); on another host, always (it cannot be checked from here)."""
        if self.host != socket.gethostname():
            return True
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:  # another user's process
            pass
        return not self.ticks or _start_ticks(self.pid) in (0, self.ticks)

    def text(self) -> str:
        return f"pid {self.pid} on {self.host}, `{self.command}`, started {self.started}"


def _start_ticks(pid: int) -> int:
    """The start time of process `pid` in clock ticks since boot (field 22 of /proc/PID/stat), 0 where unknown."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        return int(stat.rsplit(")", 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return 0


def _read(fd: int) -> Holder | None:
    try:
        data = json.loads(os.pread(fd, 65536, 0).decode("utf-8"))
        return Holder(**data)
    except (OSError, ValueError, TypeError):
        return None


def _refusal(what: str, path: Path, holder: Holder | None) -> SimulationInputError:
    if holder is None:
        return SimulationInputError(f"{what} is in use by another run (its lock {path} names none); wait for it to end "
                                    "or choose another --out")
    gone = "" if holder.host == socket.gethostname() else f" (if that run is gone, remove {path})"
    return SimulationInputError(f"{what} is in use by another run: {holder.text()}; wait for it to end or choose "
                                f"another --out{gone}")


def lock_folder(folder: str | os.PathLike, what: str = "") -> None:
    """Take the lock of the output folder `folder` (which must exist) for this process, or refuse with one line
    (SimulationInputError) naming the run that holds it; `what` names the folder in that line (default "--out
    FOLDER"). Re-entrant: every `lock_folder` needs its `unlock_folder`."""
    import fcntl

    key = Path(folder).absolute()
    what = what or f"--out {folder}"
    if key in _HELD:
        _HELD[key][1] += 1
        return
    path = key / LOCK_FILE
    for _ in range(5):  # a run that ended between our open and our lock removed the file we hold: open it again
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _read(fd)
            os.close(fd)
            raise _refusal(what, path, holder) from None
        except OSError as exc:
            if exc.errno not in _NO_FLOCK:
                os.close(fd)
                raise
            holder = _read(fd)  # no flock here: the file's content decides
            if holder is not None and holder.pid != os.getpid() and holder.alive():
                os.close(fd)
                raise _refusal(what, path, holder) from None
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps(asdict(Holder.this_process())).encode("utf-8"), 0)
            _HELD[key] = [fd, 1]
            return
        os.close(fd)
    raise _refusal(what, path, None)


def unlock_folder(folder: str | os.PathLike) -> None:
    """Give back a lock `lock_folder` took; the last one removes the lock file."""
    key = Path(folder).absolute()
    held = _HELD.get(key)
    if held is None:
        return
    held[1] -= 1
    if held[1] > 0:
        return
    del _HELD[key]
    try:
        (key / LOCK_FILE).unlink(missing_ok=True)  # removed while held: a run waiting on it opens a new file
    finally:
        os.close(held[0])


def holds(folder: str | os.PathLike) -> bool:
    """Whether this process holds the lock of `folder`."""
    return Path(folder).absolute() in _HELD


@contextmanager
def locked(folder: str | os.PathLike, what: str = "") -> Iterator[None]:
    """The lock of `folder` for the block (`lock_folder`, `unlock_folder`)."""
    lock_folder(folder, what)
    try:
        yield
    finally:
        unlock_folder(folder)
