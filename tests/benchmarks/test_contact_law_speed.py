"""Cost of the damped contact law (Eq. 10) per stepped-sine point, same run, interleaved back-to-back pairs of
CPU times (medians), at the strongly modulated and the almost periodic point of test_exact_speed.py (7.4 / eta
0.99 from the base velocity, 0.978 after a down-sweep), for both integrators:

* the elastic law (r_cont = 1) against the tree before Eq. 10 entered the integrators (git revision BASELINE_REV,
  env IES_BASELINE_REV to change it): the bar is 5 %;
* the damped law at r_cont,diss = 0.99 against the elastic law of this tree: reported (every contact of the
  exact integrator then takes the Dormand-Prince pair instead of collocation);
* dry friction (mu = 0.07, Appendix C; ode3 only) against the elastic law without friction: reported.

Run: pytest -m benchmark tests/benchmarks/test_contact_law_speed.py -s
"""
import os
from pathlib import Path

import numpy as np
import pytest
from tests.benchmarks._ab import pairs, worker

pytestmark = pytest.mark.benchmark
ROOT = Path(__file__).resolve().parents[2]
#: the last commit before Eq. 10 in the integrators
BASELINE_REV = os.environ.get("IES_BASELINE_REV", "766ad5b")
REPEATS = 9
POINTS = [(0.99, None, "strongly modulated"), (0.978, 0.99, "almost periodic")]


@pytest.fixture(scope="module")
def baseline_tree(tree_at):
    return tree_at(BASELINE_REV)


@pytest.mark.parametrize("integrator", ["exact", "ode3"])
@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_elastic_law_costs_what_it_did(baseline_tree, integrator, eta, prepare, label):
    times = pairs({"before": worker(baseline_tree, eta, prepare, integrator),
                   "after": worker(ROOT, eta, prepare, integrator)}, REPEATS)
    ratio = float(np.median(np.array(times["after"]) / np.array(times["before"])))
    print(f"\n{integrator}, {label} (7.4, eta {eta}), r_cont 1: before {np.median(times['before']) * 1e3:.1f} ms, "
          f"after {np.median(times['after']) * 1e3:.1f} ms CPU per point; median ratio of the pairs {ratio:.3f}")
    assert ratio <= 1.05


@pytest.mark.parametrize("integrator", ["exact", "ode3"])
@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_cost_of_the_damped_law(integrator, eta, prepare, label):
    times = pairs({"elastic": worker(ROOT, eta, prepare, integrator),
                   "damped": worker(ROOT, eta, prepare, integrator, "0.99")}, REPEATS)
    ratio = float(np.median(np.array(times["damped"]) / np.array(times["elastic"])))
    print(f"\n{integrator}, {label} (7.4, eta {eta}): elastic {np.median(times['elastic']) * 1e3:.1f} ms, damped "
          f"(r_cont 0.99) {np.median(times['damped']) * 1e3:.1f} ms CPU per point; median ratio {ratio:.2f}")
    assert np.isfinite(ratio)


@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_cost_of_friction(eta, prepare, label):
    times = pairs({"frictionless": worker(ROOT, eta, prepare, "ode3"),
                   "friction": worker(ROOT, eta, prepare, "ode3", "1", "0.07")}, REPEATS)
    ratio = float(np.median(np.array(times["friction"]) / np.array(times["frictionless"])))
    print(f"\node3, {label} (7.4, eta {eta}): without friction {np.median(times['frictionless']) * 1e3:.1f} ms, with "
          f"(mu 0.07) {np.median(times['friction']) * 1e3:.1f} ms CPU per point; median ratio {ratio:.2f}")
    assert np.isfinite(ratio)
