"""The output folder's lock (`sim.common.folder_lock`): re-entrant in one process, taken over from a dead run, and on a
file system without flock decided by the holder's pid and start time on this host. Two real processes racing for a
folder: tests/test_new_user_pass_iv.py."""
from __future__ import annotations

import errno
import json
import socket
import subprocess
import sys

import pytest

from sim.common import folder_lock
from sim.common.errors import SimulationInputError
from sim.common.folder_lock import LOCK_FILE, Holder, holds, lock_folder, locked, unlock_folder


def test_the_lock_is_reentrant_in_one_process_and_its_file_goes_with_the_last_release(tmp_path):
    lock_folder(tmp_path)
    lock_folder(tmp_path)
    data = json.loads((tmp_path / LOCK_FILE).read_text())
    assert data["pid"] == Holder.this_process().pid and data["host"] == socket.gethostname()
    unlock_folder(tmp_path)
    assert holds(tmp_path) and (tmp_path / LOCK_FILE).exists()
    unlock_folder(tmp_path)
    assert not holds(tmp_path) and not (tmp_path / LOCK_FILE).exists()


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_holder_is_alive_while_its_process_runs_with_its_start_time():
    me = Holder.this_process()
    assert me.alive() and me.ticks > 0
    assert not Holder(_dead_pid(), me.host, "ies sweep", me.started).alive()
    assert not Holder(me.pid, me.host, "ies sweep", me.started, ticks=me.ticks + 1).alive()  # a reused pid
    assert Holder(_dead_pid(), "another-host", "ies sweep", me.started).alive()  # cannot be checked from here


def test_without_flock_the_file_names_the_run_and_a_dead_one_is_taken_over(tmp_path, monkeypatch):
    def no_flock(fd, operation):
        raise OSError(errno.ENOLCK, "No locks available")

    monkeypatch.setattr("fcntl.flock", no_flock)
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        ticks = folder_lock._start_ticks(sleeper.pid)
        live = Holder(sleeper.pid, socket.gethostname(), "ies interval s.toml", "2030-01-01 12:00:00", ticks)
        (tmp_path / LOCK_FILE).write_text(json.dumps(live.__dict__))
        with pytest.raises(SimulationInputError, match=f"in use by another run: pid {sleeper.pid} on "):
            lock_folder(tmp_path)
    finally:
        sleeper.kill()
        sleeper.wait()
    with locked(tmp_path):  # its process is gone: taken over
        assert json.loads((tmp_path / LOCK_FILE).read_text())["pid"] == Holder.this_process().pid
    other = Holder(1, "another-host", "ies sobol s.toml", "2030-01-01 12:00:00")
    (tmp_path / LOCK_FILE).write_text(json.dumps(other.__dict__))
    with pytest.raises(SimulationInputError, match=f"if that run is gone, remove {tmp_path / LOCK_FILE}"):
        lock_folder(tmp_path)
