"""The figure of `ies orbits`: the periodic orbits' frequency response (or level curve), one panel per level (or
eta), in the workbench's layout (`sim.common.figure_style`: legend beside the axes, mathtext units).

How to read it. Each branch (one colour, named by how it was found) is drawn solid where its orbits are stable and
dashed where they are unstable, as the legend's first two entries say; the linear orbits (no impact) are grey and
dotted. Markers sit on located bifurcations only (MARKERS: |mu| within 1e-4 of 1, a grazing's gap within 1e-9 g;
a change that could not be located has none). The shaded ranges are where no stable orbit of period <= k T was
found, neither by continuation and branch switching nor by the direct simulations at every change of stability
(`sim.orbits.searches`): there the response a stepped sine sees cannot be one of these orbits and is modulated,
quasi-periodic or chaotic. The stepped-sine points of a sweep folder (`--sweep DIR`, of the panel's level: sweep.csv
of `ies sweep --out DIR`, mean with its range over the samples) are drawn on top, their marker saying their dynamics
when the sweep measured it (`ies sweep --lyapunov`: periodic, quasi-periodic, chaotic). A point inside the shading is
not a contradiction: it is an attractor that is not a periodic orbit (chaotic on the rig at 7.4, whose largest
Lyapunov exponent there is 5-8 per period).

The branches share one colour and one legend entry per kind (the start's, those of symmetry breaking, of period
doubling, the searches' finds) and period; an entry is drawn as its branches are: a line when one has two or more
points in the panel's range, the marker of a single orbit, none when nothing of them lies in the range. It draws plain columns
(`sim.orbits.tables.ORBITS_COLUMNS` as arrays), so it can be redrawn from orbits.csv.
"""
from __future__ import annotations

import os
from typing import Any, Mapping, Sequence

import numpy as np

from sim.common.figure_style import ETA_LABEL, LEVEL_LABEL, RESPONSE_LABEL, legend_beside

#: marker of each bifurcation label (`sim.orbits.bifurcations.LABELS`)
MARKERS = {"fold": ">", "symmetry-breaking": "D", "period-doubling": "s", "neimark-sacker": "o",
           "branch-point": "+", "grazing": "x"}
