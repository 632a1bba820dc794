"""Linearity of the host by stepped-sine base excitation without the IES (Appendix B of the seed paper, Fig. B.2):
per level the resonance and the half-power damping, a single-nonlinear-mode model with amplitude-dependent frequency
and damping (its backbone, and each level's FRF synthesized from it), and the interval of the damping ratio D_1 over
a response range, which the studies and `ies design` propagate (Table 2: 0.075-0.09 % over 0.58-0.95 mm).

Records (CSV, one file per level; units in the header as in `sim.measured.records`):

* a frequency response: ``frequency_Hz``, the tip's amplitude relative to the base ``amplitude_m`` (or mm, um; the
  magnitude of its fundamental harmonic, the paper's a) or its complex value ``real_m``, ``imag_m``, and the base
  amplitude ``a_base_m`` (one value, repeated on every row);
* or time records per frequency step: ``time_s``, ``frequency_Hz`` (the step's excitation frequency on every sample),
  the base's and the tip's absolute motion ``base_UNIT``, ``tip_UNIT`` (acceleration, velocity or displacement). Of
  each step the last STEADY_SHARE of its whole periods is used: the fundamental Fourier coefficients give a_base and
  the tip's amplitude relative to the base; a step whose base amplitude strays from the level's mean (the shaker's
  control) has its tip amplitude scaled to that mean, as a linear response would be.

Half-power damping: the peak of a / a_base (a parabola through the three highest points), the half-power frequencies
where (a / a_base)^2 falls to half the peak (linear interpolation), D = (f_2 - f_1) / (2 f_r).

Single nonlinear mode (similar to the paper's [45]): the resonant mode with amplitude-dependent natural frequency and
damping, s'' + 2 D(a) omega(a) s' + omega(a)^2 s = Gamma Omega^2 a_base cos(Omega t), tip amplitude a = phi_tip |s|,
so that a |omega(a)^2 - Omega^2 + 2 i D(a) omega(a) Omega| = G Omega^2 a_base with G = phi_tip Gamma (harmonic
balance). omega(a) = omega_0 (1 + c_1 u + c_2 u^2) and D(a) = D_0 + d_1 u + d_2 u^2 with u = a / a_ref (a_ref the largest
measured amplitude); omega_0, c, D_0, d and G are fitted to every measured point of every level at once (least squares
of the relative residual of that equation at the measured a, so magnitudes suffice). The backbone is omega(a); the
synthesized FRF of a level solves the equation for a at each frequency (every root, on a grid and by bisection).

Damping interval over a response range [a_lo, a_hi]: the least and largest D(a) there; the nominal D_1* is the mean of
D(a) over the range (Table 2's 0.085 % sits likewise inside 0.075-0.09 %). A range beyond the measured amplitudes is
an extrapolation: flagged, and said on stderr.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sim.common.errors import SimulationInputError
from sim.measured.records import TO_DISPLACEMENT, UNITS, _increasing, _split_header, _table

#: share of a step's whole periods (the last ones) analysed in a time record
STEADY_SHARE = 0.5
#: coefficients of omega(a) and D(a) beyond the constant
POLY_DEGREE = 2


@dataclass(frozen=True)
class LevelRecord:
    """One level's stepped sine: base amplitude a_base (m), excitation frequencies (Hz) and the tip's amplitude relative
    to the base (m) at each; source: the file."""

    a_base: float
    frequencies_hz: np.ndarray
    amplitude: np.ndarray
    source: str

    @property
    def gain(self) -> np.ndarray:
        """a / a_base (-)."""
        return self.amplitude / self.a_base


def read_level(path: str | os.PathLike) -> LevelRecord:
    """A level's record (module docstring): a frequency response or time records per frequency step."""
    path = Path(path)
    example = "frequency_Hz,amplitude_m,a_base_m"
    header, data = _table(path, "stepped-sine record", example)
    cols = {}
    for col, cell in enumerate(header):
        name, unit = _split_header(cell)
        if unit in ("deg", "rad"):  # a phase: the magnitudes suffice (module docstring)
            continue
        if unit not in UNITS:
            raise SimulationInputError(f"{path}: column '{cell}' has no unit this reader knows; e.g. '{example}' or "
                                       "'time_s,frequency_Hz,base_m_s2,tip_m_s2'")
        cols[name.lower()] = (col, *UNITS[unit])
    if "frequency" not in cols:
        raise SimulationInputError(f"{path}: no frequency_Hz column; e.g. '{example}'")
    fcol, _, ffac = cols["frequency"]
    if "time" in cols:
        return _from_time(path, data, cols)
    f = data[:, fcol] * ffac
    _increasing(path, f, "the frequency", "steps")
    if "a_base" not in cols:
        raise SimulationInputError(f"{path}: no a_base_m column (the base amplitude of this level); e.g. '{example}'")
    base = data[:, cols["a_base"][0]] * cols["a_base"][2]
    if np.ptp(base) > 1e-9 * abs(base[0]) or base[0] <= 0:
        raise SimulationInputError(f"{path}: a_base must be one positive value on every row (one level per file)")
    if "amplitude" in cols:
        amplitude = np.abs(data[:, cols["amplitude"][0]] * cols["amplitude"][2])
    elif "real" in cols and "imag" in cols:
        amplitude = np.hypot(data[:, cols["real"][0]] * cols["real"][2], data[:, cols["imag"][0]] * cols["imag"][2])
    else:
        raise SimulationInputError(f"{path}: no response column: give amplitude_m, or real_m and imag_m")
    return LevelRecord(float(base[0]), f, amplitude, str(path))


