"""`ies impacts` and `ies modal-fit`: the analyses of measured (or simulated) signals as commands, thin layers
over `sim.analysis.impacts` (Appendix D.1 of the seed paper) and `sim.analysis.modal_fit` (Sect. 5.5, Eq. 9).

Both read a signal CSV (`sim.analysis.signals`: a header line, a uniform `t` column in s, SI units) and print a small
table, or one JSON object with --json; every bad input ends in one `SimulationInputError` line (exit 2) before
anything is written. A signal that also holds the simulator's contact forces (`f_left`, `f_right`, as
`ies trace` writes them) is checked against them: the detector's agreement with the simulator's contacts is
reported, and a warning printed when more than 5 % of its impacts are not within 0.2 ms of one.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from sim.common.errors import SimulationInputError
from sim.common.options import figure_file
from sim.common.outputs import Column, OutputFile

IMPACTS_HELP = ("impacts in wall accelerations: high-pass, envelope, threshold on the low-passed tip RMS, impacts "
                "per period (Appendix D.1)")
MODAL_FIT_HELP = "modal energies after impacts from the tip velocity: least-squares fit of Eq. 9 between impacts"
#: Detections farther than this from every simulator contact count as false (s; about two contact durations).
MATCH_TOLERANCE = 2e-4
#: Share of false detections above which the command warns (the acceptance bar of the detector).
FALSE_SHARE_WARNING = 0.05
#: Warnings of the fit printed in the text output.
MAX_WARNINGS_SHOWN = 5
IMPACTS_JSON = OutputFile("impacts --json", "ies impacts SIGNAL.csv --json", "", (
    Column("impacts", "", "one entry per detected impact: t (s), wall, peak (envelope, m/s^2), level (peak / "
           "reference RMS)"),
    Column("impacts_per_period, thresholds", "-", "one value per threshold"),
    Column("fs", "Hz", "the signal's sampling rate"),
    Column("reference_rms", "m/s^2", "RMS of the low-passed tip acceleration"),
    Column("excitation_hz", "Hz", "given or estimated from the tip (excitation_estimated true)"),
    Column("n_periods, duration", "-, s", "excitation periods and length of the signal"),
    Column("highpass_hz, lowpass_hz", "Hz", "the filters' cut-offs"),
    Column("min_separation", "s", "shortest time between two impacts"),
    Column("simulator_check", "", "null for a measurement; for a trace contacts, detected, found_share, false_share, "
           "tolerance_s, warning"),
))
MODAL_FIT_JSON = OutputFile("modal-fit --json", "ies modal-fit SIGNAL.csv --json", "", (
    Column("higher_share", "-", "mean share of modes 2..N in the modal energy after the impacts"),
    Column("energies", "J", "windows x modes"),
    Column("windows", "", "per window impact, start and stop (s), energies, higher_share, the modes' displacement and "
           "velocity at its start, base_acceleration (m/s^2), base_phase, A, B, alpha, beta (Eq. 9), condition, "
           "residual, well_posed"),
    Column("impacts, excitation_hz, excitation_estimated, guard", "-, Hz, -, s", "the impacts used and the settings"),
    Column("n_modes, model, fs", "-, , Hz", "modes fitted, the modal model, the sampling rate"),
    Column("warnings, simulator_check", "", "windows left out and why; the check against a trace's contacts"),
))


def add_detection_arguments(parser: argparse.ArgumentParser, *, threshold_default: str) -> None:
    """The detector's settings (`sim.analysis.impacts.detect_impacts`)."""
    from sim.analysis.impacts import HIGHPASS_HZ, LOWPASS_HZ

    parser.add_argument("--threshold", default=threshold_default, metavar="F|START:STOP[:N]",
                        help=f"threshold factor(s) of the RMS of the low-passed tip acceleration (default "
                             f"{threshold_default})")
    parser.add_argument("--highpass", type=float, default=HIGHPASS_HZ, metavar="HZ",
                        help=f"high-pass cut-off of the wall accelerations (default {HIGHPASS_HZ:g}, the paper's; "
                             "must lie below fs/2)")
    parser.add_argument("--lowpass", type=float, default=LOWPASS_HZ, metavar="HZ",
                        help=f"low-pass cut-off of the tip acceleration for the threshold (default {LOWPASS_HZ:g})")
    parser.add_argument("--excitation-hz", dest="excitation_hz", type=float, default=None, metavar="HZ",
                        help="excitation frequency (default: estimated from the tip acceleration)")


