"""Speed of `ies trace`: recording 50 excitation periods of the rig at 51.2 kHz after the wait (target < 2 s),
against the same 50 periods without recording (the cost of the recorded states), and the whole command
(lead-in and wait of 3 s each, CSV and JSON) in a fresh process. Kernels warmed up before timing; medians of 5
interleaved repetitions (the machine is shared).

Run: pytest -m benchmark tests/benchmarks/test_trace_speed.py -s
"""
import math
import statistics
import subprocess
import sys
import time

import numpy as np
import pytest

from sim.integration import exact
from sim.integration.integrators import warm_up
from sim.hosts.rig import seed_rig_model
from sim.model.system import Impactor, a_base_star, system_arrays

pytestmark = pytest.mark.benchmark
REPEATS = 5


def test_recording_50_periods_at_51_kHz(tmp_path):
    warm_up("exact")
    model = seed_rig_model(9)
    sys_ = system_arrays(model, Impactor())
    a_base, Omega = 7.4 * a_base_star(model), 0.976 * model.omega[0]
    y0 = np.zeros(2 * model.n_modes + 2)
    y0[-1] = a_base * Omega
    exact.run_step(y0, int(round(3.0 * Omega / (2 * math.pi))), Omega, a_base, sys_)  # the wait
    M = int(round(51.2e3 / (Omega / (2 * math.pi))))
    recorded, plain = [], []
    for _ in range(REPEATS):
        for record, times in ((np.empty((50 * M + 1, y0.size)), recorded), (None, plain)):
            y = y0.copy()
            started = time.perf_counter()
            exact.run_step(y, 50, Omega, a_base, sys_, record)
            times.append(time.perf_counter() - started)
    r, p = statistics.median(recorded), statistics.median(plain)
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "uq", "trace", "--level", "7.4", "--eta", "0.976", "--out", str(tmp_path / "t")],
                   check=True, capture_output=True)
    command = time.perf_counter() - started
    print(f"\n50 periods, M = {M}: recorded {r:.3f} s, not recorded {p:.3f} s (ratio {r / p:.2f}); "
          f"whole ies trace command {command:.1f} s")
    assert r < 2.0
