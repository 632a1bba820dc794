"""Figures of the simulation stage in the style of the seed paper: the stepped-sine frequency response (Fig. 5,
Sect. 5.2), the resonant level against the excitation level (Fig. 6, Sect. 5.3), the time histories of one
point (Figs. 4 and 9a, Sects. 5.1 and 5.5), and the impacts per period and the modal coefficient of restitution
against the excitation level (Figs. D.2, D.3, Appendix D).

They draw plain data (mappings of arrays), so that a result folder can be redrawn from its files (`ies plot`):
a frequency response has the keys of `sim.stepped_sine.protocol.SweepResult.to_dict` (eta, mean, mean_lo, mean_hi, max,
max_lo, max_hi); the resonant levels those of `sim.stepped_sine.tables.overview_data` (levels, resonant_mean, ...,
regime); a time history the columns t, q_tip, v_tip of `sim.analysis.trace.COLUMNS` and the keys of
`sim.analysis.trace.trace_data`. Files are written atomically through `sim.common.files` (format from the suffix).
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from sim.common.files import plot_to, save_figure
from sim.plots.redraw import PlotOptions, register, selected

from sim.stepped_sine.measures import PAPER_APR_LEVEL, PAPER_OPTIMUM_LEVEL, PAPER_REDUCTION_MAX, PAPER_REDUCTION_MEAN


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
    from sim.common.files import pyplot

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
    linear: `sim.stepped_sine.measures.classify_regime` through the aggregation) above the axes, this model's optimum (the
    lowest resonant mean) and, with `paper_optimum`, the paper's landmarks: the optimum (a_base/a_base* ~ 6.7 with its
    mean and max levels, Sect. 5.3) and the almost periodic level at 7.4 (Appendix B)."""
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
        draw_paper_landmarks(ax)
    ax.set_xlabel(r"$a_{base} / a^*_{base}$")
    ax.set_ylabel(r"resonant level $a / a^{noabs*}$")
    ax.set_ylim(bottom=0)
    ax.set_title(title, pad=28, fontsize=9)
    ax.grid(alpha=0.3)


def draw_paper_landmarks(ax: Any) -> None:
    """The paper's Fig. 6 landmarks on `ax`: its optimum (a_base/a_base* ~ 6.7, a vertical line, with its mean and
    max levels as stars, Sect. 5.3) and its almost periodic level at 7.4 (a grey box, Appendix B)."""
    from matplotlib.patches import Rectangle

    ax.axvline(PAPER_OPTIMUM_LEVEL, color="k", lw=1, ls="-.", alpha=0.6,
               label=f"paper's optimum ({PAPER_OPTIMUM_LEVEL:g}: mean /{PAPER_REDUCTION_MEAN:g}, "
                     f"max /{PAPER_REDUCTION_MAX:g}, stars)")
    ax.plot([PAPER_OPTIMUM_LEVEL] * 2, [1 / PAPER_REDUCTION_MEAN, 1 / PAPER_REDUCTION_MAX], "k*", ms=8)
    ax.add_patch(Rectangle((7.2, PAPER_APR_LEVEL[0]), 0.4, PAPER_APR_LEVEL[1] - PAPER_APR_LEVEL[0],
                           facecolor="0.6", alpha=0.5,
                           label=f"paper's almost periodic level at 7.4 ({PAPER_APR_LEVEL[0]:g}-"
                                 f"{PAPER_APR_LEVEL[1]:g}, App. B)"))


def plot_overview(data: Mapping[str, Any], path: str | os.PathLike, title: str, *, paper_optimum: bool = False) -> None:
    """Fig. 6, written to `path`."""
    with plot_to(path, figsize=(6.5, 4.4)) as (fig, ax):
        draw_overview(ax, data, title, paper_optimum=paper_optimum)
        ax.legend(fontsize=7, loc="upper left")  # the low SMR levels leave that corner free


