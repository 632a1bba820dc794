"""Speed of the periodic orbits (`sim.orbits`): one frequency response at one level on the built-in rig
(a_base/a_base* = 7.4, eta 0.95-1.0) as `ies orbits` computes it by default: the two-impact branch from the slow-flow
start with every bifurcation located, the switchings at its symmetry breakings and period doublings and the
direct-simulation searches at every change of stability (within the response's budget of map runs,
`sim.orbits.response.GROWTH_RUNS`), the linear orbits, the multipliers of every orbit: at most 30 s of CPU on one
core, kernels compiled (warmed up before timing). The machine is shared: CPU time (time.process_time) rather than wall
time, the median of three runs, and the runs' map evaluations printed beside it (the cost that does not depend on
the load).

Run: pytest -m benchmark tests/benchmarks/test_orbits_speed.py -s
"""
import statistics
import time

import pytest

from sim.hosts.rig import seed_rig_model
from sim.integration.integrators import warm_up
from sim.model.system import Impactor
from sim.orbits import shooting
from sim.orbits.response import orbit_response
from sim.orbits.setting import OrbitSetting

pytestmark = pytest.mark.benchmark
REPEATS = 3
TARGET_S = 30.0


def test_one_frequency_response_within_30_s():
    warm_up("exact")
    setting = OrbitSetting(seed_rig_model(9), Impactor(), 7.4, 0.975)
    orbit_response(setting, "eta", (0.95, 0.951), switches=0)  # imports, caches, first calls
    times, summaries = [], []
    calls = [0]
    original = shooting.ShootingMap.__call__

    def counted(self, y):
        calls[0] += 1
        return original(self, y)

    shooting.ShootingMap.__call__ = counted
    try:
        for _ in range(REPEATS):
            calls[0] = 0
            started = time.process_time()
            response = orbit_response(setting, "eta", (0.95, 1.0))
            times.append(time.process_time() - started)
            points = sum(len(b.points) for b in response.branches)
            summaries.append((points, calls[0], [len(b.points) for b in response.branches],
                              sum(p.orbit.stable for b in response.branches for p in b.points),
                              sum(bool(p.label) for b in response.branches for p in b.points), len(response.searches)))
    finally:
        shooting.ShootingMap.__call__ = original
    median = statistics.median(times)
    print(f"\nfrequency response at 7.4, eta 0.95-1.0: CPU {', '.join(f'{t:.1f}' for t in times)} s (median {median:.1f} s); "
          f"orbits, map runs, points per branch, stable orbits, located points, searches: {summaries[0]}")
    assert len(response.branches) >= 2 and all(b.points for b in response.branches)
    assert median <= TARGET_S
