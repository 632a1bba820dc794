"""The uncertainty stage's words of the `ies` command line: `interval`, `sobol`, `response`, `reproduce`
(seed paper Sects. 5.2-5.4, Figs. 5-8), `plot` and `compare`.

* `ies interval STUDY.toml`: interval (vertex) bands of the resonant response, Figs. 7 and 8.
* `ies sobol STUDY.toml [--n N | --method pce [--points N] [--degree P]]`: Sobol' indices (S1, ST) of the
  resonant response levels, from Saltelli's sampling or a polynomial-chaos surrogate (`uq.surrogate`).
* `ies response STUDY.toml`: the nominal point's frequency responses and resonant levels over the excitation
  levels through the task store (resumable, parallel, on a cluster), Figs. 5 and 6.
* `ies reproduce NAME|all [--quick] [--out DIR]`: the paper's figures of `uq.paper_figures.PAPER_FIGURES` (fig5,
  fig6, fig7, fig8, figD2, figD3 in `all`; fig11, figC1 when named), each run from its study file (uq/studies/NAME.toml,
  or its -quick variant) into DIR/NAME, drawn and printed by its row. Before a study that varies k_H it calibrates
  k_H on the shipped crater (the calibration `ies calibrate --json` prints, kept in DIR/calibration.json) and
  uses the calibrated k_H as the upper bound of k_H (`uq.study.with_calibration`, Sect. 4.1). A failed
  calibration is one warning line, and Table 2's bounds are kept.
* `ies plot DIR`: redraw the figures of a result folder from its data (`sim.plots.redraw`), in other formats, another
  matplotlib style or for a subset of the levels, without recomputing.
* `ies compare DIR DIR ... --out OUT`: the Fig. 6 landmarks of several response studies side by side with the
  paper's (`uq.compare`; the fidelity report's table), a table and one figure.

`add_commands(subparsers, calibrate=...)` registers them with the front door (`uq.cli`), which hands over
the calibration as a callable: this stage never imports the contact stage itself. Heavy imports stay
inside the functions, so that `ies --help` stays fast.
"""
from __future__ import annotations

import argparse
import contextlib
import functools
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable, Iterator

from sim.common.options import figure_formats, level_list, positive_int
from uq.errors import StudyError

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


def add_commands(subparsers: Any, *, calibrate: Calibrate) -> None:
    """Register `interval`, `sobol`, `response`, `reproduce`, `plot` and `compare` on the front door's subparsers (argparse);
    `calibrate` is the calibration `reproduce` runs unless told otherwise."""
    reproduce = functools.partial(reproduce_command, calibrate=calibrate)
    for name, help_text, add_arguments, run in (("interval", INTERVAL_HELP, add_interval_arguments, interval_command),
                                                ("sobol", SOBOL_HELP, add_sobol_arguments, sobol_command),
                                                ("response", RESPONSE_HELP, add_response_arguments, response_command),
                                                ("reproduce", REPRODUCE_HELP, add_reproduce_arguments, reproduce),
                                                ("plot", PLOT_HELP, add_plot_arguments, plot_command),
                                                ("compare", COMPARE_HELP, add_compare_arguments, compare_command),
                                                ("design", DESIGN_HELP, add_design_arguments, design_command)):
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)


# ---- ies interval, ies sobol --------------------------------------------------------------------------------

def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """--out, --jobs, --scheduler, --cluster and its options (`uq.cluster`), --resume, --no-figures, --quiet."""
    from uq.cluster import add_cluster_arguments

    parser.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: the study's [study] output)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on a Dask cluster, e.g. tcp://host:8786 (needs dask.distributed)")
    parser.add_argument("--resume", action="store_true",
                        help="continue a study in --out: reuse finished tasks, run only the missing ones")
    parser.add_argument("--no-figures", action="store_true", help="write the data only")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_cluster_arguments(parser)


def add_interval_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies interval`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"interval\")")
    add_run_arguments(parser)


def add_sobol_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies sobol`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"sobol\")")
    parser.add_argument("--n", type=positive_int, metavar="N",
                        help="Saltelli's base sample size, a power of two (default: [sobol] n)")
    parser.add_argument("--method", choices=("saltelli", "pce"),
                        help="Saltelli's sampling (the reference) or a polynomial-chaos surrogate (default: [sobol] method)")
    parser.add_argument("--points", type=positive_int, metavar="N",
                        help="pce: design points of the surrogate (default: [sobol] points, else 3 per polynomial "
                             "term, rounded up to a power of 2)")
    parser.add_argument("--degree", type=positive_int, metavar="P",
                        help="pce: total polynomial degree (default: [sobol] degree, else 2)")
    add_run_arguments(parser)


