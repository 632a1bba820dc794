"""The figure of `ies orbits`: the periodic orbits' frequency response (or level curve), one panel per level (or
eta), in the workbench's layout (`sim.common.figure_style`: legend beside the axes, mathtext units).

Each branch is drawn solid where its orbits are stable and dashed where not (the linear orbits grey); located
bifurcations are marked (MARKERS); where no branch has a stable orbit, the range is shaded: there the response
cannot settle on a periodic orbit of period <= k T and is modulated (or chaotic); the stepped-sine points of a
sweep folder (`--sweep DIR`: sweep.csv of `ies sweep --out DIR`, mean with its range over the samples) are drawn
on top. It draws plain columns (`sim.orbits.tables.ORBITS_COLUMNS` as arrays), so it can be redrawn from
orbits.csv.
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
    xs, sts = [], []
    colour = 0
    drawn_kind: set[str] = set()
    for b in np.unique(branch_ids):
        sel = branch_ids == b
        x = x_all[sel]
        y = np.asarray(columns["amplitude"], dtype=float)[sel]
        stable = np.asarray(columns["stable"], dtype=int)[sel] == 1
        linear = np.asarray(columns["impacts_per_period"], dtype=float)[sel] == 0
        origin = str(np.asarray(columns["origin"])[sel][0])
        k = int(np.asarray(columns["period_multiple"], dtype=int)[sel][0])
        if linear.all():
            ax.plot(x, y, ls=":", color="0.5", lw=1.0, label="linear orbits (sphere at rest; unstable)")
            continue
        xs.append(x)
        sts.append(stable)
        c = f"C{colour % 10}"
        colour += 1
        name = f"{origin} ({k} T)"
        for start, stop in _runs(stable):
            seg = slice(max(start - 1, 0) if not stable[start] else start, stop)
            ax.plot(x[seg], y[seg], ls="-" if stable[start] else "--", color=c, lw=1.4 if stable[start] else 0.9,
                    label=name if name not in drawn_kind else None)
            drawn_kind.add(name)
    labels = np.asarray(columns["bifurcation"]).astype(str)
    amp = np.asarray(columns["amplitude"], dtype=float)
    for label, marker in MARKERS.items():
        sel = labels == label
        if sel.any():
            ax.plot(x_all[sel], amp[sel], ls="none", marker=marker, ms=5, mfc="none", mec="k", mew=0.8, label=label)
    edges, covered = stable_cover(xs, sts, lo, hi)
    shaded = False
    for start, stop in _runs(covered):
        if not covered[start]:
            ax.axvspan(edges[start], edges[stop], color="0.92", lw=0, zorder=0,
                       label=None if shaded else f"no stable orbit of period <= {max_period} T: modulated response")
            shaded = True
    if sweep is not None and parameter == "eta":
        mean = np.asarray(sweep["mean"], dtype=float)
        err = np.vstack([mean - np.asarray(sweep["mean_lo"], dtype=float),
                         np.asarray(sweep["mean_hi"], dtype=float) - mean])
        ax.errorbar(np.asarray(sweep["eta"], dtype=float), mean, yerr=err, fmt="o", ms=3, color="k", lw=0.8,
                    capsize=2, label="stepped sine: mean and range")
    ax.set_xlim(lo, hi)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel(ETA_LABEL if parameter == "eta" else LEVEL_LABEL)
    ax.set_ylabel(RESPONSE_LABEL)
    if title:
        ax.set_title(title, fontsize=9)


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
        if title:
            fig.suptitle(title, fontsize=10)
        save_figure(fig, path)
    finally:
        plt.close(fig)


def read_sweep(folder: str | os.PathLike) -> dict[str, np.ndarray] | None:
    """The columns eta, mean, mean_lo, mean_hi (and the level from sweep.json) of a `ies sweep --out DIR` folder,
    or None when it has no sweep.csv."""
    import csv
    import json
    from pathlib import Path

    table = Path(folder) / "sweep.csv"
    if not table.is_file():
        return None
    with table.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    data = {key: np.array([float(r[key]) for r in rows]) for key in ("eta", "mean", "mean_lo", "mean_hi")}
    meta = Path(folder) / "sweep.json"
    level = json.loads(meta.read_text()).get("level") if meta.is_file() else None
    data["level"] = np.array([np.nan if level is None else float(level)])
    return data
