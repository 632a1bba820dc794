"""Figures drawn from a study's data files, in the style of the seed paper's Figs. 5-8.

* Fig. 7 (individual variation, one panel per parameter) and Fig. 8 (joint band, and the residual band with k_H
  fixed at its best estimate), interval studies: every curve and band edge carries the standard error of its
  repetition mean as error bars; marks show where the nominal value lies outside its band (beyond the noise,
  or within it) and where the monotonicity check failed or could not be made; the legend explains them.
  "Nominal" is the point (D*, g*, k_H*) of Table 2 (k_H* = 282e3 N/mm^1.5), named so on the figure.
* nominal-levels: the nominal point's resonant mean and max against the excitation level with the regime of
  each level (an interval study's by-product; not the paper's Fig. 6, which a response study draws).
* Fig. 5 (frequency responses, one panel per level) and Fig. 6 (resonant levels against the excitation level,
  the paper's optimum marked), response studies, through `sim.plots.figures`.
* Sobol': S1 and ST with their confidence intervals vs level, and the repetition-noise share.

Only the data files are read, never the runs, so `ies plot` redraws any of them (`sim.plots.redraw`: the Sobol' and
`ies reproduce` folders are registered here, the interval and response studies with the figure table in
`uq.outputs.paper_figures`, which names the figures). This module knows no figure's name. Every figure is written in the
formats of the plot options (PNG and PDF by default).
"""
from __future__ import annotations

import json
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from sim.common.errors import SimulationInputError
from sim.plots.figures import (
    LEGEND_PT,
    LEVEL_LABEL,
    N_PER_MM15,
    RESPONSE_LABEL,
    legend_below,
    legend_beside,
    shade_regimes,
    tip_mm_per_level,
    tip_note,
)
from sim.common.files import pyplot, read_rows, save_figure
from sim.plots.redraw import KINDS, PlotOptions, kind_of, register, selected
from uq.outputs.results import nominal_regimes, study_kind

_YLABEL = {"mean": f"mean resonant level {RESPONSE_LABEL}", "max": f"max resonant level {RESPONSE_LABEL}",
           "value": "response", "restitution": "modal coefficient of restitution $r$ (tip)",
           "restitution_wall": "modal coefficient of restitution $r$ (wall)"}
_NOISE_NOTE = "error bars: standard error of the repetition mean ({n} runs per point)"
#: the outputs whose bands are drawn level by level (bars, no band between levels): r exists at APR levels only
_DISCRETE_OUTPUTS = ("restitution", "restitution_wall")


def _rows(path: Path, options: PlotOptions | None = None) -> list[dict]:
    """A CSV file's rows (`sim.common.files.read_rows`: one line naming the file and the line where it is cut short);
    with `options`, only the rows of the chosen levels."""
    rows = read_rows(path)
    if options is not None and rows and "level" in rows[0]:
        rows = [r for r in rows if options.keeps(float(r["level"]))]
    return rows


def _save(fig: Any, folder: Path, stem: str, options: PlotOptions) -> list[Path]:
    paths = options.paths(folder, stem)
    for path in paths:
        save_figure(fig, path)
    return paths


def _study(folder: Path) -> dict:
    return json.loads((folder / "study.json").read_text())


def _curve(points: list[dict], design: str, point: str, output: str) -> tuple[np.ndarray, ...]:
    """(levels, values, standard errors) of one point of a design, ordered by level."""
    rows = sorted((r for r in points if r["design"] == design and r["point"] == point and r["output"] == output),
                  key=lambda r: float(r["level"]))
    return tuple(np.array([float(r[k]) for r in rows]) for k in ("level", "mean", "se"))


def _band(bands: list[dict], design: str, output: str) -> dict[str, np.ndarray]:
    rows = sorted((r for r in bands if r["design"] == design and r["output"] == output), key=lambda r: float(r["level"]))
    out = {k: np.array([float(r[k]) for r in rows]) for k in ("level", "lower", "upper", "lower_se", "upper_se",
                                                               "nominal", "nominal_se")}
    for k in ("flagged", "tested", "nominal_outside"):
        out[k] = np.array([int(r[k]) for r in rows])
    return out


def parameter_text(name: str, value: float, star: bool = False) -> str:
    """A parameter value as the figures print it, in the unit of Table 2 (mathtext): D in %, g in mm, k_H in
    N/mm^1.5 ('$g$ = 0.580 mm'); star: the nominal symbol ('$g^*$'); other parameters by name, plain."""
    mark = "^*" if star else ""
    if name == "D":
        return f"$D{mark}$ = {100 * value:.3g} %"
    if name == "g":
        return f"$g{mark}$ = {1e3 * value:.3f} mm"
    if name == "k_H":
        return f"$k_H{mark}$ = {value / 1e3**1.5 / 1e3:.0f}$\\times 10^3$ {N_PER_MM15}"
    return f"{name}{'*' if star else ''} = {value:.4g}"


