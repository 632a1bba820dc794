"""Figures of the simulation stage in the style of the seed paper: the stepped-sine frequency response (Fig. 5,
Sect. 5.2), the resonant level against the excitation level (Fig. 6, Sect. 5.3), the time histories of one
point (Figs. 4 and 9a, Sects. 5.1 and 5.5), and the impacts per period and the modal coefficient of restitution
against the excitation level (Figs. D.2, D.3, Appendix D).

They draw plain data (mappings of arrays), so that a result folder can be redrawn from its files (`ies plot`):
a frequency response has the keys of `sim.stepped_sine.protocol.SweepResult.to_dict` (eta, mean, mean_lo, mean_hi, max,
max_lo, max_hi); the resonant levels those of `sim.stepped_sine.tables.overview_data` (levels, resonant_mean, ...,
regime); a time history the columns t, q_tip, v_tip of `sim.analysis.trace.COLUMNS` and the keys of
`sim.analysis.trace.trace_data`. Files are written atomically through `sim.common.files` (format from the suffix).

Every figure of the workbench follows the same layout (checked by tests/test_figure_layout.py): legends beside
or below the axes (`legend_beside`, `legend_below`), never on data; panels that compare one plot on one y scale;
the regimes shaded on the level plots (`shade_regimes`); the tip amplitude in mm on a right-hand axis where one
level is shown (`secondary_mm`) and as Eq. B.1's stated factor on the level plots (`tip_note`); symbols and
units in mathtext; colours from the style's cycle (C0, C1, ...), so that a grayscale style greys everything.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from sim.common.files import plot_to, save_figure
from sim.stepped_sine.measures import (
    PAPER_APR_LEVEL,
    PAPER_OPTIMUM_LEVEL,
    PAPER_REDUCTION_MAX,
    PAPER_REDUCTION_MEAN,
)
from sim.common.figure_style import (  # noqa: F401 (re-exported for the figures' callers)
    ETA_LABEL,
    LEGEND_PT,
    LEVEL_LABEL,
    MICROMETRE,
    N_PER_MM15,
    RESPONSE_LABEL,
    legend_below,
    legend_beside,
)
from sim.plots.redraw import PlotOptions, register, selected

#: the shading of a regime on the level plots (Sect. 5.1, `sim.stepped_sine.measures.classify_regime`); SMR levels stay
#: white; "mixed": a band's points in both regimes at a level (`uq.outputs.figures`)
REGIME_SHADING = {"APR": {"facecolor": "0.9", "label": "APR levels (almost periodic response); white: SMR"},
                  "mixed": {"facecolor": "0.965", "label": "mixed levels: APR and SMR points"},
                  "linear": {"facecolor": "none", "edgecolor": "0.6", "hatch": "..",
                             "label": "linear levels (no impacts)"}}


def shade_regimes(ax: Any, levels: Sequence[float], regimes: Sequence[str],
                  labels: Mapping[str, str] | None = None) -> dict[str, list[tuple[float, float]]]:
    """Shade the excitation levels of each regime (REGIME_SHADING; `labels` replaces its legend entries, e.g. to say
    whose regime it is) behind the data of a level plot: a level's span reaches half way to its neighbours (half the
    nearest spacing beyond the first and last level). Returns the spans (from, to) of each regime, shaded or not."""
    import numpy as np

    spans: dict[str, list[tuple[float, float]]] = {}
    if not len(levels):
        return spans
    order = np.argsort(np.asarray(levels, dtype=float))
    x = np.asarray(levels, dtype=float)[order]
    kinds = [str(regimes[i]) for i in order]
    step = float(np.min(np.diff(x))) if x.size > 1 else 0.5
    edges = np.concatenate([[x[0] - step / 2], (x[1:] + x[:-1]) / 2, [x[-1] + step / 2]])
    labelled = set()
    i = 0
    while i < x.size:
        j = i
        while j + 1 < x.size and kinds[j + 1] == kinds[i]:
            j += 1
        spans.setdefault(kinds[i], []).append((float(edges[i]), float(edges[j + 1])))
        style = REGIME_SHADING.get(kinds[i])
        if style is not None:
            style = dict(style)
            label = (labels or {}).get(kinds[i], style.pop("label"))
            style.pop("label", None)
            ax.axvspan(edges[i], edges[j + 1], lw=0, zorder=0, label=None if kinds[i] in labelled else label,
                       gid=f"regime:{kinds[i]}", **style)
            labelled.add(kinds[i])
        i = j + 1
    return spans


def tip_mm_per_level(model: Any) -> float:
    """The tip amplitude (mm) of a normalised amplitude a/a_noabs* = 1 at the excitation level a_base/a_base* = 1,
    Eq. B.1: (phi_tip/phi_c) g*; the tip amplitude at a level L is (a/a_noabs*) L times this."""
    from sim.stepped_sine.measures import physical_amplitude

    return 1e3 * float(physical_amplitude(1.0, 1.0, model))


def tip_note(mm_per_level: float | None) -> str | None:
    """The stated factor of a level plot (Eq. B.1) that turns a/a_noabs* at a level into the tip amplitude in mm."""
    if mm_per_level is None:
        return None
    return (f"tip amplitude = {RESPONSE_LABEL} $\\times$ level $\\times$ {mm_per_level:.3f} mm (Eq. B.1)")


def secondary_mm(ax: Any, a_noabs: float, label: str = "tip amplitude (mm)") -> Any:
    """A right-hand axis in mm on a plot of a/a_noabs* at one level: a = (a/a_noabs*) a_noabs*, a_noabs* in m."""
    scale = 1e3 * float(a_noabs)
    axis = ax.secondary_yaxis("right", functions=(lambda y: y * scale, lambda y: y / scale))
    axis.set_ylabel(label)
    return axis


def draw_sweep(ax: Any, data: Mapping[str, Any], title: str, *, right_mm: bool = True) -> None:
    """Fig. 5 on `ax`: mean (solid, circles) and max (dashed, squares) amplitude a/a_noabs* at each frequency point of
    the stepped sine (a marker each: between two points nothing is known, a jump is not a slope), each with the range
    of its repetition samples as a translucent band (the spread of the paper's figure; neither band hides the other
    where they overlap); with `right_mm` and the data's a_noabs (m, a_noabs* at this level, Sect. 5), a right-hand
    axis gives the tip amplitude in mm."""
    eta = data["eta"]
    ax.fill_between(eta, data["max_lo"], data["max_hi"], color="C3", alpha=0.2, lw=0, label="max: range of the runs")
    ax.fill_between(eta, data["mean_lo"], data["mean_hi"], color="C0", alpha=0.25, lw=0,
                    label="mean: range of the runs")
    ax.plot(eta, data["max"], "s--", color="C3", ms=2.5, lw=1.0, label="max")
    ax.plot(eta, data["mean"], "o-", color="C0", ms=2.5, lw=1.0, label="mean")
    if data.get("dynamics"):  # ies sweep --lyapunov: periodic / quasi-periodic / chaotic on the mean
        from sim.plots.dynamics import draw_dynamics

        draw_dynamics(ax, eta, data["mean"], data["dynamics"])
    ax.set_xlabel(ETA_LABEL)
    ax.set_ylabel(RESPONSE_LABEL)
    ax.set_title(title, fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    if right_mm and data.get("a_noabs"):
        secondary_mm(ax, data["a_noabs"])


def plot_sweep(data: Mapping[str, Any], path: str | os.PathLike, title: str) -> None:
    """Fig. 5 of one frequency response, written to `path`."""
    with plot_to(path, figsize=(7.0, 4.0)) as (fig, ax):
        draw_sweep(ax, data, title)
        legend_beside(ax)


def plot_sweeps(panels: Sequence[tuple[Mapping[str, Any], str]], path: str | os.PathLike, title: str) -> None:
    """Fig. 5: one panel per (frequency response, panel title), two columns on one y scale (the panels are
    compared), one legend below them, written to `path`. The tip amplitude in mm is said once, as Eq. B.1's factor
    (`tip_note`), not as a right-hand scale per panel: a_noabs* grows with the level, so one left scale would carry a
    different mm scale in every panel."""
    from sim.common.files import pyplot

    plt = pyplot()
    columns = min(2, len(panels))
    rows = math.ceil(len(panels) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(5.6 * columns, 3.3 * rows + 0.9), squeeze=False, sharey=True,
                             layout="constrained")
    try:
        for ax, (data, panel_title) in zip(axes.flat, panels):
            draw_sweep(ax, data, panel_title, right_mm=False)
        for ax in axes.flat[len(panels):]:
            ax.set_visible(False)
        # one y range for all panels, from 0 to the highest band edge of any of them
        axes.flat[0].set_ylim(0.0, 1.05 * max(ax.dataLim.y1 for ax in axes.flat[:len(panels)]))
        for ax in axes[:, 1:].flat:
            ax.set_ylabel("")  # the shared scale is labelled once, on the left
        handles, labels = axes.flat[0].get_legend_handles_labels()
        first = panels[0][0]
        level = first.get("level")
        level = level[0] if isinstance(level, (list, tuple)) and level else level  # a sweeps.csv column or a number
        factor = 1e3 * first["a_noabs"] / level if first.get("a_noabs") and level else None
        fig.legend(handles, labels, loc="outside lower center", ncols=4, fontsize=LEGEND_PT, frameon=False,
                   title=tip_note(factor), title_fontsize=LEGEND_PT)
        fig.suptitle(title, fontsize=10)
        save_figure(fig, path)
    finally:
        plt.close(fig)


def _reduction(value: float) -> str:
    """'25-fold' for a resonant level of 0.04 a_noabs*: how many times smaller than without absorber."""
    return f"{1 / value:.0f}-fold" if value > 0 else "-"


#: what the legend of a level plot says about the mean and max drawn apart at each level
SIDE_BY_SIDE = "max (left) and mean (right) drawn side by side at each level"


def draw_overview(ax: Any, data: Mapping[str, Any], title: str, *, paper_optimum: bool = False) -> None:
    """Fig. 6 on `ax`: the resonant mean (solid) and max (dashed) level vs the excitation level, each with the
    range of its repetition samples at the resonant eta as error bars, drawn side by side at each level (SIDE_BY_SIDE:
    the bars of an SMR level overlap), the regime of each level (APR, SMR, linear:
    `sim.stepped_sine.measures.classify_regime` through the aggregation) shaded behind the data, this model's optimum
    (the lowest resonant mean) ringed on its two points and, with `paper_optimum`, the paper's landmarks: its optimum
    (a_base/a_base* ~ 6.7, its mean and max levels as stars, Sect. 5.3) and the almost periodic level at 7.4
    (Appendix B)."""
    import numpy as np

    levels = np.asarray(data["levels"], dtype=float)
    shade_regimes(ax, levels, data["regime"])
    tops = []
    step = float(np.min(np.diff(np.unique(levels)))) if np.unique(levels).size > 1 else 1.0
    at = {}
    for side, (name, style, color) in zip((-1, 1), (("max", "s--", "C3"), ("mean", "o-", "C0"))):
        value = np.asarray(data[f"resonant_{name}"], dtype=float)
        spread = [value - np.asarray(data[f"resonant_{name}_lo"], dtype=float),
                  np.asarray(data[f"resonant_{name}_hi"], dtype=float) - value]
        at[name] = (levels + side * step / 8, value)
        ax.errorbar(at[name][0], value, yerr=spread, fmt=style, color=color, ms=4, capsize=2, lw=1.2,
                    label=f"resonant {name} (bars: range of the runs)")
        tops.append(np.fmax(value, np.asarray(data[f"resonant_{name}_hi"], dtype=float)))
    y_top = 1.3 * max([float(np.nanmax(np.nanmax(tops, axis=0))),
                       *((PAPER_APR_LEVEL[1], 1 / PAPER_REDUCTION_MAX) if paper_optimum else ())])
    best = int(np.argmin(data["resonant_mean"]))
    ax.plot([at["max"][0][best], at["mean"][0][best]], [at["max"][1][best], at["mean"][1][best]], "o", ms=12,
            mfc="none", mec="C2", mew=1.5, ls="none", zorder=5,
            label=f"optimum of this model at {levels[best]:g} (rings): mean reduced "
                  f"{_reduction(data['resonant_mean'][best])}, max {_reduction(data['resonant_max'][best])}")
    if paper_optimum:
        draw_paper_landmarks(ax)
    ax.set_ylim(0, y_top)
    ax.set_xlabel(LEVEL_LABEL)
    ax.set_ylabel(f"resonant level {RESPONSE_LABEL}")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)


def draw_paper_landmarks(ax: Any, vertical_line: Any = None) -> None:
    """The paper's Fig. 6 landmarks on `ax`: its optimum (a_base/a_base* ~ 6.7, its mean and max levels as stars,
    Sect. 5.3) and its almost periodic level at 7.4 (a grey box, Appendix B). vertical_line(x, **style): a line also
    marking the optimum's level where a plot wants one (`plot_series`; default none: the stars mark it)."""
    from matplotlib.patches import Rectangle

    if vertical_line is not None:
        vertical_line(PAPER_OPTIMUM_LEVEL, color="k", lw=1, ls="-.", alpha=0.6)
    ax.plot([PAPER_OPTIMUM_LEVEL] * 2, [1 / PAPER_REDUCTION_MEAN, 1 / PAPER_REDUCTION_MAX], "k*", ms=8, ls="none",
            label=f"paper's optimum at {PAPER_OPTIMUM_LEVEL:g} (stars, its mean and max): mean reduced "
                  f"{PAPER_REDUCTION_MEAN:g}-fold, max {PAPER_REDUCTION_MAX:g}-fold")
    ax.add_patch(Rectangle((7.2, PAPER_APR_LEVEL[0]), 0.4, PAPER_APR_LEVEL[1] - PAPER_APR_LEVEL[0],
                           facecolor="0.55", edgecolor="0.3", alpha=0.6, lw=0.8,
                           label=f"paper's almost periodic level at 7.4 ({PAPER_APR_LEVEL[0]:g}-"
                                 f"{PAPER_APR_LEVEL[1]:g}, App. B)"))


