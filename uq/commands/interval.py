"""`ies interval STUDY.toml`: interval (vertex) bands of the resonant response, Figs. 7 and 8."""
from __future__ import annotations

import argparse
from pathlib import Path

from uq.commands._study import add_run_arguments, report

NAME = "interval"
HELP = "interval bands of the resonant response level for D, g, k_H (paper Sect. 5.4, Figs. 7-8)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"interval\")")
    add_run_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from uq.errors import StudyError
    from uq.execute import run_interval_study
    from uq.study import load_study

    study = load_study(args.study)
    if study.kind != "interval":
        raise StudyError(f"{args.study} is a '{study.kind}' study; run it with `ies {study.kind}`")
    result = run_interval_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                progress=not args.quiet)
    figures = []
    if not args.no_figures:
        from uq.figures import interval_figures

        figures = interval_figures(result.folder)
    report(result, figures)
    return 0
