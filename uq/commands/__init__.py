"""The uncertainty stage's words of the `ies` command line, one module each: the study commands (`study`: interval,
sobol, response), `reproduce` (the paper's figures), `plot`, `compare` and `design`.

`COMMANDS` is the table of these words (name, help, options, run); `add_commands(subparsers, calibrate=...)`
registers them with the front door (`uq.cli`), which hands over the calibration as a callable: this stage never
imports the contact stage itself. Heavy imports stay inside the functions, so that `ies --help` stays fast.
"""
from __future__ import annotations

import functools
from typing import Any

from uq.commands import compare, design, plot, reproduce, study

#: (name, help, add_arguments(parser), run(args) -> exit code), in the order `ies --help` lists them
COMMANDS = (
    ("interval", study.INTERVAL_HELP, study.add_interval_arguments, study.interval_command),
    ("sobol", study.SOBOL_HELP, study.add_sobol_arguments, study.sobol_command),
    ("response", study.RESPONSE_HELP, study.add_response_arguments, study.response_command),
    ("reproduce", reproduce.REPRODUCE_HELP, reproduce.add_reproduce_arguments, reproduce.reproduce_command),
    ("plot", plot.PLOT_HELP, plot.add_plot_arguments, plot.plot_command),
    ("compare", compare.COMPARE_HELP, compare.add_compare_arguments, compare.compare_command),
    ("design", design.DESIGN_HELP, design.add_design_arguments, design.design_command),
)


def add_commands(subparsers: Any, *, calibrate: reproduce.Calibrate) -> None:
    """Register `COMMANDS` on the front door's subparsers (argparse); `calibrate` is the calibration `reproduce`
    runs unless told otherwise."""
    for name, help_text, add_arguments, run in COMMANDS:
        if run is reproduce.reproduce_command:
            run = functools.partial(run, calibrate=calibrate)
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)
