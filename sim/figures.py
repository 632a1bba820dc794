"""Figures of the simulation stage in the style of the seed paper: the stepped-sine frequency response (Fig. 5,
Sect. 5.2), the resonant level against the excitation level (Fig. 6, Sect. 5.3), and the impacts per period and
the modal coefficient of restitution against the excitation level (Figs. D.2, D.3, Appendix D).

They draw plain data (mappings of arrays), so that a result folder can be redrawn from its files (`ies plot`):
a frequency response has the keys of `sim.protocol.SweepResult.to_dict` (eta, mean, mean_lo, mean_hi, max,
max_lo, max_hi); the resonant levels those of `sim.tables.overview_data` (levels, resonant_mean, ...,
regime). Files are written atomically through `sim.files` (format from the suffix).
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from sim.files import plot_to, save_figure
from sim.redraw import PlotOptions, register, selected

#: the paper's optimum (Sect. 5.3): a_base/a_base* ~ 6.7, resonant max reduced 10x, mean 20x
PAPER_OPTIMUM = 6.7


def draw_sweep(ax: Any, data: Mapping[str, Any], title: str) -> None:
    """Fig. 5 on `ax`: mean (solid) and max (dashed) amplitude a/a_noabs* vs eta, each with the range of its
    repetition samples as a band (the spread of the paper's figure)."""
    eta = data["eta"]
    ax.fill_between(eta, data["max_lo"], data["max_hi"], color="tab:red", alpha=0.2, lw=0, label="max: spread")
    ax.plot(eta, data["max"], "--", color="tab:red", label="max")
    ax.fill_between(eta, data["mean_lo"], data["mean_hi"], color="tab:blue", alpha=0.25, lw=0, label="mean: spread")
    ax.plot(eta, data["mean"], "-", color="tab:blue", label="mean")
    ax.set_xlabel(r"$\eta = \Omega/\omega^*$")
    ax.set_ylabel(r"$a / a^{noabs*}$")
    ax.set_title(title, fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)


def plot_sweep(data: Mapping[str, Any], path: str | os.PathLike, title: str) -> None:
    """Fig. 5 of one frequency response, written to `path`."""
    with plot_to(path, figsize=(6.0, 4.0)) as (fig, ax):
        draw_sweep(ax, data, title)
        ax.legend(fontsize=8)


def plot_sweeps(panels: Sequence[tuple[Mapping[str, Any], str]], path: str | os.PathLike, title: str) -> None:
    """Fig. 5: one panel per (frequency response, panel title), two columns, written to `path`."""
    from sim.files import pyplot

    plt = pyplot()
    columns = min(2, len(panels))
    rows = math.ceil(len(panels) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(5.2 * columns, 3.6 * rows), squeeze=False)
    try:
        for ax, (data, panel_title) in zip(axes.flat, panels):
            draw_sweep(ax, data, panel_title)
        for ax in axes.flat[len(panels):]:
            ax.set_visible(False)
        axes.flat[0].legend(fontsize=7)
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        save_figure(fig, path)
    finally:
        plt.close(fig)


def draw_overview(ax: Any, data: Mapping[str, Any], title: str, *, paper_optimum: bool = False) -> None:
    """Fig. 6 on `ax`: the resonant mean (solid) and max (dashed) level vs the excitation level, each with the
    range of its repetition samples at the resonant eta as error bars, the regime of each level (APR, SMR,
    linear: `sim.measures.classify_regime` through the aggregation) above the axes, this model's optimum (the
    lowest resonant mean) and, with `paper_optimum`, the paper's (a_base/a_base* ~ 6.7, Sect. 5.3)."""
    import numpy as np

    levels = np.asarray(data["levels"], dtype=float)
    for name, style, color in (("max", "s--", "tab:red"), ("mean", "o-", "tab:blue")):
        value = np.asarray(data[f"resonant_{name}"], dtype=float)
        spread = [value - np.asarray(data[f"resonant_{name}_lo"], dtype=float),
                  np.asarray(data[f"resonant_{name}_hi"], dtype=float) - value]
        ax.errorbar(levels, value, yerr=spread, fmt=style, color=color, ms=4, capsize=2, lw=1.2,
                    label=f"resonant {name} (bars: spread of the runs)")
    for level, regime in zip(levels, data["regime"]):
        ax.annotate(regime, (level, 1.0), xycoords=("data", "axes fraction"), ha="center", va="bottom", fontsize=7,
                    rotation=90)
    best = int(np.argmin(data["resonant_mean"]))
    ax.axvline(levels[best], color="tab:green", lw=1, ls=":",
               label=f"optimum of this model ({levels[best]:g}: mean /{1 / data['resonant_mean'][best]:.0f}, "
                     f"max /{1 / data['resonant_max'][best]:.0f})")
    if paper_optimum:
        ax.axvline(PAPER_OPTIMUM, color="k", lw=1, ls="-.", alpha=0.6,
                   label=f"paper's optimum ({PAPER_OPTIMUM:g}: mean /20, max /10)")
    ax.set_xlabel(r"$a_{base} / a^*_{base}$")
    ax.set_ylabel(r"resonant level $a / a^{noabs*}$")
    ax.set_ylim(bottom=0)
    ax.set_title(title, pad=28, fontsize=9)
    ax.grid(alpha=0.3)


def plot_overview(data: Mapping[str, Any], path: str | os.PathLike, title: str, *, paper_optimum: bool = False) -> None:
    """Fig. 6, written to `path`."""
    with plot_to(path, figsize=(6.5, 4.4)) as (fig, ax):
        draw_overview(ax, data, title, paper_optimum=paper_optimum)
        ax.legend(fontsize=7)


def plot_scattering(overview: Mapping[str, Any], runs: Sequence[Mapping[str, Any]], path: str | os.PathLike,
                    title: str, figure: str) -> None:
    """Fig. D.2 ("figD2": all and significant impacts per excitation period) or Fig. D.3 ("figD3": the modal
    coefficient of restitution r, Eq. D.1, from the tip and from the wall, at the levels whose resonant response
    is almost periodic) against the excitation level, at the resonant eta (`sim.tables.overview_data` keys), each
    with the range of the runs' own values as error bars (`runs`: rows with level and the measures; Appendix D)."""
    import numpy as np

    levels = np.asarray(overview["levels"], dtype=float)
    if figure == "figD2":
        curves = (("impacts_per_period", "all contact onsets", "s--", "tab:gray"),
                  ("significant_impacts_per_period", "significant impacts", "o-", "tab:blue"))
        ylabel = "impacts per excitation period"
        keep = np.ones(levels.size, dtype=bool)
    else:
        curves = (("restitution", "r from the tip (Eq. D.1)", "o-", "tab:blue"),
                  ("restitution_wall", "r from the wall", "s--", "tab:red"))
        ylabel = "modal coefficient of restitution r"
        keep = np.array([regime == "APR" for regime in overview["regime"]])
    with plot_to(path, figsize=(6.5, 4.4)) as (fig, ax):
        for key, label, style, color in curves:
            value = np.asarray(overview[key], dtype=float)[keep]
            per_run = [[float(r[key]) for r in runs if float(r["level"]) == level and key in r]
                       for level in levels[keep]]
            lo = np.array([np.nanmin(v) if np.isfinite(v).any() else np.nan for v in map(np.asarray, per_run)])
            hi = np.array([np.nanmax(v) if np.isfinite(v).any() else np.nan for v in map(np.asarray, per_run)])
            spread = [np.clip(value - lo, 0, None), np.clip(hi - value, 0, None)]
            if runs and key in runs[0]:
                ax.errorbar(levels[keep], value, yerr=spread, fmt=style, color=color, ms=4, capsize=2, lw=1.2,
                            label=f"{label} (bars: range of the runs)")
            else:
                ax.plot(levels[keep], value, style, color=color, ms=4, lw=1.2, label=label)
        if figure == "figD3":
            ax.axhline(0.8, color="k", lw=1, ls="-.", alpha=0.6, label="paper: r ~ 0.8 (Fig. D.3)")
            ax.axhline(1.0, color="k", lw=0.8, alpha=0.3)
        else:
            ax.axhline(2.0, color="k", lw=1, ls="-.", alpha=0.6, label="paper: 2 per period in APR (Fig. D.2)")
        ax.set_xlabel(r"$a_{base} / a^*_{base}$")
        ax.set_ylabel(ylabel)
        ax.set_ylim(bottom=0)
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)


