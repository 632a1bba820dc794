"""The study commands, one per study kind of the method registry (`uq.methods`: `ies interval`, `ies sobol`, `ies
response`, Sects. 5.2-5.4, Figs. 5-8), derived from the methods' settings, and the options every study command
shares (--out, --jobs, --scheduler, --cluster, --resume, --allow-large)."""
from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import Any, Callable, Iterator

from sim.common.options import positive_int
from uq.problem.tasks import MAX_RUNS
from uq.errors import StudyError

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
    parser.add_argument("--allow-large", action="store_true",
                        help=f"run a study of more than {MAX_RUNS:,} runs (refused by default: a typo more often than a "
                             "plan)")
    add_cluster_arguments(parser)


def add_study_arguments(kind: str) -> Callable[[argparse.ArgumentParser], None]:
    """The options of `ies KIND`: the study file, the options of its methods' settings (`Setting.option`), --method
    when the kind has several methods, and the run options."""
    def add(parser: argparse.ArgumentParser) -> None:
        from uq.methods import kinds

        methods = kinds()[kind]
        parser.add_argument("study", type=Path, metavar="STUDY.toml", help=f"study file ([study] kind = \"{kind}\")")
        seen = set()
        for method in methods:
            for s in method.settings:
                if s.option and s.option not in seen:
                    seen.add(s.option)
                    only = f"{method.name}: " if len(methods) > 1 else ""
                    parser.add_argument(s.option, dest=s.key, type=s.parse, metavar=s.metavar,
                                        help=f"{only}{s.help} (default: [{kind}] {s.key})")
        if len(methods) > 1:
            parser.add_argument("--method", choices=[m.name for m in methods],
                                help="; ".join(f"{m.name}: {m.help}" for m in methods) + f" (default: [{kind}] method, "
                                     f"else {methods[0].name})")
        parser.add_argument("--allow-implausible", action="store_true",
                            help="compute with values of implausible magnitude in the study file (a clearance of "
                                 "0.612 m, a damping ratio of 9 %%), refused by default as unit slips")
        add_run_arguments(parser)

    return add


def study_command(kind: str) -> Callable[[argparse.Namespace], int]:
    """`ies KIND`: run the study file with its method (the options over its [KIND] table), draw its figures and
    print its table (`Method.figures`, `Method.report`)."""
    def run(args: argparse.Namespace) -> int:
        from uq.engine.execution import run_study
        from uq.methods import METHODS, kinds
        from uq.problem.study import with_settings

        study = _load_study(args.study, kind, allow_implausible=args.allow_implausible)
        given = {s.key: getattr(args, s.key, None) for m in kinds()[kind] for s in m.settings if s.option}
        given["method"] = getattr(args, "method", None)
        study = with_settings(study, METHODS, given)
        with engine(args, study.cluster) as client:
            result = run_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                               progress=not args.quiet, client=client, allow_large=args.allow_large)
        _report(result, [] if args.no_figures else study.method.figures(result.folder))
        study.method.report(result.folder, result.summary, study.name)
        return 0

    return run


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


def _load_study(path: Path, kind: str, *, allow_implausible: bool = False) -> Any:
    """The study file, refused (one line) when it is of another kind."""
    from uq.methods import load_study

    study = load_study(path, allow_implausible=allow_implausible)
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
