"""Figures of `ies design` (`uq.design`).

design-map: the objective's worst case over the grid, verified values where they exist. One radius: a curve against
the clearance per material (verified, predicted by the similarity law, screened by the slow flow), with the
clearances whose switch falls within the operating range and its margin shaded. Several radii: per material a map of
clearance x radius, verified cells plain, predicted or screened ones hatched, and the predicted edge of the margin.
Both mark the recommendation (star) and the baseline (diamond).

design-curves: the objective against the base amplitude for the recommendation, the baseline and the next best
verified designs (band over the box's corners, line at its centre), the structure without IES, the top of the range
with its margin, and the recommendation's switch at the box's worst corner.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from sim.common.figure_style import LEGEND_PT, MICROMETRE, legend_below
from sim.common.files import plot_to

#: colours of the verified designs on the curves: the recommendation, then the others
CURVE_COLOURS = ("tab:red", "tab:blue", "tab:green", "tab:purple")


def _values(result: Any, material: str, radius: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per source (verified, predicted, screened) the clearances (m) and worst cases (objective unit, SI) of one sphere."""
    o, s = result.objective, result.screened
    g = np.asarray(result.problem.clearances)
    verified = {v.design.clearance: v.worst for v in result.verified
                if v.design.material == material and v.design.radius == radius}
    predicted = {d.clearance: p.worst for d, p in result.predictions.items()
                 if d.material == material and d.radius == radius and p is not None}
    screened = {}
    for d, worst, tip in zip(s.designs, s.worst, s.tip):
        if d.material == material and d.radius == radius and np.isfinite(worst):
            screened[d.clearance] = float(np.max(o.screened(tip, result.omega_1)))
    out = {}
    for name, table in (("verified", verified), ("predicted", predicted), ("screened", screened)):
        xs = np.array(sorted(x for x in table if x in g))
        out[name] = (xs, np.array([table[x] for x in xs]))
    return out


def _margin_edge(result: Any, material: str, radius: float) -> float | None:
    """The clearance (m) at which the predicted margin at the box's worst corner reaches --margin (linear between grid
    clearances), None when the predictions do not cross it."""
    top, m = result.top, result.problem.margin
    pairs = sorted((d.clearance, p.margin(top)) for d, p in result.predictions.items()
                   if d.material == material and d.radius == radius and p is not None)
    for (g0, m0), (g1, m1) in zip(pairs, pairs[1:]):
        if (m0 - m) * (m1 - m) <= 0 and m0 != m1:
            return g0 + (m - m0) / (m1 - m0) * (g1 - g0)
    return None


def _marks(ax: Any, result: Any, material: str, radius: float | None, y_of: Any) -> None:
    """The recommendation (star) and the baseline (diamond) on one panel; y_of(sphere) gives the y value."""
    best = result.recommendation.design
    if best.material == material and (radius is None or best.radius == radius):
        ax.plot(best.clearance * 1e3, y_of(best), "*", color="tab:red", ms=15, mec="k", ls="", zorder=5,
                label="recommendation")
    base = result.problem.baseline
    if base is not None and base.material == material and (radius is None or base.radius == radius):
        ax.plot(base.clearance * 1e3, y_of(base), "D", color="w", mec="k", ms=7, ls="", zorder=5, label="baseline")


def plot_design_map(result: Any, path: Path) -> Path:
    """design-map: worst case against clearance (one radius), else a clearance x radius map per material."""
    if len(result.problem.radii) == 1:
        return _clearance_curves(result, path)
    return _clearance_radius_map(result, path)


