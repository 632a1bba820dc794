"""Time histories of one stepped-sine point (seed paper Sect. 5.1, Fig. 4; Sect. 5.5, Fig. 9a): `ies trace`.

The stepped-sine run of a protocol (`sim.stepped_sine.protocol.visit_points`: lead-in, wait, and the holds of the points
before) is walked to its last point; after that point's wait, `periods` excitation periods of its hold are
simulated with the state recorded at M = round(fs / f_exc) instants per period, exactly at those instants
(the integrator's states, not interpolated: `sim.model.system` record contract). The sampling rate is therefore
M f_exc, the nearest to the requested one that puts a whole number of samples in every period. The recorded
states become the signal columns of `sim.analysis.signals.simulated_signal` (SI units). The impact list comes from the
integrator's own impact records (`sim.integration.energy.Ledger`: exact onset time, duration, impulse, velocities and modal
energies of each contact) with the stretch's scattering measures (Sect. 5.5, Appendix D); an integrator that keeps
no records (ode3) falls back to the contacts seen between samples (`sim.analysis.signals.simulated_contacts`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.outputs import Column, OutputFile
from sim.integration.energy import Ledger
from sim.stepped_sine.dynamics import (check_record, classify, largest_lyapunov, linear_host_exponent, one_period,
                                       periodicity, state_scales)
from sim.stepped_sine.dynamics import poincare as poincare_section
from sim.stepped_sine.measures import SCATTERING_MEASURES, hold_measures, point_measures
from sim.stepped_sine.protocol import SteppedSine, check_level, simulated_system, visit_points
from sim.analysis.signals import Signal, SimulatedContacts, simulated_contacts, simulated_signal
from sim.model.system import Impactor, ModalModel, Nominal, a_base_star, a_noabs_star

#: The paper's sampling rate (Sect. 5.5: 51.2 kHz).
DEFAULT_FS = 51.2e3
DEFAULT_PERIODS = 50
TRACE_CSV = OutputFile("trace.csv", "ies trace --out DIR", "One row per sample, SI units; the columns of "
                       "`sim.analysis.signals.simulated_signal`, t first.", (
    Column("t", "s", "time from the start of the recorded stretch, at phase 0 of q_base = a_base cos(Omega t)"),
    Column("q_tip", "m", "tip displacement relative to the base"),
    Column("v_tip", "m/s", "tip velocity relative to the base"),
    Column("a_tip", "m/s^2", "absolute tip acceleration"),
    Column("q_wall_left", "m", "displacement of the left cavity wall relative to the base"),
    Column("q_wall_right", "m", "displacement of the right cavity wall relative to the base"),
    Column("a_left", "m/s^2", "absolute acceleration of the left wall (a sensor of Appendix D.1)"),
    Column("a_right", "m/s^2", "absolute acceleration of the right wall"),
    Column("q_sphere", "m", "sphere displacement relative to the base"),
    Column("f_left", "N", "Hertz contact force on the sphere at the left wall (>= 0, Eq. 4)"),
    Column("f_right", "N", "Hertz contact force on the sphere at the right wall (<= 0)"),
))
TRACE_JSON = OutputFile("trace.json", "ies trace --out DIR, also --json", "The command's settings (`integrator`, "
                        "`seed`, `protocol` as in sweep.json, `impactor`, `model`, `D1`, `fs_requested`, ...) and:", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("a_base, a_noabs", "m", "base amplitude, linear resonant amplitude a_noabs*"),
    Column("eta, eta_actual", "-", "the point's nominal and simulated Omega/omega*"),
    Column("excitation_hz", "Hz", "the excitation frequency"),
    Column("fs", "Hz", "the sampling rate used: samples_per_period x excitation_hz"),
    Column("samples_per_period, periods, n_samples", "-", "M = round(fs/f_exc), recorded periods, rows of trace.csv"),
    Column("amplitudes", "a/a_noabs*", "the amplitude of each recorded period (Fig. 4)"),
    Column("mean, max", "a/a_noabs*", "their mean and largest value"),
    Column("cv", "-", "std/mean of the per-period amplitudes"),
    Column("impacts_per_period, onsets_per_period", "-", "contact onsets counted by the integrator (mean, per period)"),
    Column("impacts", "", "one entry per contact: t (s, onset), wall; from the integrator's records also duration (s), "
           "impulse (N s), approach_speed (m/s), the sphere's velocities before/after (m/s) and the modal energies at "
           "onset and release (J)"),
    Column("impacts_source", "", "integrator (exact records) or samples (ode3: contacts seen between samples)"),
    Column("significant_impacts_per_period, restitution, ..., dissipation_friction", "",
           "the stretch's scattering measures, as the columns of sweep.csv"),
    Column("columns, units", "", "trace.csv's column names and their units"),
    Column("wall_time_s", "s", "the command's wall time"),
    Column("lyapunov_per_period", "-", "with --lyapunov: the largest Lyapunov exponent, natural log per excitation "
           "period, over the recorded periods (`sim.stepped_sine.dynamics`)"),
    Column("lyapunov_standard_error", "-", "its standard error (batch means)"),
    Column("lyapunov_convergence", "-", "the running estimate over the record after its transient, one per period"),
    Column("lyapunov_transient_periods, lyapunov_periods_needed", "-", "the periods left out at the record's start; "
           "the record that would bring the error below 5 % of the exponent (or 2e-3)"),
    Column("lyapunov_converged", "", "true when the error is that small"),
    Column("lyapunov_linear_host", "-", "without impactor: mode 1's decay -2 pi D_1/eta per period, what the exponent "
           "of the linear host is; null with the sphere"),
    Column("dynamics", "", "with --lyapunov: periodic, quasi-periodic or chaotic"),
    Column("dynamics_period", "-", "k of a periodic response that repeats after k periods (null otherwise)"),
    Column("poincare", "", "with --poincare: q_tip, v_tip (the tip's displacement and velocity / Omega at phase 0 "
           "over a_noabs*, one per period), frequency_per_period, amplitude_spectrum (the per-period amplitudes' "
           "power spectrum, mean removed)"),
))
#: The columns of the trace's CSV, in order
COLUMNS = TRACE_CSV.names
#: Units of the columns (SI).
UNITS = {c.name: c.unit for c in TRACE_CSV.columns}

@dataclass(frozen=True)
class Trace:
    """The recorded stretch of one stepped-sine point.

    signal: the columns (`COLUMNS`, SI) from t = 0 at the start of the recorded stretch (phase 0 of the
    excitation q_base = a_base cos(Omega t)); states: the recorded rows y = [s, s', u_a, u_a'] (`sim.model.system`);
    contacts: the simulator's contacts between samples; samples_per_period M; fs = M Omega / (2 pi) (Hz);
    amplitudes: |c_1| of q_tip per recorded period (m, Sect. 5); impacts: contact onsets per period;
    level a_base/a_base*, a_base, a_noabs (m); eta, eta_actual: the point's nominal and simulated
    Omega / omega_1; Omega (rad/s); ledger: the energy bookkeeping and impact records of the recorded stretch.
    """

    signal: Signal
    states: np.ndarray
    contacts: SimulatedContacts
    samples_per_period: int
    fs: float
    amplitudes: np.ndarray
    impacts: np.ndarray
    level: float
    a_base: float
    a_noabs: float
    eta: float
    eta_actual: float
    Omega: float
    ledger: Ledger | None = None

    @property
    def normalised_amplitudes(self) -> np.ndarray:
        """a / a_noabs* per recorded period (-), the paper's Fig. 4 ordinate."""
        return self.amplitudes / self.a_noabs


