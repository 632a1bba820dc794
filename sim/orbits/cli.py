"""`ies orbits`: the periodic orbits of the full model, stable and unstable, with their bifurcations, against eta at
one or more levels, or against the level at one eta (`--level-curve ETA`); the built-in rig or `--model FILE`, every
contact law of the registry (`sim.model.contact_law.LAWS`). Writes orbits.csv, results.nc, orbits.json and
orbits.png into --out DIR (`sim.orbits.tables`, `sim.orbits.figures`), all computed before anything is written.

The command's options beyond the system's (which `sim.cli` adds, shared with `ies sweep`) are added here; `sim.cli`
registers the command and hands in what it shares (the system builder, the output folder), so that this part of
`sim` imports nothing above it.
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from typing import Any, Callable

from sim.common.errors import SimulationInputError
from sim.common.options import count, figure_file

def _period_multiple(text: str) -> int:
    from sim.orbits.shooting import MAX_PERIOD_MULTIPLE

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer in 1..{MAX_PERIOD_MULTIPLE}, got {text!r}") from None
    if not 1 <= value <= MAX_PERIOD_MULTIPLE:
        raise argparse.ArgumentTypeError(f"must be an integer in 1..{MAX_PERIOD_MULTIPLE} (the period multiple k of "
                                         f"a kT orbit), got {value}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of `ies orbits` besides the system's (module docstring)."""
    from sim.orbits.response import GROWTH_RUNS, STARTS
    from sim.integration.integrators import DEFAULT_INTEGRATOR, INTEGRATORS
    from sim.orbits.starts import DEFAULT_RESTITUTION

    parser.add_argument("--level", required=True, metavar="L1,L2,..|LO:HI",
                        help="excitation levels a_base/a_base* (-) or base amplitudes with their unit, e.g. 7.4, "
                             "5,7.4,9 or 3.3um; with --level-curve the range LO:HI of the level")
    parser.add_argument("--eta", default="0.95:1.0", metavar="LO:HI",
                        help="range of eta = Omega/omega_1 (default 0.95:1.0); with --level-curve ignored")
    parser.add_argument("--level-curve", dest="level_curve", type=float, default=None, metavar="ETA",
                        help="continue in the level at this eta instead of in eta (the level curve)")
    parser.add_argument("--start", default="slow-flow", choices=STARTS,
                        help="starting orbit: slow-flow (default: the slow flow's two-impact orbit carried to the full "
                             "model by continuation in the higher modes' damping), simulation (the state an up-sweep "
                             "from the range's low end reaches at --at, then k = 1..--max-period), linear (the linear orbit)")
    parser.add_argument("--at", type=float, default=None, metavar="X",
                        help="the eta (or level) to start at (default: the start's own choice in the range)")
    parser.add_argument("--restitution", type=float, default=DEFAULT_RESTITUTION, metavar="R",
                        help=f"the slow flow's modal restitution r for the slow-flow start (default {DEFAULT_RESTITUTION})")
    parser.add_argument("--max-period", dest="max_period", type=_period_multiple, default=2, metavar="K",
                        help="largest period multiple k of a kT orbit found by period doubling (default 2, at most 8)")
    parser.add_argument("--switches", type=count, default=None, metavar="N",
                        help="branch switchings at symmetry-breaking and period-doubling points, those nearest to a "
                             "stable orbit first (default: every located one, within the response's budget; 0: the "
                             "start's branch and the direct-simulation searches only)")
    parser.add_argument("--budget", type=count, default=GROWTH_RUNS, metavar="RUNS",
                        help=f"runs of the one-period map for the switchings and searches of each response, beyond "
                             f"its first branch (default {GROWTH_RUNS:,}: about 12 s of CPU on the rig; what it leaves "
                             "undone is said)")
    parser.add_argument("--integrator", default=DEFAULT_INTEGRATOR, choices=tuple(INTEGRATORS),
                        help=f"time integrator of the shooting (default {DEFAULT_INTEGRATOR}; the others for checks)")
    scaled = " and ".join(name for name, record in INTEGRATORS.items() if record.dt_scale)
    parser.add_argument("--dt-scale", dest="dt_scale", type=float, default=1.0, metavar="X",
                        help=f"{scaled} step as a multiple of the paper's 2 pi/(15 omega_9) (default 1)")
    parser.add_argument("--sweep", metavar="DIR",
                        help="an `ies sweep --out DIR` folder whose stepped-sine points are drawn on the orbits of its "
                             "level (one of --level's), with their dynamics when it was run with --lyapunov")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="write orbits.csv, results.nc, orbits.json and orbits.png (or --plot) into DIR")
    parser.add_argument("--plot", type=figure_file, default=None, metavar="FILE",
                        help="the figure's file instead of DIR/orbits.png (format by suffix)")
    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty --out folder, replacing its files of the same names")
    parser.add_argument("--json", action="store_true", help="print orbits.json's object instead of the text summary")


