"""The uncertainty stage's words of the `ies` command line: `interval`, `sobol`, `response`, `reproduce`
(seed paper Sects. 5.2-5.4, Figs. 5-8), `plot` and `compare`.

* `ies interval STUDY.toml`: interval (vertex) bands of the resonant response, Figs. 7 and 8.
* `ies sobol STUDY.toml [--n N]`: Sobol' indices (S1, ST) of the resonant response levels.
* `ies response STUDY.toml`: the nominal point's frequency responses and resonant levels over the excitation
  levels through the task store (resumable, parallel, on a cluster), Figs. 5 and 6.
* `ies reproduce fig5|fig6|fig7|fig8|figD2|figD3|all [--quick] [--out DIR]`: the paper's figures, run from the
  shipped study files (uq/studies/fig5.toml ... figD3.toml, or their -quick variants) into DIR/fig5 ... DIR/figD3.
  Before Figs. 7 and 8 it calibrates k_H on the shipped crater (the calibration `ies calibrate --json` prints,
  kept in DIR/calibration.json) and uses the calibrated k_H as the upper bound of k_H, as the paper does with
  its BEM result 1.52 k_H* (Sect. 4.1); the best estimate stays 1.25 k_H* unless the calibration falls below
  it (then the midpoint of k_H* and the calibrated value). A failed calibration is one warning line, and
  Table 2's bounds are kept.
* `ies plot DIR`: redraw the figures of a result folder from its data (`sim.redraw`), in other formats, another
  matplotlib style or for a subset of the levels, without recomputing.
* `ies compare DIR DIR ... --out OUT`: the Fig. 6 landmarks of several response studies side by side with the
  paper's (`uq.compare`; the README's fidelity table), a table and one figure.

`add_commands(subparsers, calibrate=...)` registers them with the front door (`uq.cli`), which hands over
the calibration as a callable: this stage never imports the contact stage itself. Heavy imports stay
inside the functions, so that `ies --help` stays fast.
"""
from __future__ import annotations

import argparse
import functools
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable

from sim.options import figure_formats, level_list, positive_int

#: the calibration `ies reproduce` runs: no arguments, returns the JSON object of `ies calibrate --json`
Calibrate = Callable[[], dict]

INTERVAL_HELP = "interval bands of the resonant response level for D, g, k_H (paper Sect. 5.4, Figs. 7-8)"
SOBOL_HELP = "Sobol' sensitivity indices of the resonant response level per excitation level (SALib)"
RESPONSE_HELP = ("frequency responses and resonant levels of the nominal point over the excitation levels, run as a "
                 "resumable study (paper Sects. 5.2-5.3, Figs. 5-6)")
REPRODUCE_HELP = ("reproduce the paper's Figs. 5 and 6 (nominal response), 7 and 8 (uncertainty of D, g, k_H) and "
                  "D.2 and D.3 (impacts per period, restitution)")
PLOT_HELP = "redraw a result folder's figures from its saved data (formats, style, levels) without recomputing"
COMPARE_HELP = ("the Fig. 6 landmarks of several response studies side by side with the paper's: switch, optimum, "
                "levels at 7.4 and 9, impacts, r and energy share at 7.4 (table and figure)")
JOBS_HELP = ("local worker processes (1 runs in this process; default: the first run is timed here, then one worker per "
             "CPU core if the rest takes longer than starting the workers, else serially; more than the cores warns)")
#: the paper's figures that `ies reproduce` runs, in the order of `all`
FIGURES = ("fig5", "fig6", "fig7", "fig8", "figD2", "figD3")
#: figures `ies reproduce` runs when named, not in `all` (five contact laws, friction: minutes even when quick)
EXTRA_FIGURES = ("fig11", "figC1")
#: the levels whose time histories a figure traces (Fig. C.1b: 1.26 and 5.3, with friction)
TRACED = {"figC1": (1.26, 5.3)}


def add_commands(subparsers: Any, *, calibrate: Calibrate) -> None:
    """Register `interval`, `sobol`, `response`, `reproduce`, `plot` and `compare` on the front door's subparsers (argparse);
    `calibrate` is the calibration `reproduce` runs unless told otherwise."""
    reproduce = functools.partial(reproduce_command, calibrate=calibrate)
    for name, help_text, add_arguments, run in (("interval", INTERVAL_HELP, add_interval_arguments, interval_command),
                                                ("sobol", SOBOL_HELP, add_sobol_arguments, sobol_command),
                                                ("response", RESPONSE_HELP, add_response_arguments, response_command),
                                                ("reproduce", REPRODUCE_HELP, add_reproduce_arguments, reproduce),
                                                ("plot", PLOT_HELP, add_plot_arguments, plot_command),
                                                ("compare", COMPARE_HELP, add_compare_arguments, compare_command)):
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)


