"""Cost of the contact-law seam (issue 27, items 3 and 5: the laws compiled per law from one registry, the kernels'
arguments packed): the elastic law's stepped-sine point, same run, against the tree before the seam (git revision
SEAM_BASELINE_REV, env IES_SEAM_BASELINE_REV to change it), both in fresh worker processes (`_point_worker.py`) on
the same core, asked in turn (alternating who goes first), REPEATS pairs of CPU times, the median of the pairs'
ratios; at the strongly modulated point (SMR: 7.4 a_base*, eta 0.99 from the base velocity) and the almost periodic
point (APR: eta 0.978 after a down-sweep from 0.99), with the exact integrator and with ode3.

Target: no slower than 2 % (median ratio <= 1.02), and the end state and the hold's amplitudes the same bit for bit
(the elastic law's arithmetic is unchanged).
Latest: exact SMR 1.017, APR 1.000; ode3 SMR 0.979, APR 0.957 (median ratios of 9 pairs, 17-143 ms CPU per
point); the same bits at all four.

Run: pytest -m benchmark tests/benchmarks/test_contact_seam_speed.py -s
"""
import os
from pathlib import Path

import numpy as np
import pytest
from tests.benchmarks._ab import pairs, worker

pytestmark = pytest.mark.benchmark
ROOT = Path(__file__).resolve().parents[2]
#: the last commit before the seam (sim in sub-packages, the Hertz force written out in each integrator)
SEAM_BASELINE_REV = os.environ.get("IES_SEAM_BASELINE_REV", "f6aa200")
REPEATS = 9
BAR = 1.02
POINTS = [(0.99, None, "SMR"), (0.978, 0.99, "APR")]


@pytest.fixture(scope="module")
def baseline_tree(tree_at):
    return tree_at(SEAM_BASELINE_REV)


@pytest.mark.parametrize("integrator", ["exact", "ode3"])
@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_the_seam_costs_nothing_and_changes_no_bit(baseline_tree, integrator, eta, prepare, label):
    states: dict[str, str] = {}
    times = pairs({"before": worker(baseline_tree, eta, prepare, integrator),
                   "after": worker(ROOT, eta, prepare, integrator)}, REPEATS, states)
    ratio = float(np.median(np.array(times["after"]) / np.array(times["before"])))
    print(f"\n{integrator}, {label} (7.4, eta {eta}): before {np.median(times['before']) * 1e3:.1f} ms, "
          f"after {np.median(times['after']) * 1e3:.1f} ms CPU per point; median ratio of the pairs {ratio:.3f}; "
          f"same bits: {states['before'] == states['after']}")
    assert states["before"] == states["after"] and len(states["after"]) > 100
    assert ratio <= BAR