def add_response_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies response`."""
    parser.add_argument("study", type=Path, metavar="STUDY.toml", help="study file ([study] kind = \"response\")")
    add_run_arguments(parser)


def interval_command(args: argparse.Namespace) -> int:
    """`ies interval`: the study's interval bands (Sect. 5.4), then Figs. 7-8; prints the bands."""
    from uq.execute import run_interval_study
    from uq.paper_figures import interval_figures

    study = _load_study(args.study, "interval")
    with engine(args, study.cluster) as client:
        result = run_interval_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                    progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else interval_figures(result.folder))
    print_interval_result(result.folder, result.summary, study.name)
    return 0


def sobol_command(args: argparse.Namespace) -> int:
    """`ies sobol`: the study's Sobol' indices (SALib, or a PCE surrogate), then their figure; prints the indices and
    the noise (and the surrogate's fit)."""
    from uq.execute import run_sobol_study
    from uq.figures import sobol_figure
    from uq.results import sobol_table
    from uq.study import with_sobol_method

    study = with_sobol_method(_load_study(args.study, "sobol"), args.method, args.points, args.degree)
    if study.sobol_method == "pce" and args.n is not None:
        raise StudyError("--n is Saltelli's base sample size; the surrogate's design size is --points")
    with engine(args, study.cluster) as client:
        result = run_sobol_study(study, out=args.out, n=args.n, jobs=args.jobs, scheduler=args.scheduler,
                                 resume=args.resume, progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else sobol_figure(result.folder))
    print(sobol_table(result.folder))
    return 0


def response_command(args: argparse.Namespace) -> int:
    """`ies response`: the study's frequency responses and resonant levels (Sects. 5.2-5.3), then Figs. 5-6."""
    from uq.execute import run_response_study
    from uq.paper_figures import response_figures

    study = _load_study(args.study, "response")
    with engine(args, study.cluster) as client:
        result = run_response_study(study, out=args.out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                                    progress=not args.quiet, client=client)
    _report(result, [] if args.no_figures else response_figures(result.folder))
    print_response_result(result.folder, study.name)
    return 0


@contextlib.contextmanager
def engine(args: argparse.Namespace, table: Any) -> Iterator[Any]:
    """The Dask client of a batch cluster when --cluster or the study's [cluster] table asks for one (started
    here, closed on exit: `uq.cluster.open_cluster`), else None (--jobs or --scheduler, as the runner does)."""
    from uq.cluster import cluster_settings, open_cluster

    settings = cluster_settings(args, table)
    if settings is None:
        yield None
        return
    with open_cluster(settings) as client:
        yield client


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
    """The bands with their noise and checks, and for an individual variation the trends (Figs. 7, 8;
    `uq.paper_figures.interval_table`)."""
    from uq.paper_figures import interval_table

    interval_table(folder, summary, name)


def print_response_result(folder: Path, name: str) -> None:
    """The table a response study prints: that of the figure it is named after when it has one
    (`uq.paper_figures.PaperFigure.table`: Figs. D.2, D.3 the impacts and scattering measures), else the
    resonant levels and the optimum (Fig. 6)."""
    from uq.paper_figures import PAPER_FIGURES, response_table

    row = PAPER_FIGURES.get(name)
    (response_table if row is None else row.table)(folder, {}, name)


# ---- ies reproduce ------------------------------------------------------------------------------------------

def add_reproduce_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies reproduce`."""
    from uq.paper_figures import PAPER_FIGURES

    rows = PAPER_FIGURES.values()
    parser.add_argument("figure", choices=(*PAPER_FIGURES, "all"),
                        help="which figure(s): " + ", ".join(f"{row.name} ({row.help}{'' if row.in_all else '; not in all'})"
                                                             for row in rows) + ", all")
    parser.add_argument("--quick", action="store_true",
                        help="reduced protocol (fewer levels, frequencies, repetitions, shorter holds); same trends")
    parser.add_argument("--out", type=Path, default=Path("ies-out/reproduce"), metavar="DIR",
                        help="output folder (default ies-out/reproduce)")
    parser.add_argument("--jobs", type=positive_int, default=None, metavar="N", help=JOBS_HELP)
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://host:8786")
    parser.add_argument("--resume", action="store_true", help="continue an interrupted reproduction in --out")
    from uq.cluster import add_cluster_arguments

    add_cluster_arguments(parser)
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
    """The study file of a figure (`uq.paper_figures.PaperFigure.study_file`)."""
    from uq.paper_figures import PAPER_FIGURES

    return PAPER_FIGURES[figure].study_file(quick)


def run_calibration(calibrate: Calibrate, out: Path) -> dict | None:
    """Run the calibration and keep its JSON object in out/calibration.json (Sect. 4.1).

    Returns None after one warning line when it fails: the calibration is optional, and whatever stops it
    (a bad scan, a solver that does not converge, ...) leaves the studies on Table 2's k_H bounds.
    """
    from sim.common.files import dumps, write_text

    try:
        data = calibrate()
    except Exception as exc:  # noqa: BLE001 - any failure falls back to Table 2, named in the warning
        sys.stderr.write(f"warning: the calibration failed ({type(exc).__name__}: {exc}); using Table 2's k_H bounds\n")
        return None
    write_text(out / "calibration.json", dumps(data))
    return data


def reproduce_command(args: argparse.Namespace, *, calibrate: Calibrate) -> int:
    """`ies reproduce`: check every study first, connect to the cluster once, then calibrate (for Figs. 7-8, with
    `calibrate` unless --calibration FILE or --no-calibration) and run."""
    from uq.runner import check_writable, dask_client
    from uq.space import calibrated_k_H
    from uq.study import load_study

    from uq.paper_figures import figures_of_all

    figures = figures_of_all() if args.figure == "all" else (args.figure,)
    studies = [load_study(study_file(f, args.quick)) for f in figures]
    if args.integrator:
        studies = [replace(s, protocol={**s.protocol, "integrator": args.integrator}) for s in studies]
    if args.model is not None:
        studies = [replace(s, modal_model=args.model) for s in studies]
    models = [s.make_model() for s in studies]
    for model in models:
        model.check()  # bad settings (e.g. an unknown integrator) fail here, before anything is written
    calibration = None
    if args.calibration is not None:  # a bad file fails here too
        calibration = {"k_H": calibrated_k_H(args.calibration), "source": str(args.calibration)}
    with engine(args, None) as batch, dask_client(args.scheduler, batch) as client:
        # connected (or the batch cluster started) once, first: a bad address leaves nothing behind
        check_writable(args.out)
        from sim.integration.integrators import warm_up_all

        # every kernel any study's workers will call, compiled here once, before the first bar
        warm_up_all(pair for model in models if hasattr(model, "kernel_variants") for pair in model.kernel_variants())
        return _reproduce(args, figures, studies, client, calibrate, calibration)


def _reproduce(args: argparse.Namespace, figures: tuple[str, ...], studies: list, client: Any,
               calibrate: Calibrate, calibration: dict | None) -> int:
    """Calibration (the given one, or run unless disabled) when an interval study needs it, then each figure's
    study, its figures and its table; then OUT/summary.txt, each figure's table.txt and OUT/index.md
    (`uq.reproduce_report`)."""
    from sim.common.files import report_written
    from uq.reproduce_report import captured_stdout, write_index, write_summary

    calibrated = False
    sections: list[tuple[str, str]] = []
    for figure, study in zip(figures, studies):
        with captured_stdout() as printed:
            calibration, calibrated = _reproduce_figure(args, figure, study, client, calibrate, calibration,
                                                        calibrated)
        sections.append((figure, printed.copy.getvalue()))
    command = " ".join(["ies reproduce", args.figure, *(["--quick"] if args.quick else []), "--out", str(args.out)])
    report_written([*write_summary(args.out, command, sections), write_index(args.out)])
    return 0


def _reproduce_figure(args: argparse.Namespace, figure: str, study: Any, client: Any, calibrate: Calibrate,
                      calibration: dict | None, calibrated: bool) -> tuple[dict | None, bool]:
    """One figure of `ies reproduce`: the calibration first if its study varies k_H and none was made yet, then
    the study, its figures and its table. Returns (the calibration, whether it was made)."""
    from uq.execute import run_interval_study, run_response_study
    from uq.paper_figures import PAPER_FIGURES, STUDY_FIGURES, interval_table
    from uq.space import K_H_STAR, calibrated_k_H
    from uq.study import with_calibration

    out = args.out
    row = PAPER_FIGURES[figure]
    if study.kind == "interval" and "k_H" in [p.name for p in study.space.varied]:  # calibrated once, first
        if not calibrated and calibration is None and not args.no_calibration:
            calibration = run_calibration(calibrate, out)
        if calibration is not None:
            k_cal = calibrated_k_H(calibration)
            study = with_calibration(study, k_cal)  # one line if k_cal < k_H*
            if not calibrated:
                print(f"calibrated k_H = {k_cal:.4g} N/m^1.5 = {k_cal / K_H_STAR:.3f} k_H* (upper bound of k_H)")
        calibrated = True
    folder = out / figure
    print(f"{figure}: {study.source} -> {folder}/")
    run = run_response_study if study.kind == "response" else run_interval_study
    result = run(study, out=folder, jobs=args.jobs, client=client, resume=args.resume, progress=not args.quiet)
    paths = STUDY_FIGURES[study.kind](result.folder)
    if row.traced:
        from uq.execute import series_traces

        paths += series_traces(study, folder, row.traced)
    s = result.summary
    print(f"{figure}: {s['tasks']} runs ({s['ran']} run now), {s['failed_runs']} failed, "
          f"{s['wall_time_s']:.1f} s; figures: {', '.join(p.name for p in paths)}")
    (row.table if study.kind == "response" else interval_table)(folder, s, figure)
    return calibration, calibrated


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
    """`ies plot`: redraw the figures of a result folder from its data files (`sim.plots.redraw`)."""
    import sim.plots.figures  # noqa: F401 - registers ies sweep's, overview's and trace's folders
    import uq.figures  # noqa: F401 - registers the Sobol' and reproduce folders
    import uq.paper_figures  # noqa: F401 - registers the interval and response study folders
    from sim.common.errors import SimulationInputError
    from sim.common.files import report_written
    from sim.plots.redraw import PlotOptions, kind_of, redraw, style

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
    from sim.common.errors import SimulationInputError
    from sim.common.files import dumps, report_written, write_csv, write_text
    from sim.plots.figures import plot_series
    from sim.plots.redraw import style
    from uq.compare import (
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


# ---- ies design ---------------------------------------------------------------------------------------------------

DESIGN_HELP = ("choose the clearance and the sphere (radius, material) for a host structure: the worst case of the "
               "resonant tip amplitude over an excitation range and the uncertain D, clearance and k_H, screened by "
               "the slow flow and verified by stepped-sine simulation (uq.design)")
def add_design_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", nargs="?", type=Path, metavar="STUDY.toml",
                        help="a design study file ([study] kind = \"design\", [design] with the options below as keys); "
                             "options given here win")
    parser.add_argument("--excitation", metavar="RANGE",
                        help="operating base amplitudes START:STOP[:COUNT] with units (e.g. 0.66um:6.6um:10) or base "
                             "accelerations (0.5m/s2:2m/s2); required")
    parser.add_argument("--clearance", metavar="RANGE", help="clearances to consider (default 0.3mm:1.2mm:10)")
    parser.add_argument("--radius", metavar="RANGE", help="sphere radii (default the paper's 7.92mm)")
    parser.add_argument("--material", metavar="LIST", help="sphere materials, comma separated: brass, steel, tungsten "
                                                           "(default brass)")
    parser.add_argument("--model", metavar="FILE", help="the host as a modal-model file (default: the built-in rig)")
    parser.add_argument("--objective", choices=("mean", "max"), help="the amplitude whose worst case is minimised: "
                                                                     "the resonant mean (default) or max")
    parser.add_argument("--damping", metavar="LOW:HIGH", help="interval of D_1 (default Table 2: 0.00075:0.0009)")
    parser.add_argument("--clearance-tolerance", metavar="LOW:HIGH",
                        help="tolerance added to each clearance (default Table 2: 0:0.032mm)")
    parser.add_argument("--k-H-factor", metavar="LOW:HIGH", help="factor on Eq. 8's k_H (default Table 2: 1:1.518)")
    parser.add_argument("--calibration", metavar="FILE",
                        help="`ies calibrate --json` output: its k_H / k_H* becomes the upper end of the k_H factor "
                             "(the crater's stiffening, as `ies reproduce` uses it)")
    parser.add_argument("--candidates", type=positive_int, metavar="N", help="screened designs to verify (default 5)")
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
    `uq.design.read_design_file`, `uq.design.problem_of`)."""
    from uq import design as d

    file = d.read_design_file(args.study) if args.study is not None else d.DesignFile()
    given = {name: getattr(args, name) for name in d.DESIGN_SETTINGS if getattr(args, name, None) is not None}
    settings = {**d.DESIGN_SETTINGS, **file.settings, **given}
    return d.problem_of(settings, file.protocol), Path(args.out or settings["output"]), file.cluster


def design_command(args: argparse.Namespace) -> int:
    """`ies design`: screen, verify and recommend (uq.design)."""
    from uq.design import design_table, run_design

    problem, out, cluster = design_problem(args)
    with engine(args, cluster) as client:
        result = run_design(problem, out, jobs=args.jobs, scheduler=args.scheduler, resume=args.resume,
                            progress=not args.quiet, figures=not args.no_figures, client=client)
    print(design_table(result))
    print(f"wrote {len(result.files)} files to {result.folder}")
    return 0