def samples_per_period(fs: float, Omega: float) -> int:
    """M = round(fs / f_exc) for a requested sampling rate fs (Hz) at the excitation Omega (rad/s); at least two
    samples per period (one-line SimulationInputError otherwise)."""
    f_exc = Omega / (2.0 * math.pi)
    if not (math.isfinite(fs) and fs >= 2.0 * f_exc):
        raise SimulationInputError(f"--fs {fs:g} Hz is below twice the excitation frequency ({2.0 * f_exc:.4g} Hz); "
                                   f"give --fs of at least that (default {DEFAULT_FS:g})")
    return int(round(fs / f_exc))


def check_trace_settings(model: ModalModel, protocol: SteppedSine, periods: int, fs: float) -> None:
    """One-line SimulationInputError for a record length `periods` that is not a whole number >= 1 or a rate fs (Hz)
    below two samples per period at the protocol's lowest excitation: checked before anything is simulated (or
    compiled)."""
    if int(periods) != periods or periods < 1:
        raise SimulationInputError(f"--periods must be a whole number >= 1, got {periods!r}")
    lowest = protocol.eta[0] * float(model.omega[0]) * (1.0 - protocol.perturbation)
    samples_per_period(float(fs), lowest)


#: wall time of one recorded sample (s): the integrator stops at every sampling instant (2.4-3.0 us), the signal
#: columns (3.0-3.5 us) and the CSV row of 11 cells (50 us); measured with the exact integrator on the seed rig, 1e5 and 1e6
#: samples (2-core development machine)
SAMPLE_COST_S = 55e-6


