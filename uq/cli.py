"""The `ies` command line: one entry point, one subcommand per job.

Each module in `uq/commands/` is one subcommand. It defines
``NAME`` (the subcommand), ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> int``. Heavy imports (numba, scipy) belong inside ``run`` so that
``ies --help`` stays fast.

User mistakes end with one line on stderr, ``ies <command>: error: <what and how to fix>``,
and exit code 2; numerical failures exit with code 3. No traceback for either.
"""
from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
from typing import Sequence

import uq.commands
from bem_contact.errors import ContactInputError, ConvergenceError
from scans.errors import ScanError
from sim.errors import SimulationDiverged, SimulationInputError
from uq.errors import StudyError

USER_ERRORS = (ContactInputError, ScanError, SimulationInputError, StudyError)
NUMERICAL_FAILURES = (ConvergenceError, SimulationDiverged)


class _Parser(argparse.ArgumentParser):
    """argparse prints usage + message on error; we keep the one-line message and exit 2."""

    def error(self, message: str) -> None:  # noqa: D401 - argparse API
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """Parser with every subcommand found in `uq.commands`."""
    parser = _Parser(prog="ies", description="Impact Energy Scatterer workbench: contact, simulation, uncertainty.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for info in sorted(pkgutil.iter_modules(uq.commands.__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"uq.commands.{info.name}")
        command = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(command)
        command.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run `ies` with `argv` (default: the process arguments) and return the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    prog = f"ies {args.command}"
    try:
        return int(args._run(args) or 0)
    except USER_ERRORS as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return 2
    except NUMERICAL_FAILURES as exc:
        sys.stderr.write(f"{prog}: numerical failure: {exc}\n")
        return 3
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError) as exc:
        where = f": {exc.filename}" if getattr(exc, "filename", None) else ""
        sys.stderr.write(f"{prog}: error: {exc.strerror or exc}{where}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write(f"{prog}: interrupted; finished results were kept (rerun with --resume where offered)\n")
        return 130
    except BrokenPipeError:
        # e.g. `ies modes --json | head`; silence the second error at interpreter exit
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
