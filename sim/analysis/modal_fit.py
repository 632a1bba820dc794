"""Modal reconstruction of the tip velocity between impacts, Eq. 9 of the seed paper (Sect. 5.5).

Between two impacts the beam is linear, and its tip displacement is the particular solution plus the free
vibration of N modes (Eq. 9, time tau from the window's start):

    q_tip = phi_tip,1 (A cos Omega tau + B sin Omega tau)
            + sum_j phi_tip,j exp(-D_j omega_j tau) (alpha_j cos omega_d,j tau + beta_j sin omega_d,j tau).

Eq. 9 keeps the particular solution of the resonant mode only. Here every mode has its own, from the modal
model's response to the harmonic base motion (Eq. 7), with the same two unknowns (the real and imaginary
part of P):

    p_j = Re(P H_j e^{i Omega tau}),   H_j = (phi_j^T M b) / (omega_j^2 - Omega^2 + 2 i D_j omega_j Omega),

P = a_base Omega^2 e^{i phase} (m/s^2); mode 1's part is Eq. 9's A cos + B sin. The higher modes' particular
parts are small, but next to a small free vibration they are not: leaving them out puts up to 16 % errors
into the energy of a weakly excited mode (simulated strongly modulated response at 7.4, eta = 0.99).

The fit is made on velocity level (the tip velocity v_tip, relative to the base) by linear least squares in
each window between consecutive impacts, leaving out a guard interval after an impact (the contact) and
before the next one. Instead of (alpha_j, beta_j) each mode is described by its state at the window's start,
s_j(0) and s_j'(0), through the free responses h_j (s = 1, s' = 0) and g_j (s = 0, s' = 1); the particular
solution enters less the free response that starts from its own initial state, so it does not change the
state at the start:

    s_j = s_j(0) h_j + s_j'(0) g_j + p_j - p_j(0) h_j - p_j'(0) g_j.

This is the same span as with (A, B, alpha_j, beta_j), which follow from it, but it removes the
near-collinearity that makes Eq. 9 ill-posed over short windows: with Omega close to omega_1 the particular
solution and the free mode 1 differ only by the slow beat (omega_1 - Omega) tau, so only their sum is well
determined. Here that sum is the state of mode 1 at the window's start, determined as well as any other
mode; P (and A, B) are determined by the beat alone (uncertain over short windows), and they hardly enter
the energies.

Mechanical energy of mode j after the impact (mass-normalised modal coordinates, J):
E_j = (s_j'(0)^2 + omega_j^2 s_j(0)^2) / 2, particular part included. The share of the higher modes is
sum_{j>=2} E_j / sum_j E_j, over the well-posed windows (the paper: 15 % simulated, 12 % measured at
a_base/a_base* = 7.4, eta = 0.976).

A window is flagged (and left out of the share, with a warning) when it is shorter than one period of
mode 2 (the modes cannot be told apart), when the condition number of its column-normalised least-squares
matrix exceeds MAX_CONDITION (noise is amplified that much), or when Eq. 9 does not describe it (relative
misfit above MAX_RESIDUAL: an impact the detector missed); with fewer than two samples per unknown it is
not fitted at all.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import save_figure
from sim.analysis.impacts import (
    LOWPASS_HZ,
    NOMINAL_THRESHOLD,
    check_excitation_hz,
    detect_impacts,
    estimate_excitation_hz,
)
from sim.analysis.signals import Signal, as_signal
from sim.model.system import ModalModel

#: Time left out after each impact and before the next one (s): the contact (~80 us) and the detector's
#: timing uncertainty.
GUARD = 0.2e-3
#: Condition number of the column-normalised window matrix above which the fit counts as ill-conditioned:
#: a relative error e of v_tip moves the normalised coefficients by up to about condition * e. Windows of
#: at least one period of mode 2 on the rig's traces have 8 to 4.2e3.
MAX_CONDITION = 1e4
#: Relative rms misfit of a window above which it counts as not described by Eq. 9 (an impact the detector
#: missed, a contact still going on): on traces of the rig model, windows without contacts fit to < 1e-6 and
#: a missed contact leaves >= 5e-3 with modal energies 10-300 % off. Raise it above the noise-to-signal
#: ratio of a noisy measurement.
MAX_RESIDUAL = 1e-3
#: Fewest samples per unknown in a window.
MIN_SAMPLES_PER_UNKNOWN = 2


@dataclass(frozen=True)
class WindowFit:
    """The fit of one window between impacts.

    impact: time of the impact before the window (s); start, stop: first and last sample time used (s);
    displacement, velocity: s_j(0), s_j'(0) of each mode at `start` (m sqrt(kg), m sqrt(kg)/s);
    excitation: P of the particular solutions (complex, m/s^2, module docstring); A, B: particular solution
    of mode 1 (m sqrt(kg), Eq. 9 with tau from `start`); alpha, beta: Eq. 9's homogeneous coefficients
    (m sqrt(kg)); energies: E_j at `start` (J); condition: condition number of the column-normalised
    matrix; residual: rms misfit / rms of the velocity in the window (-); well_posed: False when flagged
    (module docstring).
    """

    impact: float
    start: float
    stop: float
    displacement: np.ndarray
    velocity: np.ndarray
    excitation: complex
    A: float
    B: float
    alpha: np.ndarray
    beta: np.ndarray
    energies: np.ndarray
    condition: float
    residual: float
    well_posed: bool

    @property
    def higher_share(self) -> float:
        """sum_{j>=2} E_j / sum_j E_j in this window (-)."""
        return float(self.energies[1:].sum() / self.energies.sum())

    def to_dict(self) -> dict:
        """Plain data for JSON (SI units; the complex P as base_acceleration |P| and base_phase arg P)."""
        return {
            "impact": self.impact, "start": self.start, "stop": self.stop,
            "energies": self.energies.tolist(), "higher_share": self.higher_share,
            "displacement": self.displacement.tolist(), "velocity": self.velocity.tolist(),
            "base_acceleration": abs(self.excitation), "base_phase": float(np.angle(self.excitation)),
            "A": self.A, "B": self.B, "alpha": self.alpha.tolist(), "beta": self.beta.tolist(),
            "condition": self.condition, "residual": self.residual, "well_posed": self.well_posed,
        }


@dataclass(frozen=True)
class ModalFit:
    """Result of `fit_modes` (Eq. 9): the fitted windows, the settings and warnings.

    windows: one WindowFit per window between consecutive impacts (and after the last one);
    impacts: the impact times used (s); excitation_hz (Hz) and whether it was estimated; guard (s);
    model: the modal model; warnings: one line per problem (short or ill-conditioned windows);
    signal: the analysed signal (for plots).
    """

    windows: tuple[WindowFit, ...]
    impacts: np.ndarray
    excitation_hz: float
    excitation_estimated: bool
    guard: float
    model: ModalModel
    warnings: tuple[str, ...]
    signal: Signal = field(repr=False)

    @property
    def energies(self) -> np.ndarray:
        """E_j after each impact, (n_windows, n_modes), J."""
        return np.array([w.energies for w in self.windows]).reshape(-1, self.model.n_modes)

    @property
    def higher_share(self) -> float:
        """Share of the modes 2..N in the mechanical energy after the impacts, over the well-posed windows
        (sum over windows and modes j >= 2 of E_j divided by the sum over windows and all modes); NaN if
        there is none."""
        energies = np.array([w.energies for w in self.windows if w.well_posed])
        return float(energies[:, 1:].sum() / energies.sum()) if energies.size else float("nan")

    def reconstruction(self, t: np.ndarray) -> np.ndarray:
        """The fitted tip velocity (m/s) at times t (s); NaN outside the fitted windows."""
        t = np.asarray(t, dtype=float)
        out = np.full(t.shape, np.nan)
        for window in self.windows:
            inside = (t >= window.start) & (t <= window.stop)
            out[inside] = _velocity_basis(t[inside] - window.start, self.model, 2 * np.pi * self.excitation_hz) @ \
                _coefficients(window)
        return out

    def to_dict(self) -> dict:
        """Plain data for JSON (SI units)."""
        return {
            "higher_share": self.higher_share,
            "energies": self.energies.tolist(),
            "windows": [w.to_dict() for w in self.windows],
            "impacts": self.impacts.tolist(),
            "excitation_hz": self.excitation_hz,
            "excitation_estimated": self.excitation_estimated,
            "guard": self.guard,
            "n_modes": self.model.n_modes,
            "model": self.model.source,
            "fs": self.signal.fs,
            "warnings": list(self.warnings),
        }


def load_model(spec: str | os.PathLike | ModalModel) -> ModalModel:
    """The modal model of a command-line option: 'builtin' (the seed rig, 9 modes, `sim.hosts.rig`), a modal-model
    file (`sim.hosts.modal_file`), or a ModalModel as it is."""
    if isinstance(spec, ModalModel):
        return spec
    if str(spec) == "builtin":
        from sim.hosts.rig import seed_rig_model

        return seed_rig_model(n_modes=9)
    from sim.hosts.modal_file import load_modal_model

    if not Path(spec).exists():
        raise SimulationInputError(f"unknown model {str(spec)!r}: give 'builtin' or the path of a modal-model file "
                                   "(.toml, as written by `ies modes --save`)")
    return load_modal_model(spec)


def fit_modes(source: Signal | str | os.PathLike, model: ModalModel | str | os.PathLike = "builtin",
              impacts: np.ndarray | None = None, *, excitation_hz: float | None = None, guard: float = GUARD,
              max_residual: float = MAX_RESIDUAL, threshold: float = NOMINAL_THRESHOLD, **detection) -> ModalFit:
    """Least-squares fit of Eq. 9 to the tip velocity between impacts, and the modal energies after them.

    source: a CSV path or a Signal with v_tip (m/s, relative to the base) and, unless `impacts` (s) are
    given, a_left, a_right, a_tip for the detector (`sim.analysis.impacts.detect_impacts` at `threshold`, with the
    other keyword arguments passed on); model: a ModalModel, 'builtin' or a modal-model file; excitation_hz:
    Omega / (2 pi) in Hz, else the detector's estimate or, with given impacts, the strongest component of
    v_tip below the low-pass cut-off; guard: time left out after and before each impact (s); max_residual:
    relative rms misfit above which a window is flagged (MAX_RESIDUAL).
    Raises SimulationInputError with one line for a bad signal, model or setting.
    """
    model = load_model(model)
    guard, max_residual = float(guard), float(max_residual)
    if not np.isfinite(guard) or guard < 0:
        raise SimulationInputError(f"guard must be >= 0 s, got {guard!r}")
    if not max_residual > 0:
        raise SimulationInputError(f"max_residual must be a positive fraction, got {max_residual!r}")
    if impacts is None:
        signal = as_signal(source, ("v_tip", "a_left", "a_right", "a_tip"))
        found = detect_impacts(signal, [threshold], excitation_hz=excitation_hz, **detection)
        times, excitation, estimated = found.times, found.excitation_hz, found.excitation_estimated
    else:
        signal = as_signal(source, ("v_tip",))
        times = np.sort(np.asarray(impacts, dtype=float).ravel())
        if not np.all(np.isfinite(times)):
            raise SimulationInputError("impact times must be finite numbers (s)")
        if excitation_hz is None:
            excitation = estimate_excitation_hz(signal["v_tip"], signal.fs, detection.get("lowpass_hz", LOWPASS_HZ))
            estimated = True
        else:
            excitation = check_excitation_hz(excitation_hz, signal["v_tip"], signal.fs,
                                             detection.get("lowpass_hz", LOWPASS_HZ), "v_tip")
            estimated = False
    if not np.isfinite(excitation) or excitation <= 0:
        raise SimulationInputError(f"the excitation frequency must be positive (Hz), got {excitation!r}")
    Omega = 2 * np.pi * excitation
    t, v = signal.t, signal["v_tip"]
    n_unknowns = 2 * model.n_modes + 2
    shortest = 2 * np.pi / model.omega[1] if model.n_modes > 1 else 0.0
    windows, warnings = [], []
    bounds = np.r_[times, t[-1] + guard + 1.0 / signal.fs]
    for impact, following in zip(bounds[:-1], bounds[1:]):
        inside = np.flatnonzero((t >= impact + guard) & (t <= following - guard))
        where = f"window after the impact at {impact:.6f} s"
        if inside.size < MIN_SAMPLES_PER_UNKNOWN * n_unknowns:
            warnings.append(f"{where}: {inside.size} samples for {n_unknowns} unknowns; not fitted")
            continue
        window = _fit_window(t[inside], v[inside], model, Omega, impact)
        problem = _problem(window, shortest, max_residual)
        if problem:
            warnings.append(f"{where}: {problem}, left out of the share")
            window = replace(window, well_posed=False)
        windows.append(window)
    if not windows:
        warnings.append("no window between impacts could be fitted")
    return ModalFit(tuple(windows), times, excitation, estimated, guard, model, tuple(warnings), signal)


def _problem(window: WindowFit, shortest: float, max_residual: float) -> str | None:
    """Why a fitted window cannot be trusted (module docstring), or None."""
    length = window.stop - window.start
    if length < shortest:
        return (f"{length * 1e3:.3g} ms is shorter than one period of mode 2 ({shortest * 1e3:.3g} ms); "
                "the modes cannot be separated")
    if window.condition > MAX_CONDITION:
        return f"condition number {window.condition:.3g} above {MAX_CONDITION:.0e}; ill-conditioned"
    if window.residual > max_residual:
        return (f"relative misfit {window.residual:.2g} above {max_residual:.0e} (an undetected impact or a contact "
                "still going on?)")
    return None


def _harmonic_response(model: ModalModel, Omega: float) -> np.ndarray:
    """H_j = (phi_j^T M b) / (omega_j^2 - Omega^2 + 2 i D_j omega_j Omega) (s^2 sqrt(kg)), Eq. 7: the particular
    solution of mode j is Re(P H_j e^{i Omega t}) under the harmonic modal force Re(P e^{i Omega t}) phi_j^T M b."""
    w, D = model.omega, model.damping_ratios
    return model.participation / (w**2 - Omega**2 + 2j * D * w * Omega)


def _velocity_basis(tau: np.ndarray, model: ModalModel, Omega: float) -> np.ndarray:
    """Columns of the tip velocity per unit coefficient at times tau (s) from the window's start (module
    docstring): phi_tip,j h_j' and phi_tip,j g_j' for every mode, then the particular solutions for P = 1
    and P = i, each mode's part less the free response from its own initial state."""
    w, D, phi = model.omega, model.damping_ratios, model.phi_tip
    sigma = D * w
    wd = w * np.sqrt(1.0 - D**2)
    tau = tau[:, None]
    decay = np.exp(-sigma * tau)
    cos, sin = np.cos(wd * tau), np.sin(wd * tau)
    h_rate = -(w**2 / wd) * decay * sin  # d/dtau of the free response with s(0) = 1, s'(0) = 0
    g_rate = decay * (cos - (sigma / wd) * sin)  # ... with s(0) = 0, s'(0) = 1
    rotation = np.exp(1j * Omega * tau)
    particular = []
    for unit in (1.0, 1j):
        G = unit * _harmonic_response(model, Omega)
        rate = (1j * Omega * G * rotation).real - G.real * h_rate - (1j * Omega * G).real * g_rate
        particular.append(rate @ phi)
    return np.column_stack([h_rate * phi, g_rate * phi, *particular])