def plot_series(series: Sequence[tuple[str, Mapping[str, Any]]], path: str | os.PathLike, title: str,
                paper_line: tuple[float, str] | None = None, *, paper_landmarks: bool = False) -> None:
    """Figs. 11 and C.1a: the resonant mean level against the excitation level, one curve per value of a series
    (`series`: [(label, `sim.stepped_sine.tables.overview_data` keys)]), each with the range of its runs as error bars;
    paper_line: (level, what the paper says there) marked as a vertical line; paper_landmarks: the paper's Fig. 6
    landmarks (draw_paper_landmarks; `ies compare`)."""
    import numpy as np

    many = len(series) > 6  # legend beside the axes; markers and line styles tell apart curves of one colour
    with plot_to(path, figsize=(9.5, 4.4) if many else (6.5, 4.4)) as (fig, ax):
        for i, (label, data) in enumerate(series):
            levels = np.asarray(data["levels"], dtype=float)
            value = np.asarray(data["resonant_mean"], dtype=float)
            spread = [value - np.asarray(data["resonant_mean_lo"], dtype=float),
                      np.asarray(data["resonant_mean_hi"], dtype=float) - value]
            fmt = "os^vD"[i // 10 % 5] + ("-", "--", ":")[i // 10 % 3]
            ax.errorbar(levels, value, yerr=spread, fmt=fmt, ms=3, capsize=2, lw=1.2, label=label)
        if paper_line is not None:
            ax.axvline(paper_line[0], color="k", lw=1, ls="-.", alpha=0.6, label=paper_line[1])
        if paper_landmarks:
            draw_paper_landmarks(ax)
            ax.set_ylim(bottom=0)
        ax.set_xlabel("excitation level a_base / a_base*")
        ax.set_ylabel("resonant mean a / a_noabs*")
        ax.set_title(title, fontsize=8)
        if many:
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        else:
            ax.legend(fontsize=7, loc="upper left")


#: what `plot_scattering` draws: impacts per period (Fig. D.2) or the coefficient of restitution (Fig. D.3)
SCATTERING_PLOTS = ("impacts", "restitution")


def plot_scattering(overview: Mapping[str, Any], runs: Sequence[Mapping[str, Any]], path: str | os.PathLike,
                    title: str, measure: str) -> None:
    """Fig. D.2 (`measure` "impacts": all and significant impacts per excitation period) or Fig. D.3 ("restitution": the modal
    coefficient of restitution r, Eq. D.1, from the tip and from the wall, at the levels whose resonant response
    is almost periodic) against the excitation level, at the resonant eta (`sim.stepped_sine.tables.overview_data` keys), each
    with the range of the runs' own values as error bars (`runs`: rows with level and the measures; Appendix D)."""
    import numpy as np

    levels = np.asarray(overview["levels"], dtype=float)
    if measure not in SCATTERING_PLOTS:
        raise ValueError(f"plot_scattering: measure {measure!r} is not one of {', '.join(SCATTERING_PLOTS)}")
    if measure == "impacts":
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
        if measure == "restitution":
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


def draw_tip_response(ax: Any, t: Sequence[float], q_tip: Sequence[float], data: Mapping[str, Any]) -> None:
    """Fig. 4 on `ax`: q_tip / a_noabs* against t, the per-period amplitudes a / a_noabs* (steps, +-), their
    mean (solid) and max (dashed) lines."""
    import numpy as np

    T = 1.0 / data["excitation_hz"]
    a = np.asarray(data["amplitudes"])
    edges = np.arange(a.size + 1) * T
    ax.plot(t, np.asarray(q_tip) / data["a_noabs"], color="0.3", lw=0.6, label=r"$q_{tip}$")
    for sign in (1, -1):
        ax.stairs(sign * a, edges, baseline=None, color="tab:orange", lw=0.9,
                  label="amplitude per period" if sign > 0 else None)
        ax.axhline(sign * data["mean"], color="tab:blue", ls="-", lw=1.0, label="mean" if sign > 0 else None)
        ax.axhline(sign * data["max"], color="tab:red", ls="--", lw=1.0, label="max" if sign > 0 else None)
    ax.set_ylabel(r"$q_{tip} / a^{noabs*}$")
    ax.grid(alpha=0.3)


def draw_tip_velocity(ax: Any, t: Sequence[float], v_tip: Sequence[float], data: Mapping[str, Any]) -> None:
    """Fig. 9a on `ax`: q_tip' / (Omega a_noabs*) against t with the impacts marked at their walls."""
    import numpy as np

    scale = 2.0 * math.pi * data["excitation_hz"] * data["a_noabs"]
    ax.plot(t, np.asarray(v_tip) / scale, color="0.3", lw=0.6)
    for wall, color in (("left", "tab:green"), ("right", "tab:purple")):
        times = [impact["t"] for impact in data["impacts"] if impact["wall"] == wall]
        if times:
            ax.vlines(times, 0.0, 1.0, transform=ax.get_xaxis_transform(), color=color, lw=0.6, alpha=0.6,
                      label=f"impact, {wall} wall")
    ax.set_ylabel(r"$\dot q_{tip} / (\Omega a^{noabs*})$")
    ax.set_xlabel("t (s)")
    ax.grid(alpha=0.3)


def plot_trace(data: Mapping[str, Any], t: Sequence[float], q_tip: Sequence[float], v_tip: Sequence[float],
               path: str | os.PathLike) -> None:
    """Figs. 4 (top: tip response, amplitudes, mean and max) and 9a (bottom: tip velocity and impacts) of one
    time history, in one file with a shared time axis."""
    from sim.common.files import pyplot

    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.0))
    try:
        draw_tip_response(top, t, q_tip, data)
        draw_tip_velocity(bottom, t, v_tip, data)
        top.set_title(trace_title(data), fontsize=9)
        top.legend(fontsize=7, loc="upper right", ncols=4)
        if bottom.get_legend_handles_labels()[0]:  # no impacts (e.g. a sphere at rest under friction): no legend
            bottom.legend(fontsize=7, loc="upper right", ncols=2)
        save_figure(fig, path)
    finally:
        plt.close(fig)


