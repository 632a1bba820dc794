"""Speed of the signal analyses (`ies impacts`, `ies modal-fit`) on 50 excitation periods at 51.2 kHz: the impact detector
(Appendix D.1) on a synthetic measurement and on a simulated trace, and the modal fit (Eq. 9) on the
simulated trace with detected and with the simulator's impacts. Target: well under a second each. Wall time
(median of 5, the machine is shared) and the peak of Python-side allocations (tracemalloc) are printed.

Run: pytest -m benchmark tests/benchmarks/test_signals.py -s
"""
import statistics
import time
import tracemalloc

import numpy as np
import pytest

from sim.analysis.impacts import detect_impacts, synthetic_impact_signal
from sim.analysis.modal_fit import fit_modes
from tests.sim._traces import rig_trace

pytestmark = pytest.mark.benchmark
REPEATS = 5


def measure(run):
    times = []
    for _ in range(REPEATS):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    tracemalloc.start()
    run()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return statistics.median(times), peak


@pytest.fixture(scope="module")
def trace():
    return rig_trace()


def test_signal_analyses_take_well_under_a_second(trace):
    synthetic = synthetic_impact_signal(2.5, irregular=True, periods=50)
    f_excitation = trace.Omega / (2 * np.pi)
    cases = {
        "impacts, synthetic (estimated f)": lambda: detect_impacts(synthetic.signal),
        "impacts, trace (given f)": lambda: detect_impacts(trace.signal, excitation_hz=f_excitation),
        "modal-fit, trace, detected impacts": lambda: fit_modes(trace.signal, trace.model, excitation_hz=f_excitation),
        "modal-fit, trace, simulator's impacts": lambda: fit_modes(trace.signal, trace.model, trace.contacts.times,
                                                                   excitation_hz=f_excitation),
    }
    print(f"\n{trace.signal.t.size} samples at {trace.signal.fs:.0f} Hz (50 periods); "
          f"synthetic: {synthetic.signal.t.size} samples")
    for label, run in cases.items():
        seconds, peak = measure(run)
        print(f"{label:40s} {seconds * 1e3:8.1f} ms   peak allocations {peak / 2**20:6.1f} MiB")
        assert seconds < 1.0