def parameter_title(name: str, parameter: dict) -> str:
    """A panel title of Fig. 7: the parameter's label and the unit its values are printed in (`parameter_text`)."""
    unit = {"D": "%", "g": "mm", "k_H": N_PER_MM15}.get(name, parameter.get("unit", ""))
    words, _, symbol = parameter.get("label", name).rpartition(" ")
    if symbol.split("_")[0] == name.split("_")[0]:  # the label ends in the symbol: typeset it ('k_H' -> $k_H$)
        symbol = f"${symbol}$"
    label = f"{words} {symbol}".strip()
    return f"{label} ({unit})" if unit and unit != "-" else label


def nominal_label(parameters: dict) -> str:
    """'nominal ($D^*$ = 0.085 %, $g^*$ = 0.580 mm, $k_H^*$ = 282x10^3 N/mm^1.5)' for the simulator's Table 2 point;
    the parameters' nominal values for other models."""
    parts = [parameter_text(name, p["nominal"], star=True) for name, p in parameters.items() if not name.startswith("_")]
    return "nominal (" + ", ".join(parts) + ")"


def _corner_value(label: str) -> float:
    """The parameter value of a corner point of an individual design ('g=0.00061' -> 0.00061)."""
    return float(label.split("=", 1)[1])


def _errorbar(ax: Any, x: np.ndarray, y: np.ndarray, se: np.ndarray, fmt: str, **kwargs: Any) -> None:
    """A curve with standard-error bars (no bar where the error is unknown, NaN)."""
    ax.errorbar(x, y, yerr=np.nan_to_num(se, nan=0.0), fmt=fmt, capsize=2, ms=kwargs.pop("ms", 4), lw=kwargs.pop("lw", 1.2),
                elinewidth=0.8, **kwargs)


#: what the fill of a band spans (its legend entry)
BAND_SPAN = "lowest to highest point"
#: how an unresolved band is drawn and said (`uq.outputs.results.unresolved`)
UNRESOLVED = "not resolved (narrower than 2 SE of its edges): dotted"


def _band_with_noise(ax: Any, band: dict, color: str, alpha: float, label: str, *, discrete: bool = False,
                     offset: float = 0.0, width: float = 0.0,
                     curves: Sequence[tuple[np.ndarray, np.ndarray]] = ()) -> None:
    """The band, filled from its lowest to its highest point where it is resolved (wider than the noise of its edges,
    `uq.outputs.results.unresolved`) and only outlined (dotted) where it is not, and the standard errors of its edges
    (bars at both edges). discrete: one box per level (width in level units, shifted by offset), no band drawn between
    levels. curves: (levels, values) of the curves drawn with their own error bars at the same levels: where an edge is
    one of them (a corner or the nominal at a bound) its bar is theirs, not drawn twice."""
    from uq.outputs.results import unresolved

    x = band["level"] + offset
    loose = np.array([unresolved(lo, hi, lo_se, hi_se) for lo, hi, lo_se, hi_se in
                      zip(band["lower"], band["upper"], band["lower_se"], band["upper_se"])], dtype=bool)
    outline = {"fill": False, "edgecolor": color, "ls": ":", "lw": 1.2}
    if discrete:
        ax.bar(x[~loose], (band["upper"] - band["lower"])[~loose], width, bottom=band["lower"][~loose], color=color,
               alpha=alpha, lw=0, label=label)
        if loose.any():
            ax.bar(x[loose], (band["upper"] - band["lower"])[loose], width, bottom=band["lower"][loose],
                   label=f"{label.split(':')[0].split(' (')[0]} {UNRESOLVED}", **outline)
    else:
        # filled between resolved levels only (matplotlib fills between consecutive levels both kept); where a level
        # is not resolved the band is its two edges, dotted
        ax.fill_between(x, band["lower"], band["upper"], where=~loose, color=color, alpha=alpha, lw=0, label=label)
        if loose.any():
            near = _near_unresolved(loose)
            for edge in ("lower", "upper"):
                ax.plot(x, np.where(near, band[edge], np.nan), ":", color=color, lw=1.2,
                        label=f"{label.split(':')[0].split(' (')[0]} {UNRESOLVED}" if edge == "lower" else None)
    at = x - 0.3 * width if discrete else x  # a box's edge errors off its centre, where the nominal point sits
    for edge in ("lower", "upper"):
        own = ~loose  # an unresolved band's edge bars would lie on one another: its outline says it all
        if not own.any():
            continue
        for levels, values in curves:
            at_level = dict(zip(np.round(levels, 9), values))
            own &= ~np.array([np.isclose(at_level.get(round(lv, 9), np.nan), v, rtol=1e-12, atol=0.0)
                              for lv, v in zip(band["level"], band[edge])])
        ax.errorbar(at[own], band[edge][own], yerr=np.nan_to_num(band[f"{edge}_se"][own], nan=0.0), fmt="none",
                    ecolor=color, elinewidth=0.8, capsize=2, alpha=0.9)


