"""Figures drawn from a study's data files, in the style of the seed paper's Figs. 6, 7 and 8.

* Fig. 6 style: nominal resonant response levels (mean and max over the repetitions' mean) vs the
  excitation level a_base / a_base*, APR/SMR marked (model "ies").
* Fig. 7 style: individual variation, one panel per parameter: the band (shaded), the curves at the
  parameter's min and max, and the nominal curve.
* Fig. 8 style: joint variation (light band) and the residual band with k_H fixed (dark band).
* Sobol': S1 and ST with their confidence intervals vs level, and the repetition-noise share.
Every figure is written as PNG and PDF (atomically). Only the data files are read, never the runs.
"""
from __future__ import annotations

import csv
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from sim.files import save_figure

_YLABEL = {"mean": "mean resonant level  a / a_noabs*", "max": "max resonant level  a / a_noabs*",
           "value": "response"}


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, folder: Path, stem: str) -> list[Path]:
    paths = []
    for suffix in (".png", ".pdf"):
        path = folder / f"{stem}{suffix}"
        save_figure(fig, path)
        paths.append(path)
    return paths


def _curves(points: list[dict], design: str, output: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per point label: (levels, means) of one design and output."""
    by = defaultdict(list)
    for r in points:
        if r["design"] == design and r["output"] == output:
            by[r["point"]].append((float(r["level"]), float(r["mean"])))
    return {k: tuple(np.array(v).T) for k, v in by.items()}


def _band(bands: list[dict], design: str, output: str):
    rows = [r for r in bands if r["design"] == design and r["output"] == output]
    lv = np.array([float(r["level"]) for r in rows])
    lo, hi = (np.array([float(r[k]) for r in rows]) for k in ("lower", "upper"))
    flagged = np.array([r["flagged"] == "1" for r in rows], dtype=bool)
    return lv, lo, hi, flagged


def interval_figures(folder: str | Path) -> list[Path]:
    """Draw Figs. 6, 7 and 8 (as far as the study has the designs) from folder/*.csv."""
    folder = Path(folder)
    plt = _pyplot()
    meta = json.loads((folder / "study.json").read_text())
    points, bands = _rows(folder / "points.csv"), _rows(folder / "bands.csv")
    output = meta["outputs"][0]  # "mean" for the simulator: the paper's Figs. 7-8 show the mean only
    designs = list(dict.fromkeys(r["design"] for r in bands))
    params = meta["study"]["parameters"]
    nominal = _curves(points, "nominal", output).get("nominal")
    paths: list[Path] = []

    individual = [d for d in designs if d.startswith("individual:")]
    if individual:
        fig, axes = plt.subplots(1, len(individual), figsize=(4.2 * len(individual), 3.6), squeeze=False, sharey=True)
        for ax, d in zip(axes[0], individual):
            pname = d.split(":", 1)[1]
            lv, lo, hi, flagged = _band(bands, d, output)
            ax.fill_between(lv, lo, hi, color="tab:blue", alpha=0.25, label="band")
            curves = _curves(points, d, output)
            lo_label, hi_label = min(curves, key=_value_of), max(curves, key=_value_of)
            ax.plot(*curves[lo_label], "v-", color="tab:blue", label=f"{pname} min")
            ax.plot(*curves[hi_label], "^-", color="tab:red", label=f"{pname} max")
            if nominal is not None:
                ax.plot(*nominal, "k.--", label="nominal")
            if flagged.any():
                ax.plot(lv[flagged], hi[flagged], "rx", ms=9, label="not monotone")
            unit = params.get(pname, {}).get("unit", "")
            ax.set_title(f"{params.get(pname, {}).get('label', pname)} ({unit})", fontsize=9)
            ax.set_xlabel("excitation level  a_base / a_base*")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        axes[0][0].set_ylabel(_YLABEL.get(output, output))
        fig.suptitle("Individual variation (cf. Fig. 7)", fontsize=10)
        paths += _save(fig, folder, "fig7")
        plt.close(fig)

    box = [d for d in designs if d in ("joint", "residual")]
    if box:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        styles = {"joint": ("tab:blue", 0.2, "all parameters (joint)"),
                  "residual": ("tab:blue", 0.5, "residual, k_H fixed at best estimate")}
        for d in box:
            lv, lo, hi, flagged = _band(bands, d, output)
            color, alpha, label = styles[d]
            ax.fill_between(lv, lo, hi, color=color, alpha=alpha, label=label)
            if flagged.any():
                ax.plot(lv[flagged], hi[flagged], "rx", ms=9, label=f"{d}: not monotone")
        if nominal is not None:
            ax.plot(*nominal, "k.--", label="nominal")
        ax.set_xlabel("excitation level  a_base / a_base*")
        ax.set_ylabel(_YLABEL.get(output, output))
        ax.set_title("Joint variation (cf. Fig. 8)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        paths += _save(fig, folder, "fig8")
        plt.close(fig)

    if {"mean", "max"} <= set(meta["outputs"]):
        paths += _overview(folder, points, plt)
    return paths


def _value_of(label: str) -> float:
    return float(label.split("=", 1)[1]) if "=" in label else 0.0


def _overview(folder: Path, points: list[dict], plt) -> list[Path]:
    """Fig. 6 style: nominal resonant mean and max vs level, with the regime (APR/SMR) where the
    repetition-averaged resonant mean is reached (as `sim.protocol.aggregate_runs` classifies it)."""
    apr = {float(r["level"]): float(r["mean"]) for r in points if r["design"] == "nominal" and r["output"] == "apr"}
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for output, style in (("mean", "o-"), ("max", "s--")):
        curve = _curves(points, "nominal", output).get("nominal")
        if curve is not None:
            ax.plot(*curve, style, label=f"{output} (nominal)")
    top = ax.get_ylim()[1]
    for level, flag in sorted(apr.items()):
        ax.annotate("APR" if flag >= 0.5 else "SMR", (level, top), ha="center", va="bottom", fontsize=7)
    ax.set_xlabel("excitation level  a_base / a_base*")
    ax.set_ylabel("resonant response level  a / a_noabs*")
    ax.set_title("Resonant response level (cf. Fig. 6)", fontsize=10, pad=14)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    paths = _save(fig, folder, "fig6")
    plt.close(fig)
    return paths


def sobol_figure(folder: str | Path) -> list[Path]:
    """S1 and ST (with confidence bars) per parameter vs level, and the noise share, per output."""
    folder = Path(folder)
    plt = _pyplot()
    rows, var = _rows(folder / "sobol.csv"), _rows(folder / "variance.csv")
    outputs = list(dict.fromkeys(r["output"] for r in rows))
    fig, axes = plt.subplots(1, len(outputs), figsize=(5 * len(outputs), 3.8), squeeze=False)
    for ax, o in zip(axes[0], outputs):
        sub = [r for r in rows if r["output"] == o]
        levels = sorted({float(r["level"]) for r in sub})
        names = list(dict.fromkeys(r["parameter"] for r in sub))
        width = 0.8 / (2 * len(names))
        x = np.arange(len(levels))
        for k, pname in enumerate(names):
            pr = sorted((r for r in sub if r["parameter"] == pname), key=lambda r: float(r["level"]))
            for m, (idx, hatch) in enumerate((("S1", ""), ("ST", "//"))):
                vals = [float(r[idx]) for r in pr]
                errs = [float(r[f"{idx}_conf"]) for r in pr]
                ax.bar(x + (2 * k + m - len(names)) * width + width / 2, vals, width, yerr=errs, hatch=hatch,
                       color=f"C{k}", alpha=0.8 if m == 0 else 0.45, label=f"{idx} {pname}", capsize=2)
        noise = [float(r["noise_share"]) for r in sorted((r for r in var if r["output"] == o),
                                                         key=lambda r: float(r["level"]))]
        ax.plot(x, noise, "kd:", label="noise share")
        ax.set_xticks(x, [f"{lv:g}" for lv in levels])
        ax.set_xlabel("excitation level  a_base / a_base*")
        ax.set_ylabel("Sobol' index / variance share")
        ax.set_title(f"output: {o}", fontsize=9)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=6, ncol=2)
    paths = _save(fig, folder, "sobol")
    plt.close(fig)
    return paths
