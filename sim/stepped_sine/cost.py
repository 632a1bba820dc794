"""What a simulation will cost before it starts: one cost model for every command that runs stepped sines (`ies sweep`,
`ies overview`, `ies trace`, the studies, `ies reproduce`, `ies design`), a refusal above an hour, and a refusal
when a trace's arrays cannot fit in memory.

The model (`Estimate`): runs x the seconds of one run x the machine's share for the workers. One run simulates the
stepped-sine protocol of Sect. 5.1: the lead-in (one wait) and, per point and leg, its wait and hold, in whole
excitation periods (`simulated_seconds`); what a simulated second costs depends on the integrator (ode3: its fixed
steps per period, dt = 2 pi / (15 omega_9); exact: the contacts, that is the regime), the host's modes and the
machine, so it is measured, not assumed: a probe run (`probe_cost`) of the protocol itself at PROBE_POINTS points
spread over its eta grid (one leg, the protocol's wait, hold, start, integrator and step, through `run_sweep`, the
energy ledger and the measures included) at each level (PROBE_LEVELS at most), on this machine, now (its speed and its
load for one process). Parallel workers share the cores with the machine's other work (the 1-minute load average):
each gets cores / (others + workers) of a core, at most one (`Estimate.wall_s`).

Small work is not probed: when even a pessimistic cost (MAX_COST_PER_SIMULATED_S) keeps it below ANNOUNCE_AFTER_S,
nothing is said. Above ANNOUNCE_AFTER_S the estimate is one line; above LIMIT_S (an hour on this machine) the work is
refused before it starts, naming the estimate and --allow-large. The benchmark tests/benchmarks/test_cost_estimate.py
checks the estimates against the measured times.
"""
from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, replace
from typing import Any, Callable, Mapping, Sequence, TextIO

import numpy as np

from sim.common.errors import ResourceFailure, SimulationInputError
from sim.model.system import Impactor, ModalModel, Nominal
from sim.stepped_sine.protocol import SteppedSine

#: estimated wall times (s) above which the estimate is printed, and above which it is a warning
ANNOUNCE_AFTER_S = 30.0
WARN_AFTER_S = 1800.0
#: estimated wall time (s) above which work is refused unless the command says --allow-large
LIMIT_S = 3600.0
#: an upper bound of the seconds a simulated second costs (the slowest integrator setting, ode3 with friction at an
#: SMR level, on a slow or loaded machine): work below ANNOUNCE_AFTER_S even at this cost is not probed
MAX_COST_PER_SIMULATED_S = 0.5
#: stepped-sine points of a probe run (spread over the eta grid: both sides of the resonance and its peak)
PROBE_POINTS = 4
#: the most levels probed, spread over those asked for; each other level takes the cost of the nearest probed one
PROBE_LEVELS = 5
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


def probe_protocol(protocol: SteppedSine) -> SteppedSine:
    """The protocol of a probe run: PROBE_POINTS points spread over the grid, one leg up, the rest as given."""
    if protocol.n_eta <= PROBE_POINTS:
        return replace(protocol, sequence="up")
    return replace(protocol, n_eta=PROBE_POINTS, sequence="up")


def probe_cost(model: ModalModel, impactor: Impactor | None, level: float, protocol: SteppedSine,
               nominal: Nominal | None = None) -> float:
    """Wall seconds per simulated second of the protocol's runs at a_base = level a_base* (Sect. 5, a_base* of
    `nominal`, default the host's) on this machine now: one probe run (`probe_protocol`) through `run_sweep`, timed
    (the kernels must be loaded: `sim.integration.integrators.warm_up`)."""
    from sim.stepped_sine.protocol import run_sweep

    probe = probe_protocol(protocol)
    started = time.perf_counter()
    run_sweep(model, impactor, level, probe, seed=0, rep=0, nominal=nominal)
    return (time.perf_counter() - started) / simulated_seconds(probe, float(model.omega[0]))


def worth_probing(runs: int, simulated_per_run: float) -> bool:
    """Whether work of `runs` runs of `simulated_per_run` simulated seconds could take longer than ANNOUNCE_AFTER_S."""
    return runs * simulated_per_run * MAX_COST_PER_SIMULATED_S > ANNOUNCE_AFTER_S


def seconds_per_run(model: ModalModel, impactor: Impactor | None, levels: Sequence[float], protocol: SteppedSine,
                    nominal: Nominal | None = None) -> dict[float, float]:
    """Estimated wall seconds of one run of `protocol` at each of `levels` (a_base* of `nominal`) on one core of this
    machine now: `simulated_seconds` x `probe_cost` at up to PROBE_LEVELS levels spread over them (the others: the
    nearest)."""
    ordered = sorted(set(float(level) for level in levels))
    probed = [ordered[int(round(i))] for i in np.linspace(0, len(ordered) - 1, min(PROBE_LEVELS, len(ordered)))]
    # untimed: what the first run loads (the kernels' paths, the contacts' included) is loaded by one point already
    probe_cost(model, impactor, probed[-1], replace(protocol, n_eta=1, eta_stop=protocol.eta_start), nominal)
    cost = {level: probe_cost(model, impactor, level, protocol, nominal) for level in dict.fromkeys(probed)}
    per_run = simulated_seconds(protocol, float(model.omega[0]))
    return {level: per_run * cost[min(cost, key=lambda p: abs(p - level))] for level in ordered}