def plot_motion(t: Sequence[float], signal: Mapping[str, Sequence[float]], path: str | os.PathLike, title: str) -> None:
    """Fig. C.1b: the displacements of both walls and of the sphere relative to the base (mm) over a time history."""
    import numpy as np

    with plot_to(path, figsize=(7.0, 3.6)) as (fig, ax):
        t = np.asarray(t)
        for key, label, color in (("q_wall_left", "left wall", "tab:blue"), ("q_wall_right", "right wall", "tab:red"),
                                  ("q_sphere", "sphere", "k")):
            ax.plot(t, 1e3 * np.asarray(signal[key]), color=color, lw=0.9, label=label)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("displacement relative to the base (mm)")
        ax.set_title(title, fontsize=8)
        ax.legend(fontsize=7, loc="upper right", ncols=3)


def trace_title(data: Mapping[str, Any]) -> str:
    """The title of a time history's figure from its JSON data (`sim.analysis.trace.trace_data`)."""
    return (f"a_base/a_base* = {data['level']:g}, eta = {data['eta_actual']:.4f}: {data['periods']} periods at "
            f"{data['fs'] / 1e3:.2f} kHz, {data['impacts_per_period']:.2f} contact onsets per period ({data['integrator']})")


@register("ies trace --out", lambda folder: (folder / "trace.json").is_file() and (folder / "trace.csv").is_file())
def redraw_trace(folder: Path, options: PlotOptions) -> list[Path]:
    """Figs. 4 and 9a of an `ies trace --out` folder (trace.json, trace.csv), as trace.SUFFIX."""
    from sim.analysis.signals import read_signal

    data = json.loads((folder / "trace.json").read_text())
    selected([data["level"]], options, folder)
    signal = read_signal(folder / "trace.csv", ("q_tip", "v_tip"))
    paths = options.paths(folder, "trace")
    for path in paths:
        plot_trace(data, signal.t, signal["q_tip"], signal["v_tip"], path)
    return paths