def trace_samples(model: ModalModel, protocol: SteppedSine, periods: int, fs: float) -> int:
    """How many samples `record_trace` will record: periods x M + 1, M = round(fs / f_exc) at the grid's lowest
    excitation frequency (the most samples per period; fs in Hz)."""
    lowest = protocol.eta[0] * float(model.omega[0]) * (1.0 - protocol.perturbation)
    return int(periods) * samples_per_period(float(fs), lowest) + 1


def record_trace(model: ModalModel, impactor: Impactor | None, level: float, protocol: SteppedSine, *,
                 periods: int = DEFAULT_PERIODS, fs: float = DEFAULT_FS, seed: int = 0, rep: int = 0,
                 nominal: Nominal | None = None) -> Trace:
    """Simulate the stepped-sine run of `protocol` at a_base = level a_base* (Sect. 5.1) to its last point and
    record `periods` excitation periods of that point's hold at fs (Hz, rounded to M f_exc; module docstring).

    impactor None: the host structure alone. Raises SimulationInputError for bad settings.
    """
    from sim.integration.integrators import get_integrator

    level = check_level(level)
    check_trace_settings(model, protocol, periods, fs)
    fs = float(fs)
    run_step = get_integrator(protocol.integrator, dt_scale=protocol.dt_scale)
    sys = simulated_system(model, impactor)
    a_base = level * a_base_star(model, nominal)
    a_noabs = a_noabs_star(model, a_base, nominal)
    y = np.zeros(2 * model.n_modes + 2)
    points = len(protocol.legs) * int(protocol.n_eta)
    for visited, (_, eta, eta_actual, Omega) in enumerate(visit_points(model, sys, a_base, protocol, y, seed=seed,
                                                                        rep=rep), start=1):
        if visited == points:
            break
        run_step(y, protocol.periods(Omega)[1], Omega, a_base, sys, None)
    M = samples_per_period(fs, Omega)
    states = np.empty((int(periods) * M + 1, y.size))
    ledger = Ledger()
    amplitudes, impacts = run_step(y, int(periods), Omega, a_base, sys, states, ledger=ledger)
    return Trace(signal=simulated_signal(states, M, Omega, a_base, sys), states=states,
                 contacts=simulated_contacts(states, M, Omega, a_base, sys), samples_per_period=M,
                 fs=M * Omega / (2.0 * math.pi), amplitudes=amplitudes, impacts=impacts, level=level, a_base=a_base,
                 a_noabs=a_noabs, eta=eta, eta_actual=eta_actual, Omega=Omega, ledger=ledger)


#: Recorded periods with --lyapunov when --periods is not given, and the least that --poincare draws.
LYAPUNOV_PERIODS = 400
POINCARE_MIN_PERIODS = 8


