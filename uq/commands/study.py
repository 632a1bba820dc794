"""`ies interval`, `ies sobol`, `ies response`: run a study file (Sects. 5.2-5.4, Figs. 5-8), and the options every
study command shares (--out, --jobs, --scheduler, --cluster, --resume)."""
from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import Any, Iterator

from sim.common.options import positive_int
from uq.errors import StudyError

INTERVAL_HELP = "interval bands of the resonant response level for D, g, k_H (paper Sect. 5.4, Figs. 7-8)"


SOBOL_HELP = "Sobol' sensitivity indices of the resonant response level per excitation level (SALib)"


RESPONSE_HELP = ("frequency responses and resonant levels of the nominal point over the excitation levels, run as a "
                 "resumable study (paper Sects. 5.2-5.3, Figs. 5-6)")


JOBS_HELP = ("local worker processes (1 runs in this process; default: the first run is timed here, then one worker per "
             "CPU core if the rest takes longer than starting the workers, else serially; more than the cores warns)")


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """--out, --jobs, --scheduler, --cluster and its options (`uq.engine.cluster`), --resume, --no-figures, --quiet."""
    from uq.engine.cluster import add_cluster_arguments

    parser.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: the study's [study] output)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on a Dask cluster, e.g. tcp://host:8786 (needs dask.distributed)")
    parser.add_argument("--resume", action="store_true",
                        help="continue a study in --out: reuse finished tasks, run only the missing ones")
    parser.add_argument("--no-figures", action="store_true", help="write the data only")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_cluster_arguments(parser)


def add_interval_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies interval`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"interval\")")
    add_run_arguments(parser)


def add_sobol_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies sobol`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"sobol\")")
    parser.add_argument("--n", type=positive_int, metavar="N",
                        help="Saltelli's base sample size, a power of two (default: [sobol] n)")
    parser.add_argument("--method", choices=("saltelli", "pce"),
                        help="Saltelli's sampling (the reference) or a polynomial-chaos surrogate (default: [sobol] method)")
    parser.add_argument("--points", type=positive_int, metavar="N",
                        help="pce: design points of the surrogate (default: [sobol] points, else 3 per polynomial "
                             "term, rounded up to a power of 2)")
    parser.add_argument("--degree", type=positive_int, metavar="P",
                        help="pce: total polynomial degree (default: [sobol] degree, else 2)")
    add_run_arguments(parser)


def add_response_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies response`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"response\")")
    add_run_arguments(parser)


def interval_command(args: argparse.Namespace) -> int:
    """`ies interval`: the study's interval bands (Sect. 5.4), then Figs. 7-8; prints the bands."""
    from uq.engine.execute import run_interval_study
    from uq.outputs.paper_figures import interval_figures

    study = _load_study(args.study, "interval")
    with engine(args, study.cluster) as client:
        result = run_interval_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                    progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else interval_figures(result.folder))
    print_interval_result(result.folder, result.summary, study.name)
    return 0


def sobol_command(args: argparse.Namespace) -> int:
    """`ies sobol`: the study's Sobol' indices (SALib, or a PCE surrogate), then their figure; prints the indices and
    the noise (and the surrogate's fit)."""
    from uq.engine.execute import run_sobol_study
    from uq.outputs.figures import sobol_figure
    from uq.outputs.results import sobol_table
    from uq.problem.study import with_sobol_method

    study = with_sobol_method(_load_study(args.study, "sobol"), args.method, args.points, args.degree)
    if study.sobol_method == "pce" and args.n is not None:
        raise StudyError("--n is Saltelli's base sample size; the surrogate's design size is --points")
    with engine(args, study.cluster) as client:
        result = run_sobol_study(study, out=args.out, n=args.n, jobs=args.jobs, scheduler=args.scheduler,
                                 resume=args.resume, progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else sobol_figure(result.folder))
    print(sobol_table(result.folder))
    return 0


def response_command(args: argparse.Namespace) -> int:
    """`ies response`: the study's frequency responses and resonant levels (Sects. 5.2-5.3), then Figs. 5-6."""
    from uq.engine.execute import run_response_study
    from uq.outputs.paper_figures import response_figures

    study = _load_study(args.study, "response")
    with engine(args, study.cluster) as client:
        result = run_response_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                    progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else response_figures(result.folder))
    print_response_result(result.folder, study.name)
    return 0


@contextlib.contextmanager
def engine(args: argparse.Namespace, table: Any) -> Iterator[Any]:
    """The Dask client of a batch cluster when --cluster or the study's [cluster] table asks for one (started
    here, closed on exit: `uq.engine.cluster.open_cluster`), else None (--jobs or --scheduler, as the runner does)."""
    from uq.engine.cluster import cluster_settings, open_cluster

    settings = cluster_settings(args, table)
    if settings is None:
        yield None
        return
    with open_cluster(settings) as client:
        yield client


def _load_study(path: Path, kind: str) -> Any:
    """The study file, refused (one line) when it is of another kind."""
    from uq.errors import StudyError
    from uq.problem.study import load_study

    study = load_study(path)
    if study.kind != kind:
        raise StudyError(f"{path} is a '{study.kind}' study; run it with `ies {study.kind}`")
    return study


def print_files(folder: Path, paths: list[Path]) -> None:
    """Where the results are and the name of every file written there, on stdout (every study command and design)."""
    print(f"results in {folder}/")
    for path in paths:
        print(f"  {path.name}")


def _report(result: Any, figures: list[Path]) -> None:
    """Where the results are, and how many runs took how long, on stdout."""
    print_files(result.folder, [*result.files, *figures])
    s = result.summary
    print(f"{s['tasks']} runs ({s['ran']} run now, {s['reused']} reused), {s['failed_runs']} failed, "
          f"{s['wall_time_s']:.1f} s")
    if result.warnings:
        print(f"{len(result.warnings)} warning(s), listed in study.json", file=sys.stderr)


def print_interval_result(folder: Path, summary: dict, name: str) -> None:
    """The bands with their noise and checks, and for an individual variation the trends (Figs. 7, 8;
    `uq.outputs.paper_figures.interval_table`)."""
    from uq.outputs.paper_figures import interval_table

    interval_table(folder, summary, name)


def print_response_result(folder: Path, name: str) -> None:
    """The table a response study prints: that of the figure it is named after when it has one
    (`uq.outputs.paper_figures.PaperFigure.table`: Figs. D.2, D.3 the impacts and scattering measures), else the
    resonant levels and the optimum (Fig. 6)."""
    from uq.outputs.paper_figures import PAPER_FIGURES, response_table

    row = PAPER_FIGURES.get(name)
    (response_table if row is None else row.table)(folder, {}, name)
