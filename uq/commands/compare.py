"""`ies compare DIR DIR ...`: the Fig. 6 landmarks of several response studies side by side with the paper's."""
from __future__ import annotations

import argparse
from pathlib import Path

from sim.common.options import figure_formats

COMPARE_HELP = ("the Fig. 6 landmarks of several response studies side by side with the paper's: switch, optimum, "
                "levels at 7.4 and 9, impacts, r and energy share at 7.4 (table and figure)")


def add_compare_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies compare`."""
    parser.add_argument("folders", type=Path, nargs="+", metavar="DIR",
                        help="the --out folders of response studies (ies response, ies reproduce fig6)")
    parser.add_argument("--out", type=Path, default=Path("ies-out/compare"), metavar="DIR",
                        help="where compare.csv, compare.json and fig6-compare.* go (default ies-out/compare)")
    parser.add_argument("--format", dest="formats", type=figure_formats, default=(".png", ".pdf"), metavar="F1,F2",
                        help="figure formats, e.g. png,pdf,svg (default png,pdf)")
    parser.add_argument("--style", metavar="NAME|FILE",
                        help="a matplotlib style (e.g. seaborn-v0_8-paper, grayscale) or a .mplstyle file")
    parser.add_argument("--json", action="store_true", help="print the rows as one JSON object instead of the table")
    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty --out folder, replacing its files of the same names (default: refuse)")


def compare_command(args: argparse.Namespace) -> int:
    """`ies compare`: every folder is read and checked before anything is written (`uq.outputs.compare`)."""
    from sim.common.errors import SimulationInputError
    from sim.common.files import dumps, report_written, write_csv, write_json
    from sim.plots.figures import plot_series
    from sim.plots.redraw import style
    from uq.outputs.compare import (
        COMPARE_COLUMNS,
        PAPER_ROW,
        compare_row,
        compare_text,
        read_response_folder,
    )

    seen: dict[Path, Path] = {}
    for folder in args.folders:
        if folder.resolve() in seen:
            raise SimulationInputError(f"{folder} is given twice (also as {seen[folder.resolve()]}); give each study's "
                                       "folder once")
        seen[folder.resolve()] = folder
    from uq.outputs.netcdf import check_readable

    studies = [read_response_folder(folder) for folder in args.folders]
    for folder in args.folders:
        check_readable(folder)  # a damaged results.nc is named: the tables beside it came from the same run
    rows = [compare_row(study) for study in studies]
    context = style(args.style)
    if args.out.exists() and not args.out.is_dir():
        raise SimulationInputError(f"--out {args.out} exists and is not a folder; choose another path")
    if args.out.is_dir() and not args.force and any(args.out.iterdir()):
        raise SimulationInputError(f"--out {args.out} is not empty (an earlier comparison?); choose another folder or "
                                   "pass --force to replace its files")
    args.out.mkdir(parents=True, exist_ok=True)
    written = [write_csv(args.out / "compare.csv", COMPARE_COLUMNS,
                         [[row[key] for key in COMPARE_COLUMNS] for row in (*rows, PAPER_ROW)]),
               write_json(args.out / "compare.json", {"studies": rows, "paper": PAPER_ROW})]
    with context:
        for suffix in args.formats:
            path = args.out / f"fig6-compare{suffix}"
            plot_series([(study.name, study.overview) for study in studies], path, "Resonant mean vs excitation level (cf. Fig. 6) of each study, bars: range of "
                                      "its runs; the paper's landmarks", paper_landmarks=True)
            written.append(path)
    print(dumps({"studies": rows, "paper": PAPER_ROW}) if args.json else compare_text(rows))
    report_written(written, json_mode=args.json)
    return 0
