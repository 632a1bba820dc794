"""A worker process for same-run A/B timings of one stepped-sine point (tests/benchmarks/test_energy_speed.py):
imports `sim` from the tree given on the command line, prepares the start state, then answers every line
"run" on stdin with the CPU seconds of one point (3 s wait + 5 s hold at a_base/a_base* = 7.4), with the
energy bookkeeping and impact measures where the tree has them (`sim.energy.Ledger`)."""
import sys
import time

sys.path.insert(0, sys.argv[1])
ETA, PREPARE = float(sys.argv[2]), (float(sys.argv[3]) if sys.argv[3] != "-" else None)

import numpy as np  # noqa: E402

from sim import exact  # noqa: E402
from sim.rig import seed_rig_model  # noqa: E402
from sim.system import Impactor, a_base_star, a_noabs_star, system_arrays  # noqa: E402

try:
    from sim.energy import Ledger
except ImportError:  # the tree before the bookkeeping
    Ledger = None
try:
    from sim.measures import point_measures
except ImportError:
    point_measures = None

LEVEL = 7.4
model = seed_rig_model(n_modes=9)
sys_ = system_arrays(model, Impactor())
a_base = LEVEL * a_base_star(model)
y0 = np.zeros(2 * model.n_modes + 2)
if PREPARE is None:
    y0[-1] = a_base * ETA * model.omega[0]
else:
    for e in np.arange(PREPARE, ETA + 1e-9, -0.004):
        Om = e * model.omega[0]
        exact.run_step(y0, int(round(8.0 * Om / (2 * np.pi))), Om, a_base, sys_)


def one_point() -> float:
    Omega = ETA * model.omega[0]
    periods = Omega / (2 * np.pi)
    n_wait, n_hold = int(round(3.0 * periods)), int(round(5.0 * periods))
    y = y0.copy()
    started = time.thread_time()
    exact.run_step(y, n_wait, Omega, a_base, sys_, None)
    if Ledger is None:
        exact.run_step(y, n_hold, Omega, a_base, sys_, None)
    else:
        ledger = Ledger()
        amplitudes, impacts = exact.run_step(y, n_hold, Omega, a_base, sys_, None, ledger=ledger)
        if point_measures is not None:
            point_measures(amplitudes, impacts, a_noabs_star(model, a_base), ledger)
    return time.thread_time() - started


one_point()  # compile or load the kernels, build the collocation tables
print("ready", flush=True)
for line in sys.stdin:
    if line.strip() != "run":
        break
    print(f"{one_point():.6f}", flush=True)
