"""`ies plot DIR`: redraw a result folder's figures from its data, without recomputing."""
from __future__ import annotations

import argparse
from pathlib import Path

from sim.common.options import figure_formats, level_list

PLOT_HELP = "redraw a result folder's figures from its saved data (formats, style, levels) without recomputing"


def add_plot_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies plot`."""
    parser.add_argument("folder", type=Path, metavar="DIR",
                        help="a result folder: --out of ies sweep, overview, trace, interval, sobol, response or reproduce")
    parser.add_argument("--format", dest="formats", type=figure_formats, default=(".png", ".pdf"), metavar="F1,F2",
                        help="figure formats, e.g. png,pdf,svg (default png,pdf)")
    parser.add_argument("--style", metavar="NAME|FILE",
                        help="a matplotlib style (e.g. seaborn-v0_8-paper, grayscale) or a .mplstyle file")
    parser.add_argument("--levels", type=level_list, metavar="L1,L2,..",
                        help="draw only these excitation levels a_base/a_base* (default: all)")
    parser.add_argument("--out", type=Path, metavar="DIR", help="write the figures here (default: into DIR itself)")


def plot_command(args: argparse.Namespace) -> int:
    """`ies plot`: redraw the figures of a result folder from its data files (`sim.plots.redraw`)."""
    import sim.plots.figures  # noqa: F401 - registers ies sweep's, overview's and trace's folders
    import uq.outputs.figures  # noqa: F401 - registers the Sobol' and reproduce folders
    import uq.outputs.paper_figures  # noqa: F401 - registers the interval and response study folders
    from sim.common.errors import SimulationInputError
    from sim.common.files import report_written
    from sim.plots.redraw import PlotOptions, kind_of, redraw, style

    from uq.outputs.netcdf import check_readable

    kind_of(args.folder)  # what it is and whether the style exists, before any folder is made
    check_readable(args.folder)  # a damaged results.nc is named, not drawn around
    style(args.style)
    if args.out is not None:
        if args.out.exists() and not args.out.is_dir():
            raise SimulationInputError(f"--out {args.out} exists and is not a folder; choose another path")
        args.out.mkdir(parents=True, exist_ok=True)
    paths = redraw(args.folder, PlotOptions(args.formats, args.style, args.levels, args.out))
    report_written(paths)
    return 0