def plot_overview(data: Mapping[str, Any], path: str | os.PathLike, title: str, *, paper_optimum: bool = False,
                  mm_per_level: float | None = None) -> None:
    """Fig. 6, written to `path`; the legend beside the axes states the factor to the tip amplitude in mm
    (`tip_note`; from the data's sweeps when they carry a_noabs, m, else `mm_per_level`)."""
    sweeps = data.get("sweeps") or []
    if mm_per_level is None and sweeps and sweeps[0].get("a_noabs") and sweeps[0].get("level"):
        mm_per_level = 1e3 * sweeps[0]["a_noabs"] / sweeps[0]["level"]  # a_noabs* grows with a_base (Sect. 5)
    with plot_to(path, figsize=(9.5, 4.4)) as (fig, ax):
        draw_overview(ax, data, title, paper_optimum=paper_optimum)
        legend_beside(ax, title="\n".join(t for t in (SIDE_BY_SIDE, tip_note(mm_per_level)) if t))


def plot_series(series: Sequence[tuple[str, Mapping[str, Any]]], path: str | os.PathLike, title: str,
                paper_line: tuple[float, str] | None = None, *, paper_landmarks: bool = False,
                mm_per_level: float | None = None) -> None:
    """Figs. 11 and C.1a: the resonant mean level against the excitation level, one curve per value of a series
    (`series`: [(label, `sim.stepped_sine.tables.overview_data` keys)]), each with the range of its runs as error bars;
    paper_line: (level, what the paper says there) marked as a vertical line; paper_landmarks: the paper's Fig. 6
    landmarks (draw_paper_landmarks; `ies compare`); mm_per_level: the factor to the tip amplitude (`tip_note`)."""
    import numpy as np

    with plot_to(path, figsize=(11.0, 4.4)) as (fig, ax):  # wide: the series side by side at each level
        every = np.unique(np.concatenate([np.asarray(data["levels"], dtype=float) for _, data in series]))
        span = float(every[-1] - every[0]) if every.size > 1 else 1.0
        closest = float(np.min(np.diff(every))) if every.size > 1 else 1.0
        tops: list[tuple[float, float]] = []
        for i, (label, data) in enumerate(series):
            levels = np.asarray(data["levels"], dtype=float)
            value = np.asarray(data["resonant_mean"], dtype=float)
            spread = [value - np.asarray(data["resonant_mean_lo"], dtype=float),
                      np.asarray(data["resonant_mean_hi"], dtype=float) - value]
            # markers and line styles tell apart curves of one colour (and in grayscale); each series a little
            # beside the others (1 % of the level range apart, the group within 90 % of the closest levels' spacing),
            # so that no error bar hides another's
            fmt = "osD^v<>ph*"[i % 10] + ("-", "--", ":", "-.")[i % 4]
            x = levels + (i - (len(series) - 1) / 2) * min(0.01 * span, 0.9 * closest / len(series))
            ax.errorbar(x, value, yerr=spread, fmt=fmt, ms=4, mfc="none" if i % 2 else None, capsize=2, lw=1.2,
                        label=label)
            tops += [(float(at), float(top)) for at, top in zip(x, np.nan_to_num(np.fmax(value, value + spread[1])))]
        y_top = 1.3 * max([top for _, top in tops] + ([PAPER_APR_LEVEL[1], 1 / PAPER_REDUCTION_MAX]
                                                      if paper_landmarks else []), default=1.0)

        def above_the_data(x: float, **style: Any) -> None:
            """A vertical line at level x from above the error bars near it to the top (never through a bar)."""
            start = 1.08 * max((top for at, top in tops if abs(at - x) < 0.06 * span), default=0.0)
            ax.plot([x, x], [start, y_top], **style)

        if paper_line is not None:
            above_the_data(paper_line[0], color="k", lw=1, ls="-.", alpha=0.6, label=paper_line[1])
        if paper_landmarks:
            draw_paper_landmarks(ax)
        ax.set_ylim(0, y_top)
        ax.set_xlabel(LEVEL_LABEL)
        ax.set_ylabel(f"resonant mean {RESPONSE_LABEL}")
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        legend_beside(ax, title=tip_note(mm_per_level))