#: bins of the range in which the shading looks for a stable orbit
SHADE_BINS = 400
#: the stepped sine's markers by dynamics (`sim.stepped_sine.dynamics`), "" when the sweep did not measure it
DYNAMICS_MARKERS = {"periodic": "o", "quasi-periodic": "s", "chaotic": "^", "": "o"}


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the runs of equal values in a boolean array (stop exclusive)."""
    edges = np.flatnonzero(np.diff(mask.astype(int))) + 1
    bounds = np.concatenate([[0], edges, [mask.size]])
    return list(zip(bounds[:-1], bounds[1:]))


def stable_cover(x: Sequence[np.ndarray], stable: Sequence[np.ndarray], lo: float, hi: float,
                 bins: int = SHADE_BINS) -> tuple[np.ndarray, np.ndarray]:
    """(bin edges, covered) over [lo, hi]: a bin is covered when a branch (its parameter values x with their
    stability) has a stable orbit in it or passes over it between two consecutive stable orbits."""
    edges = np.linspace(lo, hi, bins + 1)
    covered = np.zeros(bins, dtype=bool)
    for xs, st in zip(x, stable):
        for i in range(len(xs)):
            if not st[i]:
                continue
            a = b = xs[i]
            if i + 1 < len(xs) and st[i + 1]:
                b = xs[i + 1]
            a, b = min(a, b), max(a, b)
            covered |= (edges[1:] >= a) & (edges[:-1] <= b)
    return edges, covered


def draw_orbits(ax: Any, columns: Mapping[str, np.ndarray], *, parameter: str = "eta",
                bounds: tuple[float, float] | None = None, sweep: Mapping[str, np.ndarray] | None = None,
                max_period: int = 1, title: str = "") -> None:
    """One panel: the branches of `columns` (orbits.csv's columns of one level or eta, as arrays) against
    `parameter` ("eta" or "level"), the shading, the markers and the sweep's points (module docstring)."""
    x_all = np.asarray(columns[parameter], dtype=float)
    lo, hi = bounds if bounds is not None else (float(x_all.min()), float(x_all.max()))
    branch_ids = np.asarray(columns["branch"], dtype=int)
    amp = np.asarray(columns["amplitude"], dtype=float)
    xs, sts = [], []
    colours: dict[str, str] = {}  # one colour and one legend entry per kind of branch and period
    entries: list[tuple[Any, str]] = []
    impacting = (np.asarray(columns["impacts_per_period"], dtype=float) > 0) & (x_all >= lo) & (x_all <= hi)
    if impacting.any():  # the line styles first: the legend lists the labelled artists in the order drawn
        ax.plot([], [], ls="-", color="k", lw=1.4, label="stable orbits (solid)")
        ax.plot([], [], ls="--", color="k", lw=0.9, label="unstable orbits (dashed)")
    kinds = np.array([f"{branch_kind(str(o))} ({int(k)} T)" for o, k in zip(np.asarray(columns["origin"]),
                                                                          np.asarray(columns["period_multiple"]))])
    stable_all = np.asarray(columns["stable"], dtype=int) == 1
    for b in np.unique(branch_ids):
        sel = branch_ids == b
        x, y = x_all[sel], amp[sel]
        stable = np.asarray(columns["stable"], dtype=int)[sel] == 1
        linear = np.asarray(columns["impacts_per_period"], dtype=float)[sel] == 0
        origin = str(np.asarray(columns["origin"])[sel][0])
        k = int(np.asarray(columns["period_multiple"], dtype=int)[sel][0])
        shown = (x >= lo) & (x <= hi)
        if linear.all():
            if shown.sum() >= 2:
                line, = ax.plot(x, y, ls=":", color="0.5", lw=1.0)
                entries.append((line, "linear orbits (sphere at rest; unstable)"))
            continue
        xs.append(x)
        sts.append(stable)
        if not shown.any():  # nothing of it in the range: no line, no entry
            continue
        name = f"{branch_kind(origin)} ({k} T)"
        first = name not in colours
        c = colours.setdefault(name, f"C{len(colours) % 10}")
        for start, stop in _runs(stable):
            seg = slice(max(start - 1, 0) if not stable[start] else start, stop)
            ax.plot(x[seg], y[seg], ls="-" if stable[start] else "--", color=c, lw=1.4 if stable[start] else 0.9)
        if shown.sum() == 1:  # one orbit: its marker, in the legend too
            ax.plot(x[shown], y[shown], ls="none", marker=".", ms=6, color=c, label=name if first else None)
        elif first:  # solid when some orbit of this kind is stable, else dashed
            ax.plot([], [], ls="-" if stable_all[kinds == name].any() else "--", color=c, lw=1.4, label=name)
    labels = np.asarray(columns["bifurcation"]).astype(str)
    for label, marker in MARKERS.items():
        sel = (labels == label) & (x_all >= lo) & (x_all <= hi)
        if sel.any():
            points, = ax.plot(x_all[sel], amp[sel], ls="none", marker=marker, ms=5, mfc="none", mec="k", mew=0.8)
            entries.append((points, label))
    edges, covered = stable_cover(xs, sts, lo, hi)
    shaded = False
    for start, stop in _runs(covered):
        if not covered[start]:
            patch = ax.axvspan(edges[start], edges[stop], color="0.92", lw=0, zorder=0)
            if not shaded:
                entries.append((patch, f"no stable orbit of period <= {max_period} T found (continuation, "
                                       "switching, searches)"))
            shaded = True
    if sweep is not None and parameter == "eta":
        entries.extend(_draw_sweep(ax, sweep))
    ax.set_xlim(lo, hi)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel(ETA_LABEL if parameter == "eta" else LEVEL_LABEL)
    ax.set_ylabel(RESPONSE_LABEL)
    if title:
        ax.set_title(title, fontsize=9)
    for handle, label in entries:
        handle.set_label(label)


def branch_kind(origin: str) -> str:
    """The kind of a branch from its origin (orbits.csv): "slow-flow start", "symmetry breaking", "period
    doubling", "simulation" (a search's find), ...: the words before " at " or " from "."""
    return origin.split(" at ")[0].split(" from ")[0]


def _draw_sweep(ax: Any, sweep: Mapping[str, np.ndarray]) -> list[tuple[Any, str]]:
    """The stepped sine's means with their range over the samples, one marker per dynamics (DYNAMICS_MARKERS);
    the legend entries, naming the sweep's level."""
    eta = np.asarray(sweep["eta"], dtype=float)
    mean = np.asarray(sweep["mean"], dtype=float)
    err = np.vstack([mean - np.asarray(sweep["mean_lo"], dtype=float), np.asarray(sweep["mean_hi"], dtype=float) - mean])
    level = float(np.asarray(sweep.get("level", [np.nan]), dtype=float)[0])
    at = f" at level {level:g}" if np.isfinite(level) else ""
    dynamics = np.asarray(sweep.get("dynamics", [""] * eta.size)).astype(str)
    entries = []
    bars = ax.errorbar(eta, mean, yerr=err, fmt="none", color="k", lw=0.8, capsize=2)
    for kind in dict.fromkeys(dynamics):
        sel = dynamics == kind
        points, = ax.plot(eta[sel], mean[sel], ls="none", marker=DYNAMICS_MARKERS.get(kind, "o"), ms=3.5, color="k",
                          mfc="k" if kind != "quasi-periodic" else "none")
        entries.append((points, f"stepped sine{at}: mean" + (f", {kind}" if kind else " and range")))
    if any(dynamics):
        entries.append((bars, "stepped sine: range over the samples"))
    return entries


def plot_orbits(panels: Sequence[tuple[Mapping[str, np.ndarray], str, tuple[float, float],
                                       Mapping[str, np.ndarray] | None]],
                path: str | os.PathLike, *, parameter: str = "eta", max_period: int = 1, title: str = "") -> None:
    """The figure: one panel per (columns, panel title, range, sweep or None), stacked on one y scale, each with its
    legend beside it, written atomically to `path` (format from the suffix)."""
    from sim.common.files import pyplot, save_figure

    plt = pyplot()
    fig, axes = plt.subplots(len(panels), 1, figsize=(8.0, 3.2 * len(panels) + 0.4), squeeze=False, sharey=True,
                             layout="constrained")  # one y scale: the panels compare the levels
    try:
        for ax, (columns, panel_title, bounds, sweep) in zip(axes[:, 0], panels):
            draw_orbits(ax, columns, parameter=parameter, bounds=bounds, sweep=sweep, max_period=max_period,
                        title=panel_title)
            legend_beside(ax)
        # one y range for the shared scale, from 0 to the highest data of any panel (a sweep's points included)
        axes[0, 0].set_ylim(0.0, 1.05 * max(ax.dataLim.y1 for ax in axes[:, 0]))
        if title:
            fig.suptitle(title, fontsize=10)
        save_figure(fig, path)
    finally:
        plt.close(fig)


def read_sweep(folder: str | os.PathLike) -> dict[str, np.ndarray] | None:
    """The columns eta, mean, mean_lo, mean_hi, dynamics ("" where the sweep did not measure it) and the level from
    sweep.json (NaN without) of a `ies sweep --out DIR` folder, or None when it has no sweep.csv."""
    import csv
    import json
    from pathlib import Path

    table = Path(folder) / "sweep.csv"
    if not table.is_file():
        return None
    with table.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    data = {key: np.array([float(r[key]) for r in rows]) for key in ("eta", "mean", "mean_lo", "mean_hi")}
    data["dynamics"] = np.array([r.get("dynamics") or "" for r in rows])
    meta = Path(folder) / "sweep.json"
    level = json.loads(meta.read_text()).get("level") if meta.is_file() else None
    data["level"] = np.array([np.nan if level is None else float(level)])
    return data
