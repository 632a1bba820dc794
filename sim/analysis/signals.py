"""Measured or simulated time signals for the analyses of Appendix D.1 and Sect. 5.5 of the seed paper.

A signal is a table of uniformly sampled columns sharing one time column ``t`` (s); the analyses name the
columns they need:

* ``a_left``, ``a_right``: absolute accelerations of the cavity walls (m/s^2), the sensors of Appendix D.1;
* ``a_tip``: absolute acceleration near the beam's tip (m/s^2);
* ``v_tip``: velocity of the tip relative to the base (m/s), the paper's q_tip' (Sect. 5, Eq. 9).

Signal files are CSV with a header line naming the columns (``t`` first or anywhere; other columns are
ignored), one row per sample, SI units; lines starting with ``#`` are comments. `simulated_signal` turns
states recorded by the simulator into the same columns (plus displacements and contact forces), so a
simulated trace and a measurement go through the same analyses.
"""
from __future__ import annotations

import io
import os
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import read_text
from sim.model.system import SystemArrays

#: Largest deviation of a time step from the mean step (relative) that still counts as uniform sampling.
UNIFORM_STEP_TOLERANCE = 0.01
#: Fewest samples a signal must have.
MIN_SAMPLES = 8


@dataclass(frozen=True)
class Signal:
    """Uniformly sampled columns on a common time axis.

    t: sample instants (s), strictly increasing and uniform; columns: name -> values (SI units), each of
    the length of t; source: where the signal came from (a path or "arrays").
    """

    t: np.ndarray
    columns: Mapping[str, np.ndarray] = field(default_factory=dict)
    source: str = "arrays"

    @property
    def fs(self) -> float:
        """Sampling rate (Hz) from the mean step of t."""
        return (self.t.size - 1) / float(self.t[-1] - self.t[0])

    @property
    def duration(self) -> float:
        """Length covered by the samples, n / fs (s)."""
        return self.t.size / self.fs

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "t":
            return self.t
        try:
            return self.columns[name]
        except KeyError:
            raise SimulationInputError(f"{self.source}: no column '{name}' (has {', '.join(self.columns) or 'none'})") from None


def make_signal(t: np.ndarray, columns: Mapping[str, np.ndarray], source: str = "arrays",
                required: Sequence[str] = ()) -> Signal:
    """Validate arrays as a Signal: t (s) strictly increasing and uniform, every column finite and as long as t.

    required: column names that must be among `columns`. Raises SimulationInputError with one line.
    """
    _require(columns, required, source)
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < MIN_SAMPLES:
        raise SimulationInputError(f"{source}: {t.size} sample(s); a signal needs at least {MIN_SAMPLES}")
    checked = {"t": t}
    for name, values in columns.items():
        values = np.asarray(values, dtype=float)
        if values.shape != t.shape:
            raise SimulationInputError(f"{source}: column '{name}' has {values.size} values but t has {t.size}")
        checked[name] = values
    for name, values in checked.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise SimulationInputError(f"{source}: column '{name}' is {values[bad[0]]} at data row {bad[0] + 1}; "
                                       "every value must be a finite number (remove or interpolate it)")
    step = np.diff(t)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0])
        raise SimulationInputError(f"{source}: t must increase, but t = {float(t[i + 1])!r} s at data row {i + 2} follows "
                                   f"t = {float(t[i])!r} s; sort the samples and remove repeated ones")
    mean = (t[-1] - t[0]) / (t.size - 1)
    off = np.abs(step - mean) > UNIFORM_STEP_TOLERANCE * mean
    if np.any(off):
        i = int(np.flatnonzero(off)[0])
        raise SimulationInputError(
            f"{source}: t is not uniformly sampled: the step {step[i]:.6g} s before data row {i + 2} differs from "
            f"the mean step {mean:.6g} s by more than {UNIFORM_STEP_TOLERANCE:.0%}; resample to a uniform rate")
    for values in checked.values():
        values.setflags(write=False)
    return Signal(checked.pop("t"), checked, source)