#: what `plot_scattering` draws: impacts per period (Fig. D.2) or the coefficient of restitution (Fig. D.3)
SCATTERING_PLOTS = ("impacts", "restitution")


def plot_scattering(overview: Mapping[str, Any], runs: Sequence[Mapping[str, Any]], path: str | os.PathLike,
                    title: str, measure: str) -> None:
    """Fig. D.2 (`measure` "impacts": all and significant impacts per excitation period, the regimes shaded) or Fig.
    D.3 ("restitution": the modal coefficient of restitution r, Eq. D.1, from the tip and from the wall, at the levels
    whose resonant response is almost periodic: separate points, no line between levels) against the excitation level, at the resonant eta (`sim.stepped_sine.tables.overview_data` keys), each
    with the range of the runs' own values as error bars (`runs`: rows with level and the measures; Appendix D)."""
    import numpy as np

    levels = np.asarray(overview["levels"], dtype=float)
    if measure not in SCATTERING_PLOTS:
        raise ValueError(f"plot_scattering: measure {measure!r} is not one of {', '.join(SCATTERING_PLOTS)}")
    if measure == "impacts":
        curves = (("impacts_per_period", "all contact onsets", "s--", "C3", "none"),
                  ("significant_impacts_per_period", "significant impacts", "o-", "C0", None))
        ylabel = "impacts per excitation period"
        keep = np.ones(levels.size, dtype=bool)
    else:
        curves = (("restitution", "$r$ from the tip (Eq. D.1)", "o", "C0", None),
                  ("restitution_wall", "$r$ from the wall", "s", "C3", "none"))
        ylabel = "modal coefficient of restitution $r$"
        keep = np.array([regime == "APR" for regime in overview["regime"]])
    step = float(np.min(np.diff(np.unique(levels)))) if np.unique(levels).size > 1 else 1.0
    with plot_to(path, figsize=(9.0, 4.4)) as (fig, ax):
        spans = shade_regimes(ax, levels, overview["regime"]) if measure == "impacts" else {}
        for k, (key, label, style, color, face) in enumerate(curves):
            value = np.asarray(overview[key], dtype=float)[keep]
            # figD3: the two estimates side by side at each level, so that neither hides the other's bar
            x = levels[keep] + (0.06 * step * (2 * k - 1) if measure == "restitution" else 0.0)
            per_run = [[float(r[key]) for r in runs if float(r["level"]) == level and key in r]
                       for level in levels[keep]]
            lo = np.array([np.nanmin(v) if np.isfinite(v).any() else np.nan for v in map(np.asarray, per_run)])
            hi = np.array([np.nanmax(v) if np.isfinite(v).any() else np.nan for v in map(np.asarray, per_run)])
            spread = [np.clip(value - lo, 0, None), np.clip(hi - value, 0, None)]
            if runs and key in runs[0]:
                ax.errorbar(x, value, yerr=np.nan_to_num(spread), fmt=style, color=color, mfc=face, ms=5, capsize=2,
                            lw=1.2, label=f"{label} (bars: range of the runs)")
            else:
                ax.plot(x, value, style, color=color, mfc=face, ms=5, lw=1.2, label=label)
        if measure == "restitution":
            ax.axhline(0.8, color="k", lw=1, ls="-.", alpha=0.6, label="paper: $r$ ~ 0.8 (Fig. D.3)")
            ax.axhline(1.0, color="k", lw=0.8, alpha=0.3, label="$r$ = 1: elastic")
        else:  # the paper's statement is about the almost periodic levels: drawn over those only
            for k, (start, stop) in enumerate(spans.get("APR", [])):
                ax.plot([start, stop], [2.0, 2.0], color="k", lw=1, ls="-.", alpha=0.6,
                        label="paper: 2 per period in APR (Fig. D.2)" if k == 0 else None)
        ax.set_xlabel(LEVEL_LABEL)
        ax.set_ylabel(ylabel)
        ax.set_ylim(bottom=0)
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        legend_beside(ax)