def _clearance_curves(result: Any, path: Path) -> Path:
    p, o = result.problem, result.objective
    R = p.radii[0]
    scale = o.shown_scale
    with plot_to(path, figsize=(6.4, 5.0)) as (fig, ax):
        edges = []
        for k, material in enumerate(p.materials):
            colour = CURVE_COLOURS[(k + 1) % len(CURVE_COLOURS)]
            values = _values(result, material, R)
            name = f" ({material})" if len(p.materials) > 1 else ""
            xs, ys = values["screened"]
            if xs.size:
                ax.plot(xs * 1e3, ys * scale, ":", color=colour, label=f"screened, slow flow{name}")
            xs, ys = values["predicted"]
            if xs.size:
                ax.plot(xs * 1e3, ys * scale, "--", color=colour, marker=".", label=f"predicted, similarity law{name}")
            verified = [v for v in result.verified if v.design.material == material and v.design.radius == R]
            ok = [v for v in verified if v.admissible(result.top, p.margin)]
            bad = [v for v in verified if v not in ok]
            if ok:
                ax.plot([v.design.clearance * 1e3 for v in ok], [v.worst * scale for v in ok], "o", color=colour,
                        mec="k", ls="", label=f"verified{name}")
            if bad:
                ax.plot([v.design.clearance * 1e3 for v in bad], [v.worst * scale for v in bad], "o", mfc="w",
                        mec=colour, ls="", label=f"verified, margin not kept{name}")
            worst = {v.design: v.worst for v in result.verified}
            _marks(ax, result, material, R, lambda s: worst.get(s, math.nan) * scale)
            edge = _margin_edge(result, material, R)
            if edge is not None:
                edges.append(edge)
        if edges:
            left = min(min(p.clearances), min(edges)) * 1e3
            ax.axvspan(left - 0.05 * (max(p.clearances) - min(p.clearances)) * 1e3, max(edges) * 1e3,
                       color="0.85", lw=0, zorder=0,
                       label=f"predicted to switch below the top ({max(p.excitation) * 1e6:.3g} {MICROMETRE}) + "
                             f"{p.margin:.0%}")
        ax.set_xlabel("clearance $g$ (mm)")
        ax.set_ylabel(f"worst case of the {o.quantity} ({o.shown_in})")
        ax.set_title(f"{', '.join(p.materials)} sphere, $R$ = {R * 1e3:.2f} mm", fontsize="medium")
        ax.margins(x=0.05)
        ax.grid(True, alpha=0.3)
        legend_below(ax, ncols=2)
    return path


