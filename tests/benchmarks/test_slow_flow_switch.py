"""Check (c) of issue 28: the slow flow's predicted SMR -> APR switch (`sim.reduced.slow_flow.switch_level`,
Eq. 9) against the full simulator's (`sim.stepped_sine.protocol.sweep`, landmarks of `sim.stepped_sine.landmarks`) on five designs: the
paper's rig at g*, 0.5 g*, 2 g*, and a sphere half and twice as heavy (same k_H, Eq. 4 contact).

Protocol as the fidelity studies (uq/studies/fidelity/baseline.toml): eta 0.96:1.0:21 up, 3 s wait, 5 s hold,
base-velocity start, exact integrator, seed 2024, one repetition per level. Levels a_base/a_base* from 2.0 to 9.0
in steps of 0.5, with a_base* of each design's OWN clearance (Nominal(clearance=g)): the slow flow with rigid
walls depends on g only through a_base/g, so this is the axis on which designs differ. r: the simulator's Eq. D.1
value at the wall (`restitution_wall`, median over the resonant points of the APR levels, of all levels
when none is APR). Agreement: the
prediction lies within one grid step (0.5) of the simulated switch interval (last SMR level, first APR level].

Run: pytest -m benchmark tests/benchmarks/test_slow_flow_switch.py -s   (6 x 15 sweeps; 2-4 min once compiled)
The measured table is in the docstring of sim/reduced/slow_flow.py (the check fails on four of the five designs).
"""
import json
import math
import os
import time
from dataclasses import replace

import numpy as np
import pytest

from sim.model.contact_law import ContactLaw
from sim.stepped_sine.protocol import SteppedSine, sweep
from sim.reduced.slow_flow import SlowFlowModel, apr_branch, host_mode, switch_level
from sim.hosts.rig import seed_rig_model
from sim.model.system import CLEARANCE_NOMINAL, SPHERE_MASS, Impactor, Nominal
from sim.stepped_sine.landmarks import landmarks

pytestmark = pytest.mark.benchmark
LEVELS = np.arange(2.0, 9.01, 0.5)
STEP = 0.5
DESIGNS = {"rig": (1.0, 1.0), "g*/2": (0.5, 1.0), "2 g*": (2.0, 1.0), "m_a/2": (1.0, 0.5), "2 m_a": (1.0, 2.0)}
#: Diagnostic row, not part of the check: the rig's mode 1 alone with the damped contact law (Eq. 10,
#: r_cont = 0.86), the full simulator's closest analogue of the slow flow's one-mode Newton model.
ONE_MODE_R_CONT = 0.86
PROTOCOL = SteppedSine(eta_start=0.96, eta_stop=1.0, n_eta=21, sequence="up", wait=3.0, hold=5.0,
                       perturbation=5e-4, repetition="run", integrator="exact", start="base-velocity")


def one_mode(model):
    return replace(model, **{name: getattr(model, name)[:1] for name in (
        "frequencies_hz", "damping_ratios", "phi_wall_left", "phi_wall_right", "phi_tip", "participation")},
        phi_floor=None, source="rig mode 1")


def simulated(model, g, m_a, law):
    nominal = Nominal(clearance=g)
    results = [sweep(model, Impactor(mass=m_a, clearance=g, contact_law=law), float(level), PROTOCOL, reps=1, seed=2024,
                     nominal=nominal, progress=False) for level in LEVELS]
    marks = landmarks(results)
    apr, every = [], []
    for result in results:
        k = int(np.argmax(result.mean))
        value = float(result.scattering["restitution_wall"][k])
        if math.isfinite(value):
            every.append(value)
            if result.regime_per_eta[k] == "APR":
                apr.append(value)
    # r of the APR levels; a design that never switches: r of every level's resonant point
    return marks, float(np.median(apr or every)) if (apr or every) else math.nan


def test_predicted_switch_within_one_grid_level_of_the_simulated_one():
    model = seed_rig_model()
    host = host_mode(model)
    rows = []
    cases = [(name, g_f, m_f, model, ContactLaw()) for name, (g_f, m_f) in DESIGNS.items()]
    cases.append(("1 mode", 1.0, 1.0, one_mode(model), ContactLaw("hertz-damped", ONE_MODE_R_CONT)))
    for name, g_factor, m_factor, host_model, law in cases:
        g, m_a = g_factor * CLEARANCE_NOMINAL, m_factor * SPHERE_MASS
        started = time.perf_counter()
        marks, r = simulated(host_model, g, m_a, law)
        flow = SlowFlowModel(host, m_a, g, r, Nominal(clearance=g))
        predicted = switch_level(flow, (0.96, 1.0)).level
        lo = marks.last_smr if marks.last_smr is not None else LEVELS[0] - STEP
        hi = marks.first_apr if marks.first_apr is not None else math.inf
        ok = lo - STEP <= predicted <= hi + STEP
        apr_74 = float(apr_branch(flow, np.array([7.5]), (0.96, 1.0))[0])
        rows.append({"design": name, "g_mm": g * 1e3, "m_a_kg": m_a, "r": r, "last_smr": marks.last_smr,
                         "first_apr": marks.first_apr, "predicted": predicted, "agree": ok,
                         "simulated_level_7_5": marks.at(7.5), "predicted_level_7_5": apr_74,
                         "seconds": time.perf_counter() - started})
        print(f"\n{name:6s} g {g * 1e3:.3f} mm m_a {m_a * 1e3:.2f} g r {r:.3f}: simulated switch "
              f"{marks.last_smr}->{marks.first_apr}, slow flow {predicted:.2f} ({'agrees' if ok else 'DISAGREES'}); "
              f"APR level at 7.5 simulated {marks.at(7.5):.3f}, slow flow {apr_74:.3f} "
              f"[{time.perf_counter() - started:.0f} s]", flush=True)
    paper = SlowFlowModel(host, SPHERE_MASS, CLEARANCE_NOMINAL, 0.8)
    print(f"paper's r = 0.8 on the rig: slow-flow switch {switch_level(paper, (0.96, 1.0)).level:.2f}")
    out = os.environ.get("SLOW_FLOW_SWITCH_JSON")
    if out:
        with open(out, "w") as f:
            json.dump(rows, f, indent=1)
    failed = [row["design"] for row in rows if not row["agree"] and row["design"] in DESIGNS]
    assert not failed, failed