def _near_unresolved(loose: np.ndarray) -> np.ndarray:
    """The levels an outline runs through: the unresolved ones and their neighbours (the dotted segments reach the
    filled part)."""
    near = loose.copy()
    near[1:] |= loose[:-1]
    near[:-1] |= loose[1:]
    return near


def _marks(ax: Any, band: dict, prefix: str = "", offset: float = 0.0) -> None:
    """Where the nominal value lies outside the band (beyond or within the noise; not judged where the band is not
    resolved: it is noise there), where the monotonicity check failed (band widened) and where it could not be made;
    each explained in the legend."""
    from uq.outputs.results import unresolved

    lv = band["level"] + offset
    loose = np.array([unresolved(lo, hi, lo_se, hi_se) for lo, hi, lo_se, hi_se in
                      zip(band["lower"], band["upper"], band["lower_se"], band["upper_se"])], dtype=bool)
    applies = (band["nominal_outside"] >= 0) & ~loose
    beyond = applies & (band["nominal_outside"] == 1)
    outside = applies & ((band["nominal"] < band["lower"]) | (band["nominal"] > band["upper"]))
    within = outside & ~beyond
    if beyond.any():
        ax.plot(lv[beyond], band["nominal"][beyond], "o", ms=11, mfc="none", mec="C4", mew=2, ls="none",
                label=f"{prefix}nominal outside its band, beyond the noise")
    if within.any():
        ax.plot(lv[within], band["nominal"][within], "o", ms=11, mfc="none", mec="0.5", mew=1.2, ls="none",
                label=f"{prefix}nominal outside its band, within the noise")
    flagged = band["flagged"] == 1
    if flagged.any():
        ax.plot(lv[flagged], band["upper"][flagged], "x", color="C3", ms=9, mew=2, ls="none",
                label=f"{prefix}monotonicity check failed (band widened to all points)")
    untested = band["tested"] == 0
    if untested.any():
        ax.plot(lv[untested], band["upper"][untested], ls="none", marker="$?$", color="0.3", ms=9,
                label=f"{prefix}monotonicity not tested (no noise estimate)")


def band_regimes(points: list[dict], design: str, output: str) -> dict[float, str]:
    """{level: regime} of a band: APR or SMR (or linear) where every point of the design and the nominal point has it,
    "mixed" where they differ (`sim.plots.figures.shade_regimes`): the nominal point's regime alone would call a
    level APR where an edge of the band is strongly modulated."""
    found: dict[float, set[str]] = {}
    for r in points:
        if r["output"] == output and r["design"] in (design, "nominal"):
            found.setdefault(float(r["level"]), set()).add(r.get("regime", ""))
    return {level: next(iter(kinds)) if len(kinds) == 1 else "mixed" for level, kinds in sorted(found.items())}


#: whose regime a band figure shades
BAND_REGIMES = {"APR": "APR: every point of the band (white: SMR)", "mixed": "mixed: APR and SMR points in the band"}


def _tip_mm_per_level(meta: dict) -> float | None:
    """Eq. B.1's factor to the tip amplitude (`sim.plots.figures.tip_mm_per_level`) of the simulator's host model (the
    built-in rig, or the study's modal-model file); None for other models or when the file cannot be read."""
    study = meta.get("study", {})
    if study.get("model") != "ies":
        return None
    from sim.hosts.sources import resolve_host

    try:
        return tip_mm_per_level(resolve_host({"model": study.get("modal_model") or None}).model)
    except (OSError, ValueError):  # a moved or changed modal file: the figure is drawn without the factor
        return None


def _level_step(levels: np.ndarray) -> float:
    unique = np.unique(levels)
    return float(np.min(np.diff(unique))) if unique.size > 1 else 1.0


def residual_label(study: dict) -> str:
    """The residual band's legend entry with the values its parameters are fixed at ('residual: $k_H$ = 352x10^3
    N/mm^1.5 fixed (its best estimate)')."""
    fixed = study.get("interval", {}).get("fix", {})
    best = study.get("parameters", {}).get("_extras", {}).get("k_H_best_estimate")
    parts = [parameter_text(name, value) + " fixed" + (" (its best estimate)" if name == "k_H" and best is not None
                                                       and np.isclose(value, best, rtol=1e-9) else "")
             for name, value in fixed.items()]
    return "residual: " + ", ".join(parts) if parts else "residual"


def joint_label(study: dict) -> str:
    """The joint band's legend entry naming what varies in it ('joint: $D$ and $g$ varied together')."""
    varied = [name for name, p in study.get("parameters", {}).items()
              if not name.startswith("_") and isinstance(p, dict) and p.get("max", 0) > p.get("min", 0)]
    names = [f"${name}$" if name in ("D", "g", "k_H") else name for name in varied]
    together = names[0] if len(names) == 1 else ", ".join(names[:-1]) + f" and {names[-1]}"
    return f"joint: {together} varied together" if names else "joint"