def _levels(text: str, curve: bool, value: Callable[[str], float]) -> tuple[list[float], tuple[float, float] | None]:
    """(levels, level range): a list of levels, or with --level-curve the range LO:HI; each a level a_base/a_base* or
    a base amplitude with its unit (3.3um), read by `value` (`sim.cli.level_value`)."""
    if curve:
        parts = text.split(":")
        if len(parts) != 2:
            raise SimulationInputError(f"--level with --level-curve must be a range LO:HI like 5:9, got {text!r}")
        return [], (value(parts[0]), value(parts[1]))
    values = [value(v) for v in text.split(",") if v.strip()]
    if not values:
        raise SimulationInputError("--level is empty; give at least one excitation level, e.g. 7.4")
    return values, None


def _eta_range(text: str) -> tuple[float, float]:
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts[:2])
        if len(parts) not in (2, 3):
            raise ValueError
    except ValueError:
        raise SimulationInputError(f"--eta must be a range LO:HI like 0.95:1.0, got {text!r}") from None
    return lo, hi


def _sweep_for(folder: str, levels: list[float], curve: bool) -> dict:
    """The stepped-sine points of `--sweep DIR` (`sim.orbits.figures.read_sweep`), refused in one line when there are
    none, when they are of another level than every one of --level's (they would be drawn on nothing), or with
    --level-curve (its axis is the level, a sweep's is eta)."""
    from sim.orbits.figures import read_sweep

    sweep = read_sweep(folder)
    if sweep is None:
        raise SimulationInputError(f"--sweep {folder}: no sweep.csv there; give a folder written by `ies sweep --out DIR`")
    if curve:
        raise SimulationInputError(f"--sweep {folder}: a stepped sine runs over eta, the level curve (--level-curve) "
                                   "over the level; drop --sweep or --level-curve")
    level = float(sweep["level"][0])
    if not math.isfinite(level):
        raise SimulationInputError(f"--sweep {folder}: its sweep.json names no level; give a folder written by "
                                   "`ies sweep --out DIR`")
    if not any(math.isclose(level, other, rel_tol=1e-9) for other in levels):
        raise SimulationInputError(f"--sweep {folder} is a stepped sine at level {level:g}, not at --level "
                                   f"{','.join(f'{v:g}' for v in levels)}: add {level:g} to --level or give a sweep of "
                                   "one of them")
    return sweep