# ---- ies interval, ies sobol --------------------------------------------------------------------------------

def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """--out, --jobs, --scheduler, --resume, --no-figures, --quiet."""
    parser.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: the study's [study] output)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on a Dask cluster, e.g. tcp://host:8786 (needs dask.distributed)")
    parser.add_argument("--resume", action="store_true",
                        help="continue a study in --out: reuse finished tasks, run only the missing ones")
    parser.add_argument("--no-figures", action="store_true", help="write the data only")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def add_interval_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies interval`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"interval\")")
    add_run_arguments(parser)


def add_sobol_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies sobol`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"sobol\")")
    parser.add_argument("--n", type=positive_int, metavar="N", help="base sample size, a power of two (default: [sobol] n)")
    add_run_arguments(parser)


def add_response_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies response`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"response\")")
    add_run_arguments(parser)


def interval_command(args: argparse.Namespace) -> int:
    """`ies interval`: the study's interval bands (Sect. 5.4), then Figs. 7-8; prints the bands."""
    from uq.execute import run_interval_study
    from uq.figures import interval_figures

    study = _load_study(args.study, "interval")
    result = run_interval_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                progress=not args.quiet)
    _report(result, [] if args.no_figures else interval_figures(result.folder))
    print_interval_result(result.folder, result.summary, study.name)
    return 0


def sobol_command(args: argparse.Namespace) -> int:
    """`ies sobol`: the study's Sobol' indices (SALib), then their figure; prints the indices and the noise."""
    from uq.execute import run_sobol_study
    from uq.figures import sobol_figure
    from uq.results import sobol_table

    study = _load_study(args.study, "sobol")
    result = run_sobol_study(study, out=args.out, n=args.n, jobs=args.jobs, scheduler=args.scheduler,
                             resume=args.resume, progress=not args.quiet)
    _report(result, [] if args.no_figures else sobol_figure(result.folder))
    print(sobol_table(result.folder))
    return 0


def response_command(args: argparse.Namespace) -> int:
    """`ies response`: the study's frequency responses and resonant levels (Sects. 5.2-5.3), then Figs. 5-6."""
    from uq.execute import run_response_study
    from uq.figures import response_figures

    study = _load_study(args.study, "response")
    result = run_response_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                progress=not args.quiet)
    _report(result, [] if args.no_figures else response_figures(result.folder))
    print_response_result(result.folder, study.name)
    return 0


def _load_study(path: Path, kind: str) -> Any:
    """The study file, refused (one line) when it is of another kind."""
    from uq.errors import StudyError
    from uq.study import load_study

    study = load_study(path)
    if study.kind != kind:
        raise StudyError(f"{path} is a '{study.kind}' study; run it with `ies {study.kind}`")
    return study


def _report(result: Any, figures: list[Path]) -> None:
    """Where the results are, and how many runs took how long, on stdout."""
    print(f"results in {result.folder}/")
    for path in [*result.files, *figures]:
        print(f"  {path.name}")
    s = result.summary
    print(f"{s['tasks']} runs ({s['ran']} run now, {s['reused']} reused), {s['failed_runs']} failed, "
          f"{s['wall_time_s']:.1f} s")
    if result.warnings:
        print(f"{len(result.warnings)} warning(s), listed in study.json", file=sys.stderr)


def print_interval_result(folder: Path, summary: dict, name: str) -> None:
    """The bands with their noise and checks, and for an individual variation the trends (Figs. 7, 8)."""
    from uq.results import band_table, influence_line, trend_table

    for key in summary["untested"]:
        print(f"{name}: monotonicity could not be tested for {key} (one repetition: no noise estimate)")
    if any(key.startswith("individual:") for key in summary["monotone"]):
        print(f"{name}: change of the resonant level from each parameter's min to its max:")
        print(trend_table(folder))
        print(f"{name}: {influence_line(folder)}")
    print(f"{name}: bands (lower, nominal, upper +- standard error) and their checks:")
    print(band_table(folder))


def print_response_result(folder: Path, name: str) -> None:
    """The resonant levels per excitation level and the optimum (Fig. 6); for Figs. D.2, D.3 the impacts and
    scattering measures at the resonant eta."""
    import json

    from sim.tables import optimum_line, overview_text, scattering_text

    from sim.variants import switch_line

    data = json.loads((folder / "study.json").read_text())
    if "series_folders" in data:
        from uq.figures import series_overviews
        from sim.tables import series_text

        print(f"{name}: resonant mean (a / a_noabs*) and the input's dissipation shares at the resonant eta "
              f"(contact / friction / mode 1 / modes 2..N) for each value:")
        print(series_text(series_overviews(folder)))
        return
    overview = data["overview"]
    if name in ("figD2", "figD3"):
        print(f"{name}: impacts, restitution and energy scattering at the resonant eta of the nominal point:")
        print(scattering_text(overview))
        return
    print(f"{name}: resonant levels (a / a_noabs*) of the nominal point:")
    print(overview_text(overview))
    print(f"{name}: {optimum_line(overview)}")
    if "landmarks" in data:
        print(f"{name}: {switch_line(data['landmarks'])}")


# ---- ies reproduce ------------------------------------------------------------------------------------------

def add_reproduce_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies reproduce`."""
    parser.add_argument("figure", choices=(*FIGURES, *EXTRA_FIGURES, "all"),
                        help="which figure(s): fig5 (frequency responses), fig6 (resonant level vs excitation level), "
                             "fig7 and fig8 (uncertainty of D, g, k_H), figD2 and figD3 (impacts per period and "
                             "restitution vs excitation level), fig11 (damped contact law, Eq. 10) and figC1 (dry friction, "
                             "Appendix C; both not in all), all")
    parser.add_argument("--quick", action="store_true",
                        help="reduced protocol (fewer levels, frequencies, repetitions, shorter holds); same trends")
    parser.add_argument("--out", type=Path, default=Path("ies-out/reproduce"), metavar="DIR",
                        help="output folder (default ies-out/reproduce)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://host:8786")
    parser.add_argument("--resume", action="store_true", help="continue an interrupted reproduction in --out")
    calib = parser.add_mutually_exclusive_group()
    calib.add_argument("--calibration", type=Path, metavar="FILE",
                       help="use this `ies calibrate --json` output instead of running the calibration")
    calib.add_argument("--no-calibration", action="store_true", help="keep Table 2's k_H bounds")
    parser.add_argument("--model", type=Path, metavar="FILE",
                        help="run the studies on this modal-model file (`ies modes --save`) instead of the built-in rig")
    parser.add_argument("--integrator", metavar="NAME",
                        help="override the study files' integrator (ode3 = the paper's scheme, exact = free flight)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def study_file(figure: str, quick: bool) -> Path:
    """The shipped study file of a figure."""
    from importlib.resources import files

    return Path(str(files("uq") / "studies" / f"{figure}{'-quick' if quick else ''}.toml"))


def run_calibration(calibrate: Calibrate, out: Path) -> dict | None:
    """Run the calibration and keep its JSON object in out/calibration.json (Sect. 4.1).

    Returns None after one warning line when it fails: the calibration is optional, and whatever stops it
    (a bad scan, a solver that does not converge, ...) leaves the studies on Table 2's k_H bounds.
    """
    from sim.files import dumps, write_text

    try:
        data = calibrate()
    except Exception as exc:  # noqa: BLE001 - any failure falls back to Table 2, named in the warning
        sys.stderr.write(f"warning: the calibration failed ({type(exc).__name__}: {exc}); using Table 2's k_H bounds\n")
        return None
    write_text(out / "calibration.json", dumps(data))
    return data


def with_calibration(study: Any, k_H_cal: float) -> Any:
    """The study with k_H's upper bound at the calibrated value (and the best estimate kept below it)."""
    from uq.space import K_H_STAR, ParameterSpace

    space = study.space
    k = space["k_H"]
    best = space.extras.get("k_H_best_estimate", 1.25 * K_H_STAR)
    if best > k_H_cal:
        best = 0.5 * (k.min + k_H_cal)
    params = tuple(replace(p, max=max(k_H_cal, p.min)) if p.name == "k_H" else p for p in space.parameters)
    new_space = ParameterSpace(params, {**space.extras, "k_H_best_estimate": best, "k_H_calibrated": k_H_cal})
    fix = {**study.fix, "k_H": best} if "k_H" in study.fix else dict(study.fix)
    return replace(study, space=new_space, fix=fix)