def read_signal(path: str | os.PathLike, required: Sequence[str] = ()) -> Signal:
    """Read a signal CSV (format in this module's docstring) with the columns `required` besides t.

    Only t and the required columns are read and checked; the others are ignored. Raises
    SimulationInputError with one line naming the file for a missing, empty or malformed file, a missing
    column, a non-numeric or non-finite value, or t that is not strictly increasing and uniform.
    """
    path = Path(path)
    text = read_text(path, "signal file", "CSV")
    header, skipped = _header(io.StringIO(text))
    if header is None:
        raise SimulationInputError(f"{path} is empty; a signal file has a header line such as "
                                   f"'t,{','.join(required) or 'a_left'}' and one row per sample")
    names = [name.strip() for name in header.split(",")]
    wanted = ["t", *required]
    _require(names, wanted, f"{path} (header '{header.strip()}')")
    duplicated = sorted({name for name in wanted if names.count(name) > 1})
    if duplicated:
        raise SimulationInputError(f"{path}: column(s) {', '.join(duplicated)} appear more than once in the header")
    columns = [names.index(name) for name in wanted]
    _check_row_lengths(text, skipped + 1, len(names), path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data": reported below
            data = np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=skipped + 1,
                              usecols=columns, ndmin=2)
    except ValueError as exc:
        text = str(exc).strip().splitlines()[-1]
        cell = re.search(r"could not convert string '(.*)' to float64 at row (\d+), column (\d+)", text)
        if cell:  # numpy counts the file's columns from 1 (not the usecols list) and the data rows from 0
            column = int(cell.group(3)) - 1
            name = names[column] if column < len(names) else f"number {column + 1}"
            value = f"'{cell.group(1)}'" if cell.group(1).strip() else "an empty cell"
            text = f"{value} in column '{name}' at data row {int(cell.group(2)) + 1} is not a number"
        raise SimulationInputError(f"{path}: {text}; every cell must be a number") from None
    if data.shape[0] == 0:
        raise SimulationInputError(f"{path}: the header has no data rows below it")
    return make_signal(data[:, 0], {name: data[:, k + 1] for k, name in enumerate(required)}, str(path), required)


def as_signal(source: Signal | str | os.PathLike, required: Sequence[str]) -> Signal:
    """A Signal from a file path (read_signal) or a Signal that must have the `required` columns."""
    if isinstance(source, Signal):
        _require(source.columns, required, source.source)
        return source
    return read_signal(source, required)


def _require(names, required: Sequence[str], source: str) -> None:
    missing = [name for name in required if name not in names]
    if missing:
        needs = ", ".join(dict.fromkeys(("t", *required)))
        raise SimulationInputError(f"{source}: missing column(s) {', '.join(missing)}; the analysis needs {needs}")


