"""Impact detection from the wall accelerations, Appendix D.1 of the seed paper.

1. The accelerations near both cavity walls (``a_left``, ``a_right``) are high-pass filtered at 20 kHz,
   just above the highest relevant bending mode, so that only the impulsive part of an impact remains.
2. Their envelopes are taken (magnitude of the analytic signal, Hilbert transform).
3. The peaks of the larger of the two envelopes are located, at least `min_separation` apart (about one
   contact duration); each peak time is refined by a parabola through the three samples around it. The
   band left between 20 kHz and the Nyquist frequency is narrow (5.6 kHz at 51.2 kHz), so the filtered
   envelope of a strong impact has side lobes for a millisecond: a peak that the filter's ring-down of a
   larger peak explains is not an impact (`ring_down_bound`).
4. Peaks below a threshold are discarded. The threshold is a factor times the root-mean-square of the tip
   acceleration ``a_tip`` low-pass filtered at 120 Hz, just above the resonant mode (Appendix D.1, nominal
   factor 1; Appendix D.2 varies it from 0.8 to 1).

Each impact is assigned to the wall whose sensor sees the larger envelope peak (both sensors see a strong
impact, the nearer one more intensely). The impacts per excitation period are the count divided by the
number of periods in the record, with the excitation frequency given or estimated from the tip signal
(`estimate_excitation_hz`).

Filters are Butterworth designs (second-order sections) applied forwards and backwards (zero phase: the
peaks stay in place); the cut-off is the -3 dB point of the single pass, so the zero-phase gain there is
1/2 (the 120 Hz low-pass passes 0.55 of a 117 Hz resonant motion into the threshold's RMS; the paper does
not name its filters). As peaks are found before the threshold is applied, the impacts at a higher threshold are always a
subset of those at a lower one.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from scipy import optimize, signal as sps

from sim.common.errors import SimulationInputError
from sim.analysis.signals import Signal, as_signal, make_signal

HIGHPASS_HZ = 20e3
LOWPASS_HZ = 120.0
#: Shortest time between two impacts (s): about one contact duration of the rig (~80 us).
MIN_SEPARATION = 1e-4
FILTER_ORDER = 4
#: A peak within RING_DOWN_SPAN (s) of a larger one is its filter ring-down if it is at most RING_DOWN_MARGIN
#: times what the high-pass leaves of an impulse at that lag (`ring_down_bound`); the margin covers bursts
#: that last longer than an impulse. On the synthetic signals (70 of `synthetic_impact_signal`: 1-4 impacts
#: per period, regular and irregular, 10 seeds) false peaks are up to 43 % of the detections without the
#: rule, up to 8.4 % at margin 2 and 2.8 % at margin 3, with the same impacts found (>= 98.3 %).
RING_DOWN_SPAN = 10e-3
RING_DOWN_MARGIN = 3.0
NOMINAL_THRESHOLD = 1.0
#: Appendix D.2: 80 % to 100 % of the nominal threshold.
DEFAULT_THRESHOLDS = (0.8, 0.85, 0.9, 0.95, 1.0)
#: Points of a threshold range given as START:STOP.
RANGE_POINTS = 5
COLUMNS = ("a_left", "a_right", "a_tip")


@dataclass(frozen=True)
class ImpactDetection:
    """Impacts found by `detect_impacts` (Appendix D.1).

    times (s), walls ("left", "right", or "unknown" when both sensors see the same), peaks (envelope height,
    m/s^2): every impact at the lowest threshold, in time order; thresholds: the factors (-) applied to
    reference_rms, the RMS of the low-passed tip acceleration (m/s^2); excitation_hz (Hz) and whether it
    was estimated; fs (Hz), duration (s) of the signal; highpass_hz, lowpass_hz (Hz), min_separation (s):
    the settings used.
    """

    times: np.ndarray
    walls: tuple[str, ...]
    peaks: np.ndarray
    thresholds: np.ndarray
    reference_rms: float
    excitation_hz: float
    excitation_estimated: bool
    fs: float
    duration: float
    highpass_hz: float
    lowpass_hz: float
    min_separation: float

    @property
    def n_periods(self) -> float:
        """Excitation periods covered by the signal (-)."""
        return self.duration * self.excitation_hz

    def above(self, factor: float) -> np.ndarray:
        """Boolean mask of the impacts whose peak reaches factor * reference_rms."""
        return self.peaks >= factor * self.reference_rms

    @property
    def impacts_per_period(self) -> np.ndarray:
        """Detected impacts per excitation period at each threshold (Appendix D.2)."""
        return np.array([np.count_nonzero(self.above(f)) for f in self.thresholds]) / self.n_periods

    def to_dict(self) -> dict:
        """Plain data for JSON (SI units). 'impacts' are those at the lowest threshold; each has its peak
        and its level = peak / reference_rms, so the list at any threshold is the impacts with level >= it."""
        return {
            "impacts": [{"t": float(t), "wall": w, "peak": float(p), "level": float(p / self.reference_rms)}
                        for t, w, p in zip(self.times, self.walls, self.peaks)],
            "impacts_per_period": [float(v) for v in self.impacts_per_period],
            "thresholds": [float(f) for f in self.thresholds],
            "fs": self.fs,
            "reference_rms": self.reference_rms,
            "excitation_hz": self.excitation_hz,
            "excitation_estimated": self.excitation_estimated,
            "n_periods": self.n_periods,
            "duration": self.duration,
            "highpass_hz": self.highpass_hz,
            "lowpass_hz": self.lowpass_hz,
            "min_separation": self.min_separation,
        }


def parse_thresholds(text: str) -> np.ndarray:
    """Threshold factors from 'F' (one value), 'START:STOP' (RANGE_POINTS values) or 'START:STOP:N'."""
    parts = str(text).split(":")
    try:
        if len(parts) == 1:
            values = np.array([float(parts[0])])
        elif len(parts) in (2, 3):
            n = int(parts[2]) if len(parts) == 3 else RANGE_POINTS
            start, stop = float(parts[0]), float(parts[1])
            if n < 2 or stop <= start:
                raise ValueError
            values = np.linspace(start, stop, n)
        else:
            raise ValueError
    except ValueError:
        raise SimulationInputError(f"threshold must be a factor such as 1.0 or a range START:STOP[:N] with "
                                   f"START < STOP and N >= 2 (e.g. 0.8:1.0), got {text!r}") from None
    return check_thresholds(values)


def check_thresholds(values) -> np.ndarray:
    """Validate threshold factors (positive, finite; or the text of `parse_thresholds`) as a sorted array."""
    if isinstance(values, str):
        return parse_thresholds(values)
    values = np.atleast_1d(np.asarray(values, dtype=float))
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise SimulationInputError(f"thresholds must be positive factors of the reference RMS, got {values.tolist()}")
    return np.sort(values)


def zero_phase_filter(x: np.ndarray, fs: float, cutoff_hz: float, kind: str, order: int = FILTER_ORDER) -> np.ndarray:
    """Butterworth 'lowpass' or 'highpass' filter of x (sampled at fs, Hz) applied forwards and backwards."""
    sos = sps.butter(order, cutoff_hz, btype=kind, fs=fs, output="sos")
    return sps.sosfiltfilt(sos, x)


def envelope(x: np.ndarray) -> np.ndarray:
    """Envelope of an oscillating signal: magnitude of its analytic signal (Hilbert transform)."""
    return np.abs(sps.hilbert(x))


def estimate_excitation_hz(x: np.ndarray, fs: float, max_hz: float) -> float:
    """Frequency (Hz) of the strongest harmonic component of x below max_hz (Appendix D.2 needs the period).

    The largest peak of the Hann-windowed spectrum (DC and the lowest two bins excluded) is refined by a
    least-squares fit of c + a cos(2 pi f t) + b sin(2 pi f t) over f within one bin of it (unfiltered x:
    components far from f barely change the fit, while a filter's edge transients would bias it). Free
    vibration of the resonant mode (set off by the impacts) pulls the estimate towards omega_1: by 0.1 %
    (almost periodic) and 0.2 % (strongly modulated response) on simulated traces of the rig at level 7.4.
    """
    n = x.size
    resolution = fs / n
    if max_hz <= 3.0 * resolution:
        raise SimulationInputError(
            f"the signal lasts {n / fs:.4g} s, too short to estimate the excitation frequency below {max_hz:g} Hz "
            f"(needs more than {3.0 / max_hz:.3g} s); give the excitation frequency")
    nfft = 1 << int(np.ceil(np.log2(8 * n)))
    spectrum = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(n), nfft))
    freqs = np.fft.rfftfreq(nfft, 1.0 / fs)
    band = np.flatnonzero((freqs > 2.0 * resolution) & (freqs <= max_hz))
    f0 = freqs[band[np.argmax(spectrum[band])]]
    t = np.arange(n) / fs

    def misfit(f: float) -> float:
        basis = np.column_stack([np.ones(n), np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)])
        coefficients = np.linalg.lstsq(basis, x, rcond=None)[0]
        return float(np.sum((x - basis @ coefficients) ** 2))

    fit = optimize.minimize_scalar(misfit, bounds=(max(f0 - resolution, resolution), f0 + resolution),
                                   method="bounded", options={"xatol": 1e-7 * f0})
    return float(fit.x)


#: largest relative difference between a given excitation frequency and the signal's dominant one
EXCITATION_TOLERANCE = 0.1


def check_excitation_hz(given: float, x: np.ndarray, fs: float, max_hz: float, what: str) -> float:
    """A given excitation frequency (Hz), positive and within EXCITATION_TOLERANCE of the signal's dominant component
    below max_hz (`estimate_excitation_hz` of x, e.g. the tip acceleration `what`; on a short signal within two
    frequency bins fs / n); one SimulationInputError line otherwise. A signal too short for the estimate is taken at
    its word."""
    given = float(given)
    if not np.isfinite(given) or given <= 0:
        raise SimulationInputError(f"the excitation frequency must be positive (Hz), got {given!r}")
    try:
        dominant = estimate_excitation_hz(x, fs, max_hz)
    except SimulationInputError:
        return given
    resolution = fs / x.size  # Hz: a short signal knows its frequency only to a few of these
    if abs(given - dominant) > max(EXCITATION_TOLERANCE * dominant, 2.0 * resolution):
        raise SimulationInputError(
            f"--excitation-hz {given:g} Hz is far from the signal's dominant frequency {dominant:.4g} Hz (in {what}, "
            f"more than {EXCITATION_TOLERANCE:.0%} apart); omit --excitation-hz to use the estimate, or check the "
            "signal's time column (s)")
    return given


def detect_impacts(source: Signal | str | os.PathLike, thresholds=DEFAULT_THRESHOLDS, *,
                   excitation_hz: float | None = None, highpass_hz: float = HIGHPASS_HZ,
                   lowpass_hz: float = LOWPASS_HZ, min_separation: float = MIN_SEPARATION) -> ImpactDetection:
    """Detect impacts in a signal (a CSV path or a Signal with a_left, a_right, a_tip), Appendix D.1.

    thresholds: factors of the RMS of the low-passed tip acceleration (one value, several, or the option text
    'F', 'START:STOP[:N]' of `parse_thresholds`); excitation_hz:
    the excitation frequency (Hz) for the impacts per period, estimated from a_tip when None; highpass_hz,
    lowpass_hz: cut-offs (Hz) of the wall and tip filters; min_separation: shortest time between impacts (s).
    Raises SimulationInputError with one line for a bad signal or settings (e.g. fs <= 2 highpass_hz).
    """
    factors = check_thresholds(thresholds)
    signal = as_signal(source, COLUMNS)
    fs = signal.fs
    highpass_hz, lowpass_hz, min_separation = float(highpass_hz), float(lowpass_hz), float(min_separation)
    if not np.isfinite(highpass_hz) or highpass_hz <= 0:
        raise SimulationInputError(f"the high-pass cut-off must be a positive frequency in Hz, got {highpass_hz!r}")
    if fs <= 2.0 * highpass_hz:
        raise SimulationInputError(
            f"{signal.source}: sampling rate {fs:.6g} Hz is too low for the {highpass_hz:g} Hz high-pass (needs more "
            f"than {2 * highpass_hz:g} Hz); record faster or lower the high-pass cut-off")
    if not np.isfinite(lowpass_hz) or not 0 < lowpass_hz < highpass_hz:
        raise SimulationInputError(f"the low-pass cut-off must lie between 0 and the high-pass cut-off "
                                   f"{highpass_hz:g} Hz, got {lowpass_hz!r}")
    if not np.isfinite(min_separation) or min_separation < 0:
        raise SimulationInputError(f"min_separation must be >= 0 s, got {min_separation!r}")
    if signal.duration < 2.0 / lowpass_hz:
        raise SimulationInputError(
            f"{signal.source}: the signal lasts {signal.duration:.3g} s; the threshold (RMS of the tip acceleration "
            f"low-passed at {lowpass_hz:g} Hz) needs at least two periods of the cut-off, {2.0 / lowpass_hz:.3g} s")
    tip = zero_phase_filter(signal["a_tip"], fs, lowpass_hz, "lowpass")
    reference_rms = float(np.sqrt(np.mean(tip**2)))
    if reference_rms <= 0:
        raise SimulationInputError(f"{signal.source}: the low-passed tip acceleration is zero; no threshold reference")
    if excitation_hz is None:
        excitation, estimated = estimate_excitation_hz(signal["a_tip"], fs, lowpass_hz), True
    else:
        excitation = check_excitation_hz(excitation_hz, signal["a_tip"], fs, lowpass_hz, "a_tip")
        estimated = False
    walls = np.vstack([envelope(zero_phase_filter(signal[name], fs, highpass_hz, "highpass"))
                       for name in ("a_left", "a_right")])
    combined = walls.max(axis=0)
    distance = max(1, int(round(min_separation * fs)))
    peaks, _ = sps.find_peaks(combined, height=factors[0] * reference_rms, distance=distance)
    peaks = _without_ring_down(peaks, combined[peaks], ring_down_bound(fs, highpass_hz))
    half = distance // 2
    seen = np.array([[w[max(p - half, 0):p + half + 1].max() for w in walls] for p in peaks]).reshape(-1, 2)
    return ImpactDetection(
        times=signal.t[0] + _refined_peak_index(combined, peaks) / fs,
        walls=tuple(_wall(left, right) for left, right in seen), peaks=combined[peaks],
        thresholds=factors, reference_rms=reference_rms, excitation_hz=excitation, excitation_estimated=estimated,
        fs=fs, duration=signal.duration, highpass_hz=highpass_hz, lowpass_hz=lowpass_hz,
        min_separation=min_separation)


def ring_down_bound(fs: float, highpass_hz: float, span: float = RING_DOWN_SPAN) -> np.ndarray:
    """Largest envelope, relative to its peak, that the zero-phase high-pass leaves at a lag of k samples
    or more from an impulse (k = 0 .. span * fs): the non-increasing hull of the filtered impulse's envelope."""
    k = int(round(span * fs))
    impulse = np.zeros(2 * k + 1)
    impulse[k] = 1.0
    response = envelope(zero_phase_filter(impulse, fs, highpass_hz, "highpass"))[k:]
    return np.maximum.accumulate((response / response[0])[::-1])[::-1]


def _without_ring_down(peaks: np.ndarray, heights: np.ndarray, bound: np.ndarray,
                       margin: float = RING_DOWN_MARGIN) -> np.ndarray:
    """The peaks (ascending sample indices) that no larger peak explains as its filter ring-down: going from
    the largest down, a peak is dropped if its height <= margin * (height of a kept peak) * bound[lag]."""
    kept = np.zeros(peaks.size, dtype=bool)
    first = np.searchsorted(peaks, peaks - bound.size + 1)  # the neighbours within the bound's span
    stop = np.searchsorted(peaks, peaks + bound.size)
    for q in np.argsort(-heights, kind="stable"):
        near = first[q] + np.flatnonzero(kept[first[q]:stop[q]])
        if not np.any(heights[q] <= margin * heights[near] * bound[np.abs(peaks[near] - peaks[q])]):
            kept[q] = True
    return peaks[kept]


def _wall(left_peak: float, right_peak: float) -> str:
    """The wall whose sensor sees the larger peak; 'unknown' when both see the same (identical sensors, as
    in a beam model where both walls are one point)."""
    if abs(left_peak - right_peak) <= 1e-9 * max(left_peak, right_peak):
        return "unknown"
    return "left" if left_peak > right_peak else "right"


def _refined_peak_index(y: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """Fractional sample index of each peak from the parabola through it and its neighbours."""
    index = peaks.astype(float)
    inner = (peaks > 0) & (peaks < y.size - 1)
    p = peaks[inner]
    left, middle, right = y[p - 1], y[p], y[p + 1]
    curvature = left - 2.0 * middle + right
    shift = np.where(curvature < 0, 0.5 * (left - right) / np.where(curvature < 0, curvature, 1.0), 0.0)
    index[inner] += np.clip(shift, -0.5, 0.5)
    return index


def match_impacts(detected: np.ndarray, reference: np.ndarray, tolerance: float = 2e-4) -> np.ndarray:
    """One-to-one matching of detected to reference impact times (s): greedily the nearest pair first,
    pairs farther apart than tolerance (s) never. Returns an (m, 2) array of index pairs (detected, reference).
    """
    detected, reference = np.asarray(detected, dtype=float), np.asarray(reference, dtype=float)
    distance = np.abs(detected[:, None] - reference[None, :])
    candidates = np.argwhere(distance <= tolerance)
    candidates = candidates[np.argsort(distance[candidates[:, 0], candidates[:, 1]], kind="stable")]
    used_detected, used_reference, pairs = set(), set(), []
    for i, j in candidates:
        if i not in used_detected and j not in used_reference:
            used_detected.add(i)
            used_reference.add(j)
            pairs.append((i, j))
    return np.array(sorted(pairs), dtype=int).reshape(-1, 2)


@dataclass(frozen=True)
class SyntheticImpacts:
    """A synthetic measurement with known impacts: signal (t, a_left, a_right, a_tip), impact onsets times
    (s) and their walls."""

    signal: Signal
    times: np.ndarray
    walls: tuple[str, ...]


#: Bending modes that impacts set ringing in the synthetic signals (Hz, D), the rig's modes 2-7 (`ies modes`).
SYNTHETIC_RINGING = ((876.7, 0.0044), (2501.1, 0.0005), (4694.3, 0.0031), (7203.4, 0.001), (10176.1, 0.001),
                     (13171.5, 0.001))


def synthetic_impact_signal(impacts_per_period: float, *, irregular: bool = False, periods: int = 50,
                            excitation_hz: float = 117.0, fs: float = 51.2e3, tip_amplitude: float = 1e-3,
                            strength: tuple[float, float] = (2.0, 20.0), crosstalk: tuple[float, float] = (0.2, 0.6),
                            burst_hz: tuple[float, float] = (20e3, 25e3), noise: float = 0.05,
                            seed: int = 0) -> SyntheticImpacts:
    """Wall and tip accelerations with known impacts, to validate the detector of Appendix D.1 (seeded).

    Carrier: the resonant motion, tip acceleration (2 pi excitation_hz)^2 tip_amplitude (m) at the excitation
    frequency (Hz), the walls 1.04 times it (phi_c / phi_tip of the rig). Regular trains (almost periodic
    response) have `impacts_per_period` impacts per period at fixed phases (jitter 1 % of a period) on
    alternating walls; irregular trains (strongly modulated response) have gamma-distributed intervals with
    that mean (at least 1 ms), mostly alternating walls, and a carrier and impact strengths modulated over
    8 and 10 periods. Each impact at time t_k adds to its wall's sensor a burst
    B (u / tau) exp(1 - u / tau) cos(2 pi f_b u), u = t - t_k >= 0, tau = 40 us (peak at the contact's middle),
    f_b uniform in burst_hz, B = (carrier amplitude) times a factor log-uniform in `strength`; the other
    wall's sensor gets a fraction uniform in `crosstalk` of it; both walls and the tip ring in the rig's
    modes 2-7 (SYNTHETIC_RINGING, amplitudes up to B / 5). White noise of standard deviation noise times
    the carrier amplitude on every channel. Sampling rate fs (Hz).
    """
    rng = np.random.default_rng(seed)
    period = 1.0 / excitation_hz
    n = int(round(periods * period * fs))
    t = np.arange(n) / fs
    carrier = (2 * np.pi * excitation_hz) ** 2 * tip_amplitude
    modulation = (lambda x: 1.0 + 0.3 * np.sin(2 * np.pi * x / (8 * period))) if irregular else (lambda x: 1.0 + 0 * x)
    if irregular:
        intervals = np.maximum(rng.gamma(2.0, period / impacts_per_period / 2.0, size=4 * n), 1e-3)
        times = 0.5e-3 + np.cumsum(intervals)
        times = times[times < t[-1] - 1e-3]
        alternate = rng.random(times.size) < 0.8
        left = np.logical_xor.accumulate(np.r_[True, alternate[1:]])
        scale = (1.0 + 0.3 * np.sin(2 * np.pi * times / (10 * period))) * modulation(times)
    else:
        k = int(impacts_per_period)
        phases = (np.arange(periods * k) + 0.25) / k + rng.normal(0.0, 0.01, periods * k)
        times = phases * period
        times = times[(times > 0.5e-3) & (times < t[-1] - 1e-3)]
        left = np.arange(times.size) % 2 == 0
        scale = np.ones(times.size)
    amplitude = carrier * np.exp(rng.uniform(*np.log(strength), size=times.size)) * scale
    wave = carrier * modulation(t) * np.cos(2 * np.pi * excitation_hz * t)
    a_left, a_right, a_tip = 1.04 * wave, 1.04 * wave, wave.copy()
    tau = 40e-6
    burst_window = int(20 * tau * fs)
    first = np.ceil(times * fs).astype(int)  # first sample at or after each impact
    for start, t_k, on_left, B in zip(first, times, left, amplitude):
        u = t[start:start + burst_window] - t_k
        burst = B * (u / tau) * np.exp(1.0 - u / tau) * np.cos(2 * np.pi * rng.uniform(*burst_hz) * u + rng.uniform(0, 2 * np.pi))
        own, other = (a_left, a_right) if on_left else (a_right, a_left)
        own[start:start + u.size] += burst
        other[start:start + u.size] += rng.uniform(*crosstalk) * burst
    for f, D in SYNTHETIC_RINGING:
        # sum_k c_k exp(lam (t - t_k)) for t >= t_k, lam = -D w + i w, as one first-order recursion over the samples
        lam = complex(-D * 2 * np.pi * f, 2 * np.pi * f * np.sqrt(1 - D**2))
        for channel in (a_left, a_right, a_tip):
            kicks = np.zeros(n, dtype=complex)
            np.add.at(kicks, first, rng.uniform(0.0, 0.2, times.size) * amplitude * np.exp(lam * (t[first] - times)))
            channel += sps.lfilter([1.0], [1.0, -np.exp(lam / fs)], kicks).imag
    for channel in (a_left, a_right, a_tip):
        channel += rng.normal(0.0, noise * carrier, n)
    walls = tuple("left" if on_left else "right" for on_left in left)
    signal = make_signal(t, {"a_left": a_left, "a_right": a_right, "a_tip": a_tip}, "synthetic impacts", COLUMNS)
    return SyntheticImpacts(signal, times, walls)