def detection_settings(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of `sim.analysis.impacts.detect_impacts` from the options."""
    return {"highpass_hz": args.highpass, "lowpass_hz": args.lowpass, "excitation_hz": args.excitation_hz}


def simulator_check(path: str, times: Any) -> dict[str, Any] | None:
    """The detected impact times (s) against the simulator's contacts in the file's f_left, f_right columns
    (onset: the first sample of each run of non-zero force); None for a signal without them (a measurement).
    Returns the counts, the share of contacts found and of false detections (MATCH_TOLERANCE) and a warning."""
    import numpy as np

    from sim.analysis.impacts import match_impacts
    from sim.analysis.signals import read_signal

    try:
        forces = read_signal(path, ("f_left", "f_right"))
    except SimulationInputError:
        return None
    pressed = (forces["f_left"] != 0) | (forces["f_right"] != 0)
    onsets = forces.t[np.flatnonzero(np.diff(pressed.astype(int)) == 1) + 1]
    pairs = match_impacts(np.asarray(times), onsets, MATCH_TOLERANCE)
    found = pairs.shape[0] / onsets.size if onsets.size else float("nan")
    false = 1.0 - pairs.shape[0] / len(times) if len(times) else 0.0
    check = {"contacts": int(onsets.size), "detected": int(len(times)), "found_share": found, "false_share": false,
             "tolerance_s": MATCH_TOLERANCE, "warning": None}
    if false > FALSE_SHARE_WARNING:
        check["warning"] = (f"{100 * false:.0f} % of the impacts are not within {1e3 * MATCH_TOLERANCE:g} ms of a "
                            "contact of the simulator (f_left, f_right columns): the high-pass passes a lightly damped "
                            "mode close to its cut-off (the built-in rig's mode 9 at 19.83 kHz rings through 20 kHz); "
                            "raise --highpass clear of the model's highest mode (22000 for the rig)")
    return check


# ---- ies impacts --------------------------------------------------------------------------------------------

def add_impacts_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies impacts`."""
    parser.add_argument("signal", metavar="SIGNAL.csv", help="signal CSV with columns t (s), a_left, a_right, a_tip (m/s^2)")
    add_detection_arguments(parser, threshold_default="0.8:1.0")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def impacts_command(args: argparse.Namespace) -> int:
    """`ies impacts`: Appendix D.1's detector on a signal file, impacts per period per threshold."""
    from sim.common.files import dumps
    from sim.analysis.impacts import detect_impacts, parse_thresholds

    thresholds = parse_thresholds(args.threshold)
    detection = detect_impacts(args.signal, thresholds, **detection_settings(args))
    data = detection.to_dict()
    data["simulator_check"] = simulator_check(args.signal, detection.times)
    if args.json:
        print(dumps(data))
        return 0
    print(f"# {args.signal}: fs = {detection.fs:.1f} Hz, {detection.duration:.4g} s, excitation "
          f"{detection.excitation_hz:.3f} Hz ({'estimated' if detection.excitation_estimated else 'given'}), "
          f"{detection.n_periods:.1f} periods; high-pass {detection.highpass_hz:g} Hz, low-pass "
          f"{detection.lowpass_hz:g} Hz, reference RMS {detection.reference_rms:.4g} m/s^2")
    print(f"{'threshold':>9} {'impacts':>8} {'per period':>10}")
    for factor, rate in zip(detection.thresholds, detection.impacts_per_period):
        print(f"{factor:9.3f} {int(round(rate * detection.n_periods)):8d} {rate:10.3f}")
    _print_check(data["simulator_check"])
    return 0


def _print_check(check: dict | None) -> None:
    if check is None:
        return
    print(f"simulated signal: {check['contacts']} contacts of the simulator, {100 * check['found_share']:.1f} % of them "
          f"within {1e3 * check['tolerance_s']:g} ms of an impact, {100 * check['false_share']:.1f} % of the "
          f"{check['detected']} impacts false")
    if check["warning"]:
        print(f"warning: {check['warning']}")


# ---- ies modal-fit ------------------------------------------------------------------------------------------

def add_modal_fit_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies modal-fit`."""
    parser.add_argument("signal", metavar="SIGNAL.csv",
                        help="signal CSV with columns t (s), v_tip (m/s) and, unless --impacts, a_left, a_right, a_tip")
    parser.add_argument("--model", required=True, metavar="FILE|builtin",
                        help="modal model: a modal-model file (ies modes --save) or builtin (the seed rig, 9 modes)")
    parser.add_argument("--impacts", metavar="FILE.json",
                        help="impact times instead of the detector: a JSON object with a list 'impacts' of {\"t\": s} "
                             "(the output of ies impacts --json, or trace.json of ies trace)")
    add_detection_arguments(parser, threshold_default="1.0")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help="write Fig. 9b/10b: the tip velocity against its reconstruction")


def impact_times(path: str) -> Any:
    """The impact times (s) of a JSON file with a list 'impacts' of objects with 't' (one-line error otherwise)."""
    import numpy as np

    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        times = np.array([float(impact["t"]) for impact in data["impacts"]])
    except FileNotFoundError:
        raise SimulationInputError(f"--impacts {path}: file not found") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError):
        raise SimulationInputError(f"--impacts {path}: not a JSON object with a list 'impacts' of {{\"t\": seconds}} "
                                   "(as ies impacts --json or ies trace write)") from None
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise SimulationInputError(f"--impacts {path}: the impact list is empty or holds non-finite times")
    return np.sort(times)


def impacts_within_signal(times: Any, signal_path: str, impacts_path: str) -> Any:
    """The impact times (s) that lie within the signal's time span; none inside is one SimulationInputError line,
    some outside one warning line on stderr (they are dropped)."""
    from sim.analysis.signals import read_signal

    t = read_signal(signal_path).t
    inside = (times >= t[0]) & (times <= t[-1])
    if not inside.any():
        raise SimulationInputError(f"--impacts {impacts_path}: none of its {times.size} impact times "
                                   f"({times[0]:.6g} to {times[-1]:.6g} s) lies within the signal ({t[0]:.6g} to "
                                   f"{t[-1]:.6g} s); give the impacts of this signal (same time origin)")
    if not inside.all():
        sys.stderr.write(f"warning: {int((~inside).sum())} of the {times.size} impact times of {impacts_path} lie "
                         f"outside the signal ({t[0]:.6g} to {t[-1]:.6g} s) and are ignored\n")
    return times[inside]


def modal_fit_command(args: argparse.Namespace) -> int:
    """`ies modal-fit`: Eq. 9 fitted between impacts, modal energies after each (Sect. 5.5)."""
    from sim.common.files import dumps, report_written
    from sim.analysis.impacts import parse_thresholds
    from sim.analysis.modal_fit import fit_modes, load_model, plot_modal_fit

    model = load_model(args.model)
    given = impact_times(args.impacts) if args.impacts else None
    thresholds = parse_thresholds(args.threshold)
    if thresholds.size != 1:
        raise SimulationInputError(f"--threshold {args.threshold}: the fit needs one threshold factor, e.g. 1.0")
    if args.plot and not Path(args.plot).resolve().parent.is_dir():
        raise SimulationInputError(f"--plot {args.plot}: folder {Path(args.plot).parent} does not exist")
    if given is not None:
        given = impacts_within_signal(given, args.signal, args.impacts)
    settings = detection_settings(args)
    excitation = settings.pop("excitation_hz")
    fit = fit_modes(args.signal, model, given, excitation_hz=excitation, threshold=float(thresholds[0]),
                    **({} if given is not None else settings))
    data = fit.to_dict()
    data["simulator_check"] = None if given is not None else simulator_check(args.signal, fit.impacts)
    written = [plot_modal_fit(fit, args.plot)] if args.plot else []
    if args.json:
        print(dumps(data))
        report_written(written, json_mode=True)
        return 0
    good = [w for w in fit.windows if w.well_posed]
    print(f"# {args.signal}: {len(fit.windows)} windows after {fit.impacts.size} impacts "
          f"({'given' if given is not None else 'detected'}), {len(good)} well posed; {model.n_modes} modes "
          f"({model.source}); excitation {fit.excitation_hz:.3f} Hz")
    if good:
        import numpy as np

        energies = np.array([w.energies for w in good])
        share = energies / energies.sum(axis=1, keepdims=True)
        print(f"{'mode':>4} {'mean E after impacts (J)':>25} {'mean share':>11}")
        for j in range(model.n_modes):
            print(f"{j + 1:4d} {energies[:, j].mean():25.4e} {share[:, j].mean():11.4f}")
    if math.isfinite(fit.higher_share):
        print(f"share of modes 2..{model.n_modes} in the energy after impacts: {100 * fit.higher_share:.2f} %")
    else:
        print(f"share of modes 2..{model.n_modes} in the energy after impacts: not available (no well-posed window "
              "between impacts; see the warnings)")
    for line in fit.warnings[:MAX_WARNINGS_SHOWN]:
        print(f"warning: {line}")
    if len(fit.warnings) > MAX_WARNINGS_SHOWN:
        print(f"... and {len(fit.warnings) - MAX_WARNINGS_SHOWN} more warnings (all in --json)")
    _print_check(data["simulator_check"])
    report_written(written)
    return 0
