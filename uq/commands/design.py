"""`ies design`: choose the clearance and the sphere for a host structure (`uq.design`)."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from sim.common.options import positive_int
from sim.model.parameters import PARAMETERS
from uq.commands.study import add_run_arguments, engine, print_files

DESIGN_HELP = ("choose the clearance and the sphere (radius, material) for a host structure: the worst case of the "
               "resonant tip amplitude over an excitation range and the uncertain D, clearance and k_H, with a margin to "
               "the switch to the almost periodic response; screened by the slow flow, predicted by the similarity law "
               "of the full model, verified by stepped-sine simulation (uq.design)")


def add_design_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", nargs="?", type=Path, metavar="STUDY.toml",
                        help="a design study file ([study] kind = \"design\", [design] with the options below as keys); "
                             "options given here win")
    parser.add_argument("--excitation", metavar="RANGE",
                        help="operating base amplitudes START:STOP[:COUNT] with units (e.g. 0.66um:6.6um:10) or base "
                             "accelerations (0.5m/s2:2m/s2); required")
    flags = sorted(PARAMETERS["g"].option.flags, key=lambda flag: flag != "--clearance")  # the clearance's names
    parser.add_argument(*flags, dest="clearance", metavar="RANGE",
                        help=f"clearances to consider (default 0.3mm:1.2mm:10); also {', '.join(flags[1:])} (the "
                             "same quantity as in ies sweep)")
    parser.add_argument("--radius", metavar="RANGE", help="sphere radii (default the paper's 7.92mm)")
    parser.add_argument("--material", metavar="LIST", help="sphere materials, comma separated: brass, steel, tungsten, "
                                                           "or your own E=200GPa,nu=0.29,density=7850kg/m3 (default brass)")
    from sim.model.materials import WALL_MATERIALS

    parser.add_argument("--wall-material", metavar="NAME",
                        help=f"the cavity walls' material for Eq. 8's k_H*: {', '.join(WALL_MATERIALS)}, or your own "
                             "E=70GPa,nu=0.33 (default: the host's [host] wall_material, else steel)")
    parser.add_argument("--model", metavar="FILE", help="the host as a modal-model file (default: the built-in rig)")
    from uq.design.objectives import OBJECTIVES

    parser.add_argument("--objective", metavar="NAME",
                        help="what is minimised in the worst case (uq.design.objectives): "
                             + "; ".join(f"{o.name}: {o.quantity}, {o.statistic} ({o.unit})" for o in OBJECTIVES.values())
                             + f" (default {next(iter(OBJECTIVES))})")
    parser.add_argument("--margin", metavar="FRACTION",
                        help="the margin a design's switch to the almost periodic response must keep above the top of "
                             "--excitation at every corner of the box, as a fraction in (0, 1] (default 0.2: 20 %%)")
    D, g, k_H = (PARAMETERS[name].spread for name in ("D", "g", "k_H"))  # Table 2's intervals (the one vocabulary)
    parser.add_argument("--damping", metavar="LOW:HIGH",
                        help="interval of D_1 (ratios, or in %%: 0.075%%:0.09%%), containing the host's nominal D_1* "
                             "(default: the host's [host] "
                             f"damping_interval, else Table 2's relative interval around its D_1*; the rig: "
                             f"{D.low:g}:{D.high:g})")
    parser.add_argument("--clearance-tolerance", metavar="LOW:HIGH",
                        help=f"tolerance added to each clearance (default Table 2: {g.low * 1e3:g}:{g.high * 1e3:g}mm)")
    parser.add_argument("--k-H-factor", metavar="LOW:HIGH",
                        help=f"factor on Eq. 8's k_H* of each sphere on the walls (default Table 2: "
                             f"{k_H.low:g}:{k_H.high:.4g})")
    parser.add_argument("--calibration", metavar="FILE",
                        help="`ies calibrate --json` output: its k_H / k_H* becomes the upper end of the k_H factor "
                             "(the crater's stiffening, as `ies reproduce` uses it)")
    parser.add_argument("--candidates", type=positive_int, metavar="N",
                        help="designs in the first verified batch, the best predicted (default 5); the search then "
                             "verifies the best verified design's neighbours until it has them on every side")
    parser.add_argument("--reps", type=positive_int, metavar="N", help="repetitions per verification run (default 3)")
    parser.add_argument("--restitution", type=float, metavar="R",
                        help="modal restitution r (Eq. D.1) of the screening (default 0.86, the simulator's at the rig)")
    parser.add_argument("--baseline", metavar="G[,R[,MAT]]",
                        help="a design to verify beside the recommendation, e.g. the paper's 0.58mm,7.92mm,brass")
    parser.add_argument("--block-width", metavar="LENGTH", help="the host's block across the cavity (default 28mm)")
    parser.add_argument("--min-wall", metavar="LENGTH", help="thinnest wall left beside the cavity (default 5.5mm)")
    add_run_arguments(parser)


def design_problem(args: argparse.Namespace) -> tuple[Any, Path, Any]:
    """The design problem, output folder and [cluster] table of `ies design`'s study file and options (options win;
    `uq.design.problem.read_design_file`, `uq.design.problem.problem_of`)."""
    from uq.design import problem as d

    file = d.read_design_file(args.study) if args.study is not None else d.DesignFile()
    given = {name: getattr(args, name) for name in d.DESIGN_SETTINGS if getattr(args, name, None) not in (None, False)}
    settings = {**d.DESIGN_SETTINGS, **file.settings, **given}
    return d.problem_of(settings, file.protocol), Path(args.out or settings["output"]), file.cluster


def design_command(args: argparse.Namespace) -> int:
    """`ies design`: screen, verify and recommend (uq.design); exit 3 with the verified designs written (all marked not
    admissible) when none keeps the margin."""
    import sys

    from uq.design.results import design_table
    from uq.design.search import run_design

    from uq.engine.runner import release_output

    problem, out, cluster = design_problem(args)
    try:
        with engine(args, cluster) as client:
            result = run_design(problem, out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                progress=not args.quiet, figures=not args.no_figures, client=client)
    finally:
        release_output(out)  # the folder's lock, taken when the design's runs began (uq.engine.runner.prepare_output)
    print(design_table(result))
    print_files(result.folder, result.files)
    if result.refusal is not None:
        sys.stderr.write(f"ies design: no admissible design: {result.refusal}\n")
        return 3
    return 0
