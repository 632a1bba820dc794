"""The design search of `ies design`: screening by the slow flow, prediction by the similarity law of the full model,
verification by stepped-sine simulation at the corners of the uncertainty box, iterated over the best verified
design's neighbours until the best has verified neighbours on every side, the ranking of the best two settled by
extra repetitions at the cells that decide their worst cases (`settle`, `uq.design.uncertainty`), and the
recommendation (the best admissible verified design)."""
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
    Design,
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

    from sim.reduced.slow_flow import screen

    started = time.perf_counter()
    a_base = np.asarray(problem.excitation, dtype=float)
    g = np.asarray(problem.clearances, dtype=float)
    R = np.asarray(problem.radii, dtype=float)
    designs, tips, regimes, switches = [], [], [], []
    for name in problem.materials:
        masses = np.array([Design(0.0, float(Ri), name, problem.wall).mass for Ri in R])  # sim.model.sphere's
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
        designs += [Design(float(gi), float(Ri), name, problem.wall) for Ri in R for gi in g]
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


def check_size(problem: DesignProblem, seconds_per_run: float = SECONDS_PER_RUN) -> None:
    """Refuse, before any work, a design whose first batch and references exceed a study's run limit
    (`uq.problem.tasks.MAX_RUNS`) unless `allow_large`, with the estimate in the line (`seconds_per_run` on one core:
    the host's, `IESModel.typical_seconds_per_run`, where the caller has it)."""
    from uq.problem.tasks import MAX_RUNS

    verify, references = first_runs(problem)
    total = verify + references
    if total > MAX_RUNS and not problem.allow_large:
        raise StudyError(f"this design would run at least {total} simulations before its search adds neighbours "
                         f"({verify} to verify the first {min(problem.candidates, len(problem.grid()))} design(s) at "
                         f"{len(problem.excitation)} levels, {problem.repetitions} repetitions; up to {references} for the "
                         f"similarity references), about {duration(total * seconds_per_run)} on one core; a design runs at "
                         f"most {MAX_RUNS:,} without --allow-large: give fewer levels, candidates or repetitions, or pass "
                         "--allow-large")


def ranked(problem: DesignProblem, predictions: Mapping[Design, DesignPrediction]) -> list[Design]:
    """Designs by their prediction: those predicted admissible (margin to the switch at the box's worst corner of at
    least `problem.margin`) by their predicted worst case, then the others by their margin, largest first."""
    top = max(problem.excitation)
    admissible = [s for s, p in predictions.items() if p.margin(top) >= problem.margin]
    others = [s for s in predictions if s not in admissible]
    return (sorted(admissible, key=lambda s: (_finite(predictions[s].worst), _grid_order(problem, s)))
            + sorted(others, key=lambda s: (-predictions[s].margin(top), _grid_order(problem, s))))


def _finite(x: float) -> float:
    return x if math.isfinite(x) else math.inf


def _grid_order(problem: DesignProblem, s: Design) -> tuple[int, int, int]:
    """A design's place on the grid (material, radius, clearance), for ties."""
    def at(values: Sequence[Any], x: Any) -> int:
        return list(values).index(x) if x in values else len(values)

    return at(problem.materials, s.material), at(problem.radii, s.radius), at(problem.clearances, s.clearance)


def material_axis(problem: DesignProblem) -> list[str]:
    """The materials of the grid in the order of their density (the sphere's mass at a radius): the material axis on
    which a design has neighbours."""
    from sim.model.materials import material

    return sorted(problem.materials, key=lambda name: material(name).density)


def neighbours(problem: DesignProblem, sphere: Design) -> list[Design]:
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
    return (sorted(ok, key=lambda v: (_finite(v.worst), _grid_order(problem, v.design)))
            + sorted(rest, key=lambda v: (-v.margin(top), _grid_order(problem, v.design))))