def machine_load() -> float:
    """The 1-minute load average (runnable processes), 0 where the system does not say."""
    try:
        return float(os.getloadavg()[0])
    except (AttributeError, OSError):
        return 0.0


@dataclass(frozen=True)
class Estimate:
    """The time work takes: `runs` runs of `per_run_s` seconds each (mean, on one core of this machine as measured
    now), on `workers` processes of `cores` cores while the machine runs `load` other processes (the load average)."""

    runs: int
    per_run_s: float
    workers: int = 1
    cores: int = 1
    load: float = 0.0

    @property
    def serial_s(self) -> float:
        """Seconds on one core, as measured (under the present load)."""
        return self.runs * self.per_run_s

    @property
    def wall_s(self) -> float:
        """Seconds with `workers` processes: each gets cores / (others + workers) of a core (at most one), the probe
        that measured `per_run_s` cores / (others + 1); others = the load average less this process."""
        workers = max(1, min(self.workers, self.runs))
        others = max(0.0, self.load - 1.0)
        share = lambda k: min(1.0, self.cores / (others + k))  # noqa: E731
        return self.serial_s * share(1) / (workers * share(workers))

    def text(self) -> str:
        """"2400 run(s) x 72 s = 48 h on one core; about 31 h on 2 workers (2 cores, load 1.3)"."""
        line = (f"{self.runs} run(s) x {duration_text(self.per_run_s)} (measured here) = about "
                f"{duration_text(self.serial_s)} on one core")
        if min(self.workers, self.runs) > 1:
            line += f"; about {duration_text(self.wall_s)} on {min(self.workers, self.runs)} workers"
        return line + f" ({self.cores} core(s), load {self.load:.1f})"


def estimate(runs_at: Mapping[Any, int], per_run: Mapping[Any, float], *, workers: int = 1,
             cores: int | None = None, load: float | None = None) -> Estimate:
    """The `Estimate` of `runs_at[key]` runs of each kind (a level; a study's level), each taking `per_run[key]` seconds
    on one core."""
    runs = int(sum(runs_at.values()))
    serial = float(sum(n * per_run[level] for level, n in runs_at.items()))
    return Estimate(runs, serial / runs if runs else 0.0, max(1, int(workers)), cores or os.cpu_count() or 1,
                    machine_load() if load is None else load)


def duration_text(seconds: float) -> str:
    """A wall time as "0.42 s", "12 s", "4.2 min", "1.0 h" or "48 h"."""
    if seconds < 90:
        return f"{seconds:.2g} s" if seconds < 10 else f"{seconds:.0f} s"
    if seconds < 3600:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h" if seconds < 36000 else f"{seconds / 3600:.0f} h"


def check_estimate(work: Estimate, hint: str, *, allow_large: bool = False, quiet: bool = False,
                   stream: TextIO | None = None, write: Callable[[str], None] | None = None) -> float:
    """Before the work: refuse it (SimulationInputError, one line naming the estimate, `hint` on how to ask for less
    and --allow-large) above LIMIT_S unless `allow_large`; say it in one line above ANNOUNCE_AFTER_S (a warning with
    `hint` above WARN_AFTER_S; with `quiet`, --quiet, the warning only), through `write` (a progress bar's) or on
    `stream` (stderr). Returns the wall time."""
    wall = work.wall_s
    if wall > LIMIT_S and not allow_large:
        raise SimulationInputError(f"cost estimate: {work.text()}: more than the {duration_text(LIMIT_S)} a command "
                                   f"runs without --allow-large; {hint}, or pass --allow-large")
    if wall > (WARN_AFTER_S if quiet else ANNOUNCE_AFTER_S):
        line = f"cost estimate: {work.text()}"
        line = f"warning: {line}; {hint}" if wall > WARN_AFTER_S else line
        if write is not None:
            write(line)
        else:
            stream = stream or sys.stderr
            stream.write(line + "\n")
            stream.flush()
    return wall


def first_run_line(remaining: int, measured_s: float, expected_s: float | None, workers: int = 1) -> str | None:
    """After the first run of many (timed, `uq.engine.runner`): the line that says what the rest will take, when
    nothing was estimated before (`expected_s` None: a model the probe cannot run) or the first run took 3 times as
    long or short as estimated (it is one run, at one point of the study: the line says so); else None."""
    total = remaining * measured_s / max(1, workers)
    if expected_s is None:
        if total <= ANNOUNCE_AFTER_S:
            return None
        return (f"cost estimate: {remaining} run(s) x {duration_text(measured_s)} (the first, measured) = about "
                f"{duration_text(total)}" + (f" on {workers} workers" if workers > 1 else " on one core"))
    if 1 / 3 <= measured_s / expected_s <= 3 or total <= ANNOUNCE_AFTER_S:
        return None
    return (f"the first run took {duration_text(measured_s)}, {measured_s / expected_s:.2g} times the estimate: if the "
            f"others are like it, the remaining {remaining} take about {duration_text(total)}")


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
