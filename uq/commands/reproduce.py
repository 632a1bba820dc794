"""`ies reproduce NAME|all`: the paper's figures, each from its shipped study file, with the crater calibration
as k_H's upper bound (Sect. 4.1)."""
from __future__ import annotations

import argparse
import contextlib
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable, Iterator

from sim.common.options import positive_int
from uq.commands.study import JOBS_HELP, engine

#: the calibration `ies reproduce` runs: no arguments, returns the JSON object of `ies calibrate --json`
Calibrate = Callable[[], dict]


REPRODUCE_HELP = ("reproduce the paper's Figs. 5 and 6 (nominal response), 7 and 8 (uncertainty of D, g, k_H) and "
                  "D.2 and D.3 (impacts per period, restitution)")


def add_reproduce_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies reproduce`."""
    from uq.outputs.paper_figures import PAPER_FIGURES

    rows = PAPER_FIGURES.values()
    parser.add_argument("figure", choices=(*PAPER_FIGURES, "all"),
                        help="which figure(s): " + ", ".join(f"{row.name} ({row.help}{'' if row.in_all else '; not in all'})"
                                                             for row in rows) + ", all")
    parser.add_argument("--quick", action="store_true",
                        help="reduced protocol (fewer levels, frequencies, repetitions, shorter holds); same trends")
    parser.add_argument("--out", type=Path, default=Path("ies-out/reproduce"), metavar="DIR",
                        help="output folder (default ies-out/reproduce)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://host:8786")
    parser.add_argument("--resume", action="store_true", help="continue an interrupted reproduction in --out")
    from uq.engine.cluster import add_cluster_arguments

    add_cluster_arguments(parser)
    calib = parser.add_mutually_exclusive_group()
    calib.add_argument("--calibration", type=Path, metavar="FILE",
                       help="use this `ies calibrate --json` output instead of running the calibration")
    calib.add_argument("--no-calibration", action="store_true", help="keep Table 2's k_H bounds")
    parser.add_argument("--model", type=Path, metavar="FILE",
                        help="run the studies on this modal-model file (`ies modes --save`) instead of the built-in rig")
    parser.add_argument("--integrator", metavar="NAME",
                        help="override the study files' integrator (ode3 = the paper's scheme, exact = free flight)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--allow-large", action="store_true",
                        help="run when the cost estimate of the figures (measured here before the first run) exceeds "
                             "an hour (refused by default; the paper's protocol takes longer than --quick)")


def study_file(figure: str, quick: bool) -> Path:
    """The study file of a figure (`uq.outputs.paper_figures.PaperFigure.study_file`)."""
    from uq.outputs.paper_figures import PAPER_FIGURES

    return PAPER_FIGURES[figure].study_file(quick)


def run_calibration(calibrate: Calibrate, out: Path) -> dict | None:
    """Run the calibration and keep its JSON object in out/calibration.json (Sect. 4.1).

    Returns None after one warning line when it fails: the calibration is optional, and whatever stops it
    (a bad scan, a solver that does not converge, ...) leaves the studies on Table 2's k_H bounds.
    """
    from sim.common.files import dumps, write_text

    try:
        data = calibrate()
    except Exception as exc:  # noqa: BLE001 - any failure falls back to Table 2, named in the warning
        sys.stderr.write(f"warning: the calibration failed ({type(exc).__name__}: {exc}); using Table 2's k_H bounds\n")
        return None
    write_text(out / "calibration.json", dumps(data))
    return data


def reproduce_command(args: argparse.Namespace, *, calibrate: Calibrate) -> int:
    """`ies reproduce`: check every study first, connect to the cluster once, then calibrate (for Figs. 7-8, with
    `calibrate` unless --calibration FILE or --no-calibration) and run."""
    from uq.engine.runner import check_writable, dask_client
    from uq.outputs.paper_figures import figures_of_all
    from uq.methods import load_study
    from uq.problem.space import calibrated_k_H

    figures = figures_of_all() if args.figure == "all" else (args.figure,)
    studies = [load_study(study_file(f, args.quick)) for f in figures]
    if args.integrator:
        studies = [replace(s, protocol={**s.protocol, "integrator": args.integrator}) for s in studies]
    if args.model is not None:
        studies = [replace(s, modal_model=args.model) for s in studies]
    models = [s.make_model() for s in studies]
    for model in models:
        model.check()  # bad settings (e.g. an unknown integrator) fail here, before anything is written
    calibration = None
    if args.calibration is not None:  # a bad file fails here too
        calibration = {"k_H": calibrated_k_H(args.calibration), "source": str(args.calibration)}
    with engine(args, None) as batch, dask_client(args.scheduler, batch) as client, _made(args.out):
        # connected (or the batch cluster started) once, first: a bad address leaves nothing behind
        check_writable(args.out)
        from sim.common.folder_lock import locked
        from sim.integration.integrators import warm_up_all

        with locked(args.out):  # one reproduction per --out: its calibration, summary and index beside the figures
            # every kernel any study's workers will call, compiled here once, before the first bar
            warm_up_all(pair for model in models if hasattr(model, "kernel_variants") for pair in model.kernel_variants())
            check_cost(args, figures, studies, calibration, client)
            return _reproduce(args, figures, studies, client, calibrate, calibration)


@contextlib.contextmanager
def _made(folder: Path) -> Iterator[None]:
    """Remove `folder` again when it is made here and the command ends before anything is written into it (refused
    by the cost estimate, say)."""
    made = not folder.exists()
    try:
        yield
    except BaseException:
        if made and folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()
        raise


def check_cost(args: argparse.Namespace, figures: tuple[str, ...], studies: list, calibration: dict | None,
               client: Any) -> None:
    """The cost of every figure's runs together, estimated before the first (`sim.stepped_sine.cost`: a probe of each
    study's protocol here): one line, refused above an hour unless --allow-large. With --resume only the runs not
    stored count (an interval study's k_H bound from the calibration given or kept in OUT/calibration.json)."""
    from collections import Counter

    from sim.stepped_sine.cost import check_estimate, estimate
    from uq.engine.runner import pending_tasks, workers_for
    from uq.problem.space import calibrated_k_H
    from uq.problem.study import with_calibration
    from uq.problem.tasks import Task

    kept = args.out / "calibration.json"
    if calibration is None and args.resume and kept.is_file() and not args.no_calibration:
        calibration = {"k_H": calibrated_k_H(kept)}
    runs_at: Counter = Counter()
    per_run: dict = {}
    for figure, study in zip(figures, studies):
        if calibration is not None and study.kind == "interval" and "k_H" in [p.name for p in study.space.varied]:
            study = with_calibration(study, calibrated_k_H(calibration))
        model = study.make_model()
        if not hasattr(model, "seconds_per_run") or study.method.substudies(study):
            continue  # the series (Figs. 11, C.1, not in `all`) say their own estimate as each part starts
        model = model.with_rig()
        tasks = [Task.make(p, level, rep) for p in study.method.plan(study).points for level in study.levels
                 for rep in range(study.repetitions)]
        if args.resume:
            tasks = pending_tasks(model, tasks, study.seed, args.out / figure)
        levels = Counter(task.level for task in tasks)
        seconds = model.seconds_per_run(list(levels), len(tasks)) if tasks else None
        if seconds is None:
            continue
        runs_at.update({(figure, level): n for level, n in levels.items()})
        per_run.update({(figure, level): seconds[level] for level in levels})
    if runs_at:
        serial = estimate(runs_at, per_run).serial_s
        check_estimate(estimate(runs_at, per_run, workers=workers_for(args.jobs, serial, client)),
                       "run --quick (minutes), one figure at a time, or on a cluster (--cluster)",
                       allow_large=args.allow_large)


def _reproduce(args: argparse.Namespace, figures: tuple[str, ...], studies: list, client: Any,
               calibrate: Calibrate, calibration: dict | None) -> int:
    """Calibration (the given one, or run unless disabled) when an interval study needs it, then each figure's
    study, its figures and its table; then OUT/summary.txt, each figure's table.txt and OUT/index.md
    (`uq.outputs.reproduce_report`)."""
    from sim.common.files import report_written
    from uq.outputs.reproduce_report import captured_stdout, write_index, write_summary

    calibrated = False
    sections: list[tuple[str, str]] = []
    for figure, study in zip(figures, studies):
        with captured_stdout() as printed:
            calibration, calibrated = _reproduce_figure(args, figure, study, client, calibrate, calibration,
                                                        calibrated)
        sections.append((figure, printed.copy.getvalue()))
    command = " ".join(["ies reproduce", args.figure, *(["--quick"] if args.quick else []), "--out", str(args.out)])
    report_written([*write_summary(args.out, command, sections), write_index(args.out)])
    return 0


def _reproduce_figure(args: argparse.Namespace, figure: str, study: Any, client: Any, calibrate: Calibrate,
                      calibration: dict | None, calibrated: bool) -> tuple[dict | None, bool]:
    """One figure of `ies reproduce`: the calibration first if its study varies k_H and none was made yet, then
    the study, its figures and its table. Returns (the calibration, whether it was made)."""
    from uq.engine.execution import run_study
    from uq.outputs.paper_figures import PAPER_FIGURES
    from uq.problem.space import K_H_STAR, calibrated_k_H
    from uq.problem.study import with_calibration

    out = args.out
    row = PAPER_FIGURES[figure]
    if study.kind == "interval" and "k_H" in [p.name for p in study.space.varied]:  # calibrated once, first
        if not calibrated and calibration is None and not args.no_calibration:
            calibration = run_calibration(calibrate, out)
        if calibration is not None:
            k_cal = calibrated_k_H(calibration)
            study = with_calibration(study, k_cal)  # one line if k_cal < k_H*
            if not calibrated:
                print(f"calibrated k_H = {k_cal:.4g} N/m^1.5 = {k_cal / K_H_STAR:.3f} k_H* (upper bound of k_H)")
        calibrated = True
    folder = out / figure
    print(f"{figure}: {study.source} -> {folder}/")
    result = run_study(study, out=folder, jobs=args.jobs, client=client, resume=args.resume, progress=not args.quiet,
                       allow_large=args.allow_large, paper_figure=figure)
    paths = study.method.figures(result.folder)
    if row.traced:
        from uq.methods.response import series_traces

        paths += series_traces(study, folder, row.traced)
    s = result.summary
    print(f"{figure}: {s['tasks']} runs ({s['ran']} run now), {s['failed_runs']} failed, "
          f"{s['wall_time_s']:.1f} s; figures: {', '.join(p.name for p in paths)}")
    study.method.report(folder, s, figure)
    return calibration, calibrated