def reproduce_command(args: argparse.Namespace, *, calibrate: Calibrate) -> int:
    """`ies reproduce`: check every study first, connect to the cluster once, then calibrate (for Figs. 7-8, with
    `calibrate` unless --calibration FILE or --no-calibration) and run."""
    from uq.runner import check_writable, dask_client
    from uq.space import calibrated_k_H
    from uq.study import load_study

    figures = FIGURES if args.figure == "all" else (args.figure,)
    studies = [load_study(study_file(f, args.quick)) for f in figures]
    if args.integrator:
        studies = [replace(s, protocol={**s.protocol, "integrator": args.integrator}) for s in studies]
    if args.model is not None:
        studies = [replace(s, modal_model=args.model) for s in studies]
    for s in studies:
        s.make_model().check()  # bad settings (e.g. an unknown integrator) fail here, before anything is written
    calibration = None
    if args.calibration is not None:  # a bad file fails here too
        calibration = {"k_H": calibrated_k_H(args.calibration), "source": str(args.calibration)}
    with dask_client(args.scheduler) as client:  # connected once, first: a bad address leaves nothing behind
        check_writable(args.out)
        return _reproduce(args, figures, studies, client, calibrate, calibration)


def _reproduce(args: argparse.Namespace, figures: tuple[str, ...], studies: list, client: Any,
               calibrate: Calibrate, calibration: dict | None) -> int:
    """Calibration (the given one, or run unless disabled) when an interval study needs it, then each figure's
    study, its figures and its summary."""
    from uq.errors import StudyError
    from uq.execute import run_interval_study, run_response_study
    from uq.figures import interval_figures, response_figures
    from uq.space import K_H_STAR, calibrated_k_H

    out = args.out
    calibrated = False
    for figure, study in zip(figures, studies):
        if study.kind == "interval" and "k_H" in [p.name for p in study.space.varied]:  # calibrated once, first
            if not calibrated and calibration is None and not args.no_calibration:
                calibration = run_calibration(calibrate, out)
            if calibration is not None:
                k_cal = calibrated_k_H(calibration)
                if k_cal < K_H_STAR:
                    raise StudyError(f"the calibrated k_H = {k_cal:.4g} N/m^1.5 is below k_H* = {K_H_STAR:.4g}; a "
                                     "crater should stiffen the contact: check the calibration or use --no-calibration")
                if not calibrated:
                    print(f"calibrated k_H = {k_cal:.4g} N/m^1.5 = {k_cal / K_H_STAR:.3f} k_H* (upper bound of k_H)")
                study = with_calibration(study, k_cal)
            calibrated = True
        folder = out / figure
        print(f"{figure}: {study.source} -> {folder}/")
        run, draw = ((run_response_study, response_figures) if study.kind == "response"
                     else (run_interval_study, interval_figures))
        result = run(study, out=folder, jobs=args.jobs, client=client, resume=args.resume, progress=not args.quiet)
        paths = draw(result.folder)
        if figure in TRACED:
            from uq.execute import series_traces

            paths += series_traces(study, folder, TRACED[figure])
        s = result.summary
        print(f"{figure}: {s['tasks']} runs ({s['ran']} run now), {s['failed_runs']} failed, "
              f"{s['wall_time_s']:.1f} s; figures: {', '.join(p.name for p in paths)}")
        if study.kind == "response":
            print_response_result(folder, figure)
        else:
            print_interval_result(folder, s, figure)
    return 0