def _from_time(path: Path, data: np.ndarray, cols: dict) -> LevelRecord:
    for need in ("base", "tip"):
        if need not in cols:
            raise SimulationInputError(f"{path}: a time record per step needs the columns base_UNIT and tip_UNIT "
                                       "(absolute motions, e.g. base_m_s2,tip_m_s2)")
    t = data[:, cols["time"][0]] * cols["time"][2]
    _increasing(path, t, "the time", "samples")
    f = data[:, cols["frequency"][0]] * cols["frequency"][2]
    steps = np.flatnonzero(np.r_[True, np.diff(f) != 0])
    freqs, base_amp, tip_amp = [], [], []
    for i, start in enumerate(steps):
        stop = steps[i + 1] if i + 1 < steps.size else f.size
        fs = 1.0 / float(np.mean(np.diff(t[start:stop]))) if stop - start > 1 else 0.0
        omega = 2 * np.pi * f[start]
        whole = int(np.floor((stop - start) / fs * f[start])) if fs else 0
        use = int(round(max(1, int(STEADY_SHARE * whole)) / f[start] * fs))
        if whole < 2 or use < 8:
            raise SimulationInputError(f"{path}: the step at {f[start]:g} Hz holds fewer than two whole periods; record "
                                       "longer steps")
        window = slice(stop - use, stop)
        phase = np.exp(-1j * omega * t[window])
        coef = {}
        for name in ("base", "tip"):
            col, quantity, factor = cols[name]
            c = 2 * np.mean(data[window, col] * factor * phase)
            coef[name] = c * (1j * omega) ** TO_DISPLACEMENT[quantity]
        freqs.append(f[start])
        base_amp.append(abs(coef["base"]))
        tip_amp.append(abs(coef["tip"] - coef["base"]))
    freqs = np.array(freqs)
    _increasing(path, freqs, "the steps' frequency", "steps")
    base = np.array(base_amp)
    return LevelRecord(float(np.mean(base)), freqs, np.array(tip_amp) * np.mean(base) / base, str(path))


@dataclass(frozen=True)
class HalfPower:
    """Half-power estimate of one level: resonance frequency (Hz), damping ratio (-) and the peak amplitude (m); the
    damping is NaN when a half-power frequency lies outside the steps."""

    frequency_hz: float
    damping_ratio: float
    peak_amplitude: float


def half_power(level: LevelRecord) -> HalfPower:
    """Resonance and half-power damping of a level (module docstring)."""
    f, g = level.frequencies_hz, level.gain
    k = int(np.argmax(g))
    fr, peak = float(f[k]), float(g[k])
    if 0 < k < f.size - 1:  # parabola through the three highest points
        x, y = f[k - 1:k + 2], g[k - 1:k + 2]
        a, b, c = np.polyfit(x - f[k], y, 2)
        if a < 0:
            fr, peak = f[k] - b / (2 * a), c - b * b / (4 * a)
    level2 = peak**2 / 2
    below = np.flatnonzero(g[:k] ** 2 < level2)
    above = np.flatnonzero(g[k:] ** 2 < level2)
    if below.size == 0 or above.size == 0:
        return HalfPower(fr, float("nan"), peak * level.a_base)
    i, j = below[-1], k + above[0]
    f1 = np.interp(level2, [g[i] ** 2, g[i + 1] ** 2], [f[i], f[i + 1]])
    f2 = np.interp(level2, [g[j] ** 2, g[j - 1] ** 2], [f[j], f[j - 1]])
    return HalfPower(fr, float((f2 - f1) / (2 * fr)), peak * level.a_base)


