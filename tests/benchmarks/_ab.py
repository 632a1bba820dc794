"""Same-run A/B timings of one stepped-sine point: worker processes (`_point_worker.py`) on two source trees,
asked in turn, so that every pair of CPU times is measured back to back on the same machine load, and on the same
core: unpinned, a worker that the scheduler keeps on a busier core (a sibling thread shared with another tenant) was
seen 5-30 % slower for a whole run, a bias that the pairing cannot remove."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

WORKER = Path(__file__).with_name("_point_worker.py")


def worker(tree: Path, eta: float, prepare: float | None, *options: str) -> subprocess.Popen:
    """A worker on `tree` at eta (prepared by a down-sweep from `prepare`, or None), ready to answer "run";
    options: INTEGRATOR [R_CONT] of `_point_worker.py`."""
    proc = subprocess.Popen([sys.executable, str(WORKER), str(tree), str(eta), "-" if prepare is None else str(prepare),
                             *options], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    if hasattr(os, "sched_setaffinity"):  # every worker on the same core (Linux)
        os.sched_setaffinity(proc.pid, {min(os.sched_getaffinity(0))})
    assert proc.stdout.readline().strip() == "ready"
    return proc


def pairs(workers: dict[str, subprocess.Popen], repeats: int,
          states: dict[str, str] | None = None) -> dict[str, list[float]]:
    """CPU seconds per point of each worker, `repeats` rounds of one point each, in turn (the first worker first in
    odd rounds, last in even ones); the workers are closed. states: receives each worker's `state` at the end."""
    times: dict[str, list[float]] = {name: [] for name in workers}
    try:
        for round_ in range(repeats):
            order = list(workers.items())
            for name, proc in order if round_ % 2 == 0 else order[::-1]:
                proc.stdin.write("run\n")
                proc.stdin.flush()
                times[name].append(float(proc.stdout.readline()))
        if states is not None:
            states.update({name: state(proc) for name, proc in workers.items()})
    finally:
        for proc in workers.values():
            proc.stdin.close()
            proc.wait()
    return times


def state(proc: subprocess.Popen) -> str:
    """The bytes (hex) of the end state and hold amplitudes of the worker's last point."""
    proc.stdin.write("state\n")
    proc.stdin.flush()
    return proc.stdout.readline().strip()