def verification_model(problem: DesignProblem) -> Any:
    """The study model that simulates one run of a design (`uq.problem.models.IESModel`; the sphere mass m_a per task)."""
    from uq.problem.models import IESModel

    return IESModel(protocol=dict(problem.protocol), modal_file=problem.modal_file)


#: the deciding cells of the recommendation hold at least this many times the design's repetitions (`settle`)
SETTLE_MIN = 2
#: where the runner-up's interval overlaps the recommendation's, the deciding cells of both gain the design's
#: repetitions, round by round, up to this many times them (15 runs a cell with --reps 3): the budget
SETTLE_MAX = 5


def verify(problem: DesignProblem, objective: Objective, designs: Sequence[Design], rig: Any,
           run: Callable[[list[Any]], Mapping[Any, Any]], *, round_: int = 0,
           predictions: Mapping[Design, DesignPrediction] | None = None,
           reps_at: Mapping[Design, Mapping[tuple[int, int], int]] | None = None) -> list[Verified]:
    """Stage 3: every corner and the centre of the box of every design at every operating level and at the margin
    level (`DesignProblem.margin_level`), each with the problem's repetitions (more at the cells `reps_at` names: the
    repetition indices beyond the problem's, so other seeds), through `run` (the study runner: cached in the design's
    folder, resumable). Each design's worst case comes with its interval and deciding cells (`uq.design.uncertainty`)."""
    from sim.reduced.slow_flow import host_mode as mode_of
    from uq.design.uncertainty import worst_case
    from uq.problem.tasks import Task

    excitation = np.array([*problem.excitation, problem.margin_level()])
    levels = levels_of(rig, excitation)
    omega_1 = float(rig.omega[0])
    mode = mode_of(rig)
    n_op = len(problem.excitation)
    boxes = {s: problem.corners(s) for s in designs}

    def count(s: Design, i: int, k: int) -> int:
        return int((reps_at or {}).get(s, {}).get((i, k), problem.repetitions))

    tasks = [Task.make(p, L, rep) for s in designs for i, p in enumerate(boxes[s]) for k, L in enumerate(levels)
             for rep in range(count(s, i, k))]
    results = run(tasks)
    out = []
    for s in designs:
        box = boxes[s]
        value = np.empty((len(box), levels.size))
        se = np.zeros_like(value)
        apr = np.zeros_like(value)
        counts = np.zeros(value.shape, dtype=int)
        cells: list[np.ndarray] = []
        for i, p in enumerate(box):
            for k, L in enumerate(levels):
                runs = [results[Task.make(p, L, rep)] for rep in range(count(s, i, k))]
                values = np.array([objective.of_run(r, omega_1) for r in runs])
                counts[i, k] = values.size
                value[i, k] = values.mean()
                se[i, k] = values.std(ddof=1) / math.sqrt(values.size) if values.size > 1 else 0.0
                apr[i, k] = np.mean([r["outputs"].get("apr", 0.0) if not r.get("error") else 0.0 for r in runs])
                if k < n_op:
                    cells.append(values)
        low, high = value[:-1, :n_op].min(axis=0), value[:-1, :n_op].max(axis=0)
        nominal = value[-1, :n_op]
        outside = (nominal > high + 2.0 * se[-1, :n_op]) | (nominal < low - 2.0 * se[-1, :n_op])
        onset = np.array([first_impacts(dataclasses.replace(mode, D=p["D"]), p["g"]) for p in box])
        worst = worst_case(cells, seed=problem.seed)
        deciding = tuple(divmod(c, n_op) for c in worst.deciding)  # cell index -> (box point, operating level)
        out.append(Verified(s, low, high, nominal, apr[:, :n_op].mean(axis=0), outside, int(counts.sum()),
                            point_apr=apr, point_onset=onset, margin_high=float(np.max(value[:, -1])),
                            excitation=tuple(float(x) for x in excitation), prediction=(predictions or {}).get(s),
                            round=round_, worst_interval=worst.interval, deciding=deciding,
                            point_runs=counts))
    return out


