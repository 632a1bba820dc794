"""A worker process for same-run A/B timings of one stepped-sine point (tests/benchmarks/test_energy_speed.py,
test_contact_law_speed.py): imports `sim` from the tree given on the command line, prepares the start state, then
answers every line "run" on stdin with the CPU seconds of one point (3 s wait + 5 s hold at a_base/a_base* = 7.4),
with the energy bookkeeping and impact measures where the tree has them (`sim.integration.energy.Ledger`), and the
line "state" with the bytes (hex) of the last point's end state and hold amplitudes (bit-for-bit comparisons).

Arguments: TREE ETA PREPARE [INTEGRATOR [R_CONT [MU]]]: PREPARE "-" starts from the base velocity, else a down-sweep
from that eta; INTEGRATOR exact (default) or ode3; R_CONT < 1: the damped contact law of Eq. 10; MU > 0: dry friction
at the floor (Appendix C, ode3)."""
import sys
import time

sys.path.insert(0, sys.argv[1])
ETA, PREPARE = float(sys.argv[2]), (float(sys.argv[3]) if sys.argv[3] != "-" else None)
INTEGRATOR = sys.argv[4] if len(sys.argv) > 4 else "exact"
R_CONT = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
MU = float(sys.argv[6]) if len(sys.argv) > 6 else 0.0

import numpy as np  # noqa: E402

from sim.integration import exact, ode3  # noqa: E402
from sim.hosts.rig import seed_rig_model  # noqa: E402
from sim.model.system import Impactor, a_base_star, a_noabs_star, system_arrays  # noqa: E402

try:
    from sim.integration.energy import Ledger
except ImportError:  # the tree before the bookkeeping
    Ledger = None
try:
    from sim.stepped_sine.measures import point_measures
except ImportError:
    point_measures = None

LEVEL = 7.4
model = seed_rig_model(n_modes=9)
if R_CONT < 1.0 or MU > 0.0:
    from sim.model.contact_law import ContactLaw

    law = ContactLaw("hertz-damped", R_CONT) if R_CONT < 1.0 else ContactLaw()
    sys_ = system_arrays(model, Impactor(contact_law=law, friction=MU))
else:
    sys_ = system_arrays(model, Impactor())
integrator = {"exact": exact, "ode3": ode3}[INTEGRATOR]
a_base = LEVEL * a_base_star(model)
y0 = np.zeros(2 * model.n_modes + 2)
if PREPARE is None:
    y0[-1] = a_base * ETA * model.omega[0]
else:
    for e in np.arange(PREPARE, ETA + 1e-9, -0.004):
        Om = e * model.omega[0]
        integrator.run_step(y0, int(round(8.0 * Om / (2 * np.pi))), Om, a_base, sys_)


last: list[np.ndarray] = []


def one_point() -> float:
    Omega = ETA * model.omega[0]
    periods = Omega / (2 * np.pi)
    n_wait, n_hold = int(round(3.0 * periods)), int(round(5.0 * periods))
    y = y0.copy()
    started = time.thread_time()
    integrator.run_step(y, n_wait, Omega, a_base, sys_, None)
    if Ledger is None:
        amplitudes, _ = integrator.run_step(y, n_hold, Omega, a_base, sys_, None)
    else:
        ledger = Ledger()
        amplitudes, impacts = integrator.run_step(y, n_hold, Omega, a_base, sys_, None, ledger=ledger)
        if point_measures is not None:
            point_measures(amplitudes, impacts, a_noabs_star(model, a_base), ledger)
    elapsed = time.thread_time() - started
    last[:] = [y, amplitudes]
    return elapsed


one_point()  # compile or load the kernels, build the collocation tables
print("ready", flush=True)
for line in sys.stdin:
    if line.strip() == "state":
        print(b"".join(a.tobytes() for a in last).hex(), flush=True)
    elif line.strip() == "run":
        print(f"{one_point():.6f}", flush=True)
    else:
        break