@dataclass(frozen=True)
class NonlinearMode:
    """A single nonlinear mode (module docstring): omega_0 (rad/s), c (frequency coefficients), D_0, d (damping
    coefficients), G = phi_tip Gamma (sqrt(kg)/sqrt(kg) = -: tip amplitude per base amplitude per Omega^2/den) and the
    reference amplitude a_ref (m)."""

    omega_0: float
    c: tuple[float, ...]
    D_0: float
    d: tuple[float, ...]
    G: float
    a_ref: float

    def omega(self, a: np.ndarray) -> np.ndarray:
        """Backbone omega(a) (rad/s) at tip amplitudes a (m)."""
        u = np.asarray(a, float) / self.a_ref
        return self.omega_0 * (1 + sum(ci * u ** (i + 1) for i, ci in enumerate(self.c)))

    def damping(self, a: np.ndarray) -> np.ndarray:
        """D(a) (-) at tip amplitudes a (m)."""
        u = np.asarray(a, float) / self.a_ref
        return self.D_0 + sum(di * u ** (i + 1) for i, di in enumerate(self.d))

    def residual(self, a: np.ndarray, Omega: np.ndarray, a_base: np.ndarray) -> np.ndarray:
        """a |omega(a)^2 - Omega^2 + 2 i D(a) omega(a) Omega| / (G Omega^2 a_base) - 1 (-)."""
        w = self.omega(a)
        den = np.abs(w**2 - Omega**2 + 2j * self.damping(a) * w * Omega)
        return a * den / (self.G * Omega**2 * a_base) - 1.0

    def responses(self, Omega: float, a_base: float, a_max: float) -> np.ndarray:
        """Every tip amplitude a (m) in (0, a_max] that solves the harmonic-balance equation at Omega (rad/s)."""
        return balance_roots(self.omega, self.damping, self.G, Omega, a_base, a_max)


def balance_roots(omega_of, damping_of, G: float, Omega: float, a_base: float, a_max: float) -> np.ndarray:
    """Every tip amplitude a (m) in (a_max 1e-4, a_max] with a |omega(a)^2 - Omega^2 + 2 i D(a) omega(a) Omega| =
    G Omega^2 a_base (module docstring), for backbone functions omega_of(a) (rad/s) and damping_of(a) (-): sign changes
    on a log grid, refined by bisection."""
    from scipy.optimize import brentq

    def residual(a):
        w = omega_of(a)
        return a * np.abs(w**2 - Omega**2 + 2j * damping_of(a) * w * Omega) / (G * Omega**2 * a_base) - 1.0

    grid = np.geomspace(a_max * 1e-4, a_max, 400)
    r = residual(grid)
    return np.array([brentq(lambda x: float(residual(np.array(x))), grid[i], grid[i + 1], xtol=1e-14 * a_max)
                     for i in np.flatnonzero(np.sign(r[:-1]) != np.sign(r[1:]))])


def fit_nonlinear_mode(levels: list[LevelRecord]) -> NonlinearMode:
    """The single nonlinear mode fitted to every point of every level (module docstring)."""
    from scipy.optimize import least_squares

    Omega = np.concatenate([2 * np.pi * lv.frequencies_hz for lv in levels])
    a = np.concatenate([lv.amplitude for lv in levels])
    a_base = np.concatenate([np.full(lv.amplitude.size, lv.a_base) for lv in levels])
    lowest = min(levels, key=lambda lv: lv.a_base)
    start = half_power(lowest)
    D0 = start.damping_ratio if np.isfinite(start.damping_ratio) else 1e-3
    w0 = 2 * np.pi * start.frequency_hz
    a_ref = float(a.max())
    G0 = start.peak_amplitude / lowest.a_base * 2 * D0
    n = POLY_DEGREE

    def model(x: np.ndarray) -> NonlinearMode:
        return NonlinearMode(w0 * x[0], tuple(1e-3 * x[1:1 + n]), D0 * x[1 + n], tuple(D0 * x[2 + n:2 + 2 * n]),
                             G0 * x[-1], a_ref)

    x0 = np.r_[1.0, np.zeros(n), 1.0, np.zeros(n), 1.0]
    fit = least_squares(lambda x: model(x).residual(a, Omega, a_base), x0, x_scale="jac", xtol=1e-14, ftol=1e-14)
    return model(fit.x)


@dataclass(frozen=True)
class DampingInterval:
    """D_1 over a response range [a_lo, a_hi] (m): the least and largest D(a), the nominal (the mean over the range)
    and whether the range reaches beyond the measured amplitudes (extrapolated)."""

    a_lo: float
    a_hi: float
    low: float
    high: float
    nominal: float
    extrapolated: bool


def damping_interval(mode: NonlinearMode, a_lo: float, a_hi: float, measured: tuple[float, float]) -> DampingInterval:
    """The damping interval of `mode` over [a_lo, a_hi] (m) (module docstring); measured: the least and largest
    measured amplitude (m)."""
    if not 0 < a_lo < a_hi:
        raise SimulationInputError(f"--range {a_lo:g}:{a_hi:g} m: give LO:HI with 0 < LO < HI, e.g. 0.58mm:0.95mm")
    grid = np.linspace(a_lo, a_hi, 201)
    D = mode.damping(grid)
    if np.any(D <= 0):
        raise SimulationInputError(f"the fitted damping turns negative in the range {1e3 * a_lo:g}-{1e3 * a_hi:g} mm (an "
                                   "extrapolation too far); give a range inside the measured amplitudes")
    extrapolated = a_lo < measured[0] * (1 - 1e-9) or a_hi > measured[1] * (1 + 1e-9)
    return DampingInterval(a_lo, a_hi, float(D.min()), float(D.max()), float(np.mean(D)), bool(extrapolated))
