"""Speed of the exact free-flight integrator against the paper's ode3: one stepped-sine
point (3 s wait + 5 s hold, 9 modes of the built-in rig, nominal parameters) at a strongly modulated and at
an almost periodic operating point, both integrators measured in the same run from the same state.

The almost periodic branch at a_base/a_base* = 7.4 is not reached from rest: its start state is
prepared by a down-sweep 0.99 -> 0.978 with the exact integrator. CPU time of this thread is the figure
(the machine is shared); wall time is printed too.

Run: pytest -m benchmark tests/benchmarks/test_exact_speed.py -s
"""
import functools
import time

import numpy as np
import pytest

from sim.integration import collocation, exact, ode3
from sim.stepped_sine.measures import hold_measures
from sim.model.system import Impactor, a_base_star, a_noabs_star, system_arrays

pytestmark = pytest.mark.benchmark
LEVEL = 7.4


@pytest.fixture(scope="module")
def rig():
    from sim.hosts.rig import seed_rig_model

    return seed_rig_model(n_modes=9)


def _start_state(rig, sys, eta, prepare_down_from):
    """Rest, or the state at the end of a down-sweep ending just above eta (3 s + 5 s per point)."""
    y = np.zeros(2 * rig.n_modes + 2)
    a_base = LEVEL * a_base_star(rig)
    if prepare_down_from is not None:
        for e in np.arange(prepare_down_from, eta + 1e-9, -0.004):
            Omega = e * rig.omega[0]
            exact.run_step(y, int(round(8.0 * Omega / (2 * np.pi))), Omega, a_base, sys)
    return y


def _one_point(run_step, y0, rig, sys, eta):
    """One stepped-sine point exactly as sim.stepped_sine.protocol.run_sweep does it (wait, then hold)."""
    Omega = eta * rig.omega[0]
    periods = Omega / (2 * np.pi)
    n_wait, n_hold = int(round(3.0 * periods)), int(round(5.0 * periods))
    a_base = LEVEL * a_base_star(rig)
    y = y0.copy()
    started = time.thread_time()
    started_wall = time.perf_counter()
    run_step(y, n_wait, Omega, a_base, sys, None)
    amplitudes, impacts = run_step(y, n_hold, Omega, a_base, sys, None)
    cpu, wall = time.thread_time() - started, time.perf_counter() - started_wall
    return cpu, wall, hold_measures(amplitudes, impacts, a_noabs_star(rig, a_base))


@pytest.mark.parametrize("eta, prepare, label", [(0.99, None, "strongly modulated, from rest"),
                                                 (0.978, 0.99, "almost periodic, after a down-sweep")])
def test_exact_vs_ode3_one_stepped_sine_point(rig, eta, prepare, label):
    sys = system_arrays(rig, Impactor())
    y0 = _start_state(rig, sys, eta, prepare)
    for run_step in (exact.run_step, ode3.run_step):  # JIT warm-up
        run_step(np.zeros_like(y0), 2, eta * rig.omega[0], 1e-6, sys, None)
    rows = {}
    candidates = (("exact", exact.run_step),
                  ("exact, dopri5 contacts", functools.partial(exact.run_step, contacts="dopri5", rtol=1e-7)),
                  ("exact, dopri5 rtol 1e-10", functools.partial(exact.run_step, contacts="dopri5", rtol=1e-10)),
                  ("ode3", ode3.run_step),
                  ("ode3 dt/8", functools.partial(ode3.run_step, dt_scale=1 / 8)))  # the per-impact accuracy bar
    collocation._CACHE.clear()
    first = _one_point(exact.run_step, y0, rig, sys, eta)[0]  # builds the collocation tables (once per system)
    for _, run_step in candidates:
        _one_point(run_step, y0, rig, sys, eta)
    results = {name: [] for name, _ in candidates}
    for _ in range(5):  # interleaved, so that the machine's load affects every candidate alike
        for name, run_step in candidates:
            results[name].append(_one_point(run_step, y0, rig, sys, eta))
    for name, res in results.items():
        rows[name] = (float(np.median([r[0] for r in res])), float(np.median([r[1] for r in res])), res[-1][2])
    print(f"\nlevel {LEVEL}, eta {eta} ({label}), one point = 3 s wait + 5 s hold, median of 5 "
          f"(the first point of a system, building its collocation tables: {first * 1e3:.1f} ms):")
    for name, (cpu, wall, m) in rows.items():
        print(f"  {name:24s}: {cpu * 1e3:7.1f} ms CPU, {wall * 1e3:7.1f} ms wall; mean {m.mean:.4f}, max {m.max:.4f}, "
              f"cv {m.std / m.mean:.3f}, {m.impacts_per_period:.2f} impacts/period")
    ratio = rows["ode3"][0] / rows["exact"][0]
    print(f"  speed-up (CPU) ode3/exact = {ratio:.1f}x (target >= 10x, <= 25 ms per point); dopri5 contacts at the "
          f"collocation's accuracy (rtol 1e-10) / collocation = {rows['exact, dopri5 rtol 1e-10'][0] / rows['exact'][0]:.2f}x, "
          f"at rtol 1e-7 (400x less accurate) = {rows['exact, dopri5 contacts'][0] / rows['exact'][0]:.2f}x")
    print(f"  at equal accuracy (ode3 at dt/8 is the per-impact error bar; exact is ~1000x below it): "
          f"ode3 dt/8 / exact = {rows['ode3 dt/8'][0] / rows['exact'][0]:.1f}x")
    assert ratio > 1.0