@dataclasses.dataclass
class Settling:
    """How the recommendation's ranking against the runner-up was settled (`settle`): the two designs (None where
    there is no admissible runner-up), whether their intervals still overlap, the most runs a deciding cell holds, and
    the budget (runs a cell may reach)."""

    winner: Design | None = None
    runner_up: Design | None = None
    overlap: bool = False
    most_runs: int = 0
    budget: int = 0

    def text(self, verified: Mapping[Design, Verified], shown: Callable[[float], str], unit: str) -> str:
        """The ranking in words: settled, or within the noise after the budget."""
        if self.winner is None or self.runner_up is None:
            return "no admissible runner-up"
        r = verified[self.runner_up]
        lo, hi = r.worst_interval
        other = (f"the runner-up {r.design.label()} ({shown(r.worst)} {unit}, interval {shown(lo)}-{shown(hi)} "
                 f"{unit})")
        if not self.overlap:
            return f"ranking settled: {other} lies apart ({self.most_runs} runs at the deciding cells)"
        return (f"ranking within the noise: {other} overlaps it after {self.most_runs} runs at the deciding cells "
                f"(the budget, {self.budget}): either will do")


def settle(problem: DesignProblem, verified: dict[Design, Verified], reps_at: dict[Design, dict[tuple[int, int], int]],
           reverify: Callable[[list[Design]], list[Verified]],
           log: Callable[[str], None] = lambda line: None) -> Settling:
    """Extra repetitions where the ranking needs them: the recommendation's deciding cells get SETTLE_MIN times the
    repetitions; while the runner-up's interval overlaps the recommendation's, the deciding cells of both gain the
    repetitions again, up to SETTLE_MAX times them (the budget). `reverify` verifies designs again with `reps_at` (the
    finished runs are cached); `verified` is updated in place. The order may change on the way (a verified design is
    ranked by its pooled worst case, and a new almost periodic run counts): each pass re-ranks."""
    from uq.design.uncertainty import overlap

    reps = problem.repetitions
    budget = SETTLE_MAX * reps
    top = max(problem.excitation)
    while True:
        ok = [v for v in best_of(problem, list(verified.values())) if v.admissible(top, problem.margin)]
        if not ok:
            return Settling(budget=budget)
        winner, runner = ok[0], (ok[1] if len(ok) > 1 else None)
        apart = runner is None or not overlap(winner.worst_interval, runner.worst_interval)
        want: dict[Design, int] = {}
        if any(reps_at.get(winner.design, {}).get(c, reps) < SETTLE_MIN * reps for c in winner.deciding):
            want[winner.design] = SETTLE_MIN * reps
        if not apart:
            for v in (winner, runner):
                held = [reps_at.get(v.design, {}).get(c, reps) for c in v.deciding]
                if held and min(held) < budget:
                    want[v.design] = min(min(held) + reps, budget)
        if not want:
            cells = [reps_at.get(v.design, {}).get(c, reps) for v in (winner, runner) if v is not None for c in v.deciding]
            return Settling(winner.design, None if runner is None else runner.design, not apart, max(cells, default=reps),
                            budget)
        for d, n in want.items():
            cells = {c: max(n, reps_at.get(d, {}).get(c, reps)) for c in verified[d].deciding}
            reps_at.setdefault(d, {}).update(cells)
        log(("the runner-up's interval overlaps the recommendation's: " if not apart else "")
            + "more repetitions at the deciding cells of " + "; ".join(d.label() for d in want))
        for v in reverify(list(want)):
            verified[v.design] = v


@dataclasses.dataclass
class Search:
    """The verification rounds of a design search: the designs of each round, why it stopped, how the ranking of the
    best two was settled (`settle`) and the extra repetitions it verified."""

    rounds: list[list[Design]] = dataclasses.field(default_factory=list)
    stop: str = ""
    settling: Settling = dataclasses.field(default_factory=Settling)
    reps_at: dict[Design, dict[tuple[int, int], int]] = dataclasses.field(default_factory=dict)


