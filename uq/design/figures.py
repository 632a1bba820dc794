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
    """Per source (verified, predicted, screened) the clearances (m) and worst cases (objective unit, SI) of one
    sphere."""
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
    """The recommendation and the baseline on one panel as rings around their points (they hide nothing); y_of(design)
    gives the y value."""
    best = result.recommendation.design
    if best.material == material and (radius is None or best.radius == radius):
        ax.plot(best.clearance * 1e3, y_of(best), "o", mfc="none", mec="tab:red", mew=2.0, ms=17, ls="", zorder=6,
                label="recommendation (ringed)")
    base = result.problem.baseline
    if base is not None and base.material == material and (radius is None or base.radius == radius):
        ax.plot(base.clearance * 1e3, y_of(base), "s", mfc="none", mec="k", mew=1.2, ms=14, ls="", zorder=6,
                label="baseline (boxed)")


def _sphere_title(result: Any, radius: float) -> str:
    """`brass sphere, R = 7.92 mm, on steel walls`; several materials: `brass or steel sphere, ...`."""
    p = result.problem
    return f"{' or '.join(p.materials)} sphere, $R$ = {radius * 1e3:.2f} mm, on {p.wall.name} walls"


def plot_design_map(result: Any, path: Path) -> Path:
    """design-map: worst case against clearance (one radius), else a clearance x radius map per material."""
    if len(result.problem.radii) == 1:
        return _clearance_curves(result, path)
    return _clearance_radius_map(result, path)


#: the map's axis reaches this factor above the highest interval of the decisive verified designs
HEADROOM = 1.15
#: verified designs up to this factor above the recommendation's worst case decide the map's axis
DECISIVE = 3.0


def _above(ax: Any, xs: np.ndarray, ys: Any, top: float, colour: str, label: str | None, row: int | None,
           **kw: Any) -> None:
    """Points of a series above the axis top, as triangles at the top edge, with their value in text row `row` below
    the edge (None: without)."""
    for x, y in zip(xs, ys):
        ax.plot([x], [top * 0.97], "^", color=colour, ms=6, ls="", label=label, **kw)
        if row is not None:
            ax.annotate(f"{y:.2g}", (x, top * 0.97), xytext=(5, -4 - 10 * row), textcoords="offset points",
                        fontsize=LEGEND_PT, color=colour)
        label = None


