"""Figures of the simulation stage in the style of the seed paper: the stepped-sine frequency response
(Fig. 5, Sect. 5.2) and the resonant level against the excitation level (Fig. 6, Sect. 5.3).

Both are written atomically through `sim.files.plot_to` (format from the file suffix).
"""
from __future__ import annotations

import os
from typing import Sequence

from sim.files import plot_to
from sim.protocol import SweepResult


def plot_sweep(result: SweepResult, path: str | os.PathLike, title: str) -> None:
    """Fig. 5: mean (solid) and max (dashed) amplitude a/a_noabs* vs eta, the repetition spread as bands."""
    with plot_to(path, figsize=(6.0, 4.0)) as (fig, ax):
        ax.fill_between(result.eta, result.max_lo, result.max_hi, color="tab:red", alpha=0.2, lw=0)
        ax.plot(result.eta, result.max, "--", color="tab:red", label="max")
        ax.fill_between(result.eta, result.mean_lo, result.mean_hi, color="tab:blue", alpha=0.25, lw=0)
        ax.plot(result.eta, result.mean, "-", color="tab:blue", label="mean")
        ax.set_xlabel(r"$\eta = \Omega/\omega^*$")
        ax.set_ylabel(r"$a / a^{noabs*}$")
        ax.set_title(title)
        ax.set_ylim(bottom=0)
        ax.legend()
        ax.grid(alpha=0.3)


def plot_overview(levels: Sequence[float], results: Sequence[SweepResult], path: str | os.PathLike, title: str) -> None:
    """Fig. 6: resonant mean (solid) and max (dashed) level vs excitation level a_base/a_base*, the regime
    (APR, SMR, linear) of each level written above the axes."""
    with plot_to(path, figsize=(6.5, 4.0)) as (fig, ax):
        ax.plot(levels, [r.resonant_max for r in results], "s--", color="tab:red", label="max")
        ax.plot(levels, [r.resonant_mean for r in results], "o-", color="tab:blue", label="mean")
        for level, r in zip(levels, results):
            ax.annotate(r.regime, (level, 1.0), xycoords=("data", "axes fraction"), ha="center", va="bottom",
                        fontsize=7, rotation=90)
        ax.set_xlabel(r"$a_{base} / a^*_{base}$")
        ax.set_ylabel(r"resonant level $a / a^{noabs*}$")
        ax.set_ylim(bottom=0)
        ax.set_title(title, pad=28)
        ax.legend()
        ax.grid(alpha=0.3)
