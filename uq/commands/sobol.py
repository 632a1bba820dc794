"""`ies sobol STUDY.toml [--n N]`: Sobol' indices (S1, ST) of the resonant response levels."""
from __future__ import annotations

import argparse
from pathlib import Path

from uq.commands._study import add_run_arguments, report

NAME = "sobol"
HELP = "Sobol' sensitivity indices of the resonant response level per excitation level (SALib)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"sobol\")")
    parser.add_argument("--n", type=int, metavar="N", help="base sample size, a power of two (default: [sobol] n)")
    add_run_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from uq.errors import StudyError
    from uq.execute import run_sobol_study
    from uq.study import load_study

    study = load_study(args.study)
    if study.kind != "sobol":
        raise StudyError(f"{args.study} is a '{study.kind}' study; run it with `ies {study.kind}`")
    result = run_sobol_study(study, out=args.out, n=args.n, jobs=args.jobs, scheduler=args.scheduler,
                             resume=args.resume, progress=not args.quiet)
    figures = []
    if not args.no_figures:
        from uq.figures import sobol_figure

        figures = sobol_figure(result.folder)
    report(result, figures)
    return 0
