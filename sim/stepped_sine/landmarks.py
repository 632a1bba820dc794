"""The landmarks of the paper's Fig. 6 (Sect. 5.3, Appendices B, D) measured on an overview of resonant levels: the
yardstick of the rig model's fidelity (`sim.hosts.variants`, uq/studies/fidelity/README.md) and of the slow flow's
predicted switch (`sim.reduced.slow_flow`).

Landmarks of the paper (Sect. 5.3, Fig. 6, Appendix B):
* the switch from strongly modulated (SMR) to almost periodic response (APR), and with it the optimum, at
  a_base/a_base* ~ 6.7, where the resonant mean (max) level is 1/20 (1/10) of a^noabs*;
* at 7.4 the resonant level is reached in the APR near eta = 0.976, with about two significant impacts per
  period; the measured APR tip amplitudes 0.58-0.95 mm are 0.14-0.19 a^noabs* by Eq. B.1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from sim.stepped_sine.measures import PAPER_APR_ETA, PAPER_APR_LEVEL, PAPER_OPTIMUM_LEVEL, REGIME_CV_THRESHOLD

#: a level is APR when at least this share of its repetitions is (the majority rule)
APR_SHARE = 0.5


@dataclass(frozen=True)
class Landmarks:
    """The Fig. 6 landmarks of one overview (Sect. 5.3).

    levels (a_base/a_base*, ascending); resonant_mean, resonant_max (/ a^noabs*, averaged over the repetition
    samples) with the samples' range *_lo, *_hi; regime of the averaged response at the resonant mean;
    apr_samples: share of the repetition samples whose own resonant point is APR (cv <= threshold, with impacts).
    The switch: first_apr is the lowest level from which most samples (at least half) of every level are APR (None
    if the highest level is not), last_smr the highest level below it where most are not (None if there is none).
    optimum_level: the level of the lowest resonant
    mean, with reduction_mean = 1/resonant_mean and reduction_max = 1/resonant_max there; impacts_at_apr_eta:
    contact onsets per period at the grid point nearest PAPER_APR_ETA for each level (NaN off the grid).
    """

    levels: np.ndarray
    resonant_mean: np.ndarray
    resonant_mean_lo: np.ndarray
    resonant_mean_hi: np.ndarray
    resonant_max: np.ndarray
    resonant_max_lo: np.ndarray
    resonant_max_hi: np.ndarray
    regime: tuple[str, ...]
    apr_samples: np.ndarray
    impacts_at_apr_eta: np.ndarray
    first_apr: float | None
    last_smr: float | None
    optimum_level: float
    reduction_mean: float
    reduction_max: float

    def at(self, level: float, key: str = "resonant_mean") -> float:
        """A per-level quantity at `level` (NaN when the overview does not have it)."""
        hit = np.flatnonzero(np.isclose(self.levels, level))
        return float(getattr(self, key)[hit[0]]) if hit.size else float("nan")

    def summary(self) -> dict:
        """Plain data: the switch, the optimum, and the APR levels and impacts at 7.4 and 9."""
        return {
            "last_smr": self.last_smr, "first_apr": self.first_apr, "optimum_level": self.optimum_level,
            "reduction_mean": self.reduction_mean, "reduction_max": self.reduction_max,
            **{f"{key}_{level:g}": self.at(level, key) for level in (7.4, 9.0)
               for key in ("resonant_mean", "resonant_mean_lo", "resonant_mean_hi", "impacts_at_apr_eta")},
        }


def landmarks(results: Sequence) -> Landmarks:
    """Landmarks (Sect. 5.3) of an overview: one `sim.stepped_sine.protocol.SweepResult` per excitation level, any order."""
    results = sorted(results, key=lambda r: r.level)
    levels = np.array([r.level for r in results])
    mean = np.array([r.resonant_mean for r in results])
    mx = np.array([r.resonant_max for r in results])
    regime = tuple(r.regime for r in results)
    apr_samples = []
    impacts = []
    for r in results:
        rows, at_peak = np.arange(r.mean_samples.shape[0]), np.argmax(r.mean_samples, axis=1)
        apr = (r.cv_samples[rows, at_peak] <= REGIME_CV_THRESHOLD) & (r.impacts_samples[rows, at_peak] > 0)
        apr_samples.append(float(np.mean(apr)))
        k = int(np.argmin(np.abs(r.eta - PAPER_APR_ETA)))
        impacts.append(float(r.impacts_per_period[k]) if abs(r.eta[k] - PAPER_APR_ETA) < 1e-9 else float("nan"))
    mostly_apr = np.array(apr_samples) >= APR_SHARE
    tail = np.flatnonzero(np.cumprod(mostly_apr[::-1])[::-1])  # indices of the mostly-APR levels at the top
    first_apr = float(levels[tail[0]]) if tail.size else None
    below = np.flatnonzero(~mostly_apr[: tail[0] if tail.size else levels.size])
    last_smr = float(levels[below[-1]]) if below.size else None
    best = int(np.argmin(mean))
    return Landmarks(
        levels=levels, resonant_mean=mean, resonant_max=mx,
        resonant_mean_lo=np.array([r.resonant_mean_samples.min() for r in results]),
        resonant_mean_hi=np.array([r.resonant_mean_samples.max() for r in results]),
        resonant_max_lo=np.array([r.resonant_max_samples.min() for r in results]),
        resonant_max_hi=np.array([r.resonant_max_samples.max() for r in results]),
        regime=regime, apr_samples=np.array(apr_samples), impacts_at_apr_eta=np.array(impacts),
        first_apr=first_apr, last_smr=last_smr, optimum_level=float(levels[best]),
        reduction_mean=1.0 / float(mean[best]), reduction_max=1.0 / float(mx[best]))


def switch_line(summary: dict) -> str:
    """One line on the switch to the almost periodic response of `Landmarks.summary()` next to the paper's."""
    last, first = summary["last_smr"], summary["first_apr"]
    if first is None:
        where = "no switch to APR: most repetition samples are not APR at the highest level"
    elif last is None:
        where = f"APR from the lowest level ({first:g}) on"
    else:
        where = f"switch from SMR to APR between a_base/a_base* = {last:g} and {first:g}"
    at_7_4 = summary.get("resonant_mean_7.4")  # NaN (None in JSON) when 7.4 is not among the levels
    level = "" if at_7_4 is None or math.isnan(at_7_4) else f"; resonant mean level at 7.4: {at_7_4:.3f}"
    return (f"{where} (by the majority of repetition samples){level}; the paper: switch and optimum at "
            f"{PAPER_OPTIMUM_LEVEL:g}, APR level at 7.4 {PAPER_APR_LEVEL[0]:g}-{PAPER_APR_LEVEL[1]:g} (Appendix B)")