def run(args: argparse.Namespace, build_system: Callable[[argparse.Namespace], tuple[Any, Any]],
        output_folder: Callable[..., Any], system_data: Callable[..., dict], *,
        nominal_of: Callable[[argparse.Namespace, Any], Any], level_value: Callable[[str], float],
        level_of: Callable[[float, Any, Any], float]) -> int:
    """`ies orbits` (module docstring): build the system (`sim.cli.build_system`) and its normalisation
    (`sim.cli.nominal_of`: the host's own D_1*, --g-star), read the levels (`sim.cli.level_value`, `level_of`: a level
    or a base amplitude with its unit), compute every level's (or the eta's) orbits, then write the files into the
    output folder (`sim.cli.output_folder`) and print the summary."""
    import sys

    from tqdm import tqdm

    from sim.common.files import check_writable, dumps, report_written, write_or_fallback
    from sim.integration.integrators import warm_up
    from sim.orbits.figures import plot_orbits
    from sim.orbits.response import StartFailed, check_range, orbit_response
    from sim.orbits.setting import OrbitSetting
    from sim.orbits.shooting import OrbitNotConverged
    from sim.orbits.tables import (ORBITS_COLUMNS, orbit_rows, orbit_table, response_summary, write_orbit_files,
                                   write_start_attempts)

    started = time.perf_counter()
    if args.no_impactor:
        raise SimulationInputError("ies orbits needs the sphere: without it the host is linear and its only orbit is "
                                   "the analytic frequency response (ies sweep --no-impactor)")
    curve = args.level_curve is not None
    levels, level_range = _levels(args.level, curve, level_value)
    eta_range = check_range("eta", _eta_range(args.eta)) if not curve else None
    if args.plot:
        check_writable(args.plot, "--plot")
    model, impactor = build_system(args)
    nominal = nominal_of(args, model)
    levels = [level_of(v, model, nominal) for v in levels]
    if curve:
        level_range = tuple(level_of(v, model, nominal) for v in level_range)
        check_range("eta", (args.level_curve, args.level_curve * (1 + 1e-9)))
        check_range("level", level_range)
    sweep = _sweep_for(args.sweep, levels, curve) if args.sweep is not None else None
    if not (args.dt_scale > 0):
        raise SimulationInputError(f"--dt-scale must be positive, got {args.dt_scale!r}")
    # every setting is built (and refused) before the kernels compile: friction, a bad level, ...
    if curve:
        todo = [(OrbitSetting(model, impactor, level_range[0], args.level_curve, integrator=args.integrator,
                              dt_scale=args.dt_scale, nominal=nominal), "level", level_range)]
    else:
        todo = [(OrbitSetting(model, impactor, level, 0.5 * sum(eta_range), integrator=args.integrator,
                              dt_scale=args.dt_scale, nominal=nominal), "eta", eta_range) for level in levels]
    with output_folder(args.out, args.force) as folder:
        warm_up(args.integrator, law=impactor.contact_law.law.name)
        responses = []
        with tqdm(desc="orbits", unit="orbit", disable=not sys.stderr.isatty(), leave=False, file=sys.stderr) as bar:
            for base, name, bounds in todo:
                try:
                    response = orbit_response(base, name, bounds, start=args.start, at=args.at,
                                              max_period=args.max_period, switches=args.switches,
                                              restitution=args.restitution, budget=args.budget,
                                              progress=bar.update)
                except StartFailed as failure:  # keep what it tried, say what else to try
                    written = write_or_fallback(lambda where: [write_start_attempts(where, failure)], folder,
                                                "orbits")
                    raise OrbitNotConverged(f"{failure}; wrote {written[0]}") from None
                responses.append(response)
        if all(r.impacts and not r.branches for r in responses):  # nothing found anywhere: say why, write nothing
            where = (f"level {responses[-1].base.level:g}" if not curve else f"eta {args.level_curve:g}")
            raise OrbitNotConverged(f"no impacting orbit found at {where} ({responses[-1].notes[-1]}); try another "
                                    "--start or --at; nothing was written")
        settings = {"command": "ies orbits", "parameter": "level" if curve else "eta",
                    "levels": levels if not curve else None, "level_range": level_range,
                    "eta_range": eta_range, "level_curve_eta": args.level_curve, "start": args.start,
                    "max_period": args.max_period, "switches": args.switches, "budget": args.budget,
                    "restitution": args.restitution,
                    "integrator": args.integrator, "dt_scale": args.dt_scale, **system_data(model, impactor, nominal),
                    "wall_time_s": time.perf_counter() - started}
        rows = orbit_rows(responses)
        panels = []
        for response in responses:
            cols = {name: [r[j] for r in rows if (r[0] == response.base.level if not curve else True)]
                    for j, name in enumerate(ORBITS_COLUMNS)}
            level_sweep = (sweep if sweep is not None and not curve
                           and math.isclose(float(sweep["level"][0]), response.base.level, rel_tol=1e-9) else None)
            title = (f"$a_\\mathrm{{base}}/a_\\mathrm{{base}}^* = {response.base.level:g}$" if not curve
                     else f"$\\eta = {response.base.eta:g}$")
            panels.append((cols, title, response.bounds, level_sweep))
        figure = Path(args.plot) if args.plot else None

        def write(where: Path) -> list[Path]:
            written = write_orbit_files(where, responses, settings)
            target = figure if figure is not None and where == folder else where / (figure.name if figure else
                                                                                     "orbits.png")
            plot_orbits(panels, target, parameter="level" if curve else "eta", max_period=args.max_period,
                        title=f"periodic orbits: {model.source.split(' (')[0]}")
            return [*written, target]

        written = write_or_fallback(write, folder, "orbits")
    data = {**settings, "responses": [response_summary(r) for r in responses]}
    print(dumps(data) if args.json else "\n".join(orbit_table(r) for r in responses), flush=True)
    report_written(written, json_mode=args.json)
    return 0
