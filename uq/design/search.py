"""The design search of `ies design`: screening by the slow flow, verification of the best designs by stepped-sine
simulation at the corners of the uncertainty box, and the recommendation (the best verified design)."""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from uq.design.problem import (
    DesignProblem,
    Sphere,
    first_impacts,
    host_mode,
    host_model,
    levels_of,
    micrometres,
    no_absorber,
)
from uq.design.results import DesignResult, Screened, Verified, write_design
from uq.errors import StudyError


def screen_designs(problem: DesignProblem, mode: Any) -> Screened:
    """Stage 1: one slow-flow screening per material, damping end and clearance-tolerance end (the clearances and
    levels of a material are one vectorised call)."""
    import time

    from sim.model.materials import material, sphere_mass
    from sim.reduced.slow_flow import screen

    started = time.perf_counter()
    a_base = np.asarray(problem.excitation, dtype=float)
    g = np.asarray(problem.clearances, dtype=float)
    R = np.asarray(problem.radii, dtype=float)
    designs, tips, regimes, switches = [], [], [], []
    for name in problem.materials:
        masses = sphere_mass(R, material(name))
        worst_tip, worst_regime, switch = None, None, None
        for D in sorted(set(problem.D)):
            host = dataclasses.replace(mode, D=float(D))
            for tol in sorted(set(problem.clearance_tolerance)):
                s = screen(host, g + tol, masses, a_base, problem.restitution)
                if worst_tip is None:
                    worst_tip, worst_regime, switch = s.tip.copy(), s.regime.copy(), s.switch_a_base.copy()
                else:
                    higher = s.tip > worst_tip
                    worst_tip[higher], worst_regime[higher] = s.tip[higher], s.regime[higher]
                    switch = np.maximum(switch, s.switch_a_base)
        # (clearance, radius, level) -> designs in grid order (radius outer, clearance inner)
        tips.append(worst_tip.transpose(1, 0, 2).reshape(-1, a_base.size))
        regimes.append(worst_regime.transpose(1, 0, 2).reshape(-1, a_base.size))
        switches.append(switch.T.reshape(-1))
        designs += [Sphere(float(gi), float(Ri), name) for Ri in R for gi in g]
    b = problem.baseline
    if b is not None and b not in designs:  # the baseline off the grid: screened too, as one more design
        one = dataclasses.replace(problem, clearances=(b.clearance,), radii=(b.radius,), materials=(b.material,),
                                  baseline=None)
        extra = screen_designs(one, mode)
        designs.append(b)
        tips.append(extra.tip)
        regimes.append(extra.regime)
        switches.append(extra.switch)
    tip, regime, switch = np.vstack(tips), np.vstack(regimes), np.concatenate(switches)
    worst = np.where([problem.fits(d) for d in designs], tip.max(axis=1), np.inf)
    return Screened(designs, tip, regime, switch, worst, time.perf_counter() - started)


def candidates(problem: DesignProblem, screened: Screened) -> list[Sphere]:
    """The designs to verify: the `problem.candidates` best screened designs that fit, the clearance neighbours of the
    best of them on the grid (same sphere), and the baseline, each once, best first."""
    order = [i for i in np.argsort(screened.worst, kind="stable") if np.isfinite(screened.worst[i])]
    chosen = [screened.designs[i] for i in order[: problem.candidates]]
    g = list(problem.clearances)
    if chosen and chosen[0].clearance in g:
        best = chosen[0]
        k = g.index(best.clearance)
        for j in (k - 1, k + 1):
            if 0 <= j < len(g):
                neighbour = Sphere(g[j], best.radius, best.material)
                if problem.fits(neighbour) and neighbour not in chosen:
                    chosen.append(neighbour)
    if problem.baseline is not None and problem.baseline not in chosen:
        chosen.append(problem.baseline)
    return chosen


def corners(problem: DesignProblem, sphere: Sphere) -> list[dict[str, float]]:
    """The uncertainty box of one design as task parameters (D, g, k_H, m_a in SI): its 8 corners, then the nominal
    point (D's midpoint, the clearance and k_H of the design) for the monotonicity check; built from the parameter
    rows (`DesignProblem.corners`)."""
    return problem.corners(sphere)




def verification_model(problem: DesignProblem) -> Any:
    """The study model that simulates one run of a design (`uq.problem.models.IESModel`; the sphere mass m_a per task)."""
    from uq.problem.models import IESModel

    return IESModel(protocol=dict(problem.protocol), modal_file=problem.modal_file)