def predicted_refusal(problem: DesignProblem, predictions: Mapping[Design, DesignPrediction | None]) -> str | None:
    """The line refusing a design before any verification, when the similarity law predicts no design keeping the
    margin (with the best predicted margins and what fits the block); None when one does."""
    top = max(problem.excitation)
    known = {s: p for s, p in predictions.items() if p is not None}
    if not known or any(p.margin(top) >= problem.margin for p in known.values()):
        return None
    best = sorted(known, key=lambda s: -known[s].margin(top))[:3]
    margins = "; ".join(f"{s.label()}: {known[s].margin(top):.0%} (switch at {micrometres(known[s].switch_worst)} um)"
                        for s in best)
    return (f"the similarity law predicts no design keeping a margin of {problem.margin:.0%} to the switch above "
            f"{micrometres(top)} um at the box's worst corner; the best predicted: {margins}. {problem.fitting_text()}. "
            "Lower the top of --excitation, allow larger clearances or a lower --margin (nothing was verified; the "
            "similarity references are kept for --resume)")


def search(problem: DesignProblem, predictor: Predictor,
           verify_batch: Callable[[list[Design], int, Mapping[Design, Mapping[tuple[int, int], int]]], list[Verified]],
           screened: Screened, *, log: Callable[[str], None] = lambda line: None) -> tuple[list[Verified], Search]:
    """Stage 2 and 3, iterated: predict the spheres of the best screened designs, verify the `problem.candidates` best
    predicted designs (and the baseline), then, round by round, the unverified neighbours (`neighbours`) of the best
    verified design (`best_of`), until it has verified neighbours on every axis or the grid ends there; after each
    round the ranking of the best two is settled by extra repetitions (`settle`). Refuses (StudyError, before any
    verification) when the law predicts no design keeping the margin, every fitting sphere predicted. Returns the
    verified designs (best first) and the search."""
    grid = set(problem.grid())
    fitting = [screened.designs[i] for i in np.argsort(screened.worst, kind="stable")
               if np.isfinite(screened.worst[i]) and screened.designs[i] in grid]
    spheres = list(dict.fromkeys((s.radius, s.material) for s in fitting))[: problem.candidates]
    first_spheres = [s for s in fitting if (s.radius, s.material) in spheres]
    predictor.ensure(first_spheres)
    predictions = {s: predictor.predict(s) for s in first_spheres}
    if predicted_refusal(problem, predictions) is not None and len(first_spheres) < len(fitting):
        predictor.ensure(fitting)  # every fitting sphere before refusing
        predictions = {s: predictor.predict(s) for s in fitting}
    refusal = predicted_refusal(problem, predictions)
    if refusal is not None:
        raise StudyError(refusal)
    batch = ranked(problem, predictions)[: problem.candidates]
    if problem.baseline is not None and problem.baseline not in batch:
        batch.append(problem.baseline)
    verified: dict[Design, Verified] = {}
    trail = Search()

    def reverify(designs: list[Design]) -> list[Verified]:
        out = []
        for r in sorted({verified[d].round for d in designs}):  # each keeps the round that first verified it
            out += verify_batch([d for d in designs if verified[d].round == r], r, trail.reps_at)
        return out

    while batch:
        log(f"round {len(trail.rounds) + 1}: verifying {len(batch)} design(s): "
            + "; ".join(s.label() for s in batch))
        for v in verify_batch(batch, len(trail.rounds), trail.reps_at):
            verified[v.design] = v
        trail.rounds.append(list(batch))
        trail.settling = settle(problem, verified, trail.reps_at, reverify, log)
        on_grid = [v for v in verified.values() if v.design in grid]
        if not on_grid:
            trail.stop = "no design of the grid was verified"
            break
        best = best_of(problem, on_grid)[0]  # an off-grid baseline has no neighbours to walk to
        around = neighbours(problem, best.design)
        batch = [s for s in around if s not in verified]
        if not batch:
            trail.stop = (f"the best verified design ({best.design.label()}) has every neighbour on the grid verified"
                          if around else f"the best verified design ({best.design.label()}) has no neighbour on the grid")
    return best_of(problem, list(verified.values())), trail