def sweep_title(data: Mapping[str, Any]) -> str:
    """The title of a frequency response's figure from its data (`SweepResult.to_dict`)."""
    return (f"$a_\\mathrm{{base}}/a_\\mathrm{{base}}^*$ = {data['level']:g}, {data['n_samples']} samples "
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
    mean (solid) and max (dashed) lines with their values; a right-hand axis gives the tip displacement in mm
    (a_noabs* = data["a_noabs"], m)."""
    import numpy as np

    T = 1.0 / data["excitation_hz"]
    a = np.asarray(data["amplitudes"])
    edges = np.arange(a.size + 1) * T
    ax.plot(t, np.asarray(q_tip) / data["a_noabs"], color="0.45", lw=0.6, label=r"$q_\mathrm{tip}$")
    for sign in (1, -1):
        ax.stairs(sign * a, edges, baseline=None, color="C1", lw=1.0,
                  label="amplitude per period" if sign > 0 else None)
        ax.axhline(sign * data["mean"], color="C0", ls="-", lw=1.2, label=f"mean {data['mean']:.3f}" if sign > 0 else None)
        ax.axhline(sign * data["max"], color="C3", ls="--", lw=1.2, label=f"max {data['max']:.3f}" if sign > 0 else None)
    ax.set_ylabel(r"$q_\mathrm{tip}/a_\mathrm{noabs}^*$")
    ax.grid(alpha=0.3)
    secondary_mm(ax, data["a_noabs"], r"$q_\mathrm{tip}$ (mm)")


def draw_tip_velocity(ax: Any, t: Sequence[float], v_tip: Sequence[float], data: Mapping[str, Any],
                      strip: Any = None) -> None:
    """Fig. 9a on `ax`: q_tip' / (Omega a_noabs*) against t; the impacts as one marker per impact on the axes
    `strip` (a row per wall, `draw_impacts`), or along the top edge of `ax` when no strip is given."""
    import numpy as np

    scale = 2.0 * math.pi * data["excitation_hz"] * data["a_noabs"]
    ax.plot(t, np.asarray(v_tip) / scale, color="0.3", lw=0.6)
    ax.set_ylabel(r"$\dot q_\mathrm{tip}/(\Omega a_\mathrm{noabs}^*)$")
    ax.grid(alpha=0.3)
    if strip is None:
        for wall, marker in (("left", 7), ("right", 6)):  # caret down / up on the top edge
            times = [impact["t"] for impact in data["impacts"] if impact["wall"] == wall]
            ax.plot(times, [1.0] * len(times), ls="none", marker=marker, ms=4, color="C3",
                    transform=ax.get_xaxis_transform(), clip_on=False)
        ax.set_xlabel("t (s)")
    else:
        draw_impacts(strip, data["impacts"])


def draw_impacts(ax: Any, impacts: Sequence[Mapping[str, Any]]) -> None:
    """The impacts of a time history as a strip: one short tick per contact onset, a row per wall (readable at any
    number of impacts, unlike a full-height line each)."""
    for row, (wall, color) in enumerate((("left", "C0"), ("right", "C3"))):
        times = [impact["t"] for impact in impacts if impact["wall"] == wall]
        ax.plot(times, [row] * len(times), ls="none", marker="|", ms=9, mew=1.0, color=color)
    ax.set_ylim(-0.6, 1.6)
    ax.set_yticks([0, 1], ["left wall", "right wall"], fontsize=8)
    ax.set_ylabel("impacts", fontsize=8)
    ax.grid(alpha=0.3, axis="x")
    ax.set_xlabel("t (s)")


def plot_trace(data: Mapping[str, Any], t: Sequence[float], q_tip: Sequence[float], v_tip: Sequence[float],
               path: str | os.PathLike) -> None:
    """Figs. 4 (top: tip response, amplitudes, mean and max) and 9a (middle: tip velocity; bottom: the impacts
    on each wall) of one time history, in one file with a shared time axis and the legend beside the axes."""
    from sim.common.files import pyplot

    plt = pyplot()
    fig, (top, middle, bottom) = plt.subplots(3, 1, sharex=True, figsize=(9.0, 6.6), layout="constrained",
                                              gridspec_kw={"height_ratios": (3, 3, 1)})
    try:
        draw_tip_response(top, t, q_tip, data)
        draw_tip_velocity(middle, t, v_tip, data, strip=bottom)
        top.set_title(trace_title(data), fontsize=9)
        legend_beside(top, title=r"values: $a/a_\mathrm{noabs}^*$")
        save_figure(fig, path)
    finally:
        plt.close(fig)


def plot_motion(t: Sequence[float], signal: Mapping[str, Sequence[float]], path: str | os.PathLike, title: str) -> None:
    """Fig. C.1b: the displacements of both walls and of the sphere relative to the base (mm) over a time history."""
    import numpy as np

    with plot_to(path, figsize=(8.5, 3.6)) as (fig, ax):
        t = np.asarray(t)
        for key, label, color, style in (("q_wall_left", "left wall", "C0", "-"), ("q_wall_right", "right wall", "C3", "--"),
                                         ("q_sphere", "sphere", "k", "-")):
            ax.plot(t, 1e3 * np.asarray(signal[key]), color=color, ls=style, lw=0.9, label=label)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("displacement relative to the base (mm)")
        ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
        legend_beside(ax)


def trace_title(data: Mapping[str, Any]) -> str:
    """The title of a time history's figure from its JSON data (`sim.analysis.trace.trace_data`)."""
    return (f"$a_\\mathrm{{base}}/a_\\mathrm{{base}}^*$ = {data['level']:g}, $\\eta$ = {data['eta_actual']:.4f}: "
            f"{data['periods']} periods at {data['fs'] / 1e3:.2f} kHz, {data['impacts_per_period']:.2f} contact onsets "
            f"per period ({data['integrator']})")


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