#: the title over the panels of a joint-band figure of several outputs (Fig. D.3: r from the tip and from the wall)
BOX_SUPTITLE = "Joint variation (cf. Fig. D.3)"
#: the joint-band figure of a banded output: (file stem, title, a level of the paper to mark (value, label) or None)
BoxFigure = tuple[str, str, "tuple[float, str] | None"]


def interval_figures(folder: str | Path, options: PlotOptions | None = None, *, individual_stem: str,
                     box_figure: Callable[[str], BoxFigure], nominal_levels: bool = True) -> list[Path]:
    """Draw Figs. 7 and 8 (as far as the study has the designs) and, with `nominal_levels`, the nominal point's levels
    from folder/*.csv: the individual variation under the stem `individual_stem`, the joint band as `box_figure(output)`
    names it (`uq.outputs.paper_figures.interval_figures` passes the names: the paper's for `ies reproduce`, what they
    show for a study of one's own)."""
    folder = Path(folder)
    options = options or PlotOptions()
    meta = _study(folder)
    points, bands = _rows(folder / "points.csv", options), _rows(folder / "bands.csv", options)
    selected(sorted({float(r["level"]) for r in _rows(folder / "bands.csv")}), options, folder)
    output = meta["outputs"][0]  # "mean" for the simulator: the paper's Figs. 7-8 show the mean only
    designs = list(dict.fromkeys(r["design"] for r in bands))
    discrete = output in _DISCRETE_OUTPUTS or len(nominal_regimes(points, output)) < 4
    note = _NOISE_NOTE.format(n=meta["study"]["repetitions"])
    factor = _tip_mm_per_level(meta) if output in ("mean", "max") else None
    notes = "\n".join(text for text in (note, tip_note(factor)) if text)
    view = _IntervalView(meta, points, bands, discrete, notes)
    paths: list[Path] = []
    individual = [d for d in designs if d.startswith("individual:")]
    if individual:
        paths += _individual_figure(view, individual, output, individual_stem, folder, options)
    box = [d for d in designs if d in ("joint", "residual")]
    if box:
        # Fig. D.3's r from the tip and from the wall: a panel each; Fig. 8 the resonant mean only
        shown = [o for o in meta["outputs"] if o in _DISCRETE_OUTPUTS] if output in _DISCRETE_OUTPUTS else [output]
        paths += _box_figure(view, box, shown, box_figure, folder, options)
    if nominal_levels and {"mean", "max"} <= set(meta["outputs"]):
        paths += _nominal_levels(folder, points, nominal_label(meta["study"]["parameters"]), notes, options)
    return paths


@dataclass(frozen=True)
class _IntervalView:
    """What the figures of an interval study are drawn from: study.json, points.csv and bands.csv at the chosen
    levels, whether levels are drawn one by one (`discrete`) and the notes heading the legends."""

    meta: dict
    points: list[dict]
    bands: list[dict]
    discrete: bool
    notes: str


def _individual_figure(view: _IntervalView, individual: list[str], output: str, stem: str, folder: Path,
                       options: PlotOptions) -> list[Path]:
    """Fig. 7: a panel per parameter, its band (lowest to highest point), the nominal curve and its corners, the levels
    shaded by the regimes of the band's points (`band_regimes`)."""
    plt = pyplot()
    params = view.meta["study"]["parameters"]
    nominal = _curve(view.points, "nominal", "nominal", output)
    fig, axes = plt.subplots(1, len(individual), figsize=(4.4 * len(individual), 5.6), squeeze=False, sharey=True,
                             layout="constrained")
    for ax, d in zip(axes[0], individual):
        pname = d.split(":", 1)[1]
        band = _band(view.bands, d, output)
        if not view.discrete:
            regimes = band_regimes(view.points, d, output)
            shade_regimes(ax, list(regimes), list(regimes.values()), labels=BAND_REGIMES)
        width = 0.3 * _level_step(band["level"])
        corners = sorted({r["point"] for r in view.points if r["design"] == d and r["role"] == "corner"},
                         key=_corner_value)
        value = params.get(pname, {}).get("nominal")
        # a corner at the nominal value is the nominal curve: drawn and listed once, as the nominal at that end
        ends = [(label, marker, style, color, end) for (label, marker, style, color, end) in
                ((corners[0], "v", ":", "C0", "lower"), (corners[-1], "^", "-", "C3", "upper"))
                if value is None or not np.isclose(_corner_value(label), value, rtol=1e-6)]
        at_end = [end for end in ("lower", "upper") if end not in {e[-1] for e in ends}]
        curves = [_curve(view.points, d, label, output) for label, *_ in ends]
        _band_with_noise(ax, band, "C0", 0.2, f"band: {BAND_SPAN} (bars: ± SE of its edges)", discrete=view.discrete,
                         width=width, curves=[(c[0], c[1]) for c in [nominal, *curves]])
        _errorbar(ax, *nominal, "--" if not view.discrete else "D", color="k", lw=1.4 if at_end else 1.0, ms=3,
                  zorder=4, label=(parameter_text(pname, value, star=True) + " (nominal"
                                   + "".join(f", {end} end" for end in at_end) + ")") if pname in params else "nominal")
        for (label, marker, style, color, _), curve in zip(ends, curves):
            _errorbar(ax, *curve, marker + ("" if view.discrete else style), color=color, mfc="none", ms=6, zorder=3,
                      label=parameter_text(pname, _corner_value(label)))
        _marks(ax, band)
        ax.set_title(_capitalised(parameter_title(pname, params.get(pname, {}))), fontsize=9)
        ax.set_xlabel(LEVEL_LABEL)
        ax.grid(alpha=0.3)
        legend_below(ax)
    axes[0][0].set_ylabel(_YLABEL.get(output, output))
    fig.suptitle(f"Individual variation (cf. Fig. 7); {nominal_label(params)}", fontsize=10)
    fig.supxlabel(view.notes, fontsize=LEGEND_PT)
    paths = _save(fig, folder, stem, options)
    plt.close(fig)
    return paths