def run_design(problem: DesignProblem, out: Any, *, jobs: int | None = 1, scheduler: str | None = None,
               resume: bool = False, progress: bool = True, figures: bool = True, client: Any = None) -> DesignResult:
    """Screen, predict, verify and write a design into the folder `out` (design.csv, design.json, design-levels.csv,
    results.nc, the figures): checks everything before any simulation; `resume` continues an interrupted design. Where
    the similarity law already predicts no design keeping the margin, one line (StudyError) before any verification;
    where no verified design keeps it, the result carries the refusal (`DesignResult.refusal`) and its files mark every
    verified design not admissible (no figures); the runs stay in `out`/tasks for a rerun with --resume."""
    from pathlib import Path

    from uq.engine.runner import ResultStore, dask_client, prepare_output, run_tasks

    problem.check()
    model = verification_model(problem)
    check_size(problem, model.typical_seconds_per_run())
    objective = objective_named(problem.objective)
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
        store = ResultStore(folder)

        def run(tasks: list[Any]) -> Mapping[Any, Any]:
            return run_tasks(model, tasks, problem.seed, store, jobs=jobs, scheduler=None, progress=progress,
                             client=connected)[0]

        rig = model.rig
        predictor = Predictor(problem, objective, rig, run)

        def verify_batch(designs: list[Design], round_: int,
                         reps_at: Mapping[Design, Mapping[tuple[int, int], int]]) -> list[Verified]:
            predictor.ensure(designs)
            return verify(problem, objective, designs, rig, run, round_=round_,
                          predictions={s: predictor.predict(s) for s in designs}, reps_at=reps_at)

        log = (lambda line: sys.stderr.write(f"ies design: {line}\n")) if progress else (lambda line: None)
        verified, trail = search(problem, predictor, verify_batch, screened, log=log)
    top = max(problem.excitation)
    result = DesignResult(problem, screened, verified, folder, levels_of(rig, problem.excitation),
                          no_absorber(rig, problem.excitation), [], objective=objective,
                          similarity=predictor.describe(), rounds=trail.rounds, stop=trail.stop,
                          predictions={s: predictor.predict(s) for s in screened.designs
                                       if predictor.laws.get((s.radius, s.material)) is not None},
                          reference_runs=predictor.runs, omega_1=float(mode.omega), settling=trail.settling,
                          host=host_summary(rig))
    admissible = verified[0].admissible(top, problem.margin)
    if not admissible:
        best = verified[0]
        result.refusal = (f"no verified design keeps a margin of {problem.margin:.0%} to the switch: the best, "
                          f"{best.design.label()}, has {best.margin(top):.0%} (it switches at "
                          f"{micrometres(best.switch_worst())} um at the box's worst corner, the range ends at "
                          f"{micrometres(top)} um). {problem.fitting_text()}. Lower the top of --excitation, allow "
                          f"larger clearances or a lower --margin (every verified design is in {folder}/design.csv, "
                          "marked not admissible; the runs are kept: rerun with --resume)")
    result.files.extend(write_design(result, mode))
    if figures and admissible:
        from uq.design.figures import plot_design_curves, plot_design_map

        for suffix in ("png", "pdf"):
            result.files.append(plot_design_map(result, folder / f"design-map.{suffix}"))
            result.files.append(plot_design_curves(result, folder / f"design-curves.{suffix}"))
    return result


def host_summary(model: Any) -> dict[str, Any]:
    """What design.json says of the host beside its mode 1: its nominal D_1* and damping interval with their source,
    its wall material (`sim.cli.host_data`), and the normalisation (D*, g*) of every level and a / a_noabs*."""
    from sim.cli import host_data
    from sim.model.system import Nominal

    nominal = Nominal.of(model)
    return {**host_data(model), "normalisation": {**nominal.describe(), "text": nominal.text()}}


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
