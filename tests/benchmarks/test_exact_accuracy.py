"""Accuracy table: per-impact error of the sphere's rebound velocity against scipy DOP853
(rtol 1e-12, restarted at the contact events) for the exact integrator (default tolerance and tighter)
and for the paper's ode3 at dt, dt/2, dt/4, dt/8 (dt = 2 pi/(15 omega_9)), on a 9-mode beam-like model
(f1 = 117.4 Hz ... f9 = 19.8 kHz) with the beam at rest and the sphere closing at v0.

Run: pytest -m benchmark tests/benchmarks/test_exact_accuracy.py -s
"""
import pytest

from sim.integration import exact, ode3
from sim.integration.references import rebound_error

pytestmark = pytest.mark.benchmark


def test_accuracy_table():
    speeds = (0.1, 0.5, 1.0)
    rows = []
    rows.append(("exact (collocation)", [rebound_error(v, lambda y, s, Om, a: exact.run_step(y, 1, Om, a, s))
                                         for v in speeds]))
    for rtol in (1e-7, 1e-8, 1e-10):
        rows.append((f"dopri5 rtol {rtol:g}", [rebound_error(
            v, lambda y, s, Om, a: exact.run_step(y, 1, Om, a, s, rtol=rtol, contacts="dopri5")) for v in speeds]))
    for scale, label in ((1, "dt"), (1 / 2, "dt/2"), (1 / 4, "dt/4"), (1 / 8, "dt/8")):
        rows.append((f"ode3 {label}", [rebound_error(v, lambda y, s, Om, a: ode3.run_step(y, 1, Om, a, s, dt_scale=scale))
                                       for v in speeds]))
    print("\nrelative error of the rebound velocity, per impact (v0 = " + ", ".join(f"{v} m/s" for v in speeds) + ")")
    for label, errs in rows:
        print(f"  {label:20s} " + "  ".join(f"{e:9.2e}" for e in errs))
    default = dict(rows)["exact (collocation)"]
    assert all(e <= o for e, o in zip(default, dict(rows)["ode3 dt/8"]))