def _capitalised(text: str) -> str:
    """`text` with a capital first letter (a title)."""
    return text[:1].upper() + text[1:]


def _box_figure(view: _IntervalView, box: list[str], outputs: list[str], box_figure: Callable[[str], BoxFigure],
                folder: Path, options: PlotOptions) -> list[Path]:
    """Fig. 8 (the joint band filled, the residual band in another colour over it, both see-through) or Fig. D.3 (r
    from the tip and from the wall, a panel each, the bands level by level), with the nominal curve, the marks of
    `_marks`, the levels shaded by the regimes of the joint band's points and the paper's reference level."""
    plt = pyplot()
    study = view.meta["study"]
    labels = {"joint": joint_label(study), "residual": residual_label(study)}
    colors = {"joint": ("C0", 0.22), "residual": ("C1", 0.3)}
    step = _level_step(np.array([float(r["level"]) for r in view.bands]))
    stem, _, _ = box_figure(outputs[0])
    fig, axes = plt.subplots(1, len(outputs), figsize=(9.5 if len(outputs) == 1 else 6.2 * len(outputs), 4.8),
                             squeeze=False, sharey=True, layout="constrained")
    for ax, output in zip(axes[0], outputs):
        _, title, reference = box_figure(output)  # Fig. 8 for the resonant level, Fig. D.3 for r (a panel each)
        nominal = _curve(view.points, "nominal", "nominal", output)
        if not view.discrete:
            regimes = band_regimes(view.points, box[0], output)
            shade_regimes(ax, list(regimes), list(regimes.values()), labels=BAND_REGIMES)
        for k, d in enumerate(box):
            color, alpha = colors[d]
            band = _band(view.bands, d, output)
            # discrete levels: the two bands side by side, so that no bar hides the other's
            offset = (k - (len(box) - 1) / 2) * 0.25 * step if view.discrete else 0.0
            _band_with_noise(ax, band, color, alpha, f"{labels[d]} ({BAND_SPAN}; bars: ± SE of its edges)",
                             discrete=view.discrete, offset=offset, width=0.22 * step)
            _marks(ax, band, prefix=f"{d}: ", offset=offset)
        _errorbar(ax, *nominal, "kD" if view.discrete else "k.--", ms=4, zorder=4,
                  label=nominal_label(study["parameters"]))
        if reference is not None:
            ax.axhline(reference[0], color="k", lw=1, ls="-.", alpha=0.6, label=reference[1])
        if view.discrete:
            ax.set_xticks(np.unique(nominal[0]))
        ax.set_xlabel(LEVEL_LABEL)
        ax.set_title(title, fontsize=10 if len(outputs) == 1 else 9)
        ax.grid(alpha=0.3)
    if len(outputs) > 1:
        fig.suptitle(BOX_SUPTITLE, fontsize=10)
    axes[0][0].set_ylabel(_YLABEL.get(outputs[0], outputs[0]) if len(outputs) == 1 else
                          "modal coefficient of restitution $r$")
    if outputs[0] in _DISCRETE_OUTPUTS:  # r: the data and the paper's 0.8 in view, not the whole of (0, 1]
        _fit_y(axes[0], reference[0] if reference is not None else None)
    legend_beside(axes[0][-1], title=view.notes, handles_of=list(axes[0]))
    paths = _save(fig, folder, stem, options)
    plt.close(fig)
    return paths


