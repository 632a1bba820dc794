"""The uncertainty stage's words of the `ies` command line, one module each: the study commands (`study`: one per study
kind of the method registry `uq.methods`: `interval`, `sobol`, `response`), `reproduce` (the paper's figures),
`plot`, `compare` and `design`.

`commands()` lists these words (name, help, options, run); `add_commands(subparsers, calibrate=...)` registers them
with the front door (`uq.cli`), which hands over the calibration as a callable: this stage never imports the contact
stage itself. Heavy imports stay inside the functions, so that `ies --help` stays fast.
"""
from __future__ import annotations

import functools
from typing import Any, Callable

from uq.commands import compare, design, plot, reproduce, study

#: (name, help, add_arguments(parser), run(args) -> exit code)
Command = tuple[str, str, Callable[..., None], Callable[..., int]]

#: the commands besides the study kinds', in the order `ies --help` lists them after those
OTHER_COMMANDS: tuple[Command, ...] = (
    ("reproduce", reproduce.REPRODUCE_HELP, reproduce.add_reproduce_arguments, reproduce.reproduce_command),
    ("plot", plot.PLOT_HELP, plot.add_plot_arguments, plot.plot_command),
    ("compare", compare.COMPARE_HELP, compare.add_compare_arguments, compare.compare_command),
    ("design", design.DESIGN_HELP, design.add_design_arguments, design.design_command),
)


def commands() -> list[Command]:
    """Every command of this stage: one per study kind of the method registry (its first method's kind_help, else help), then
    `OTHER_COMMANDS`."""
    from uq.methods import kinds

    return [*((kind, methods[0].kind_help or methods[0].help, study.add_study_arguments(kind), study.study_command(kind))
              for kind, methods in kinds().items()), *OTHER_COMMANDS]


def add_commands(subparsers: Any, *, calibrate: reproduce.Calibrate) -> None:
    """Register `commands()` on the front door's subparsers (argparse); `calibrate` is the calibration `reproduce`
    runs unless told otherwise."""
    for name, help_text, add_arguments, run in commands():
        if run is reproduce.reproduce_command:
            run = functools.partial(run, calibrate=calibrate)
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)
