"""Impact-hammer records to frequency response functions, as Appendix A of the seed paper measures the host: the hits
found in a continuous record and cut out, double hits and an overloaded (clipped) force detected, a force window and
an exponential response window, the H_1, H_2 and H_v estimators with the coherence averaged over the hits (the paper
took six hits and the H_v estimator, the geometric mean of H_1 and H_2), and the response integrated to displacement
in the frequency domain.

Processing (all times in s, forces in N, responses in SI units of their quantity):

* Pulses: runs of samples where |force| exceeds the threshold max(THRESHOLD_NOISE * sigma, THRESHOLD_PEAK * peak)
  (sigma: the force's noise, 1.4826 times its median absolute deviation; peak: the largest |force|); runs closer
  than 1 ms are one pulse. A pulse that starts within `rebound_s` of the previous hit's pulse is that hit's second
  impact: the hit is a double hit, rejected from the average (or only flagged, `reject_double_hits=False`).
* Clipping: a pulse whose peak sample is repeated (CLIP_SAMPLES or more samples within 1e-6 of it) was cut off by the
  amplifier's full scale; its force spectrum is wrong, so the record is refused (`SimulationInputError`).
* Blocks: each hit's block starts `pretrigger_s` before its pulse and is as long as the shortest spacing between hits
  (or `block` samples when given); a last hit the record cuts short (less than half the median spacing) is dropped.
* Windows: the force window keeps the force from the block's start to FORCE_WINDOW_TAIL_S after the pulse (a
  half-cosine taper over the same time) and zeroes the rest (noise, and a double hit's second pulse); the exponential
  window w(t) = exp(-(t - t_hit) / tau) multiplies force and response, tau chosen so that w = `exp_window_end` at the
  block's end. It makes a record that ends while a mode still rings decay inside the block, at the price of a known
  added decay rate 1/tau (1/s) on every pole: `remove_window_damping` takes it back out of identified poles
  (sigma = sigma_windowed - 1/tau, omega_d unchanged).
* Estimators per response, averaged over the kept hits: G_ff = <|F|^2>, G_xx = <|X|^2>, G_fx = <conj(F) X>;
  H_1 = G_fx / G_ff, H_2 = G_xx / conj(G_fx), coherence gamma^2 = |G_fx|^2 / (G_ff G_xx), and H_v = sqrt(H_1 H_2)
  (H_1 and H_2 share their phase, so H_v = H_1 / gamma).
* Integration: displacement per force from acceleration (divided by -omega^2) or velocity (by i omega); the
  frequency 0 is left out.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sim.common.errors import SimulationInputError

#: a pulse exceeds this many times the force's noise level ...
THRESHOLD_NOISE = 10.0
#: ... and this fraction of the record's largest force
THRESHOLD_PEAK = 0.05
#: samples at the peak value that mark a clipped (overloaded) force
CLIP_SAMPLES = 2
#: the force window ends this long after the pulse, with a half-cosine taper of the same length (s)
FORCE_WINDOW_TAIL_S = 1e-3
#: quantity of a response -> power of (i omega) that turns it into displacement
TO_DISPLACEMENT = {"acceleration": -2, "velocity": -1, "displacement": 0}


@dataclass(frozen=True)
class HammerRecord:
    """One continuous hammer-test record: sampling rate fs (Hz), the force (N) and the responses (name -> values in
    SI units), the quantity of each response ("acceleration", "velocity" or "displacement") and where it came from."""

    fs: float
    force: np.ndarray
    responses: dict[str, np.ndarray]
    quantities: dict[str, str]
    source: str = "arrays"


@dataclass(frozen=True)
class Hit:
    """One hit: its record's source, the pulse's first sample, its peak force (N), whether a second pulse followed it
    (double hit) and whether it entered the average."""

    source: str
    start: int
    peak_N: float
    double: bool = False
    used: bool = True
    note: str = ""

    def describe(self, fs: float) -> dict:
        return {"source": self.source, "time_s": self.start / fs, "peak_force_N": self.peak_N, "double_hit": self.double,
                "used": self.used, "note": self.note}


@dataclass(frozen=True)
class HammerSettings:
    """The processing's choices: block (samples; None: the shortest spacing of the hits), pretrigger_s (s),
    exp_window_end (the exponential window's value at the block's end, in (0, 1]; 1: no window), rebound_s (s: a pulse
    this soon after a hit makes it a double hit), reject_double_hits (drop them from the average, else only flag)."""

    block: int | None = None
    pretrigger_s: float = 2e-3
    exp_window_end: float = 0.01
    rebound_s: float = 0.1
    reject_double_hits: bool = True

    def __post_init__(self) -> None:
        if not 0.0 < self.exp_window_end <= 1.0:
            raise SimulationInputError(f"--exp-window must lie in (0, 1] (the window's value at the block's end; 1: "
                                       f"none), got {self.exp_window_end!r}")
        if self.block is not None and self.block < 64:
            raise SimulationInputError(f"--block must be at least 64 samples, got {self.block}")


@dataclass(frozen=True)
class FrfEstimate:
    """Averaged FRFs of displacement per force (m/N) of each response: frequencies_hz (Hz, without 0), H1, H2, Hv and
    coherence per response name, the hits, the exponential window's added decay rate window_decay (1/s; 0: none),
    fs (Hz) and block length (samples)."""

    frequencies_hz: np.ndarray
    H1: dict[str, np.ndarray]
    H2: dict[str, np.ndarray]
    Hv: dict[str, np.ndarray]
    coherence: dict[str, np.ndarray]
    hits: list[Hit] = field(default_factory=list)
    window_decay: float = 0.0
    fs: float = 0.0
    block: int = 0

    @property
    def names(self) -> list[str]:
        return list(self.Hv)


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and (exclusive) ends of the runs of True in `mask`."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def find_pulses(force: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(starts, ends, threshold N) of the force pulses above the threshold (module docstring), runs closer than 1 ms
    merged."""
    magnitude = np.abs(force - np.median(force))
    sigma = 1.4826 * float(np.median(np.abs(magnitude - np.median(magnitude)))) + 1e-300
    threshold = max(THRESHOLD_NOISE * sigma, THRESHOLD_PEAK * float(magnitude.max()))
    starts, ends = _runs(magnitude > threshold)
    if starts.size:
        keep = np.r_[True, starts[1:] - ends[:-1] > 1e-3 * fs]
        starts, ends = starts[keep], ends[np.r_[keep[1:], True]]
    return starts, ends, threshold


