"""Figures of the response's nature (`sim.stepped_sine.dynamics`): the Poincaré figure of one stepped-sine point
(`ies trace --poincare`), and the dynamics of each point of a frequency response as markers on its mean (`ies sweep
--lyapunov`, `draw_dynamics`).

The Poincaré figure: left, the section once per excitation period (the tip's displacement against its velocity over
Omega, both relative to the base and over a_noabs*, at phase 0 of the excitation); right, the power spectrum of the
per-period amplitudes against the frequency in cycles per excitation period. A periodic response is one point (k
points for a kT orbit) and no line but at multiples of 1/k; a quasi-periodic one a closed curve and discrete lines;
a chaotic one a cloud and a broad spectrum (seed paper Sect. 5.1: its two regimes "confirmed via Poincaré mappings,
not shown").
"""
from __future__ import annotations

import os
from typing import Any, Mapping

import numpy as np


def plot_poincare(data: Mapping[str, Any], path: str | os.PathLike) -> None:
    """The figure (module docstring) from a trace's JSON data (`sim.analysis.trace.trace_data` with its "poincare"
    object, and "dynamics" / "lyapunov_per_period" when measured), written atomically to `path`."""
    from sim.common.files import pyplot, save_figure

    section = data["poincare"]
    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(9.0, 3.6), layout="constrained")
    try:
        q, v = np.asarray(section["q_tip"], dtype=float), np.asarray(section["v_tip"], dtype=float)
        left.plot(q, v, ls="none", marker=".", ms=2.5, color="C0")
        left.set_xlabel(r"$q_\mathrm{tip}/a_\mathrm{noabs}^*$ at phase 0")
        left.set_ylabel(r"$\dot q_\mathrm{tip}/(\Omega\, a_\mathrm{noabs}^*)$")
        left.set_title(f"section once per period ({q.size} crossings)", fontsize=9)
        f = np.asarray(section["frequency_per_period"], dtype=float)
        power = np.asarray(section["amplitude_spectrum"], dtype=float)
        keep = f > 0
        floor = max(float(power[keep].max()) * 1e-12, 1e-300) if keep.any() else 1e-300
        right.semilogy(f[keep], np.maximum(power[keep], floor), color="C1", lw=0.9)
        right.set_xlim(0.0, 0.5)
        right.set_xlabel("frequency (cycles per excitation period)")
        right.set_ylabel("power of the per-period amplitudes (-)")
        right.set_title("spectrum of the amplitudes, mean removed", fontsize=9)
        nature = data.get("dynamics")
        exponent = data.get("lyapunov_per_period")
        head = (f"$a_\\mathrm{{base}}/a_\\mathrm{{base}}^*$ = {data['level']:g}, $\\eta$ = {data['eta_actual']:.4f}"
                + (f": {nature}" if nature else "")
                + (f", largest Lyapunov exponent {exponent:.3g} per period" if exponent is not None else ""))
        fig.suptitle(head, fontsize=10)
        save_figure(fig, path)
    finally:
        plt.close(fig)


#: The markers of the dynamics on a frequency response's mean (filled: periodic, open: quasi-periodic, up: chaotic).
MARKERS = {"periodic": ("o", "full"), "quasi-periodic": ("o", "none"), "chaotic": ("^", "full")}


def draw_dynamics(ax: Any, eta: Any, mean: Any, dynamics: Any) -> None:
    """The dynamics of each point (MARKERS) on the mean of a frequency response, one legend entry each."""
    eta, mean, dynamics = np.asarray(eta, dtype=float), np.asarray(mean, dtype=float), np.asarray(dynamics).astype(str)
    for kind, (marker, fill) in MARKERS.items():
        sel = dynamics == kind
        if sel.any():
            ax.plot(eta[sel], mean[sel], ls="none", marker=marker, ms=4, color="k", fillstyle=fill, label=kind)
