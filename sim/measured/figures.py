"""Figures of the measured host: the stabilization diagram, the measured FRF against the synthesized (or the updated
model's) one with its coherence in Fig. A.1's layout, and the linearity check in Fig. B.2's two panels (frequency
responses with the backbone and the synthesized FRFs; the damping ratio against the amplitude)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.common.figure_style import LEGEND_PT, legend_below
from sim.common import files
from sim.common.files import pyplot

STATUS = ((0, "new pole", dict(marker=".", color="0.7", s=6)), (1, "stable in frequency", dict(marker="+", color="0.4", s=14)),
          (2, "stable in frequency and damping", dict(marker="o", facecolors="none", edgecolors="k", s=14)))


def draw_stabilization(path: str | Path, identification, frf_magnitude: np.ndarray) -> Path:
    """The stabilization diagram (model order against frequency, the poles by status) over the FRF's magnitude (summed
    over the responses, m/N, log scale on the right), the chosen modes as vertical lines."""
    plt = pyplot()
    d = identification.diagram
    fig, ax = plt.subplots(figsize=(7.0, 4.2), layout="constrained")
    try:
        for status, label, style in STATUS:
            pick = d.status == status
            ax.scatter(d.frequency_hz[pick], d.order[pick], label=label, **style)
        for i, f in enumerate(identification.frequencies_hz):
            ax.axvline(f, color="k", lw=0.6, ls=":", label="chosen modes" if i == 0 else None)
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("model order (each sub-band)")
        ax.set_xlim(identification.band.lo, identification.band.hi)
        right = ax.twinx()
        f = identification.frequencies_fit_hz
        inside = (f >= identification.band.lo) & (f <= identification.band.hi)
        right.semilogy(f[inside], frf_magnitude[inside], color="0.5", lw=0.6)
        right.set_ylabel("|H| (m/N)")
        legend_below(ax, ncols=2)
        return files.save_figure(fig, path)
    finally:
        plt.close(fig)


def draw_frf(path: str | Path, frequencies_hz: np.ndarray, measured: dict[str, np.ndarray],
             other: dict[str, np.ndarray], coherence: dict[str, np.ndarray], other_label: str,
             band: tuple[float, float] | None = None) -> Path:
    """Fig. A.1's layout: magnitude (m/N, log), phase (deg) and coherence of the measured FRFs of displacement per
    force against `other` (the synthesized FRF or the updated model's), the responses one after the other."""
    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(7.0, 7.0), sharex=True, layout="constrained",
                             gridspec_kw={"height_ratios": [3, 1.5, 1]})
    styles = ("-", "--", "-.", ":")
    try:
        lo, hi = band or (frequencies_hz[0], frequencies_hz[-1])
        keep = (frequencies_hz >= lo) & (frequencies_hz <= hi)
        f = frequencies_hz[keep]
        for i, name in enumerate(measured):
            axes[0].semilogy(f, np.abs(measured[name][keep]), color="k", lw=0.8, ls=styles[i % 4], label=f"measured, {name}")
            axes[1].plot(f, phase_deg(measured[name][keep]), color="k", lw=0.8, ls=styles[i % 4])
            if name in other:
                axes[0].semilogy(f, np.abs(other[name][keep]), color="0.55", lw=1.4, ls=styles[i % 4],
                                 label=f"{other_label}, {name}")
                axes[1].plot(f, phase_deg(other[name][keep]), color="0.55", lw=1.4, ls=styles[i % 4])
            if name in coherence:
                axes[2].plot(f, coherence[name][keep], color="k", lw=0.8, ls=styles[i % 4])
        axes[0].set_ylabel("|H| (m/N)")
        axes[1].set_ylabel("phase (deg)")
        axes[1].set_yticks([-360, -180, 0])
        axes[2].set_ylabel(r"coherence $\gamma^2$")
        axes[2].set_ylim(0, 1.05)
        axes[2].set_xlabel("frequency (Hz)")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncols=2, fontsize=LEGEND_PT, frameon=False)
        return files.save_figure(fig, path)
    finally:
        plt.close(fig)


def phase_deg(H: np.ndarray) -> np.ndarray:
    """Phase of H in degrees in (-360, 0]: a receptance's phase (0 to -180 deg at a driving point) without the jumps
    between +180 and -180."""
    return np.mod(np.degrees(np.angle(H)), -360.0)


def draw_linearity(path: str | Path, levels, mode, half_powers, interval) -> Path:
    """Fig. B.2: (a) the tip amplitude (mm) against frequency (Hz) of each level, measured (markers) and synthesized
    from the single nonlinear mode (lines), with the backbone; (b) the damping ratio (%) against the amplitude (mm):
    the mode's D(a), the half-power estimate of each level, the response range and its interval."""
    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(9.0, 4.0), layout="constrained")
    markers = "osD^v<>ph*"
    try:
        a_max = max(float(lv.amplitude.max()) for lv in levels)
        for i, lv in enumerate(levels):
            a.plot(lv.frequencies_hz, 1e3 * lv.amplitude, ls="none", marker=markers[i % 10], ms=3, mfc="none", color="k",
                   label=f"a_base = {1e6 * lv.a_base:.3g} $\\mu$m")
            fine = np.linspace(lv.frequencies_hz[0], lv.frequencies_hz[-1], 300)
            synth = [mode.responses(2 * np.pi * f, lv.a_base, 1.1 * a_max) for f in fine]
            top = np.array([r.max() if r.size else np.nan for r in synth])
            a.plot(fine, 1e3 * top, color="0.5", lw=0.9, label="synthesized" if i == 0 else None)
        a_min = min(float(lv.amplitude.max()) for lv in levels)
        amp = np.linspace(0.5 * a_min, 1.05 * a_max, 200)
        a.plot(mode.omega(amp) / (2 * np.pi), 1e3 * amp, color="k", ls="--", lw=0.9, label="backbone")
        a.set_xlabel("frequency (Hz)")
        a.set_ylabel("tip amplitude a (mm)")
        legend_below(a, ncols=2)
        b.plot(1e3 * amp, 100 * mode.damping(amp), color="k", lw=1.0, label="single nonlinear mode")
        hp = [(h.peak_amplitude, h.damping_ratio) for h in half_powers if np.isfinite(h.damping_ratio)]
        if hp:
            b.plot([1e3 * x for x, _ in hp], [100 * y for _, y in hp], ls="none", marker="s", mfc="none", color="k",
                   label="half-power bandwidth")
        if interval is not None:
            b.axvspan(1e3 * interval.a_lo, 1e3 * interval.a_hi, color="0.85", zorder=0,
                      label=f"range: D = {100 * interval.low:.3g}-{100 * interval.high:.3g} %")
        b.set_xlabel("tip amplitude a (mm)")
        b.set_ylabel("damping ratio D (%)")
        legend_below(b)
        return files.save_figure(fig, path)
    finally:
        plt.close(fig)
