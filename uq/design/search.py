"""The design search of `ies design`: screening by the slow flow, prediction by the similarity law of the full model,
verification by stepped-sine simulation at the corners of the uncertainty box, iterated over the best verified
design's neighbours until the best has verified neighbours on every side, and the recommendation (the best
admissible verified design)."""
from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from uq.design.objectives import Objective, objective_named
from uq.design.prediction import DesignPrediction, Predictor
from uq.design.problem import (
    SECONDS_PER_RUN,
    DesignProblem,
    Sphere,
    first_impacts,
    host_mode,
    host_model,
    duration,
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


def first_runs(problem: DesignProblem) -> tuple[int, int]:
    """(runs of the first verified batch, an upper bound of the similarity references' runs for its spheres): what the
    design runs at least before its search adds neighbours."""
    from uq.design.prediction import LEVEL_CEILING, LEVEL_FLOOR, LEVEL_RATIO, REFERENCE_REPS

    fitting = [s for s in problem.grid() if problem.fits(s)]
    designs = min(problem.candidates, len(fitting)) + (problem.baseline is not None)
    points = len(problem.corners(fitting[0] if fitting else problem.grid()[0]))
    per_design = points * (len(problem.excitation) + 1) * problem.repetitions
    spheres = min(problem.candidates, len({(s.radius, s.material) for s in fitting}))
    levels = 1 + math.ceil(math.log(LEVEL_CEILING / LEVEL_FLOOR) / math.log(LEVEL_RATIO))
    references = 3 * len(set(problem.D)) * (levels + 6) * min(REFERENCE_REPS, problem.repetitions)
    return designs * per_design, spheres * references


def check_first_runs_cost(problem: DesignProblem, model: Any, out: Any, runs: int, *, jobs: int | None,
                          client: Any, quiet: bool) -> None:
    """The cost model's estimate (`uq.engine.runner.check_cost`) of the first `runs` runs (those not yet stored in
    `out`), spread over the operating and margin levels, before the first: one line, refused above an hour unless
    --allow-large."""
    from uq.engine.runner import ResultStore, check_cost
    from uq.problem.tasks import Task

    levels = levels_of(model.rig, [*problem.excitation, problem.margin_level()])
    each = math.ceil(max(0, runs - ResultStore(out).count()) / len(levels))
    check_cost(model, [Task.make({}, level, rep) for level in levels for rep in range(each)], jobs=jobs, client=client,
               allow_large=problem.allow_large, quiet=quiet)


def check_size(problem: DesignProblem) -> None:
    """Refuse, before any work, a design whose first batch and references exceed a study's run limit
    (`uq.problem.tasks.MAX_RUNS`) unless `allow_large`, with the estimate in the line."""
    from uq.problem.tasks import MAX_RUNS

    verify, references = first_runs(problem)
    total = verify + references
    if total > MAX_RUNS and not problem.allow_large:
        raise StudyError(f"this design would run at least {total} simulations before its search adds neighbours "
                         f"({verify} to verify the first {min(problem.candidates, len(problem.grid()))} design(s) at "
                         f"{len(problem.excitation)} levels, {problem.repetitions} repetitions; up to {references} for the "
                         f"similarity references), about {duration(total * SECONDS_PER_RUN)} on one core; a design runs at "
                         f"most {MAX_RUNS:,} without --allow-large: give fewer levels, candidates or repetitions, or pass "
                         "--allow-large")


def ranked(problem: DesignProblem, predictions: Mapping[Sphere, DesignPrediction]) -> list[Sphere]:
    """Designs by their prediction: those predicted admissible (margin to the switch at the box's worst corner of at
    least `problem.margin`) by their predicted worst case, then the others by their margin, largest first."""
    top = max(problem.excitation)
    admissible = [s for s, p in predictions.items() if p.margin(top) >= problem.margin]
    others = [s for s in predictions if s not in admissible]
    return (sorted(admissible, key=lambda s: (_finite(predictions[s].worst), _grid_order(problem, s)))
            + sorted(others, key=lambda s: (-predictions[s].margin(top), _grid_order(problem, s))))


def _finite(x: float) -> float:
    return x if math.isfinite(x) else math.inf


def _grid_order(problem: DesignProblem, s: Sphere) -> tuple[int, int, int]:
    """A design's place on the grid (material, radius, clearance), for ties."""
    def at(values: Sequence[Any], x: Any) -> int:
        return list(values).index(x) if x in values else len(values)

    return at(problem.materials, s.material), at(problem.radii, s.radius), at(problem.clearances, s.clearance)


def material_axis(problem: DesignProblem) -> list[str]:
    """The materials of the grid in the order of their density (the sphere's mass at a radius): the material axis on
    which a design has neighbours."""
    from sim.model.materials import material

    return sorted(problem.materials, key=lambda name: material(name).density)


def neighbours(problem: DesignProblem, sphere: Sphere) -> list[Sphere]:
    """The designs one grid step away from `sphere` on each axis (clearance, radius, material by density) that fit
    the cavity; none for a design off the grid (the baseline)."""
    out = []
    for axis, values in (("clearance", list(problem.clearances)), ("radius", list(problem.radii)),
                         ("material", material_axis(problem))):
        here = getattr(sphere, axis)
        if here not in values:
            return []
        k = values.index(here)
        for j in (k - 1, k + 1):
            if 0 <= j < len(values):
                other = dataclasses.replace(sphere, **{axis: values[j]})
                if problem.fits(other):
                    out.append(other)
    return out


def best_of(problem: DesignProblem, verified: Sequence[Verified]) -> list[Verified]:
    """Verified designs best first: the admissible ones by their verified worst case, then the others by their margin
    to the switch, largest first."""
    top = max(problem.excitation)
    ok = [v for v in verified if v.admissible(top, problem.margin)]
    rest = [v for v in verified if v not in ok]
    return (sorted(ok, key=lambda v: (_finite(v.worst), _grid_order(problem, v.sphere)))
            + sorted(rest, key=lambda v: (-v.margin(top), _grid_order(problem, v.sphere))))


def verification_model(problem: DesignProblem) -> Any:
    """The study model that simulates one run of a design (`uq.problem.models.IESModel`; the sphere mass m_a per task)."""
    from uq.problem.models import IESModel

    return IESModel(protocol=dict(problem.protocol), modal_file=problem.modal_file)


def verify(problem: DesignProblem, objective: Objective, spheres: Sequence[Sphere], rig: Any,
           run: Callable[[list[Any]], Mapping[Any, Any]], *, round_: int = 0,
           predictions: Mapping[Sphere, DesignPrediction] | None = None) -> list[Verified]:
    """Stage 3: every corner and the centre of the box of every design at every operating level and at the margin
    level (`DesignProblem.margin_level`), each with the problem's repetitions, through `run` (the study runner: cached
    in the design's folder, resumable)."""
    from sim.reduced.slow_flow import host_mode as mode_of
    from uq.problem.tasks import Task

    excitation = np.array([*problem.excitation, problem.margin_level()])
    levels = levels_of(rig, excitation)
    omega_1 = float(rig.omega[0])
    mode = mode_of(rig)
    boxes = {s: problem.corners(s) for s in spheres}
    tasks = [Task.make(p, L, rep) for s in spheres for p in boxes[s] for L in levels for rep in range(problem.repetitions)]
    results = run(tasks)
    out = []
    n_op = len(problem.excitation)
    for s in spheres:
        value = np.empty((len(boxes[s]), levels.size))
        se = np.zeros_like(value)
        apr = np.zeros_like(value)
        for i, p in enumerate(boxes[s]):
            for k, L in enumerate(levels):
                runs = [results[Task.make(p, L, rep)] for rep in range(problem.repetitions)]
                values = np.array([objective.of_run(r, omega_1) for r in runs])
                value[i, k] = values.mean()
                se[i, k] = values.std(ddof=1) / math.sqrt(values.size) if values.size > 1 else 0.0
                apr[i, k] = np.mean([r["outputs"].get("apr", 0.0) if not r.get("error") else 0.0 for r in runs])
        low, high = value[:-1, :n_op].min(axis=0), value[:-1, :n_op].max(axis=0)
        nominal = value[-1, :n_op]
        outside = (nominal > high + 2.0 * se[-1, :n_op]) | (nominal < low - 2.0 * se[-1, :n_op])
        onset = np.array([first_impacts(dataclasses.replace(mode, D=p["D"]), p["g"]) for p in boxes[s]])
        out.append(Verified(s, low, high, nominal, apr[:, :n_op].mean(axis=0), outside,
                            len(boxes[s]) * levels.size * problem.repetitions, point_apr=apr, point_onset=onset,
                            margin_high=float(np.max(value[:, -1])), excitation=tuple(float(x) for x in excitation),
                            prediction=(predictions or {}).get(s), round=round_))
    return out


@dataclasses.dataclass
class Search:
    """The verification rounds of a design search: the designs of each round, and why it stopped."""

    rounds: list[list[Sphere]] = dataclasses.field(default_factory=list)
    stop: str = ""


def search(problem: DesignProblem, predictor: Predictor, verify_batch: Callable[[list[Sphere], int], list[Verified]],
           screened: Screened, *, log: Callable[[str], None] = lambda line: None) -> tuple[list[Verified], Search]:
    """Stage 2 and 3, iterated: predict the spheres of the best screened designs, verify the `problem.candidates` best
    predicted designs (and the baseline), then, round by round, the unverified neighbours (`neighbours`) of the best
    verified design (`best_of`), until it has verified neighbours on every axis or the grid ends there. Returns the
    verified designs (best first) and the rounds."""
    grid = set(problem.grid())
    fitting = [screened.designs[i] for i in np.argsort(screened.worst, kind="stable")
               if np.isfinite(screened.worst[i]) and screened.designs[i] in grid]
    spheres = list(dict.fromkeys((s.radius, s.material) for s in fitting))[: problem.candidates]
    first_spheres = [s for s in fitting if (s.radius, s.material) in spheres]
    predictor.ensure(first_spheres)
    predictions = {s: predictor.predict(s) for s in first_spheres}
    batch = ranked(problem, predictions)[: problem.candidates]
    if problem.baseline is not None and problem.baseline not in batch:
        batch.append(problem.baseline)
    verified: dict[Sphere, Verified] = {}
    trail = Search()
    while batch:
        log(f"round {len(trail.rounds) + 1}: verifying {len(batch)} design(s): "
            + "; ".join(s.label() for s in batch))
        for v in verify_batch(batch, len(trail.rounds)):
            verified[v.sphere] = v
        trail.rounds.append(list(batch))
        on_grid = [v for v in verified.values() if v.sphere in grid]
        if not on_grid:
            trail.stop = "no design of the grid was verified"
            break
        best = best_of(problem, on_grid)[0]  # an off-grid baseline has no neighbours to walk to
        around = neighbours(problem, best.sphere)
        batch = [s for s in around if s not in verified]
        if not batch:
            trail.stop = (f"the best verified design ({best.sphere.label()}) has every neighbour on the grid verified"
                          if around else f"the best verified design ({best.sphere.label()}) has no neighbour on the grid")
    return best_of(problem, list(verified.values())), trail


def run_design(problem: DesignProblem, out: Any, *, jobs: int | None = 1, scheduler: str | None = None,
               resume: bool = False, progress: bool = True, figures: bool = True, client: Any = None) -> DesignResult:
    """Screen, predict, verify and write a design into the folder `out` (design.csv, design.json, design-levels.csv,
    results.nc, the figures): checks everything before any simulation; `resume` continues an interrupted design. A
    design range in which no design keeps the margin to the switch is one line (StudyError) naming the best margin;
    the verified runs stay in `out`/tasks for a rerun with --resume."""
    from pathlib import Path

    from uq.engine.runner import ResultStore, dask_client, prepare_output, run_tasks

    problem.check()
    check_size(problem)
    objective = objective_named(problem.objective)
    model = verification_model(problem)
    mode = host_mode(host_model(problem))
    g_min = min(problem.clearances) + problem.clearance_tolerance[0]
    start = first_impacts(dataclasses.replace(mode, D=min(problem.D)), g_min)
    if max(problem.excitation) < start:
        raise StudyError(f"--excitation: the structure never reaches the clearance over {micrometres(min(problem.excitation))}-"
                         f"{micrometres(max(problem.excitation))} um (no impacts, the IES does nothing); impacts begin at "
                         f"a_base = {micrometres(start)} um for g = {g_min * 1e3:.3g} mm: raise the excitation or lower the "
                         "clearance")
    verify_runs, reference_runs = first_runs(problem)
    if progress:
        sys.stderr.write(f"ies design: at least {verify_runs} runs to verify the first designs and up to {reference_runs} "
                         "for the similarity references; each further round verifies the best design's neighbours\n")
    screened = screen_designs(problem, mode)
    with dask_client(scheduler, client) as connected:
        model = model.with_rig()
        model.warm_up()
        check_first_runs_cost(problem, model, Path(out), verify_runs + reference_runs, jobs=jobs, client=connected,
                              quiet=not progress)
        folder = prepare_output(Path(out), resume=resume, study=("design", design_key(problem, model)))
        model.warm_up()
        store = ResultStore(folder)

        def run(tasks: list[Any]) -> Mapping[Any, Any]:
            return run_tasks(model, tasks, problem.seed, store, jobs=jobs, scheduler=None, progress=progress,
                             client=connected)[0]

        rig = model.rig
        predictor = Predictor(problem, objective, rig, run)

        def verify_batch(spheres: list[Sphere], round_: int) -> list[Verified]:
            predictor.ensure(spheres)
            return verify(problem, objective, spheres, rig, run, round_=round_,
                          predictions={s: predictor.predict(s) for s in spheres})

        log = (lambda line: sys.stderr.write(f"ies design: {line}\n")) if progress else (lambda line: None)
        verified, trail = search(problem, predictor, verify_batch, screened, log=log)
    top = max(problem.excitation)
    if not verified[0].admissible(top, problem.margin):
        best = verified[0]
        raise StudyError(f"no design keeps a margin of {problem.margin:.0%} to the switch: the best, "
                         f"{best.sphere.label()}, has {best.margin(top):.0%} (it switches at "
                         f"{micrometres(best.switch_worst())} um at the box's worst corner, the range ends at "
                         f"{micrometres(top)} um); lower the top of --excitation, allow larger clearances or a lower "
                         f"--margin (the runs are kept in {folder}: rerun with --resume)")
    result = DesignResult(problem, screened, verified, folder, levels_of(rig, problem.excitation),
                          no_absorber(rig, problem.excitation, min(problem.D)), [], objective=objective,
                          similarity=predictor.describe(), rounds=trail.rounds, stop=trail.stop,
                          predictions={s: predictor.predict(s) for s in screened.designs
                                       if predictor.laws.get((s.radius, s.material)) is not None},
                          reference_runs=predictor.runs, omega_1=float(mode.omega))
    result.files.extend(write_design(result, mode))
    if figures:
        from uq.design.figures import plot_design_curves, plot_design_map

        for suffix in ("png", "pdf"):
            result.files.append(plot_design_map(result, folder / f"design-map.{suffix}"))
            result.files.append(plot_design_curves(result, folder / f"design-curves.{suffix}"))
    return result


#: settings that change how many designs are verified, not what a run computes: a design resumed with another value
#: reuses every finished run
UNKEYED = ("candidates", "margin", "allow_large")


def design_key(problem: DesignProblem, model: Any) -> str:
    """SHA-256 of the problem (but UNKEYED) and the model's settings: `--resume` continues only the same design."""
    import hashlib
    import json

    from uq.engine.runner import describe_model

    settings = {k: v for k, v in dataclasses.asdict(problem).items() if k not in UNKEYED}
    text = json.dumps({"problem": settings, "model": describe_model(model)}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()
