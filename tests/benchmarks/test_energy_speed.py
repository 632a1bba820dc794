"""Cost of the energy bookkeeping and impact measures (Sect. 5.5, Appendix D) per stepped-sine point: the tree
before them (git revision BASELINE_REV, env IES_BASELINE_REV to change it) against this tree, same run,
interleaved, the median of the ratios of back-to-back pairs of CPU times, at the strongly modulated and the almost periodic point of
test_exact_speed.py (7.4 / eta 0.99 from rest, 0.978 after a down-sweep). The bar: at most 15 % slower.

Run: pytest -m benchmark tests/benchmarks/test_energy_speed.py -s
"""
import os
from pathlib import Path

import numpy as np
import pytest
from tests.benchmarks._ab import pairs, worker

pytestmark = pytest.mark.benchmark
ROOT = Path(__file__).resolve().parents[2]
#: the last commit before the energy bookkeeping
BASELINE_REV = os.environ.get("IES_BASELINE_REV", "780af5c")
REPEATS = 11


@pytest.fixture(scope="module")
def baseline_tree(tree_at):
    return tree_at(BASELINE_REV)


@pytest.mark.parametrize("eta, prepare, label", [(0.99, None, "strongly modulated"), (0.978, 0.99, "almost periodic")])
def test_bookkeeping_costs_at_most_15_percent(baseline_tree, eta, prepare, label):
    times = pairs({"before": worker(baseline_tree, eta, prepare), "after": worker(ROOT, eta, prepare)}, REPEATS)
    before, after = (float(np.median(times[name])) for name in ("before", "after"))
    ratio = float(np.median(np.array(times["after"]) / np.array(times["before"])))  # pairs measured back to back
    print(f"\n{label} (7.4, eta {eta}): before {before * 1e3:.1f} ms, after {after * 1e3:.1f} ms CPU per point "
          f"(medians of {REPEATS}); median ratio of the back-to-back pairs {ratio:.3f}")
    assert ratio <= 1.15