def find_hits(record: HammerRecord, settings: HammerSettings) -> tuple[list[Hit], list[tuple[int, int]]]:
    """The hits of one record and each hit's pulse (start, end) in samples; double hits flagged (module docstring).
    One line for a record without hits and for a clipped force."""
    force = record.force
    starts, ends, _ = find_pulses(force, record.fs)
    if starts.size == 0 or float(np.abs(force).max()) == 0.0:
        raise SimulationInputError(f"{record.source}: no hit found in the force (no pulse stands out of the noise); "
                                   "check the force column and its sensitivity")
    offset = np.median(force)
    hits: list[Hit] = []
    pulses: list[tuple[int, int]] = []
    rebound = settings.rebound_s * record.fs
    for s, e in zip(starts, ends):
        segment = np.abs(force[s:e] - offset)
        peak = float(segment.max())
        if int(np.sum(segment >= peak * (1 - 1e-6))) >= CLIP_SAMPLES and peak > 0:
            raise SimulationInputError(
                f"{record.source}: the force is clipped at the hit at t = {s / record.fs:.4g} s ({peak:.4g} N held for "
                f"{int(np.sum(segment >= peak * (1 - 1e-6)))} samples: the amplifier was overloaded); repeat the hit "
                "with a larger input range or a softer tip, or cut it out of the record")
        if hits and s - hits[-1].start < rebound:
            last = hits[-1]
            hits[-1] = Hit(last.source, last.start, last.peak_N, True, not settings.reject_double_hits,
                           f"second pulse {1e3 * (s - last.start) / record.fs:.3g} ms after the hit")
            continue
        hits.append(Hit(record.source, int(s), peak))
        pulses.append((int(s), int(e)))
    return hits, pulses