# ---- ies plot -----------------------------------------------------------------------------------------------

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
    """`ies plot`: redraw the figures of a result folder from its data files (`sim.redraw`)."""
    import sim.figures  # noqa: F401 - registers ies sweep's, overview's and trace's folders
    import uq.figures  # noqa: F401 - registers the study folders
    from sim.errors import SimulationInputError
    from sim.files import report_written
    from sim.redraw import PlotOptions, kind_of, redraw, style

    kind_of(args.folder)  # what it is and whether the style exists, before any folder is made
    style(args.style)
    if args.out is not None:
        if args.out.exists() and not args.out.is_dir():
            raise SimulationInputError(f"--out {args.out} exists and is not a folder; choose another path")
        args.out.mkdir(parents=True, exist_ok=True)
    paths = redraw(args.folder, PlotOptions(args.formats, args.style, args.levels, args.out))
    report_written(paths)
    return 0


# ---- ies compare --------------------------------------------------------------------------------------------

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
    """`ies compare`: every folder is read and checked before anything is written (`uq.compare`)."""
    from sim.errors import SimulationInputError
    from sim.figures import plot_series
    from sim.files import dumps, report_written, write_csv, write_text
    from sim.redraw import style
    from uq.compare import COMPARE_COLUMNS, PAPER_ROW, compare_row, compare_text, read_response_folder

    seen: dict[Path, Path] = {}
    for folder in args.folders:
        if folder.resolve() in seen:
            raise SimulationInputError(f"{folder} is given twice (also as {seen[folder.resolve()]}); give each study's "
                                       "folder once")
        seen[folder.resolve()] = folder
    studies = [read_response_folder(folder) for folder in args.folders]
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
               write_text(args.out / "compare.json", dumps({"studies": rows, "paper": PAPER_ROW}) + "\n")]
    with context:
        for suffix in args.formats:
            path = args.out / f"fig6-compare{suffix}"
            plot_series([(study.name, study.overview) for study in studies], path, "Resonant mean vs excitation level (cf. Fig. 6) of each study, bars: range of "
                                      "its runs; the paper's landmarks", paper_landmarks=True)
            written.append(path)
    print(dumps({"studies": rows, "paper": PAPER_ROW}) if args.json else compare_text(rows))
    report_written(written, json_mode=args.json)
    return 0