def sweep_title(data: Mapping[str, Any]) -> str:
    """The title of a frequency response's figure from its data (`SweepResult.to_dict`)."""
    return (f"a_base/a_base* = {data['level']:g}, {data['n_samples']} samples "
            f"({data['protocol']['integrator']})")


def overview_title(data: Mapping[str, Any]) -> str:
    """The title of `ies overview`'s figure from its JSON data."""
    protocol = data["sweeps"][0]["protocol"]
    return f"{protocol['sequence']}, {data['reps']} runs ({protocol['integrator']})"


@register("ies sweep --out", lambda folder: (folder / "sweep.json").is_file())
def redraw_sweep(folder: Path, options: PlotOptions) -> list[Path]:
    """Fig. 5 of an `ies sweep --out` folder (sweep.json), as fig5.SUFFIX."""
    data = json.loads((folder / "sweep.json").read_text())
    selected([data["level"]], options, folder)
    paths = options.paths(folder, "fig5")
    for path in paths:
        plot_sweep(data, path, sweep_title(data))
    return paths


@register("ies overview --out", lambda folder: (folder / "overview.json").is_file())
def redraw_overview(folder: Path, options: PlotOptions) -> list[Path]:
    """Fig. 6 of an `ies overview --out` folder (overview.json), as fig6.SUFFIX, for the chosen levels."""
    data = json.loads((folder / "overview.json").read_text())
    keep = [i for i, level in enumerate(data["levels"]) if level in selected(data["levels"], options, folder)]
    subset = {key: [value[i] for i in keep] if isinstance(value, list) and len(value) == len(data["levels"]) else value
              for key, value in data.items()}
    paths = options.paths(folder, "fig6")
    for path in paths:
        plot_overview(subset, path, overview_title(data))
    return paths
