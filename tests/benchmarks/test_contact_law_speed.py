"""Cost of the damped contact law (Eq. 10) per stepped-sine point, same run, interleaved back-to-back pairs of
CPU times (medians), at the strongly modulated and the almost periodic point of test_exact_speed.py (7.4 / eta
0.99 from the base velocity, 0.978 after a down-sweep), for both integrators:

* the elastic law (r_cont = 1) against the tree before Eq. 10 entered the integrators (git revision BASELINE_REV,
  env IES_BASELINE_REV to change it): the bar is 5 %;
* the damped law at r_cont,diss = 0.99 against the elastic law of this tree: reported (every contact of the
  exact integrator then takes the Dormand-Prince pair instead of collocation).

Run: pytest -m benchmark tests/benchmarks/test_contact_law_speed.py -s
"""
import io
import os
import subprocess
import sys
import tarfile
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.benchmark
ROOT = Path(__file__).resolve().parents[2]
#: the last commit before Eq. 10 in the integrators
BASELINE_REV = os.environ.get("IES_BASELINE_REV", "766ad5b")
REPEATS = 9
POINTS = [(0.99, None, "strongly modulated"), (0.978, 0.99, "almost periodic")]


@pytest.fixture(scope="module")
def baseline_tree(tmp_path_factory):
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", BASELINE_REV], check=True, capture_output=True).stdout
    target = tmp_path_factory.mktemp("baseline")
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(target)
    return target


def _worker(tree: Path, eta: float, prepare: float | None, integrator: str, r_cont: float = 1.0) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("_point_worker.py")), str(tree), str(eta),
                             "-" if prepare is None else str(prepare), integrator, str(r_cont)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    return proc


def _pairs(workers: dict) -> dict[str, list[float]]:
    times = {name: [] for name in workers}
    try:
        for _ in range(REPEATS):
            for name, proc in workers.items():
                proc.stdin.write("run\n")
                proc.stdin.flush()
                times[name].append(float(proc.stdout.readline()))
    finally:
        for proc in workers.values():
            proc.stdin.close()
            proc.wait()
    return times


@pytest.mark.parametrize("integrator", ["exact", "ode3"])
@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_elastic_law_costs_what_it_did(baseline_tree, integrator, eta, prepare, label):
    times = _pairs({"before": _worker(baseline_tree, eta, prepare, integrator),
                    "after": _worker(ROOT, eta, prepare, integrator)})
    ratio = float(np.median(np.array(times["after"]) / np.array(times["before"])))
    print(f"\n{integrator}, {label} (7.4, eta {eta}), r_cont 1: before {np.median(times['before']) * 1e3:.1f} ms, "
          f"after {np.median(times['after']) * 1e3:.1f} ms CPU per point; median ratio of the pairs {ratio:.3f}")
    assert ratio <= 1.05


@pytest.mark.parametrize("integrator", ["exact", "ode3"])
@pytest.mark.parametrize("eta, prepare, label", POINTS)
def test_cost_of_the_damped_law(integrator, eta, prepare, label):
    times = _pairs({"elastic": _worker(ROOT, eta, prepare, integrator),
                    "damped": _worker(ROOT, eta, prepare, integrator, 0.99)})
    ratio = float(np.median(np.array(times["damped"]) / np.array(times["elastic"])))
    print(f"\n{integrator}, {label} (7.4, eta {eta}): elastic {np.median(times['elastic']) * 1e3:.1f} ms, damped "
          f"(r_cont 0.99) {np.median(times['damped']) * 1e3:.1f} ms CPU per point; median ratio {ratio:.2f}")
    assert np.isfinite(ratio)