def check_nature_settings(periods: int, lyapunov: bool, poincare: bool) -> None:
    """One line (SimulationInputError) for a record too short for --lyapunov (`sim.stepped_sine.dynamics.
    check_record`, naming the length needed) or --poincare (POINCARE_MIN_PERIODS), before anything is simulated."""
    if lyapunov:
        check_record(periods)
    if poincare and periods < POINCARE_MIN_PERIODS:
        raise SimulationInputError(f"--poincare draws the state once per period and the spectrum of the per-period "
                                   f"amplitudes: it needs at least {POINCARE_MIN_PERIODS} periods, got --periods "
                                   f"{periods}; give --periods {POINCARE_MIN_PERIODS} or more (hundreds show a "
                                   "section's shape)")


def trace_nature(trace: Trace, model: ModalModel, impactor: Impactor | None, protocol: SteppedSine, *,
                 lyapunov: bool, poincare: bool, seed: int = 0) -> dict[str, Any]:
    """The JSON keys of the response's nature at the traced point (`sim.stepped_sine.dynamics`; TRACE_JSON):
    with `lyapunov` the largest exponent over the recorded periods, from the state at the start of the record on the
    protocol's integrator one period at a time, and the dynamics; with `poincare` the section and the spectrum of
    the recorded states and amplitudes."""
    from sim.integration.integrators import get_integrator

    data: dict[str, Any] = {}
    M = trace.samples_per_period
    sys = simulated_system(model, impactor)
    scale = state_scales(model, sys.g)
    if lyapunov:
        run = one_period(get_integrator(protocol.integrator, dt_scale=protocol.dt_scale), trace.Omega, trace.a_base, sys,
                         protocol.integrator)
        result = largest_lyapunov(run, trace.states[0], trace.amplitudes.size, scale, host_only=impactor is None,
                                  seed=seed)
        period = periodicity(trace.states[::M], scale)
        data.update(lyapunov_per_period=result.per_period, lyapunov_standard_error=result.standard_error,
                    lyapunov_convergence=result.running, lyapunov_transient_periods=result.transient,
                    lyapunov_periods_needed=result.periods_needed, lyapunov_converged=result.converged,
                    lyapunov_linear_host=(linear_host_exponent(model, trace.eta_actual) if impactor is None else None),
                    dynamics=classify(result, period, float(np.mean(trace.impacts)) if impactor is not None else 0.0),
                    dynamics_period=period)
    if poincare:
        data["poincare"] = poincare_section(trace.states[::M], trace.amplitudes, model, trace.Omega, trace.a_noabs)
    return data


def nature_line(data: dict[str, Any]) -> str:
    """The line `ies trace --lyapunov` prints: the exponent with its error and convergence, the dynamics, and for the
    host alone that it is linear and what its exponent is."""
    line = (f"largest Lyapunov exponent {data['lyapunov_per_period']:.4g} +- {data['lyapunov_standard_error']:.2g} "
            f"per period over {data['periods'] - data['lyapunov_transient_periods']} periods: {data['dynamics']}")
    if data.get("dynamics_period"):
        line += f" ({data['dynamics_period']} T)"
    if data.get("lyapunov_linear_host") is not None:
        line += (f"; the host alone is linear: its exponent is mode 1's decay, -2 pi D_1/eta = "
                 f"{data['lyapunov_linear_host']:.4g} per period")
    if not data["lyapunov_converged"]:
        line += (f"; not converged: about {data['lyapunov_periods_needed']} periods would bring its error below 5 % "
                 f"(--periods {data['lyapunov_periods_needed']})")
    return line


def trace_rows(trace: Trace) -> np.ndarray:
    """The CSV table of a trace: one row per sample, the columns of `COLUMNS`."""
    return np.column_stack([trace.signal[name] for name in COLUMNS])