def frf_estimate(records: list[HammerRecord], settings: HammerSettings = HammerSettings()) -> FrfEstimate:
    """H_1, H_2, H_v and the coherence of displacement per force (m/N) of every response, averaged over the kept hits of
    all records (module docstring). The records must share the sampling rate and the response names; one line when a
    record has no hit, a clipped force, or no hit is left to average."""
    fs = records[0].fs
    names = list(records[0].responses)
    for record in records[1:]:
        if abs(record.fs / fs - 1) > 1e-9 or list(record.responses) != names:
            raise SimulationInputError(f"{record.source}: its sampling rate or responses differ from {records[0].source}'s "
                                       f"({fs:g} Hz, {', '.join(names)}); give records of one test")
    found = [(record, *find_hits(record, settings)) for record in records]
    pre = int(round(settings.pretrigger_s * fs))
    # the block: the shortest spacing of the hits of a record (pretrigger included), or the user's
    spacings = [b.start - a.start for _, hits, _ in found for a, b in zip(hits, hits[1:])]
    median = float(np.median(spacings)) if spacings else math.inf
    blocks, cut = [], []
    for record, hits, _ in found:
        n = record.force.size
        for i, hit in enumerate(hits):
            room = (hits[i + 1].start if i + 1 < len(hits) else n + pre) - hit.start
            if i + 1 == len(hits) and spacings and room < 0.5 * median:
                cut.append((id(record), i))
                continue
            blocks.append(room)
    block = (settings.block or int(min(blocks))) if blocks else 0
    if settings.block and blocks and settings.block > min(blocks):
        raise SimulationInputError(f"--block {settings.block} is longer than the shortest room between hits "
                                   f"({int(min(blocks))} samples); give a smaller block or leave it out")
    tau = math.inf if settings.exp_window_end >= 1 else (block - pre) / fs / -math.log(settings.exp_window_end)
    t = (np.arange(block) - pre) / fs
    exp_window = np.exp(-np.clip(t, 0, None) / tau) if math.isfinite(tau) else np.ones(block)
    tail = FORCE_WINDOW_TAIL_S * fs
    Gff = 0.0
    Gxx = {name: 0.0 for name in names}
    Gfx = {name: 0.0 for name in names}
    kept, all_hits = 0, []
    for record, hits, pulses in found:
        for i, (hit, (_, end)) in enumerate(zip(hits, pulses)):
            if (id(record), i) in cut:
                all_hits.append(Hit(hit.source, hit.start, hit.peak_N, hit.double, False, "the record ends too soon after it"))
                continue
            all_hits.append(hit)
            if not hit.used or block <= 0:
                continue
            lo = hit.start - pre
            rows = np.arange(lo, lo + block)
            inside = (rows >= 0) & (rows < record.force.size)
            f = np.zeros(block)
            f[inside] = record.force[rows[inside]] - np.median(record.force)
            x_of = {}
            for name in names:
                x = np.zeros(block)
                x[inside] = record.responses[name][rows[inside]]
                x_of[name] = x
            force_window = np.ones(block)
            stop = end - lo + tail
            after = np.arange(block) - stop
            force_window[after >= 0] = np.where(after[after >= 0] < tail, 0.5 * (1 + np.cos(np.pi * after[after >= 0] / tail)), 0.0)
            F = np.fft.rfft(f * force_window * exp_window)
            Gff = Gff + np.abs(F) ** 2
            for name in names:
                X = np.fft.rfft(x_of[name] * exp_window)
                Gxx[name] = Gxx[name] + np.abs(X) ** 2
                Gfx[name] = Gfx[name] + np.conj(F) * X
            kept += 1
    if kept == 0:
        sources = ", ".join(sorted({r.source for r in records}))
        raise SimulationInputError(f"{sources}: no hit left to average (every hit is a double hit or cut short by the "
                                   "record's end); repeat the test, or keep double hits with --keep-double-hits")
    frequencies = np.fft.rfftfreq(block, 1 / fs)[1:]
    omega = 2 * np.pi * frequencies
    H1, H2, Hv, coherence = {}, {}, {}, {}
    for name in names:
        gfx, gxx, gff = Gfx[name][1:], Gxx[name][1:], Gff[1:]
        to_disp = (1j * omega) ** TO_DISPLACEMENT[records[0].quantities[name]]
        h1 = gfx / gff * to_disp
        h2 = gxx / np.conj(gfx) * to_disp
        gamma2 = np.abs(gfx) ** 2 / (gff * gxx)
        H1[name], H2[name], coherence[name] = h1, h2, gamma2
        Hv[name] = h1 / np.sqrt(gamma2)
    return FrfEstimate(frequencies, H1, H2, Hv, coherence, hits=all_hits, window_decay=0.0 if math.isinf(tau) else 1.0 / tau,
                       fs=fs, block=block)


def remove_window_damping(poles: np.ndarray, window_decay: float) -> np.ndarray:
    """Poles lambda = -sigma + i omega_d (rad/s) with the exponential window's added decay rate (1/s) taken back out:
    sigma -> sigma - window_decay (module docstring)."""
    return np.asarray(poles) + window_decay
