"""Arguments and reporting shared by `ies interval` and `ies sobol` (not a subcommand itself)."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """--out, --jobs, --scheduler, --resume, --no-figures, --quiet."""
    parser.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: the study's [study] output)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, metavar="N",
                        help="local worker processes (default: the number of CPU cores; 1 runs in this process)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on a Dask cluster, e.g. tcp://host:8786 (needs dask.distributed)")
    parser.add_argument("--resume", action="store_true",
                        help="continue a study in --out: reuse finished tasks, run only the missing ones")
    parser.add_argument("--no-figures", action="store_true", help="write the data only")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def report(result, figures: list[Path]) -> None:
    """Short human summary on stdout."""
    print(f"results in {result.folder}/")
    for path in [*result.files, *figures]:
        print(f"  {path.name}")
    s = result.summary
    print(f"{s['tasks']} runs ({s['ran']} run now, {s['reused']} reused), {s['failed_runs']} failed, "
          f"{s['wall_time_s']:.1f} s")
    if result.warnings:
        print(f"{len(result.warnings)} warning(s), listed in study.json", file=sys.stderr)
