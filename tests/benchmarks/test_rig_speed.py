"""Speed of the rig model (run with `pytest -m benchmark tests/benchmarks/test_rig_speed.py -s`).

seed_rig_model() is called by every command, so building it from the stored constants must stay well under a
second; prints medians of repeated timings (the machine is shared: compare within one run).
"""
import statistics
import subprocess
import sys
import time

import pytest

from sim.hosts.rig import RigParameters, rig_mesh, rig_modes, update_rig


def median_time(fn, repeat=7):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


@pytest.mark.benchmark
def test_rig_model_speed():
    rig_modes()  # warm-up (imports, first ARPACK call)
    t_mesh = median_time(rig_mesh)
    t_modes = median_time(rig_modes)
    code = "import time; t = time.perf_counter(); from sim.hosts.rig import seed_rig_model; seed_rig_model(); print(time.perf_counter() - t)"
    t_cold = statistics.median(float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                                    check=True).stdout) for _ in range(3))
    t_cli = median_time(lambda: subprocess.run([sys.executable, "-m", "uq", "modes", "--json"], capture_output=True,
                                               check=True), repeat=3)
    t_update = median_time(lambda: update_rig(RigParameters(212e9, 0.13, 0.028, 0.0125, 3e9)), repeat=1)
    print(f"\nrig mesh assembly: {1e3 * t_mesh:.1f} ms; 9 modes (assembly + eigensolver): {1e3 * t_modes:.1f} ms")
    print(f"cold import + seed_rig_model(): {1e3 * t_cold:.0f} ms; `ies modes --json` process: {1e3 * t_cli:.0f} ms")
    print(f"model updating (joint-spring) from a perturbed start: {t_update:.2f} s")
    assert t_modes < 0.5