def _clearance_curves(result: Any, path: Path) -> Path:
    """One radius: per material the verified worst cases with their 95 % intervals (filled: admissible; open: not),
    the similarity law's prediction and the slow flow's screening. The axis spans the decisive verified designs (on the
    grid, up to DECISIVE times the recommendation's worst case) with their intervals; whatever lies above (the slow
    flow, a lower bound of the switch and far above near it; the baseline; predictions beyond a switch) is a triangle
    at the top edge with its value."""
    p, o = result.problem, result.objective
    R = p.radii[0]
    scale = o.shown_scale
    with plot_to(path, figsize=(6.4, 5.0)) as (fig, ax):
        shown = [v for v in result.verified if v.design.radius == R]
        values = {m: _values(result, m, R) for m in p.materials}
        best = result.recommendation.worst
        grid = set(p.grid())
        decisive = [v for v in shown if v.design in grid and v.worst <= DECISIVE * best] or shown
        span = [y for v in decisive for y in (v.worst, *v.worst_interval) if np.isfinite(y)]
        top = HEADROOM * max(span) * scale if span else math.inf
        above_label = f"above the axis (predicted, verified: value in {o.shown_in})"
        edges = []
        worst = {v.design: min(v.worst * scale, top * 0.97) for v in result.verified}
        for k, material in enumerate(p.materials):
            colour = CURVE_COLOURS[(k + 1) % len(CURVE_COLOURS)]
            name = f" ({material})" if len(p.materials) > 1 else ""
            for source, style, label, row in (("screened", ":", f"screened, slow flow{name}", None),
                                              ("predicted", "--", f"predicted, similarity law{name}", 0)):
                xs, ys = values[material][source]
                if not xs.size:
                    continue
                ys = ys * scale
                within = ys <= top
                ax.plot(np.where(within, xs * 1e3, np.nan), np.where(within, ys, np.nan), style, color=colour,
                        marker="." if source == "predicted" else None, label=label)
                _above(ax, xs[~within] * 1e3, ys[~within], top, colour, above_label, row, alpha=0.6)
                above_label = None if (~within).any() else above_label
            mine = [v for v in shown if v.design.material == material]
            for admissible in (True, False):
                group = [v for v in mine if v.admissible(result.top, p.margin) == admissible]
                high = [v for v in group if v.worst * scale > top]
                group = [v for v in group if v not in high]
                _above(ax, np.array([v.design.clearance * 1e3 for v in high]), [v.worst * scale for v in high], top,
                       colour, above_label, 1, mfc="w")
                above_label = None if high else above_label
                if not group:
                    continue
                x = np.array([v.design.clearance * 1e3 for v in group])
                y = np.array([v.worst * scale for v in group])
                lo = np.array([v.worst_interval[0] * scale if np.isfinite(v.worst_interval[0]) else v.worst * scale
                               for v in group])
                hi = np.array([v.worst_interval[1] * scale if np.isfinite(v.worst_interval[1]) else v.worst * scale
                               for v in group])
                ax.errorbar(x, y, yerr=[np.maximum(y - lo, 0), np.maximum(np.minimum(hi, top) - y, 0)], fmt="o",
                            color=colour, mfc=colour if admissible else "w", capsize=3,
                            label=f"verified, 95 % interval{name}" if admissible else f"verified, not admissible{name}")
            _marks(ax, result, material, R, lambda s: worst.get(s, math.nan))
            edge = _margin_edge(result, material, R)
            if edge is not None:
                edges.append(edge)
        if edges:
            left = min(min(p.clearances), min(edges)) * 1e3
            ax.axvspan(left - 0.05 * (max(p.clearances) - min(p.clearances)) * 1e3, max(edges) * 1e3,
                       color="0.85", lw=0, zorder=0,
                       label=f"predicted to switch below the top ({max(p.excitation) * 1e6:.3g} {MICROMETRE}) + "
                             f"{p.margin:.0%}")
        if math.isfinite(top):
            ax.set_ylim(0.0, top)
        ax.set_xlabel("clearance $g$ (mm)")
        ax.set_ylabel(f"worst case of the {o.quantity} ({o.shown_in})")
        ax.set_title(_sphere_title(result, R), fontsize="medium")
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
            a.set_title(f"{material} sphere on {p.wall.name} walls", fontsize="medium")
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
    and the next best verified designs (band over the box's corners, line at its centre; dotted with open markers where
    the design is not admissible; x where the centre leaves the band), each one's highest value over the box at the
    margin level (triangle), the structure without IES at the host's D_1*, the margin level, and the recommendation's
    predicted jump at its switch at the box's worst corner, all on one log axis labelled in one format."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    p, o = result.problem, result.objective
    a = np.asarray(p.excitation) * 1e6
    scale = o.shown_scale
    best = result.recommendation
    shown = [best]
    if result.baseline is not None and result.baseline is not best:
        shown.append(result.baseline)
    shown += [v for v in result.verified if v not in shown][: max(0, 4 - len(shown))]
    margin_at = p.margin_level() * 1e6
    with plot_to(path, figsize=(6.4, 5.6)) as (fig, ax):
        ys: list[float] = []
        if o.unit == "m":
            D_star = result.host.get("D_star")
            ax.plot(a, result.no_absorber * scale, "k:",
                    label="no IES" + (f" ($D_1^*$ = {100 * D_star:.3g} %)" if D_star is not None else ""))
            ys += list(result.no_absorber * scale)
        flagged = False
        for v, colour in zip(shown, CURVE_COLOURS):
            ok = v.admissible(result.top, p.margin)
            d = v.design
            role = ("recommended" if v is best else "baseline" if v is result.baseline else "")
            role = ", ".join(r for r in (role, "" if ok else "not admissible") if r)
            label = f"g {d.clearance * 1e3:.3g} mm, {d.material} R {d.radius * 1e3:.3g} mm" + (f" ({role})" if role else "")
            ax.fill_between(a, v.low * scale, v.high * scale, color=colour, alpha=0.2 if ok else 0.1, lw=0)
            ax.plot(a, v.nominal * scale, marker="o", color=colour, ms=3 if ok else 4, mfc=colour if ok else "w",
                    lw=2.2 if v is best else 1.0, ls="-" if ok else ":", label=label)
            if np.isfinite(v.margin_high):
                ax.plot([margin_at], [v.margin_high * scale], "^", color=colour, mfc=colour if ok else "w", ms=6, ls="")
                ys.append(v.margin_high * scale)
            if v.outside.any():
                ax.plot(a[v.outside], v.nominal[v.outside] * scale, "x", color="k", ms=8, mew=1.5, ls="",
                        label=None if flagged else "centre outside the band")
                flagged = True
            ys += list(v.low * scale) + list(v.high * scale) + list(v.nominal * scale)
        right = margin_at
        ax.axvline(margin_at, color="0.4", ls="-.", lw=1.0)
        ax.annotate(f"margin level, top + {p.margin:.0%} ({margin_at:.3g} {MICROMETRE}); \u25b2: highest over the box",
                    (margin_at, 0.98), xycoords=ax.get_xaxis_transform(), xytext=(-3, 0), textcoords="offset points",
                    rotation=90, ha="right", va="top", fontsize=LEGEND_PT, color="0.3")
        prediction = best.prediction
        if prediction is not None and prediction.switch_worst_kind == "found" and np.all(np.isfinite(prediction.jump)):
            at = prediction.switch_worst * 1e6
            below, above = (x * scale for x in prediction.jump)
            ax.plot([at, at], [below, above], color=CURVE_COLOURS[0], ls="--", lw=1.2, marker="_", ms=10)
            ax.text(at, math.sqrt(below * above), f" predicted\n jump {above / below:.1f}x\n at the\n switch",
                    color=CURVE_COLOURS[0], fontsize=LEGEND_PT, ha="left", va="center")
            ys += [below, above]
            right = max(right, at)
        ax.set_xlim(min(a) - 0.04 * (right - min(a)), right + 0.16 * (right - min(a)))
        positive = [y for y in ys if np.isfinite(y) and y > 0]
        if positive:
            ax.set_ylim(min(positive) / 1.25, max(positive) * 1.25)
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_minor_locator(LogLocator(subs=np.arange(1.0, 10.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())  # one format: no 6x10^-1 beside 0.5
        ax.set_xlabel(rf"base amplitude $a_\mathrm{{base}}$ ({MICROMETRE})")
        ax.set_ylabel(f"{o.quantity} ({o.shown_in})")
        ax.grid(True, which="both", alpha=0.3)
        legend_below(ax, title="bands: the box's corners; lines: its centre", ncols=2)
    return path