def trace_data(trace: Trace, settings: dict[str, Any]) -> dict[str, Any]:
    """The JSON object of a trace (SI units): `settings` (the command's parameters), the actual sampling rate,
    the per-period amplitudes a / a_noabs* with their mean and max (Fig. 4), the contact onsets per period, and
    the simulator's impacts (`impact_list`) and the stretch's scattering measures (`sim.stepped_sine.measures`)."""
    a = trace.normalised_amplitudes
    m = hold_measures(trace.amplitudes, trace.impacts, trace.a_noabs)
    scattering = {} if trace.ledger is None else point_measures(trace.amplitudes, trace.impacts, trace.a_noabs,
                                                                trace.ledger).scattering
    return {
        **settings,
        "level": trace.level, "a_base": trace.a_base, "a_noabs": trace.a_noabs, "eta": trace.eta,
        "eta_actual": trace.eta_actual, "excitation_hz": trace.Omega / (2.0 * math.pi),
        "fs": trace.fs, "samples_per_period": trace.samples_per_period,
        "periods": int(a.size), "n_samples": int(trace.signal.t.size),
        "amplitudes": a, "mean": m.mean, "max": m.max, "cv": m.cv,
        "impacts_per_period": m.impacts_per_period, "onsets_per_period": trace.impacts,
        **impact_list(trace),
        **{name: getattr(scattering, name, math.nan) for name in SCATTERING_MEASURES},
        "columns": list(COLUMNS), "units": UNITS,
    }


def impact_list(trace: Trace) -> dict[str, Any]:
    """{"impacts": [...], "impacts_source": ...}: one entry per contact of the recorded stretch with its onset
    time "t" (s, from the stretch's start) and "wall" ("left"/"right"). From the integrator's records
    ("integrator": exact onset; also duration (s), impulse int |f| dt (N s), approach_speed (m/s), the sphere's
    velocity relative to the base before/after (m/s) and the energies of mode 1 and modes 2..N at onset and
    release (J), Appendix D) when it keeps them, else from the samples ("samples": onset to one sample interval,
    signed impulse, `sim.analysis.signals.simulated_contacts`)."""
    records = None if trace.ledger is None else trace.ledger.impacts
    if records is None or (records.size == 0 and trace.impacts.sum() > 0):
        contacts = trace.contacts
        return {"impacts_source": "samples",
                "impacts": [{"t": t, "wall": wall, "impulse": impulse}
                            for t, wall, impulse in zip(contacts.times, contacts.walls, contacts.impulses)]}
    T = 2.0 * math.pi / trace.Omega
    rows = []
    for r in records:
        row = {"t": float(r["period"] * T + r["t_onset"]), "wall": "left" if r["wall"] == 0 else "right"}
        row.update({name: float(r[name]) for name in records.dtype.names if name not in ("wall", "period", "t_onset")})
        rows.append(row)
    return {"impacts_source": "integrator", "impacts": rows}


def write_trace(folder: Path, trace: Trace, settings: dict[str, Any], plot: str | Path | None = None,
                started: float | None = None, *, draw: Callable[..., None] | None = None,
                nature: dict[str, Any] | None = None, draw_poincare: Callable[..., None] | None = None
                ) -> tuple[dict[str, Any], list[Path | str]]:
    """Write trace.csv and trace.json into `folder` (and Figs. 4 / 9a to `plot`), all or nothing; returns (the JSON
    data, the paths written). started: time.perf_counter() at the command's start (for wall_time_s); draw: the
    figure's drawing function draw(data, t, q_tip, v_tip, path) (`sim.plots.figures.plot_trace`), handed in by the
    caller with `plot` (the analysis imports no figure code: the figures sit above it); nature: the keys of
    `trace_nature`, added to trace.json; draw_poincare(data, path): with nature's "poincare", the figure
    poincare.png in `folder` (`sim.plots.dynamics.plot_poincare`)."""
    from sim.common.files import write_csv, write_json

    if plot and draw is None:
        raise ValueError("write_trace: a plot needs its drawing function (draw=sim.plots.figures.plot_trace)")

    data = {**trace_data(trace, settings), **(nature or {})}
    written: list[Path | str] = []
    try:
        written.append(write_csv(folder / "trace.csv", COLUMNS, trace_rows(trace)))
        if started is not None:
            data["wall_time_s"] = time.perf_counter() - started
        written.append(write_json(folder / "trace.json", data))
        if plot:
            draw(data, trace.signal.t, trace.signal["q_tip"], trace.signal["v_tip"], plot)
            written.append(plot)
        if draw_poincare is not None and "poincare" in data:
            draw_poincare(data, folder / "poincare.png")
            written.append(folder / "poincare.png")
    except BaseException:
        for path in written:  # all or nothing
            Path(path).unlink(missing_ok=True)
        raise
    return data, written
