"""How sure a verified worst case is (`ies design`): the response near the switch is chaotic, so a design's worst case
(the highest mean over the repetitions among its box points and levels, `uq.design.results.Verified.worst`) is one
draw; another set of seeds gives another. This module states the range in which the worst case of a **repeat of the
verification** (the same box points, levels and repetitions per point, other seeds) falls, and which (point, level)
cells decide it.

Choice (of the two the issue names: a bootstrap over the repetitions, or extra independent realisations at the
deciding cells): both, each for what it does well. A bootstrap over three repetitions per cell cannot see a spread
it did not draw (three equal values give none) and resamples with the plug-in variance ((n - 1)/n of it); extra
realisations everywhere cost a verification each. So:

1. Every cell's spread per run is its own sample standard deviation, but at least the design's pooled relative
   spread times its mean (the repetitions of all its cells pooled: a chaotic response scatters alike near the
   switch, and the pool has tens of degrees of freedom where a cell has two).
2. The sampling distribution of the worst case is drawn with the observed cell means taken as true (a parametric
   bootstrap: each cell's mean varied by its spread / sqrt(n), the maximum over the cells; `DRAWS` draws, seeded). A
   repeat's worst case is another draw of the same statistic as the observed one, so it is centred on it (a maximum of
   noisy means lies above the maximum of the true means, but the repeat's does too), and differs from it by the
   difference of two draws: the interval is the observed worst case plus sqrt(2) times the draws' central
   `CONFIDENCE` range about their mean. The deciding cells are those that are the maximum in at least
   `DECIDING_SHARE` of the draws. Two variants were tried first: a repeat drawn per cell around the observed means
   with sqrt(2) the spread (a flat prior's prediction: the maximum over many near-top cells of such draws lies too
   high, and held a repeat in 75 % of trials), and the interval centred on the observed worst case less the
   bootstrap's bias (it estimates the true means' maximum, not a repeat's: it held 2 of 5 independent realisations
   on the cantilever of the benchmark, all above it). This one holds 97-99 % of repeats of known normal cells.
3. `uq.design.search.settle` then verifies extra repetitions (other seeds: new repetition indices) at the deciding
   cells of the recommendation, and of the runner-up where the two intervals overlap, which narrows both intervals by
   sqrt(n) where it matters.

Checked against repeats drawn from known normal cells (tests/uq/design/test_uncertainty.py: the interval holds a
repeat's worst case in 95 % of trials within the binomial noise) and against independent realisations of the full
simulation on a host it has never seen (tests/benchmarks/test_design_interval.py).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: the share of repeats of the verification whose worst case the interval holds
CONFIDENCE = 0.95
#: predicted repeats of the verification drawn per design
DRAWS = 4000
#: a cell decides the worst case when it is the maximum in at least this share of the draws
DECIDING_SHARE = 0.02
#: at most this many deciding cells per design (the most frequent maxima) get extra repetitions
MAX_DECIDING = 6


@dataclass(frozen=True)
class WorstCase:
    """The worst case of one verified design: its value (the highest cell mean, SI), the `CONFIDENCE` interval of a
    repeat's worst case (low, high), the deciding cells (indices into the cells given, most decisive first) and the
    spread per run used for each cell (SI)."""

    value: float
    interval: tuple[float, float]
    deciding: tuple[int, ...]
    spread: np.ndarray


def pooled_relative_spread(runs: Sequence[np.ndarray]) -> float:
    """The pooled coefficient of variation (-) of the cells' runs: sqrt(sum (n_c - 1) (s_c / m_c)^2 / sum (n_c - 1))
    over cells with at least two runs and a positive mean; 0 without any."""
    num = den = 0.0
    for x in runs:
        x = np.asarray(x, dtype=float)
        x = x[np.isfinite(x)]
        if x.size >= 2 and x.mean() > 0:
            num += (x.size - 1) * (x.std(ddof=1) / x.mean()) ** 2
            den += x.size - 1
    return float(np.sqrt(num / den)) if den else 0.0


def worst_case(runs: Sequence[np.ndarray], seed: int = 0) -> WorstCase:
    """The worst case over cells, each given by its runs' values (SI; NaN for a failed run, left out), with the interval
    of a repeat's worst case and the deciding cells (module docstring)."""
    cells = [np.asarray(x, dtype=float)[np.isfinite(x)] for x in runs]
    means = np.array([x.mean() if x.size else np.nan for x in cells])
    counts = np.array([x.size for x in cells])
    cv = pooled_relative_spread(cells)
    own = np.array([x.std(ddof=1) if x.size >= 2 else 0.0 for x in cells])
    spread = np.maximum(own, cv * np.abs(np.nan_to_num(means)))
    ok = counts > 0
    if not ok.any():
        return WorstCase(np.nan, (np.nan, np.nan), (), spread)
    index = np.flatnonzero(ok)
    rng = np.random.default_rng(seed)
    scale = spread[index] / np.sqrt(counts[index])
    draws = means[index][None, :] + scale[None, :] * rng.standard_normal((DRAWS, index.size))
    worst = draws.max(axis=1)
    observed = float(np.nanmax(means))
    tail = 0.5 * (1.0 - CONFIDENCE)
    low, high = observed + np.sqrt(2.0) * np.quantile(worst - worst.mean(), [tail, 1.0 - tail])
    share = np.bincount(draws.argmax(axis=1), minlength=index.size) / DRAWS
    top = int(index[np.nanargmax(means[index])])
    order = [int(index[j]) for j in np.argsort(-share, kind="stable") if share[j] >= DECIDING_SHARE]
    deciding = tuple(dict.fromkeys([top, *order]))[:MAX_DECIDING]
    return WorstCase(observed, (float(low), float(high)), deciding, spread)


def overlap(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """True when two intervals (low, high) share a point."""
    return a[0] <= b[1] and b[0] <= a[1]