def _coefficients(window: WindowFit) -> np.ndarray:
    """The window's coefficients in the order of `_velocity_basis`."""
    return np.r_[window.displacement, window.velocity, window.excitation.real, window.excitation.imag]


def _fit_window(t: np.ndarray, v: np.ndarray, model: ModalModel, Omega: float, impact: float) -> WindowFit:
    """Least squares on the column-normalised basis (SVD); the state at t[0] and Eq. 9's coefficients."""
    n = model.n_modes
    basis = _velocity_basis(t - t[0], model, Omega)
    scale = np.linalg.norm(basis, axis=0)
    scale[scale == 0] = 1.0
    solution, _, _, singular = np.linalg.lstsq(basis / scale, v, rcond=None)
    c = solution / scale
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else float("inf")
    displacement, velocity, excitation = c[:n], c[n:2 * n], complex(c[2 * n], c[2 * n + 1])
    w, D = model.omega, model.damping_ratios
    sigma, wd = D * w, w * np.sqrt(1.0 - D**2)
    particular = excitation * _harmonic_response(model, Omega)  # p_j = Re(particular e^{i Omega tau})
    alpha = displacement - particular.real
    beta = (velocity - (1j * Omega * particular).real + sigma * alpha) / wd
    misfit = v - basis @ c
    return WindowFit(
        impact=float(impact), start=float(t[0]), stop=float(t[-1]), displacement=displacement, velocity=velocity,
        excitation=excitation, A=float(particular[0].real), B=float(-particular[0].imag), alpha=alpha, beta=beta,
        energies=0.5 * (velocity**2 + (w * displacement) ** 2), condition=condition,
        residual=float(np.sqrt(np.mean(misfit**2) / np.mean(v**2))), well_posed=True)