def verify(problem: DesignProblem, spheres: Sequence[Sphere], model: Any, folder: Any, *, jobs: int | None,
           scheduler: str | None, progress: bool, client: Any = None) -> list[Verified]:
    """Stage 2: every corner and nominal point of every design at every level and repetition, through the study
    runner (`uq.engine.runner.run_tasks`: cached in `folder`/tasks, resumable)."""
    from uq.engine.runner import ResultStore, Task, run_tasks

    rig = model.rig
    levels = levels_of(rig, problem.excitation)
    amplitude = "mean" if problem.objective == "mean" else "max"
    boxes = {s: corners(problem, s) for s in spheres}
    tasks = [Task.make(p, L, rep) for s in spheres for p in boxes[s] for L in levels
             for rep in range(problem.repetitions)]
    results, _ = run_tasks(model, tasks, problem.seed, ResultStore(folder), jobs=jobs, scheduler=scheduler,
                           progress=progress, client=client)
    from sim.model.system import a_noabs_star

    out = []
    for s in spheres:
        value = np.empty((len(boxes[s]), levels.size))
        se = np.zeros_like(value)
        apr = np.zeros(levels.size)
        for i, p in enumerate(boxes[s]):
            for k, (L, a_base) in enumerate(zip(levels, problem.excitation)):
                runs = [results[Task.make(p, L, rep)] for rep in range(problem.repetitions)]
                scale = a_noabs_star(rig, a_base)  # the run's amplitudes are normalised by a_noabs* (Sect. 5)
                metres = np.array([r["outputs"].get(amplitude, math.nan) if not r.get("error") else math.nan
                                   for r in runs]) * scale
                value[i, k] = metres.mean()
                se[i, k] = metres.std(ddof=1) / math.sqrt(len(runs)) if len(runs) > 1 else 0.0
                apr[k] += sum(r["outputs"].get("apr", 0.0) for r in runs if not r.get("error"))
        low, high = value[:-1].min(axis=0), value[:-1].max(axis=0)
        nominal = value[-1]
        outside = (nominal > high + 2.0 * se[-1]) | (nominal < low - 2.0 * se[-1])
        out.append(Verified(s, low, high, nominal, apr / (len(boxes[s]) * problem.repetitions), outside,
                            len(boxes[s]) * levels.size * problem.repetitions))
    return out




def run_design(problem: DesignProblem, out: Any, *, jobs: int | None = 1, scheduler: str | None = None,
               resume: bool = False, progress: bool = True, figures: bool = True, client: Any = None) -> DesignResult:
    """Screen, verify and write a design into the folder `out` (design.csv, design.json, design-levels.csv, the
    figures): checks everything before any simulation; `resume` continues an interrupted design."""
    from pathlib import Path

    from uq.engine.runner import dask_client, prepare_output

    problem.check()
    model = verification_model(problem)
    mode = host_mode(host_model(problem))
    g_min = min(problem.clearances) + problem.clearance_tolerance[0]
    start = first_impacts(dataclasses.replace(mode, D=min(problem.D)), g_min)
    if max(problem.excitation) < start:
        raise StudyError(f"--excitation: the structure never reaches the clearance over {micrometres(min(problem.excitation))}-"
                         f"{micrometres(max(problem.excitation))} um (no impacts, the IES does nothing); impacts begin at "
                         f"a_base = {micrometres(start)} um for g = {g_min * 1e3:.3g} mm: raise the excitation or lower the "
                         "clearance")
    screened = screen_designs(problem, mode)
    spheres = candidates(problem, screened)
    with dask_client(scheduler, client) as connected:
        model = model.with_rig()
        folder = prepare_output(Path(out), resume=resume, study=("design", design_key(problem, model)))
        model.warm_up()
        verified = verify(problem, spheres, model, folder, jobs=jobs, scheduler=None, progress=progress,
                          client=connected)
    verified.sort(key=lambda v: v.worst)
    rig = model.rig
    result = DesignResult(problem, screened, verified, folder, levels_of(rig, problem.excitation),
                          no_absorber(rig, problem.excitation, min(problem.D)), [])
    result.files.extend(write_design(result, mode))
    if figures:
        from uq.design.figures import plot_design_curves, plot_design_map

        for suffix in ("png", "pdf"):
            result.files.append(plot_design_map(result, folder / f"design-map.{suffix}"))
            result.files.append(plot_design_curves(result, folder / f"design-curves.{suffix}"))
    return result


def design_key(problem: DesignProblem, model: Any) -> str:
    """SHA-256 of the problem and the model's settings: `--resume` continues only the same design."""
    import hashlib
    import json

    from uq.engine.runner import describe_model

    text = json.dumps({"problem": dataclasses.asdict(problem), "model": describe_model(model)}, sort_keys=True,
                      default=str)
    return hashlib.sha256(text.encode()).hexdigest()
