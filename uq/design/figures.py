"""Figures of `ies design` (`uq.design`): the design map (clearance x radius per material, colour the screened worst
case, the switch contour, the verified designs and the recommendation) and the design curves (resonant tip amplitude
against the excitation for the three best verified designs with their bands, and the structure without IES)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from sim.common.figure_style import LEGEND_PT, legend_beside
from sim.common.files import plot_to


def plot_design_map(result: Any, path: Path) -> Path:
    """design-map: per material a panel of clearance (mm) x radius (mm) coloured by the slow flow's worst case (mm; grey
    where the cavity does not fit), the contour where the predicted switch reaches the top of the operating range
    (to its left the response turns almost periodic within the range), verified designs as circles, the
    recommendation as a star and the baseline as a diamond."""
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    p, s = result.problem, result.screened
    g = np.asarray(p.clearances) * 1e3
    R = np.asarray(p.radii) * 1e3
    n = len(p.materials)
    on_grid = n * R.size * g.size  # an off-grid baseline is screened after the grid
    worst = s.worst[:on_grid].reshape(n, R.size, g.size) * 1e3
    switch = s.switch[:on_grid].reshape(n, R.size, g.size)
    finite = worst[np.isfinite(worst)]
    norm = Normalize(vmin=finite.min(), vmax=finite.max()) if finite.size else None
    with plot_to(path, figsize=(4.2 * n + 1.4, 3.8)) as (fig, ax):
        fig.delaxes(ax)
        axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
        image = None
        for k, (name, a) in enumerate(zip(p.materials, axes)):
            shown = np.ma.masked_invalid(np.where(np.isfinite(worst[k]), worst[k], np.nan))
            a.set_facecolor("0.85")
            if g.size > 1 and R.size > 1:
                image = a.pcolormesh(g, R, shown, shading="nearest", cmap="viridis_r", norm=norm)
                if switch[k].min() < max(p.excitation) < switch[k].max():
                    a.contour(g, R, switch[k], levels=[max(p.excitation)], colors="k", linewidths=1.0,
                              linestyles="--")
            else:
                image = a.scatter(np.repeat(g[None, :], R.size, 0), np.repeat(R[:, None], g.size, 1), c=shown,
                                  cmap="viridis_r", norm=norm, s=60)
            for v in result.verified:
                if v.sphere.material == name:
                    a.plot(v.sphere.clearance * 1e3, v.sphere.radius * 1e3, "o", mfc="none", mec="k", ms=8)
            best = result.recommendation.sphere
            if best.material == name:
                a.plot(best.clearance * 1e3, best.radius * 1e3, "*", color="tab:red", ms=15, mec="k",
                       label="recommendation")
            if p.baseline is not None and p.baseline.material == name:
                a.plot(p.baseline.clearance * 1e3, p.baseline.radius * 1e3, "D", color="w", mec="k", ms=7,
                       label="baseline")
            a.set_title(name)
            a.set_xlabel("clearance $g$ (mm)")
            a.margins(0.08)
        axes[0].set_ylabel("sphere radius $R$ (mm)")
        if image is not None:  # beside the panels (constrained layout), never on them
            bar = fig.colorbar(image, ax=list(axes), pad=0.02)
            bar.set_label("screened worst case (mm)")
        handles = [h for a in axes for h in a.get_legend_handles_labels()[0]]
        labels = [lab for a in axes for lab in a.get_legend_handles_labels()[1]]
        handles += [Line2D([], [], marker="o", ls="", mfc="none", mec="k"), Line2D([], [], ls="--", color="k")]
        labels += ["verified", f"switch at {max(p.excitation) * 1e6:.3g} µm"]
        fig.legend(handles, labels, loc="outside lower center", ncols=len(labels), frameon=False, fontsize=LEGEND_PT)
    return path


def plot_design_curves(result: Any, path: Path) -> Path:
    """design-curves: the resonant tip amplitude (mm) against the base amplitude (µm) for the three best verified
    designs (band over the uncertainty corners, line at the box's centre) and the structure without IES."""
    p = result.problem
    a = np.asarray(p.excitation) * 1e6
    with plot_to(path, figsize=(6.4, 4.2)) as (fig, ax):
        ax.plot(a, result.no_absorber * 1e3, "k:", label=f"no IES ($D_1$ = {min(p.D):g})")
        for v, colour in zip(result.verified[:3], ("tab:blue", "tab:orange", "tab:green")):
            ax.fill_between(a, v.low * 1e3, v.high * 1e3, color=colour, alpha=0.25, lw=0)
            ax.plot(a, v.nominal * 1e3, "-o", color=colour, ms=3, label=v.sphere.label())
        ax.set_yscale("log")
        ax.set_xlabel("base amplitude $a_{base}$ (µm)")
        ax.set_ylabel("resonant tip amplitude (mm)")
        ax.grid(True, which="both", alpha=0.3)
        legend_beside(ax, title="bands: the uncertainty box's corners\nlines: its centre")
    return path
