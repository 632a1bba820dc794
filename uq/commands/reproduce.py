"""`ies reproduce fig7|fig8|all [--quick] [--out DIR]`: the paper's uncertainty studies (Sect. 5.4).

Runs the shipped study files (uq/studies/fig7.toml, fig8.toml, or their -quick variants) with the
paper's protocol and writes the data and figures into DIR/fig7 and DIR/fig8. Before that it runs the
calibration on the shipped crater (`ies calibrate --json`, issue 3) when that command exists, and uses
the calibrated k_H as the upper bound of k_H, as the paper does with its BEM result 1.52 k_H*
(Sect. 4.1); the best estimate stays 1.25 k_H* unless the calibration falls below it (then the
midpoint of k_H* and the calibrated value).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

NAME = "reproduce"
HELP = "reproduce the paper's Figs. 7 and 8 (uncertainty of D, g, k_H) with the shipped studies"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("figure", choices=("fig7", "fig8", "all"), help="which figure(s)")
    parser.add_argument("--quick", action="store_true",
                        help="reduced protocol (fewer levels, frequencies, repetitions, shorter holds); same trends")
    parser.add_argument("--out", type=Path, default=Path("ies-out/reproduce"), metavar="DIR",
                        help="output folder (default ies-out/reproduce)")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, metavar="N",
                        help="local worker processes (default: the number of CPU cores)")
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


def run_calibration(out: Path) -> dict | None:
    """Run `ies calibrate --json` on the shipped crater; its JSON is kept in out/calibration.json.

    Returns None (with a warning) when the calibrate command is not available or fails.
    """
    import importlib.util

    from uq.output import write_text

    if importlib.util.find_spec("uq.commands.calibrate") is None:
        sys.stderr.write("warning: `ies calibrate` is not available; using Table 2's k_H bounds\n")
        return None
    proc = subprocess.run([sys.executable, "-m", "uq", "calibrate", "--json"], capture_output=True, text=True)
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["no message"])[-1]
        sys.stderr.write(f"warning: the calibration failed ({last}); using Table 2's k_H bounds\n")
        return None
    try:
        data = json.loads(proc.stdout)
    except json.JSONDecodeError:
        sys.stderr.write("warning: `ies calibrate --json` printed no JSON; using Table 2's k_H bounds\n")
        return None
    write_text(out / "calibration.json", json.dumps(data, indent=2))
    return data


def with_calibration(study, k_H_cal: float):
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


def run(args: argparse.Namespace) -> int:
    from uq.runner import check_writable, dask_client
    from uq.study import load_study

    figures = ("fig7", "fig8") if args.figure == "all" else (args.figure,)
    studies = [load_study(study_file(f, args.quick)) for f in figures]
    if args.integrator:
        studies = [replace(s, protocol={**s.protocol, "integrator": args.integrator}) for s in studies]
    if args.model is not None:
        studies = [replace(s, modal_model=args.model) for s in studies]
    for s in studies:
        s.make_model().check()  # bad settings (e.g. an unknown integrator) fail here, before anything is written
    with dask_client(args.scheduler) as client:  # connected once, first: a bad address leaves nothing behind
        check_writable(args.out)
        return _reproduce(args, figures, studies, client)


def _reproduce(args: argparse.Namespace, figures: tuple[str, ...], studies: list, client: Any) -> int:
    """Calibration (unless disabled), then each figure's interval study, its figures and its summary."""
    from uq.errors import StudyError
    from uq.execute import run_interval_study
    from uq.figures import interval_figures
    from uq.space import K_H_STAR, calibrated_k_H

    out = args.out
    calibration = None
    if args.calibration is not None:
        calibration = {"k_H": calibrated_k_H(args.calibration), "source": str(args.calibration)}
    elif not args.no_calibration:
        calibration = run_calibration(out)
    if calibration is not None:
        k_cal = calibrated_k_H(calibration)
        if k_cal < K_H_STAR:
            raise StudyError(f"the calibrated k_H = {k_cal:.4g} N/m^1.5 is below k_H* = {K_H_STAR:.4g}; "
                             "a crater should stiffen the contact: check the calibration or use --no-calibration")
        print(f"calibrated k_H = {k_cal:.4g} N/m^1.5 = {k_cal / K_H_STAR:.3f} k_H* (upper bound of k_H)")
        studies = [with_calibration(s, k_cal) for s in studies]
    for figure, study in zip(figures, studies):
        folder = out / figure
        print(f"{figure}: {study.source} -> {folder}/")
        result = run_interval_study(study, out=folder, jobs=args.jobs, client=client, resume=args.resume,
                                    progress=not args.quiet)
        paths = interval_figures(result.folder)
        s = result.summary
        print(f"{figure}: {s['tasks']} runs ({s['ran']} run now), {s['failed_runs']} failed, "
              f"{s['wall_time_s']:.1f} s; figures: {', '.join(p.name for p in paths)}")
        for key, ok in s["monotone"].items():
            if not ok:
                print(f"{figure}: monotonicity check failed for {key} (band widened; see study.json)")
        from uq.results import band_table, influence_line, trend_table

        if any(d == "individual" for d in study.designs):
            print(f"{figure}: change of the mean resonant level from each parameter's min to its max:")
            print(trend_table(folder))
            print(f"{figure}: {influence_line(folder)}")
        else:
            print(f"{figure}: bands of the mean resonant level (a / a_noabs*):")
            print(band_table(folder))
    return 0