def _cell_edges(centres: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres (midpoints; the end cells as wide as their neighbour's half step)."""
    if centres.size == 1:
        return np.array([centres[0] * 0.9, centres[0] * 1.1])
    mid = 0.5 * (centres[1:] + centres[:-1])
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def _clearance_radius_map(result: Any, path: Path) -> Path:
    from matplotlib import cm, colormaps
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    p, o = result.problem, result.objective
    g = np.asarray(p.clearances) * 1e3
    R = np.asarray(p.radii) * 1e3
    gx, Ry = _cell_edges(g), _cell_edges(R)
    cells = {}
    for material in p.materials:
        for j, radius in enumerate(p.radii):
            values = _values(result, material, radius)
            for source in ("screened", "predicted", "verified"):  # later sources win
                for x, y in zip(*values[source]):
                    cells[(material, j, list(p.clearances).index(x))] = (y * o.shown_scale, source)
    shown = [v for v, _ in cells.values() if np.isfinite(v)]
    norm = Normalize(vmin=min(shown), vmax=max(shown)) if shown else Normalize(0, 1)
    cmap = colormaps["viridis_r"]
    hatches = {"verified": None, "predicted": "///", "screened": "..."}
    n = len(p.materials)
    with plot_to(path, figsize=(4.2 * n + 2.4, 3.8)) as (fig, ax):
        fig.delaxes(ax)
        axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
        used, contour_drawn = set(), False
        for material, a in zip(p.materials, axes):
            a.set_facecolor("0.85")
            for (m, j, i), (value, source) in cells.items():
                if m != material or not np.isfinite(value):
                    continue
                used.add(source)
                a.add_patch(Rectangle((gx[i], Ry[j]), gx[i + 1] - gx[i], Ry[j + 1] - Ry[j], facecolor=cmap(norm(value)),
                                      hatch=hatches[source], edgecolor="k" if source == "verified" else "0.3", lw=0.6))
            margins = np.full((R.size, g.size), np.nan)
            for d, pred in result.predictions.items():
                if d.material == material and pred is not None and d.radius in p.radii and d.clearance in p.clearances:
                    margins[list(p.radii).index(d.radius), list(p.clearances).index(d.clearance)] = pred.margin(result.top)
            if np.isfinite(margins).sum() >= 4 and np.nanmin(margins) < p.margin < np.nanmax(margins):
                cs = a.contour(g, R, np.ma.masked_invalid(margins), levels=[p.margin], colors="k", linewidths=1.2,
                               linestyles="--")
                contour_drawn = contour_drawn or any(len(seg) for seg in cs.allsegs[0])
            _marks(a, result, material, None, lambda s: s.radius * 1e3)
            a.set_xlim(gx[0], gx[-1])
            a.set_ylim(Ry[0], Ry[-1])
            a.set_title(material)
            a.set_xlabel("clearance $g$ (mm)")
        axes[0].set_ylabel("sphere radius $R$ (mm)")
        bar = fig.colorbar(cm.ScalarMappable(norm=norm, cmap=cmap), ax=list(axes), pad=0.02)
        bar.set_label(f"worst case ({o.shown_in})")
        handles, labels = [], []
        seen = {}
        for a in axes:
            for h, lab in zip(*a.get_legend_handles_labels()):
                seen.setdefault(lab, h)
        handles += list(seen.values())
        labels += list(seen)
        names = {"verified": "verified", "predicted": "predicted (similarity law)", "screened": "screened (slow flow)"}
        for source in ("verified", "predicted", "screened"):
            if source in used:
                handles.append(Patch(facecolor="w", edgecolor="k", hatch=hatches[source]))
                labels.append(names[source])
        if contour_drawn:
            handles.append(Line2D([], [], ls="--", color="k"))
            labels.append(f"predicted margin {p.margin:.0%} to the switch (left of it: less)")
        fig.legend(handles, labels, loc="outside lower center", ncols=min(3, len(labels)), frameon=False,
                   fontsize=LEGEND_PT)
    return path


def plot_design_curves(result: Any, path: Path) -> Path:
    """design-curves: the objective (printed unit) against the base amplitude (µm) for the recommendation, the baseline
    and the next best verified designs (band over the box's corners, line at its centre), the structure without IES,
    the top of the range times 1 + margin, and the recommendation's predicted switch at the box's worst corner."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    p, o = result.problem, result.objective
    a = np.asarray(p.excitation) * 1e6
    scale = o.shown_scale
    best = result.recommendation
    shown = [best]
    if result.baseline is not None and result.baseline is not best:
        shown.append(result.baseline)
    shown += [v for v in result.verified if v not in shown][: max(0, 4 - len(shown))]
    with plot_to(path, figsize=(6.4, 5.2)) as (fig, ax):
        if o.unit == "m":
            ax.plot(a, result.no_absorber * scale, "k:", label=f"no IES ($D_1$ = {min(p.D):g})")
        for v, colour in zip(shown, CURVE_COLOURS):
            role = ("recommended: " if v is best else "baseline: " if v is result.baseline else "")
            ax.fill_between(a, v.low * scale, v.high * scale, color=colour, alpha=0.2, lw=0)
            ax.plot(a, v.nominal * scale, marker="o", color=colour, ms=3, lw=2.2 if v is best else 1.0,
                    ls="--" if v is result.baseline and v is not best else "-", label=role + v.design.label())
        margin_at = p.margin_level() * 1e6
        ax.axvline(margin_at, color="0.4", ls="-.", lw=1.0,
                   label=f"top of the range + {p.margin:.0%} margin ({margin_at:.3g} {MICROMETRE})")
        prediction = best.prediction
        if prediction is not None and prediction.switch_worst_kind == "found":
            at = prediction.switch_worst * 1e6
            ax.axvline(at, color="tab:red", ls="--", lw=1.0,
                       label=f"recommendation's switch, box's worst corner ({at:.3g} {MICROMETRE})")
            ax.set_xlim(right=max(at, margin_at) * 1.04)
        else:
            ax.set_xlim(right=margin_at * 1.04)
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_minor_locator(LogLocator(subs=np.arange(1.0, 10.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
        ax.set_xlabel(rf"base amplitude $a_\mathrm{{base}}$ ({MICROMETRE})")
        ax.set_ylabel(f"{o.quantity} ({o.shown_in})")
        ax.grid(True, which="both", alpha=0.3)
        legend_below(ax, title="bands: the uncertainty box's corners; lines: its centre", ncols=2)
    return path
