"""What a simulation will cost before it starts: a one-line estimate, a warning when it is long, and a refusal
when its arrays cannot fit in memory (`ies sweep`, `ies overview`, `ies trace`).

The estimate is runs x simulated time per run (the stepped-sine protocol of Sect. 5.1: lead-in, and per point its
wait and hold) x the measured cost of one simulated second. That cost is measured in this process, after the
kernels are loaded, by a probe of PROBE_PERIODS excitation periods of the system itself at the middle of the eta
grid, the sphere started as the protocol starts it (`sim.stepped_sine.protocol.visit_points`). On the seed rig
with the exact integrator it ranges from 0.002 to 0.07 s per simulated second with the regime (measured on the
2-core development machine), so the estimate is good to a factor of a few: enough to tell seconds from hours.
"""
from __future__ import annotations

import math
import os
import sys
import time
from typing import TextIO

import numpy as np

from sim.common.errors import ResourceFailure
from sim.model.system import Impactor, ModalModel, a_base_star
from sim.stepped_sine.protocol import SteppedSine, simulated_system

#: excitation periods of the probe that measures the cost of one simulated second
PROBE_PERIODS = 60
#: estimated wall times (s) above which the estimate is printed, and above which it is a warning
ANNOUNCE_AFTER_S = 30.0
WARN_AFTER_S = 1800.0
#: memory one recorded sample of `ies trace` takes per state value, in bytes: the states, the signal columns, the
#: CSV table and its text (about 3 x 8 bytes per column, and 25 characters per written cell)
TRACE_BYTES_PER_VALUE = 60
#: share of the available memory a command may plan to use
MEMORY_SHARE = 0.5


def simulated_seconds(protocol: SteppedSine, omega_1: float) -> float:
    """Simulated time (s) of one stepped-sine run (Sect. 5.1): the lead-in (one wait) and every point's wait and
    hold, in whole excitation periods at the grid's frequencies (omega_1 in rad/s)."""
    total = 0.0
    for eta in protocol.eta:
        Omega = float(eta) * omega_1
        wait, hold = protocol.periods(Omega)
        total += (wait + hold) * 2.0 * math.pi / Omega
    lead_in = protocol.periods(float(protocol.eta[0]) * omega_1)[0] * 2.0 * math.pi / (float(protocol.eta[0]) * omega_1)
    return len(protocol.legs) * total + (0.0 if protocol.perturb == "each-point" else lead_in)


def cost_per_simulated_second(model: ModalModel, impactor: Impactor | None, level: float,
                              protocol: SteppedSine) -> float:
    """Wall seconds per simulated second of this system at a_base = level a_base* (Sect. 5), measured by a probe
    of PROBE_PERIODS periods at the middle of the eta grid (the kernels must be loaded:
    `sim.integration.integrators.warm_up`)."""
    from sim.integration.integrators import get_integrator

    run_step = get_integrator(protocol.integrator, dt_scale=protocol.dt_scale)
    sys_arrays = simulated_system(model, impactor)
    a_base = level * a_base_star(model)
    Omega = float(protocol.eta[len(protocol.eta) // 2]) * float(model.omega[0])
    y = np.zeros(2 * model.n_modes + 2)
    if protocol.start == "base-velocity":
        y[-1] = a_base * Omega
    started = time.perf_counter()
    run_step(y, PROBE_PERIODS, Omega, a_base, sys_arrays, None)
    return (time.perf_counter() - started) / (PROBE_PERIODS * 2.0 * math.pi / Omega)


def duration_text(seconds: float) -> str:
    """A wall time as "12 s", "4.2 min" or "3.1 h"."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min" if seconds < 5400 else f"{seconds / 3600:.1f} h"


def announce(runs: int, simulated_per_run: float, cost: float, hint: str, stream: TextIO | None = None) -> float:
    """Write the one-line estimate "runs x simulated s x cost" to `stream` (stderr) when it exceeds
    ANNOUNCE_AFTER_S, as a warning with `hint` (how to ask for less) above WARN_AFTER_S; returns the estimate (s)."""
    stream = stream or sys.stderr
    estimate = runs * simulated_per_run * cost
    if estimate > ANNOUNCE_AFTER_S:
        line = (f"cost estimate: {runs} run(s) x {simulated_per_run:.3g} s simulated x {cost:.2g} s per simulated s "
                f"= about {duration_text(estimate)} on one core")
        stream.write(f"warning: {line}; {hint}\n" if estimate > WARN_AFTER_S else f"{line}\n")
        stream.flush()
    return estimate


def announce_runs(runs: int, seconds_per_run: float, hint: str, stream: TextIO | None = None) -> float:
    """As `announce`, for runs whose wall time was measured (a study's first task): "runs x s per run"."""
    stream = stream or sys.stderr
    estimate = runs * seconds_per_run
    if estimate > ANNOUNCE_AFTER_S:
        line = (f"cost estimate: {runs} run(s) x {seconds_per_run:.2g} s per run (the first, measured) = about "
                f"{duration_text(estimate)} on one core")
        stream.write(f"warning: {line}; {hint}\n" if estimate > WARN_AFTER_S else f"{line}\n")
        stream.flush()
    return estimate


def available_memory() -> float:
    """Memory (bytes) the system can give without swapping: MemAvailable of /proc/meminfo, else the free pages."""
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return math.inf


def check_trace_memory(samples: int, n_modes: int, fix: str) -> None:
    """Refuse (ResourceFailure, exit 3, before any work) a trace of `samples` recorded samples whose arrays would
    need more than MEMORY_SHARE of the available memory; `fix` says which option to lower."""
    values = 2 * n_modes + 2 + 11  # the states y and the signal's columns (`sim.analysis.trace.COLUMNS`)
    needed = float(samples) * values * TRACE_BYTES_PER_VALUE
    available = available_memory()
    if needed > MEMORY_SHARE * available:
        raise ResourceFailure(f"the trace's {samples:.3g} samples need about {needed / 2**30:.3g} GiB of memory, "
                              f"{available / 2**30:.3g} GiB are available; {fix} (nothing was computed)")