def _fit_y(axes: Sequence[Any], reference: float | None) -> None:
    """One y range for `axes` from their data and `reference`, with a tenth of the span as margin on either side."""
    low, high = np.inf, -np.inf
    for ax in axes:
        for artist in [*ax.collections, *ax.patches, *ax.lines]:
            if artist.get_zorder() <= 0 or not artist.get_visible():
                continue
            if hasattr(artist, "get_datalim"):
                box = artist.get_datalim(ax.transData)
                ys = [box.y0, box.y1] if np.isfinite([box.y0, box.y1]).all() else []
            elif hasattr(artist, "get_bbox"):
                ys = [artist.get_bbox().y0, artist.get_bbox().y1]
            else:
                ys = [y for y in np.asarray(artist.get_ydata(), dtype=float) if np.isfinite(y)]
            if ys and not (len(ys) == 2 and ys[0] == ys[1] == reference):
                low, high = min(low, *ys), max(high, *ys)
    if reference is not None:
        low, high = min(low, reference), max(high, reference)
    if np.isfinite([low, high]).all() and high > low:
        margin = 0.1 * (high - low)
        axes[0].set_ylim(low - margin, high + margin)


def _nominal_levels(folder: Path, points: list[dict], nominal_text: str, note: str, options: PlotOptions) -> list[Path]:
    """The nominal point's resonant mean and max against the excitation level, with their standard errors and the
    regime of each level shaded (`uq.outputs.results.nominal_regimes`); `note` heads the legend. A study of one's own
    draws it (`ies reproduce` shows the nominal point's levels in Fig. 6, a study of their own)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9.5, 4.4), layout="constrained")
    regimes = nominal_regimes(points)
    shade_regimes(ax, list(regimes), list(regimes.values()))
    for output, fmt, color in (("max", "s--", "C3"), ("mean", "o-", "C0")):
        _errorbar(ax, *_curve(points, "nominal", "nominal", output), fmt, color=color, label=f"resonant {output}")
    ax.set_xlabel(LEVEL_LABEL)
    ax.set_ylabel(f"resonant response level {RESPONSE_LABEL}")
    ax.set_title("Resonant levels of the nominal point " + nominal_text.removeprefix("nominal "), fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    legend_beside(ax, title=note)
    paths = _save(fig, folder, "nominal-levels", options)
    plt.close(fig)
    return paths


#: the axis range of the Sobol' figure: indices lie in [0, 1]; estimates and intervals beyond it are sampling error
_SOBOL_RANGE = (-0.25, 1.25)


def sobol_figure(folder: str | Path, options: PlotOptions | None = None) -> list[Path]:
    """S1 and ST (with confidence bars) per parameter vs level, and the noise share as a bar of its own, per output.
    The y axis shows the indices' range [0, 1]; where an estimate or interval end leaves it (sampling error of a
    small n) the axis widens to [-0.25, 1.25], an end beyond that is marked by a triangle at the edge, and the
    legend says so and what to do (a larger [sobol] n)."""
    folder = Path(folder)
    options = options or PlotOptions()
    plt = pyplot()
    rows, var = _rows(folder / "sobol.csv", options), _rows(folder / "variance.csv", options)
    selected(sorted({float(r["level"]) for r in _rows(folder / "sobol.csv")}), options, folder)
    meta = _study(folder) if (folder / "study.json").is_file() else {}
    n = meta.get("study", {}).get("sobol", {}).get("n")
    outputs = list(dict.fromkeys(r["output"] for r in rows))
    # the surrogate's verdict (surrogate.csv): a level whose response is NOT SMOOTH has unreliable indices, drawn as
    # outlines only (and said so in the legend), never like the valid ones
    rough = {(r["output"], float(r["level"])) for r in (_rows(folder / "surrogate.csv")
                                                        if (folder / "surrogate.csv").is_file() else [])
             if r.get("smooth") == "0"}
    fig, axes = plt.subplots(1, len(outputs), figsize=(5.5 * len(outputs) + 3.0, 4.0), squeeze=False,
                             layout="constrained")
    for ax, o in zip(axes[0], outputs):
        sub = [r for r in rows if r["output"] == o]
        levels = sorted({float(r["level"]) for r in sub})
        names = list(dict.fromkeys(r["parameter"] for r in sub))
        width = 0.8 / (2 * len(names) + 1)  # S1 and ST of every parameter, then the noise share, side by side
        x = np.arange(len(levels))
        every = np.array([float(r[f"{i}"]) + s * float(r[f"{i}_conf"]) for r in sub for i in ("S1", "ST")
                          for s in (-1, 1)])
        every = every[np.isfinite(every)]
        # [0, 1] (the range of an index) unless an estimate or interval leaves it: then up to _SOBOL_RANGE
        lo = _SOBOL_RANGE[0] if every.size and every.min() < -0.02 else -0.02
        hi = _SOBOL_RANGE[1] if every.size and every.max() > 1.02 else 1.05
        beyond = False
        for k, pname in enumerate(names):
            pr = sorted((r for r in sub if r["parameter"] == pname), key=lambda r: float(r["level"]))
            for m, (idx, hatch) in enumerate((("S1", ""), ("ST", "//"))):
                vals = np.array([float(r[idx]) for r in pr])
                errs = np.array([float(r[f"{idx}_conf"]) for r in pr])
                at = x + (2 * k + m - len(names) - 0.5) * width + width / 2
                # the whiskers end at the axis edge where they would run on (marked there by a triangle)
                shown = np.array([np.clip(np.minimum(errs, vals - lo), 0, None),
                                  np.clip(np.minimum(errs, hi - vals), 0, None)])
                valid = np.array([(o, lv) not in rough for lv in levels])
                ax.bar(at[valid], vals[valid], width, yerr=shown[:, valid], hatch=hatch, color=f"C{k}",
                       alpha=0.8 if m == 0 else 0.45, edgecolor=f"C{k}", label=f"{idx} {pname}", capsize=2)
                if (~valid).any():  # no whiskers: a confidence interval of an unreliable index would mislead
                    ax.bar(at[~valid], vals[~valid], width, fill=False, hatch="xx", edgecolor="0.5", lw=0.8,
                           label="NOT SMOOTH: index unreliable\n(use Saltelli's sampling there)"
                           if k == m == 0 else None)
                for edge, marker, out_of in ((hi, "^", vals + errs > hi), (lo, "v", vals - errs < lo)):
                    if out_of.any():
                        beyond = True
                        ax.plot(at[out_of], [edge - 0.03 * np.sign(edge)] * int(out_of.sum()), ls="none",
                                marker=marker, color="k", ms=5)
        noise = [float(r["noise_share"]) for r in sorted((r for r in var if r["output"] == o),
                                                         key=lambda r: float(r["level"]))]
        ax.bar(x + (len(names) - 0.5) * width + width / 2, noise, width, color="0.55", edgecolor="0.3", lw=0.6,
               label="noise share of the variance", gid="noise-share")
        ax.axhspan(0.0, 1.0, color="0.9", zorder=0, lw=0, label="range of an index, [0, 1]")
        if beyond:
            ax.plot([], [], "k^", ls="none", ms=5,
                    label="estimate or interval beyond the axis:\nsampling error, raise [sobol] n"
                          + (f" (now {n})" if n else ""))
        ax.set_ylim(lo, hi)
        ax.set_xticks(x, [f"{lv:g}" for lv in levels])
        ax.set_xlabel(LEVEL_LABEL)
        ax.set_ylabel("Sobol' index / variance share")
        ax.set_title(f"output: {o}", fontsize=9)
        ax.grid(alpha=0.3, axis="y")
        legend_beside(ax, title="whiskers: confidence intervals")
    paths = _save(fig, folder, "sobol", options)
    plt.close(fig)
    return paths


def read_overview(folder: Path, options: PlotOptions | None = None) -> dict[str, list]:
    """A folder's overview.csv as `sim.stepped_sine.tables.overview_data` keys (numbers as floats, the regime as text); with
    `options`, only the chosen levels."""
    path = folder / "overview.csv"
    data: dict[str, list] = defaultdict(list)
    for r in _rows(path, options):
        for key, value in r.items():
            data["levels" if key == "level" else key].append(value if key == "regime" else _number(path, key, value))
    return dict(data)


def _number(path: Path, column: str, text: str) -> float:
    """A table's cell as a number; one line naming the file and the column where it is none (a damaged file)."""
    try:
        return float(text)
    except ValueError:
        raise SimulationInputError(f"{path}: {text!r} in column {column!r} is not a number (the file is damaged); rerun "
                                   "the command that wrote it") from None


