"""The `ies` front door: one entry point that dispatches to the stages' own command modules.

Each stage owns its words of the command line (`add_commands(subparsers)`, SALib's habit):
`bem_contact.cli` (calibrate), `sim.cli` (modes, sweep, overview, trace, impacts, modal-fit) and `uq.commands`
(interval, sobol, response: one per study kind of `uq.methods`; reproduce, plot, compare, design). Each subcommand parser sets ``_run(args) -> exit code``. This module only builds the parser from
the dispatch table `STAGES`, hands `ies reproduce` the calibration as a callable (so that the uq stage never
imports the contact stage), and turns the stages' errors into exit codes. It is the one module of uq that
imports scans and bem_contact (their error classes and the calibration).

User mistakes end with one line on stderr, ``ies <command>: error: <what and how to fix>``,
and exit code 2; numerical failures, resource failures (a read-only or full disk, too little memory) and a
batch cluster without workers exit with code 3. No traceback for either.
"""
from __future__ import annotations

import argparse
import os
import re
import signal
import sys
from typing import Sequence

import bem_contact.cli
import bem_contact.pipeline
import sim.cli
import uq.commands
from bem_contact.errors import ContactInputError, ConvergenceError
from scans.errors import ScanError
from sim.common.errors import ResourceFailure, SimulationDiverged, SimulationInputError
from sim.common.files import RESOURCE_ERRNOS
from uq.errors import ClusterUnavailable, StudyError

USER_ERRORS = (ContactInputError, ScanError, SimulationInputError, StudyError)
NUMERICAL_FAILURES = (ConvergenceError, SimulationDiverged)
#: the cluster's resources failed (no worker in time, workers dying): exit 3, the finished tasks kept
RESOURCE_FAILURES = (ClusterUnavailable,)

#: the dispatch table, in the pipeline's order: (stage command module, what it is handed); each module's
#: add_commands(subparsers, **handed) registers its own subcommands
STAGES = (
    (bem_contact.cli, {}),
    (sim.cli, {}),
    (uq.commands, {"calibrate": bem_contact.pipeline.calibrate_default}),
)


class _Parser(argparse.ArgumentParser):
    """argparse prints usage + message on error; we keep the one-line message and exit 2.

    A value that starts with a minus and a digit (``--g -0.5mm``, ``--level -6``) is taken as the option's value,
    not as an option (argparse's own rule covers bare numbers only), so the value's own check refuses it clearly.
    """

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> None:  # noqa: D401 - argparse API
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """Parser with the subcommands of every stage in `STAGES`."""
    parser = _Parser(prog="ies", description="Impact Energy Scatterer workbench: contact, simulation, uncertainty.")
    parser.add_argument("--version", action="version", version=version_line(),
                        help="print the version and the simulator's code version, then exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module, handed in STAGES:
        module.add_commands(sub, **handed)
    return parser


def version_line() -> str:
    """``ies-workbench VERSION (simulator code HASH)``: the installed distribution's version and the simulator's code
    version (`sim.common.kernel_cache.code_version`: in every study's task keys, and the name of the kernel folder
    ``sim-HASH`` that `ies cache` lists)."""
    from importlib.metadata import PackageNotFoundError, version

    from sim.common.kernel_cache import code_version

    try:
        installed = version("ies-workbench")
    except PackageNotFoundError:
        installed = "(not installed)"
    return f"ies-workbench {installed} (simulator code {code_version()})"


def main(argv: Sequence[str] | None = None) -> int:
    """Run `ies` with `argv` (default: the process arguments) and return the exit code.

    Run as the process's own command (argv None: the console script, ``python -m uq``), Ctrl-C is ignored once the
    exit code is settled: an interrupt while the interpreter shuts down (joblib's workers, HDF5, matplotlib being torn
    down) would otherwise end it with a traceback, "Exception ignored", a fatal error or a silent kill after the one
    line was written. While files are written it is held back until each file is whole (`sim.common.files`)."""
    def settled(code: int) -> int:
        if argv is None:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        return code

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version (0) or a refused option (2, its line already written)
        return int(exc.code or 0)
    prog = f"ies {args.command}"
    try:
        return settled(int(args._run(args) or 0))
    except KeyboardInterrupt:
        settled(130)
        if getattr(args, "resume", None) is not None:
            sys.stderr.write(f"{prog}: interrupted; finished results were kept (rerun with --resume)\n")
        else:
            sys.stderr.write(f"{prog}: interrupted; no results were written (rerun the command)\n")
        return 130
    except USER_ERRORS as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 2
    except NUMERICAL_FAILURES as exc:
        sys.stderr.write(f"{prog}: numerical failure: {exc}\n")
        return 3
    except RESOURCE_FAILURES as exc:
        sys.stderr.write(f"{prog}: cluster failure: {exc}\n")
        return 3
    except BrokenPipeError:
        # e.g. `ies modes --json | head`; silence the second error at interpreter exit
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except ResourceFailure as exc:
        sys.stderr.write(f"{prog}: resource failure: {exc}\n")
        return 3
    except MemoryError:
        sys.stderr.write(f"{prog}: resource failure: out of memory; ask for less (fewer periods, samples, levels or "
                         "repetitions) or free memory\n")
        return 3
    except OSError as exc:
        where = f": {exc.filename}" if getattr(exc, "filename", None) else ""
        if exc.errno in RESOURCE_ERRNOS:
            sys.stderr.write(f"{prog}: resource failure: {exc.strerror or exc}{where}; nothing more was written\n")
            return 3
        sys.stderr.write(f"{prog}: error: {exc.strerror or exc}{where}\n")
        return 2
    finally:
        settled(0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