def plot_modal_fit(fit: ModalFit, path: str | os.PathLike, *, t_range: tuple[float, float] | None = None,
                   velocity_scale: float | None = None) -> Path:
    """Fig. 9b/10b: the tip velocity against its reconstruction from Eq. 9, impacts marked; saved to path
    atomically (`sim.common.files.save_figure`; a missing folder raises FileNotFoundError with one line).

    Top: the whole signal with the impacts, the section shaded; bottom: the section t_range (s; default the
    first two excitation periods after the first impact) with the reconstruction of each fitted window
    (dashed where the window is flagged). velocity_scale: divide velocities by it, e.g. Omega a_noabs* (m/s)
    as in the paper; SI (m/s) when None. The format follows the suffix (.png, .pdf, ...).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.backend_bases import FigureCanvasBase

    from sim.common.figure_style import legend_beside

    t, v = fit.signal.t, fit.signal["v_tip"]
    scale = 1.0 if velocity_scale is None else float(velocity_scale)
    if not np.isfinite(scale) or scale <= 0:
        raise SimulationInputError(f"velocity_scale must be a positive velocity (m/s), got {velocity_scale!r}")
    if t_range is None:
        first = fit.impacts[0] if fit.impacts.size else t[0]
        t_range = (first - 0.1 / fit.excitation_hz, first + 2.0 / fit.excitation_hz)
    lo, hi = float(t_range[0]), float(t_range[1])
    if not lo < hi:
        raise SimulationInputError(f"t_range must be (start, stop) with start < stop in s, got {t_range!r}")
    kind = Path(path).suffix.lstrip(".").lower() or "png"
    if kind not in FigureCanvasBase.get_supported_filetypes():
        raise SimulationInputError(f"cannot write {path}: unknown figure format '.{kind}'; use .png, .pdf or .svg")
    unit = "m/s" if velocity_scale is None else r"$\Omega a_\mathrm{noabs}^*$"
    fig, (overview, section) = plt.subplots(2, 1, figsize=(9.5, 6.0), sharey=True, layout="constrained")
    try:
        overview.plot(t, v / scale, color="0.3", lw=0.6)
        overview.axvspan(lo, hi, color="C1", alpha=0.2, label="section shown in (b)")
        for axes, start, stop in ((overview, t[0], t[-1]), (section, lo, hi)):
            # one caret per impact on the top edge: readable at any number of impacts, never on the signal
            times = fit.impacts[(fit.impacts >= start) & (fit.impacts <= stop)]
            axes.plot(times, np.ones(times.size), ls="none", marker=7, ms=5, color="C3", clip_on=False,
                      transform=axes.get_xaxis_transform(), label="impact" if axes is overview else None)
        shown = (t >= lo) & (t <= hi)
        section.plot(t[shown], v[shown] / scale, color="0.3", lw=1.2, label="signal")
        labelled = set()
        for window in fit.windows:
            inside = shown & (t >= window.start) & (t <= window.stop)
            if not inside.any():
                continue
            label = "Eq. 9 fit" if window.well_posed else "Eq. 9 fit (flagged)"
            section.plot(t[inside], fit.reconstruction(t[inside]) / scale, color="C0", ls="-" if window.well_posed else "--",
                         lw=1.0, label=None if label in labelled else label)
            labelled.add(label)
        section.set_xlim(lo, hi)
        # the titles clear of the impact carets on the top edges
        overview.set_title("(a) tip velocity and detected impacts", fontsize=10, pad=10)
        section.set_title("(b) reconstruction from the least-squares fit of Eq. 9", fontsize=10, pad=10)
        for axes in (overview, section):
            axes.set_xlabel("t (s)")
            axes.set_ylabel(f"tip velocity ({unit})")
        legend_beside(overview)
        legend_beside(section)
        return save_figure(fig, path)
    finally:
        plt.close(fig)