def _check_row_lengths(text: str, first: int, n_columns: int, path: Path) -> None:
    """Every data row (from line index `first`, comments and blank lines aside) has the header's `n_columns` cells;
    a row with more is most often a decimal comma (0,5 for 0.5), which would shift that row's columns."""
    for number, line in enumerate(text.splitlines()[first:], start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cells = line.count(",") + 1
        if cells != n_columns:
            data_row = number - sum(1 for ln in text.splitlines()[first:first + number - 1]
                                    if not ln.strip() or ln.lstrip().startswith("#"))
            hint = (" (a decimal comma, e.g. 0,5 for 0.5? write numbers with a point)" if cells > n_columns else "")
            raise SimulationInputError(f"{path}: data row {data_row} has {cells} cells but the header names "
                                       f"{n_columns} columns{hint}; every row needs one cell per column")


def _header(handle) -> tuple[str | None, int]:
    """The first line that is neither blank nor a comment, and how many lines precede it."""
    for number, line in enumerate(handle):
        if line.strip() and not line.lstrip().startswith("#"):
            return line, number
    return None, 0


def simulated_signal(states: np.ndarray, samples_per_period: int, Omega: float, a_base: float,
                     sys: SystemArrays, t0: float = 0.0) -> Signal:
    """The signal columns of states recorded by a simulator (`sim.model.system` run_step contract, `record`).

    states: rows y = [s, s', u_a, u_a'] at M = samples_per_period equally spaced instants per excitation
    period, row 0 at phase 0 (a multiple of 2 pi); Omega (rad/s), a_base (m); t0: time of row 0 (s).
    Columns (SI): q_tip, v_tip (tip displacement and velocity relative to the base, Sect. 5),
    q_wall_left, q_wall_right, q_sphere (relative to the base), f_left, f_right (Eq. 4, N), and the absolute
    accelerations a_tip, a_left, a_right = phi^T s'' + q_base'' with s'' from Eq. 7 (what accelerometers
    on the beam measure, Appendix D.1).
    """
    y = np.atleast_2d(np.asarray(states, dtype=float))
    n = sys.omega.size
    M = int(samples_per_period)
    if y.shape[1] != 2 * n + 2 or M < 1:
        raise SimulationInputError(f"states must have {2 * n + 2} columns and samples_per_period must be >= 1")
    s, v, u = y[:, :n], y[:, n:2 * n], y[:, 2 * n]
    phase = 2.0 * np.pi * np.arange(y.shape[0]) / M
    base_acceleration = -a_base * Omega**2 * np.cos(phase)
    q_left, q_right = s @ sys.phi_l, s @ sys.phi_r
    f_left = sys.k_H * np.clip(q_left - u - sys.g, 0.0, None) ** 1.5
    f_right = -sys.k_H * np.clip(u - q_right - sys.g, 0.0, None) ** 1.5
    modal_acceleration = (-2.0 * sys.D * sys.omega * v - sys.omega**2 * s - np.outer(f_left, sys.phi_l)
                          - np.outer(f_right, sys.phi_r) - np.outer(base_acceleration, sys.gamma))
    columns = {
        "q_tip": s @ sys.phi_tip, "v_tip": v @ sys.phi_tip,
        "a_tip": modal_acceleration @ sys.phi_tip + base_acceleration,
        "q_wall_left": q_left, "q_wall_right": q_right,
        "a_left": modal_acceleration @ sys.phi_l + base_acceleration,
        "a_right": modal_acceleration @ sys.phi_r + base_acceleration,
        "q_sphere": u, "f_left": f_left, "f_right": f_right,
    }
    t = t0 + np.arange(y.shape[0]) * (2.0 * np.pi / Omega / M)
    return make_signal(t, columns, "simulated trace")


@dataclass(frozen=True)
class SimulatedContacts:
    """Contacts seen in recorded simulator states (`simulated_contacts`).

    times: onset instants (s), the middle of the first sample interval in which the sphere's absolute
    velocity changes; walls: "left"/"right"; impulses: m_a times the velocity change over the contact (N s,
    > 0 at the left wall, < 0 at the right); first, last: indices i of the first and last interval
    [t_i, t_i+1] of each contact.
    """

    times: np.ndarray
    walls: tuple[str, ...]
    impulses: np.ndarray
    first: np.ndarray
    last: np.ndarray


def simulated_contacts(states: np.ndarray, samples_per_period: int, Omega: float, a_base: float,
                       sys: SystemArrays, t0: float = 0.0, tolerance: float = 1e-9) -> SimulatedContacts:
    """The simulator's own impact list from recorded states (Eq. 3: the sphere flies at constant absolute
    velocity between contacts, so every change of q_a' between two samples is a contact).

    states, samples_per_period, Omega (rad/s), a_base (m), t0 (s): as in `simulated_signal`; tolerance: the
    smallest velocity change (m/s) that counts. A run of consecutive intervals with velocity changes is one
    contact (a release and a new contact within one interval merge). Contacts between the samples are all
    found; their onset is known to one sample interval.
    """
    y = np.atleast_2d(np.asarray(states, dtype=float))
    M = int(samples_per_period)
    phase = 2.0 * np.pi * np.arange(y.shape[0]) / M
    velocity = y[:, -1] - a_base * Omega * np.sin(phase)  # q_a' = u_a' + q_base'
    change = np.diff(velocity)
    moving = np.flatnonzero(np.abs(change) > tolerance)
    if moving.size == 0:
        empty = np.array([], dtype=int)
        return SimulatedContacts(np.array([]), (), np.array([]), empty, empty)
    first = moving[np.r_[True, np.diff(moving) > 1]]
    last = moving[np.r_[np.diff(moving) > 1, True]]
    cumulative = np.r_[0.0, np.cumsum(change)]
    impulses = sys.m_a * (cumulative[last + 1] - cumulative[first])
    step = 2.0 * np.pi / Omega / M
    return SimulatedContacts(t0 + (first + 0.5) * step, tuple("left" if p > 0 else "right" for p in impulses),
                             impulses, first, last)


def trace_restitution(signal: Signal, excitation_hz: float, a_base: float, clearance: float, m_a: float,
                      wall: str = "tip") -> tuple[float, int]:
    """The modal coefficient of restitution r of Eq. D.1 from a saved time history alone (the columns of `ies trace`:
    t from phase 0 of q_base = a_base cos(Omega t), q_tip or q_wall_left/right, q_sphere, q_wall_left/right and the
    contact forces f_left, f_right): an independent check of the simulator's `restitution` (`sim.stepped_sine.measures`).

    Contacts are the runs of samples with a contact force. Between contacts the sphere flies at constant absolute
    velocity (Eq. 3), so a straight line through the absolute sphere displacement q_sphere + q_base of each free
    flight gives its velocity and, where that line meets the wall (indentation 0 with the clearance, m), the onset and
    release times. q_mod' is the velocity of the fundamental harmonic of the tip (`wall="tip"`) or of the wall that
    is hit (`wall="wall"`), c_1 by the DFT of the samples of the impact's period. r is the median over the significant
    impacts (`sim.stepped_sine.measures.significant_impacts`, impulse = m_a (kg) times the change of the sphere's velocity) of the
    last `sim.stepped_sine.measures.RESTITUTION_PERIODS` periods. Returns (r, number of impacts used); excitation_hz (Hz),
    a_base (m)."""
    from sim.integration.energy import IMPACT_DTYPE
    from sim.stepped_sine.measures import RESTITUTION_PERIODS, modal_restitution, significant_impacts

    t = signal.t
    Omega = 2.0 * np.pi * excitation_hz
    M = int(round(signal.fs / excitation_hz))
    n_periods = t.size // M
    if n_periods < 1 or abs(M * excitation_hz / signal.fs - 1.0) > 1e-6:
        raise SimulationInputError("trace_restitution needs a whole number of samples per excitation period (ies trace)")
    q_abs = signal["q_sphere"] + a_base * np.cos(Omega * t)
    touching = (signal["f_left"] > 0.0) | (signal["f_right"] < 0.0)
    edges = np.flatnonzero(np.diff(touching.astype(np.int8)))
    firsts = edges[::2] + 1 if not touching[0] else edges[1::2] + 1
    lasts = edges[1::2] if not touching[0] else edges[2::2]
    firsts = firsts[:lasts.size]

    def line(a: int, b: int) -> np.ndarray | None:  # the free flight over samples a..b: (velocity, offset)
        return np.polyfit(t[a:b + 1], q_abs[a:b + 1], 1) if b - a >= 1 else None

    fits = [line(lasts[k - 1] + 1 if k else 0, firsts[k] - 1) for k in range(firsts.size)]
    fits.append(line(lasts[-1] + 1, t.size - 1) if lasts.size else None)
    rows = []
    for k, (first, last) in enumerate(zip(firsts, lasts)):
        before, after = fits[k], fits[k + 1]
        if before is None or after is None or last + 1 >= t.size:
            continue
        left = signal["f_left"][first:last + 1].max() > 0.0
        q_wall = signal["q_wall_left" if left else "q_wall_right"] + a_base * np.cos(Omega * t)
        sign = 1.0 if left else -1.0

        def closing(i: int, fit: np.ndarray) -> float:  # the indentation of the line at sample i (m)
            return sign * (q_wall[i] - np.polyval(fit, t[i])) - clearance

        c0, c1 = closing(first - 1, before), closing(first, before)
        t_on = t[first - 1] + (t[first] - t[first - 1]) * c0 / (c0 - c1)
        c0, c1 = closing(last, after), closing(last + 1, after)
        t_off = t[last] + (t[last + 1] - t[last]) * c0 / (c0 - c1)
        period = int(t_on * excitation_hz)
        rows.append((0.0 if left else 1.0, period, t_on - period / excitation_hz, t_off - t_on,
                     m_a * abs(after[0] - before[0]), np.nan,
                     before[0] + a_base * Omega * np.sin(Omega * t_on), after[0] + a_base * Omega * np.sin(Omega * t_off),
                     np.nan, np.nan, np.nan, np.nan))
    records = np.array(rows, dtype=IMPACT_DTYPE) if rows else np.zeros(0, dtype=IMPACT_DTYPE)
    records = records[records["period"] < n_periods]
    if records.size == 0:
        return float("nan"), 0
    chosen = records[significant_impacts(records)]
    chosen = chosen[chosen["period"] >= n_periods - RESTITUTION_PERIODS]
    phase = np.exp(-1j * Omega * t[:n_periods * M]).reshape(n_periods, M)

    def fundamental(column: str) -> np.ndarray:
        return 2.0 / M * np.sum(signal[column][:n_periods * M].reshape(n_periods, M) * phase, axis=1)

    if wall == "tip":
        r = modal_restitution(chosen, fundamental("q_tip"), Omega)
    else:
        r = np.where(chosen["wall"] == 0, modal_restitution(chosen, fundamental("q_wall_left"), Omega),
                     modal_restitution(chosen, fundamental("q_wall_right"), Omega))
    return (float(np.median(r)), int(r.size)) if r.size else (float("nan"), 0)
