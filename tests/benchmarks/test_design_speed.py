"""Speed of the slow-flow screening that `ies design` uses (issue 28): 50 clearances x 10 sphere radii x 20
excitation levels on the built-in rig's mode 1 (`sim.reduced.slow_flow.screen`).

Target: <= 2 s per screening (median of 5 repeats, after one untimed call: numpy only, no JIT to warm).
Latest figure: see the module's test output (`-s`); measured 0.03-0.04 s on the shared 2-core machine.

Run: pytest -m benchmark tests/benchmarks/test_design_speed.py -s
"""
import statistics
import time

import numpy as np
import pytest

from sim.reduced.slow_flow import host_mode, screen, sphere_mass
from sim.hosts.rig import seed_rig_model

pytestmark = pytest.mark.benchmark
TARGET_S = 2.0
REPEATS = 5
BRASS = 8490.0  # kg/m^3, Table 1


def test_screening_50_clearances_10_radii_20_levels():
    host = host_mode(seed_rig_model())
    clearances = np.linspace(0.2e-3, 1.2e-3, 50)
    masses = sphere_mass(np.linspace(4e-3, 9e-3, 10), BRASS)
    a_base = np.linspace(2e-6, 8e-6, 20)
    result = screen(host, clearances, masses, a_base, 0.86)  # untimed first call
    times = []
    for _ in range(REPEATS):
        started = time.perf_counter()
        result = screen(host, clearances, masses, a_base, 0.86)
        times.append(time.perf_counter() - started)
    median = statistics.median(times)
    print(f"\nscreening 50 x 10 x 20 designs: median {median:.3f} s over {REPEATS} (target {TARGET_S} s)")
    assert result.tip.shape == (50, 10, 20) and np.all(np.isfinite(result.tip)) and np.all(result.tip > 0)
    assert median <= TARGET_S