@dataclass(frozen=True)
class ResponseData:
    """What a response study's figures are drawn from: its folder, study.json (`meta`), overview.csv for the
    chosen levels (`read_overview`; empty for a series study), the plot options and the line of run settings every
    title carries."""

    folder: Path
    meta: dict
    overview: dict[str, list]
    options: PlotOptions
    runs: str


def response_data(folder: Path, options: PlotOptions) -> ResponseData:
    """What a response study's figures are drawn from (`ResponseData`): study.json, and for a study of one point its
    overview.csv at the chosen levels (a series study's figure reads each value's own overview.csv)."""
    meta = _study(folder)
    protocol = meta["study"]["protocol_resolved"]
    runs = f"{meta['study']['repetitions']} runs, {protocol['wait']:g} s wait, {protocol['hold']:g} s hold"
    if "series_folders" in meta:
        return ResponseData(folder, meta, {}, options, f"{runs}, {protocol['integrator']}")
    overview = read_overview(folder, options)
    selected([float(r["level"]) for r in _rows(folder / "overview.csv")], options, folder)
    return ResponseData(folder, meta, overview, options, runs)


def frequency_responses(data: ResponseData, stem: str) -> list[Path]:
    """Fig. 5: the frequency response at every level, a panel each, from sweeps.csv."""
    from sim.plots.figures import plot_sweeps

    by_level: dict[float, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    for r in _rows(data.folder / "sweeps.csv", data.options):
        for key, value in r.items():
            by_level[float(r["level"])][key].append(value if key == "regime" else float(value))
    regime = dict(zip(data.overview["levels"], data.overview["regime"]))
    factor = _tip_mm_per_level(data.meta)
    if factor is not None:  # a_noabs* at each level (m): the panels' right-hand axes in mm
        for level, values in by_level.items():
            values["a_noabs"] = 1e-3 * factor * level
    panels = [(values, f"$a_\\mathrm{{base}}/a_\\mathrm{{base}}^*$ = {level:g} (resonance: {regime.get(level, '?')})")
              for level, values in sorted(by_level.items())]
    paths = data.options.paths(data.folder, stem)
    for path in paths:
        plot_sweeps(panels, path, f"Frequency responses (cf. Fig. 5), nominal parameters, {data.runs}; bands: "
                                  "range of the runs")
    return paths


def scattering_figure(measure: str, what: str):
    """A drawer of Fig. D.2 (`measure` "impacts") or D.3 ("restitution") at the resonant eta from overview.csv
    and runs.csv (`sim.plots.figures.plot_scattering`); `what` begins its title."""
    def draw(data: ResponseData, stem: str) -> list[Path]:
        from sim.plots.figures import plot_scattering

        runs_rows = _rows(data.folder / "runs.csv", data.options)
        paths = data.options.paths(data.folder, stem)
        for path in paths:
            plot_scattering(data.overview, runs_rows, path, f"{what} at the resonant $\\eta$, nominal parameters, "
                                                            f"{data.runs}", measure)
        return paths

    return draw


def resonant_levels(data: ResponseData, stem: str) -> list[Path]:
    """Fig. 6: resonant levels against the excitation level, the paper's optimum marked, from overview.csv."""
    from sim.plots.figures import plot_overview

    paths = data.options.paths(data.folder, stem)
    for path in paths:
        plot_overview(data.overview, path, f"Resonant level vs excitation level (cf. Fig. 6), nominal parameters, "
                                           f"{data.runs}", paper_optimum=True, mm_per_level=_tip_mm_per_level(data.meta))
    return paths


def series_overviews(folder: Path, options: PlotOptions | None = None) -> list[tuple[str, dict[str, list]]]:
    """[(NAME=VALUE, overview)] of a series response study (Fig. 11), from each value's overview.csv."""
    meta = _study(folder)
    return [(sub, read_overview(folder / sub, options)) for sub in meta["series_folders"]]


def series_figure(caption: str, paper_line: tuple[float, str] | None = None):
    """A drawer of a series study's figure (Fig. 11, C.1): the resonant mean against the excitation level for each
    value of the series; `caption` ("cf. Fig. 11") and the paper's level to mark (`paper_line`) go on it."""
    def draw(data: ResponseData, stem: str) -> list[Path]:
        from sim.plots.figures import plot_series

        name = next(iter(data.meta["study"]["series"]))
        paths = data.options.paths(data.folder, stem)
        for path in paths:
            plot_series([(series_label(sub), values) for sub, values in series_overviews(data.folder, data.options)],
                        path, f"Resonant mean for each {name} ({caption}), contact law "
                              f"{data.meta['study']['contact_law']}, {data.runs}", paper_line,
                        mm_per_level=_tip_mm_per_level(data.meta))
        return paths

    return draw


def series_label(sub: str) -> str:
    """A series value's legend entry in Table 2's units ('g=0.00058' -> '$g$ = 0.580 mm'); else the folder name."""
    name, _, value = sub.partition("=")
    try:
        return parameter_text(name, float(value))
    except ValueError:
        return sub


register("ies sobol", study_kind("sobol"))(sobol_figure)


def _result_children(folder: Path) -> list[Path]:
    """The subfolders of `folder` that are result folders of another registered kind (e.g. ies reproduce's)."""
    children = []
    for child in sorted(p for p in folder.iterdir() if p.is_dir()):
        if any(kind.name != REPRODUCE and kind.detect(child) for kind in KINDS):
            children.append(child)
    return children


REPRODUCE = "ies reproduce --out"


@register(REPRODUCE, lambda folder: not (folder / "study.json").is_file() and bool(_result_children(folder)))
def redraw_children(folder: Path, options: PlotOptions) -> list[Path]:
    """Every result subfolder (fig5, fig6, fig7, fig8 of `ies reproduce`), each into its own folder (or into
    OUT/NAME with --out)."""
    from dataclasses import replace

    paths: list[Path] = []
    for child in _result_children(folder):
        child_options = options if options.out is None else replace(options, out=options.out / child.name)
        levels = _levels_of(child)
        if levels and not any(options.keeps(level) for level in levels):
            continue  # another figure's levels
        if child_options.out is not None:
            child_options.out.mkdir(parents=True, exist_ok=True)
        paths += kind_of(child).redraw(child, child_options)
    if not paths:
        raise SimulationInputError(f"no result in {folder} has the levels {', '.join(f'{v:g}' for v in options.levels)}")
    return paths


def _levels_of(folder: Path) -> list[float]:
    """The excitation levels of a study folder (from study.json; [] for other folders)."""
    path = folder / "study.json"
    return list(json.loads(path.read_text())["study"]["levels"]) if path.is_file() else []
