"""The measured host's words of the `ies` command line (registered in `sim.cli.COMMANDS`): `ies identify` (hammer
records or measured FRFs to modes, Appendix A), `ies update` (a model updated to them, Appendix A, Table A.1),
`ies linearity` (stepped sines at several levels to the damping interval, Appendix B) and `ies synthetic-tests` (a
synthetic measurement set of the rig to try them on). Heavy imports stay inside the functions (`ies --help` stays
fast); every user mistake is one `SimulationInputError` line, before anything is written.
"""
from __future__ import annotations

import argparse
import sys
from typing import Any, Callable

from sim.common.errors import SimulationInputError
from sim.common.options import figure_file, positive_int

IDENTIFY_HELP = ("modes of the host from hammer records or measured FRFs (CSV, UFF 58): H_v with coherence, LSCF "
                 "stabilization diagram, LSFD; modes.csv, frf.csv, figures (Appendix A, Fig. A.1)")
UPDATE_HELP = ("a host model updated to measured modes: stiffness scale (E) fitted to a mode, errors per mode, measured "
               "damping (Appendix A, Table A.1); writes a modal-model file")
LINEARITY_HELP = ("stepped sines of the host alone at several levels: half-power damping, single nonlinear mode, the "
                  "damping interval over a response range (Appendix B, Fig. B.2)")
SYNTHETIC_HELP = ("a synthetic measurement set of the rig (hammer record with noise and a double hit; five shaker levels "
                  "with friction at the clamp) for identify, update, linearity")

FREQUENCY_UNITS = {"Hz": 1.0, "kHz": 1e3}


def _span(text: str, units: dict[str, float], si: str, option: str, example: str) -> tuple[float, float]:
    """'LO:HI' with optional units (a plain number is SI) -> (lo, hi)."""
    from sim.common.units import Quantity, parse_quantity

    quantity = Quantity(option, si, units, (0.0, float("inf")), example)
    parts = text.split(":")
    if len(parts) != 2:
        raise SimulationInputError(f"{option} {text!r}: give LO:HI, e.g. {option} {example}")
    lo, hi = (parse_quantity(p, quantity) for p in parts)
    if not 0 < lo < hi:
        raise SimulationInputError(f"{option} {text!r}: give 0 < LO < HI, e.g. {option} {example}")
    return lo, hi


def _ratio(text: str, option: str) -> float:
    """A damping ratio as a number or a percentage ('0.1%')."""
    try:
        value = float(text[:-1]) / 100 if text.strip().endswith("%") else float(text)
    except ValueError:
        raise SimulationInputError(f"{option} {text!r}: give a damping ratio, e.g. 0.001 or 0.1%") from None
    if not 0 < value < 1:
        raise SimulationInputError(f"{option} {text!r}: a damping ratio lies in (0, 1), e.g. 0.001 or 0.1%")
    return value


# ---- ies identify ----------------------------------------------------------------------------------------------

def add_identify_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies identify`."""
    parser.add_argument("files", nargs="+", metavar="FILE",
                        help="hammer records (CSV time_s,force_N,accel_m_s2,...; UFF 58 time data) or measured FRFs "
                             "(CSV frequency_Hz,NAME_real_m_N,NAME_imag_m_N; UFF 58 FRFs)")
    parser.add_argument("--out", default="ies-out/identify", metavar="DIR",
                        help="write modes.csv, frf.csv, poles.csv, identification.json, stabilization.png, frf.png "
                             "(default ies-out/identify)")
    parser.add_argument("--band", metavar="LO:HI", help="frequency band of the identification, e.g. 50:6400 or "
                                                        "50Hz:6.4kHz (default: 20 Hz to 78 %% of the Nyquist frequency, "
                                                        "for FRF files of their last line)")
    parser.add_argument("--modes", type=positive_int, metavar="N", help="keep the N modes with the highest peaks")
    parser.add_argument("--max-order", dest="max_order", type=positive_int, default=20, metavar="N",
                        help="highest LSCF order of each sub-band (default 20)")
    parser.add_argument("--method", choices=("lscf", "sdypy"), default="lscf",
                        help="pole estimator: lscf (the workbench's) or sdypy (sdypy-EMA's LSCF; pip install "
                             "'.[measured]'); both with the same stabilization, choice of poles and LSFD")
    parser.add_argument("--estimator", choices=("Hv", "H1", "H2"), default="Hv",
                        help="FRF estimator of hammer records (default Hv, the paper's)")
    parser.add_argument("--block", type=positive_int, metavar="N", help="samples per hit (default: the shortest spacing)")
    parser.add_argument("--exp-window", dest="exp_window", type=float, default=0.01, metavar="END",
                        help="exponential window's value at the block's end (default 0.01; 1: none); its damping is "
                             "taken out of the poles")
    parser.add_argument("--keep-double-hits", dest="keep_double_hits", action="store_true",
                        help="average double hits too (default: reject them, and say so)")
    parser.add_argument("--json", action="store_true", help="print one JSON object (frequencies_hz, damping_ratios, ...)")
    parser.add_argument("--force", action="store_true", help="write into a non-empty --out folder")


def expand(table: Any, names: list[str]) -> list[str]:
    """The CSV header of a table of `sim.measured.tables`, each "<NAME>" column once per response name (a row naming
    two columns, "a, b", gives both)."""
    out = []
    for column in table.columns:
        for name in (c.strip() for c in column.name.split(",")):
            out += [name.replace("<NAME>", n) for n in names] if "<NAME>" in name else [name]
    return out


def identify_command(args: argparse.Namespace, output_folder: Callable[..., Any]) -> int:
    """`ies identify`: read, estimate, identify (all before writing), then write the outputs."""
    import numpy as np

    from sim.common.files import dumps, report_written, write_csv, write_json
    from sim.measured.figures import draw_frf, draw_stabilization
    from sim.measured.hammer import HammerSettings, frf_estimate
    from sim.measured.identification import Band, identify
    from sim.measured.records import read_hammer_inputs
    from sim.measured.tables import FRF_CSV, MODES_CSV, POLES_CSV

    band_given = _span(args.band, FREQUENCY_UNITS, "Hz", "--band", "50:6400") if args.band else None
    settings = HammerSettings(block=args.block, exp_window_end=args.exp_window,
                              reject_double_hits=not args.keep_double_hits)
    records, frfs = read_hammer_inputs(args.files)
    source = ", ".join(args.files)
    hits, decay, estimator = [], 0.0, "measured FRFs"
    if records:
        estimate = frf_estimate(records, settings)
        frequencies = estimate.frequencies_hz
        chosen = {"Hv": estimate.Hv, "H1": estimate.H1, "H2": estimate.H2}[args.estimator]
        names, frf, coherence = estimate.names, chosen, estimate.coherence
        hits, decay, estimator = estimate.hits, estimate.window_decay, args.estimator
        fs = estimate.fs
    else:
        if len(frfs) > 1:
            raise SimulationInputError(f"{args.files[1]}: give measured FRFs in one file (several responses as columns)")
        frequencies, frf, coherence, names = frfs[0].frequencies_hz, frfs[0].frf, frfs[0].coherence, list(frfs[0].frf)
        decay = frfs[0].window_decay
        fs = 2 * float(frequencies[-1])  # the last line taken as the analyser's Nyquist frequency
    band = Band(*band_given) if band_given else Band(max(20.0, 4 * float(frequencies[0])),
                                                     min(0.78 * fs / 2, float(frequencies[-1])))
    matrix = np.array([frf[name] for name in names])
    result = identify(frequencies, matrix, names, band, modes=args.modes, max_order=args.max_order,
                      window_decay=decay, source=source, method=args.method)
    summary = {
        "frequencies_hz": result.frequencies_hz, "damping_ratios": result.damping_ratios,
        "modal_constants_per_kg": {n: result.modal_constants[o].real for o, n in enumerate(names)},
        "complexity": {n: result.complexity[o] for o, n in enumerate(names)},
        "band_hz": [band.lo, band.hi], "estimator": estimator, "inputs": list(args.files),
        "window_decay_per_s": decay, "block_samples": estimate.block if records else None,
        "hits": [h.describe(fs) for h in hits], "max_order": args.max_order, "method": args.method,
        "units": {"frequencies_hz": "Hz", "damping_ratios": "1", "modal_constants_per_kg": "1/kg (displacement per force)",
                  "window_decay_per_s": "1/s (added by the exponential window, taken out of the damping)"},
    }
    with output_folder(args.out, args.force) as folder:
        rows = [[j + 1, result.frequencies_hz[j], result.damping_ratios[j],
                 *(result.modal_constants[o, j].real for o in range(len(names)))] for j in range(result.frequencies_hz.size)]
        written = [write_csv(folder / "modes.csv", expand(MODES_CSV, names), rows)]
        columns = ["frequency_Hz"] + [c for n in names for c in expand(FRF_CSV, [n])[1:]
                                       if n in coherence or not c.endswith("_coherence")]
        data = [frequencies]
        for n in names:
            data += [frf[n].real, frf[n].imag] + ([coherence[n]] if n in coherence else [])
        # the exponential window's decay rate, for a later `ies identify frf.csv` (sim.measured.records)
        written.append(write_csv(folder / "frf.csv", columns, np.column_stack(data),
                                 comment=f"window_decay_per_s = {float(decay)!r}" if decay else ""))
        d = result.diagram
        written.append(write_csv(folder / "poles.csv", list(POLES_CSV.names),
                                 zip(d.order, d.frequency_hz, d.damping_ratio, d.status)))
        written.append(write_json(folder / "identification.json", summary))
        magnitude = np.sum(np.abs(matrix), axis=0)
        written.append(draw_stabilization(folder / "stabilization.png", result, magnitude))
        written.append(draw_frf(folder / "frf.png", frequencies, {n: frf[n] for n in names}, result.synthesized,
                                coherence, "synthesized", (band.lo, band.hi)))
    if args.json:
        sys.stdout.write(dumps(summary) + "\n")
    else:
        rejected = [h for h in hits if not h.used]
        if hits:
            sys.stdout.write(f"{len(hits)} hit(s), {len(hits) - len(rejected)} averaged ({estimator})"
                             + "".join(f"; rejected at t = {h.start / fs:.3g} s: {h.note or 'double hit'}" for h in rejected)
                             + "\n")
        sys.stdout.write(f"{'mode':>4} {'f (Hz)':>10} {'D (%)':>8}\n")
        for j, (f, D) in enumerate(zip(result.frequencies_hz, result.damping_ratios)):
            sys.stdout.write(f"{j + 1:>4} {f:>10.2f} {100 * D:>8.4f}\n")
    report_written(written, json_mode=args.json)
    return 0


# ---- ies update ------------------------------------------------------------------------------------------------

def add_update_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies update`: the host options of every simulation command, or MODEL as a shorthand."""
    from sim.hosts.sources import add_host_arguments

    parser.add_argument("model_word", nargs="?", metavar="MODEL",
                        help="rig (the built-in beam, default), solid (the 3D model) or a model file (as --model)")
    parser.add_argument("--measured", required=True, metavar="modes.csv", help="the modes.csv of `ies identify`; with modal constants at 3 or more points that "
                        "the model file's [shapes] table names, modes pair by MAC as well as frequency")
    parser.add_argument("--out", required=True, metavar="FILE.toml", help="write the updated modal-model file")
    parser.add_argument("--fit-mode", dest="fit_mode", default="1", metavar="N|all",
                        help="measured mode the stiffness scale matches (default 1, as the paper), or all (least squares)")
    parser.add_argument("--E0", dest="E0", metavar="E", help="the model's elastic modulus, e.g. 210GPa (known for the "
                                                             "built-in rig and the solid)")
    parser.add_argument("--default-damping", dest="default_damping", default="0.1%", metavar="D",
                        help="damping ratio of the modes not measured (default 0.1%%, the paper's)")
    parser.add_argument("--pair-tolerance", dest="pair_tolerance", type=float, default=0.15, metavar="R",
                        help="largest relative frequency distance of a measured mode to its model mode (default 0.15)")
    parser.add_argument("--frf", metavar="frf.csv", help="with --plot: the measured FRF (identify's frf.csv) to compare")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help="Fig. A.1: the measured FRF against the updated model's (seen through the measurement's "
                             "exponential window), with the coherence (needs --frf)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    add_host_arguments(parser)


def _model_and_E0(args: argparse.Namespace) -> tuple[Any, float | None, str, str | None]:
    """The model to update, its E_0 (Pa, or None), a word for the report and its modal file (None: built)."""
    from sim.hosts.sources import HOST_OPTIONS, HOST_SOURCES, resolve_host

    options = {k: getattr(args, k) for k in HOST_OPTIONS if hasattr(args, k)}
    options.update({row.dest: getattr(args, row.dest, None) for row in HOST_SOURCES.values() if row.flag})
    word = args.model_word
    if word is not None:
        if any(options.get(row.dest) for row in HOST_SOURCES.values() if row.flag):
            raise SimulationInputError(f"MODEL {word!r} and a host option (--model, --solid, --from-calculix) name the "
                                       "model twice; give one")
        if word == "solid":
            options["solid"] = True
        elif word != "rig":
            options["model"] = word
    host = resolve_host(options)
    E0, what = None, "model file"
    if not any(options.get(row.dest) for row in HOST_SOURCES.values() if row.flag):
        from sim.hosts.rig import DEFAULT_VARIANT, variant_parameters

        E0, what = variant_parameters(args.variant or DEFAULT_VARIANT).E, "built-in rig"
        if args.joint_stiffness is not None and host.provenance:
            E0 = host.provenance["updated_parameters"]["E_Pa"]
    elif options.get("solid"):
        from sim.hosts.sources import solid_geometry

        E0, what = solid_geometry(args.geometry)[1].E, "3D solid"
    return host.model, E0, what, options.get("model")


def update_command(args: argparse.Namespace) -> int:
    """`ies update`: pair, scale, damp, write."""
    from sim.common.files import check_writable, dumps, report_written, to_jsonable
    from sim.common.units import Quantity, parse_quantity
    from sim.hosts.modal_file import load_shapes, save_modal_model
    from sim.measured.update import read_modes, update_model

    measured = read_modes(args.measured)
    fit_mode = None if args.fit_mode == "all" else _int(args.fit_mode, "--fit-mode")
    default = _ratio(args.default_damping, "--default-damping")
    if args.plot and not args.frf:
        raise SimulationInputError("--plot draws the measured FRF against the model's: give --frf frf.csv too")
    frf = None
    if args.frf:
        from sim.measured.records import read_frf_csv

        frf = read_frf_csv(args.frf)
    check_writable(args.out, "--out")
    if args.plot:
        check_writable(args.plot, "--plot")
    model, E0, what, model_file = _model_and_E0(args)
    shapes = load_shapes(model_file, model.n_modes) if model_file else {}
    if args.E0:
        E0 = parse_quantity(args.E0, Quantity("--E0", "Pa", {"Pa": 1.0, "MPa": 1e6, "GPa": 1e9}, (1e6, 1e13), "210GPa"))
    result = update_model(model, measured, fit_mode=fit_mode, E_0=E0, default_damping=default,
                          tolerance=args.pair_tolerance,
                          source=f"{model.source}, updated to {measured.source} (ies update)", shapes=shapes)
    rows = [{"measured_mode": i + 1, "model_mode": int(j) + 1, "measured_hz": float(measured.frequencies_hz[i]),
             "model_hz": float(result.before_hz[j]), "updated_hz": float(result.model.frequencies_hz[j]),
             "error": float(result.errors[i]), "damping_ratio": float(measured.damping_ratios[i]),
             **({} if result.mac is None else {"mac": float(result.mac[i])})}
            for i, j in enumerate(result.pairs)]
    paired_by = (f"frequency and shape (MAC at {', '.join(result.mac_points)})" if result.mac_points else "frequency")
    # TOML has no null: E_0 and E are left out for a model whose modulus is unknown (a modal file without --E0)
    provenance = to_jsonable({"updated_by": "ies update (sim.measured.update, Appendix A)", "measured": measured.source,
                              "model": what, "stiffness_scale": result.scale, "E_0_Pa": E0, "E_Pa": result.E,
                              "fit_mode": args.fit_mode, "default_damping": default, "paired_by": paired_by,
                              "pairs": rows,
                              **({"note": result.note} if result.note else {})})
    provenance = {k: v for k, v in provenance.items() if v is not None}
    written = [save_modal_model(result.model, args.out, provenance, shapes)]
    if args.plot:
        from sim.measured.figures import draw_frf
        from sim.measured.update import model_frf

        name = next(iter(frf.frf))
        f = frf.frequencies_hz
        written.append(draw_frf(args.plot, f, {name: frf.frf[name]}, {name: model_frf(result.model, f, frf.window_decay)}, frf.coherence,
                                "updated model", (max(20.0, 4 * float(f[0])), 0.78 * float(f[-1]))))
    summary = {"E_Pa": result.E, "E_0_Pa": E0, "stiffness_scale": result.scale, "paired_by": paired_by, "pairs": rows,
               "frequency_errors": result.errors, "frequencies_hz": result.model.frequencies_hz,
               "damping_ratios": result.model.damping_ratios, "note": result.note}
    if args.json:
        sys.stdout.write(dumps(summary) + "\n")
    else:
        E = (f"E = {result.E / 1e9:.4g} GPa (from {E0 / 1e9:.4g} GPa), " if result.E else "") + \
            f"stiffness scale {result.scale:.5f}"
        sys.stdout.write(f"{what} updated to {measured.source}: {E}; modes paired by {paired_by}\n")
        mac = result.mac is not None
        sys.stdout.write(f"{'mode':>4} {'measured (Hz)':>14} {'model (Hz)':>11} {'updated (Hz)':>13} {'error (%)':>10} "
                         f"{'D (%)':>7}" + (f" {'MAC':>6}" if mac else "") + "\n")
        for r in rows:
            sys.stdout.write(f"{r['model_mode']:>4} {r['measured_hz']:>14.2f} {r['model_hz']:>11.2f} "
                             f"{r['updated_hz']:>13.2f} {100 * r['error']:>+10.3f} {100 * r['damping_ratio']:>7.3f}"
                             + (f" {r['mac']:>6.3f}" if mac else "") + "\n")
        others = [j + 1 for j in range(result.model.n_modes) if not result.damping_measured[j]]
        if others:
            sys.stdout.write(f"modes {', '.join(map(str, others))}: damping {100 * default:g} % (not measured)\n")
        if result.note:
            sys.stdout.write(result.note + "\n")
    report_written(written, json_mode=args.json)
    return 0


def _int(text: str, option: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise SimulationInputError(f"{option} {text!r}: give a mode number (1, 2, ...) or all") from None


# ---- ies linearity ---------------------------------------------------------------------------------------------

def add_linearity_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies linearity`."""
    parser.add_argument("files", nargs="+", metavar="FILE",
                        help="one stepped-sine record per level: CSV frequency_Hz,amplitude_m,a_base_m (or real_m, "
                             "imag_m), or time records time_s,frequency_Hz,base_UNIT,tip_UNIT")
    parser.add_argument("--range", dest="span", default="0.58mm:0.95mm", metavar="LO:HI",
                        help="response range of the damping interval, tip amplitude (default 0.58mm:0.95mm, the paper's)")
    parser.add_argument("--out", default="ies-out/linearity", metavar="DIR",
                        help="write levels.csv, backbone.csv, linearity.json, linearity.png (default ies-out/linearity)")
    parser.add_argument("--model", metavar="FILE", help="a modal-model file whose [host] damping interval to set")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--write", metavar="FILE2", help="write the model with the interval to FILE2")
    where.add_argument("--in-place", dest="in_place", action="store_true", help="rewrite --model itself")
    parser.add_argument("--set-nominal", dest="set_nominal", action="store_true",
                        help="also set the model's D_1 (damping_ratios[0], the nominal D_1*) to the nominal measured "
                             "over the range")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--force", action="store_true", help="write into a non-empty --out folder")


def linearity_command(args: argparse.Namespace, output_folder: Callable[..., Any]) -> int:
    """`ies linearity`: per level, the nonlinear mode, the interval; then the files."""
    from dataclasses import replace

    import numpy as np

    from sim.common.files import check_writable, dumps, report_written, write_csv, write_json
    from sim.common.units import LENGTH_UNITS
    from sim.hosts.modal_file import load_modal_model, load_provenance, load_shapes, save_modal_model
    from sim.measured.figures import draw_linearity
    from sim.measured.linearity import damping_interval, fit_nonlinear_mode, half_power, read_level
    from sim.measured.tables import BACKBONE_CSV, LEVELS_CSV

    a_lo, a_hi = _span(args.span, LENGTH_UNITS, "m", "--range", "0.58mm:0.95mm")
    if (args.write or args.in_place or args.set_nominal) and not args.model:
        raise SimulationInputError("--write, --in-place and --set-nominal change a modal-model file: give --model FILE")
    if args.model and not (args.write or args.in_place):
        raise SimulationInputError("--model FILE: say where the interval goes, --write FILE2 or --in-place")
    model = load_modal_model(args.model) if args.model else None
    target = args.model if args.in_place else args.write
    if target:
        check_writable(target, "--write" if args.write else "--in-place")
    levels = sorted((read_level(p) for p in args.files), key=lambda lv: lv.a_base)
    if len(levels) < 2:
        raise SimulationInputError(f"{args.files[0]}: one level only; the amplitude dependence needs two or more levels")
    halves = [half_power(lv) for lv in levels]
    mode = fit_nonlinear_mode(levels)
    measured = (min(float(lv.amplitude.max()) for lv in levels), max(float(lv.amplitude.max()) for lv in levels))
    interval = damping_interval(mode, a_lo, a_hi, measured)
    updated = None
    if model is not None:
        damping = model.damping_ratios.copy()
        if args.set_nominal:
            damping[0] = interval.nominal
        try:
            updated = replace(model, damping_ratios=damping, damping_interval=(interval.low, interval.high),
                              nominal_damping=None)
        except SimulationInputError as exc:
            raise SimulationInputError(f"{args.model}: {exc}; or pass --set-nominal to take the measured nominal "
                                       f"{100 * interval.nominal:.4g} %") from None
    amp = np.linspace(0.0, 1.05 * measured[1], 43)[1:]
    summary = {
        "levels": [{"source": lv.source, "a_base_m": lv.a_base, "resonance_hz": h.frequency_hz,
                    "half_power_damping_ratio": h.damping_ratio, "peak_amplitude_m": h.peak_amplitude}
                   for lv, h in zip(levels, halves)],
        "nonlinear_mode": {"f0_hz": mode.omega_0 / (2 * np.pi), "frequency_coefficients": mode.c, "D0": mode.D_0,
                           "damping_coefficients": mode.d, "G": mode.G, "a_ref_m": mode.a_ref},
        "range_m": [a_lo, a_hi], "damping_interval": [interval.low, interval.high], "nominal_damping": interval.nominal,
        "extrapolated": interval.extrapolated, "frequency_shift": float(mode.omega(measured[1]) / mode.omega_0 - 1),
        "units": {"range_m": "m (tip amplitude)", "damping_interval": "1", "nominal_damping": "1",
                  "frequency_shift": "1 (omega(largest measured a) / omega_0 - 1)"},
    }
    if interval.extrapolated:
        sys.stderr.write(f"warning: the range {1e3 * a_lo:g}-{1e3 * a_hi:g} mm reaches beyond the measured peak amplitudes "
                         f"({1e3 * measured[0]:.3g}-{1e3 * measured[1]:.3g} mm): the interval is extrapolated\n")
    with output_folder(args.out, args.force) as folder:
        written = [write_csv(folder / "levels.csv", list(LEVELS_CSV.names),
                             [[lv.a_base, h.frequency_hz, h.damping_ratio, h.peak_amplitude] for lv, h in zip(levels, halves)]),
                   write_csv(folder / "backbone.csv", list(BACKBONE_CSV.names),
                             zip(amp, mode.omega(amp) / (2 * np.pi), mode.damping(amp))),
                   write_json(folder / "linearity.json", summary),
                   draw_linearity(folder / "linearity.png", levels, mode, halves, interval)]
        if updated is not None:
            provenance = load_provenance(args.model)
            provenance["damping_interval"] = {"by": "ies linearity (sim.measured.linearity, Appendix B)",
                                              "records": list(args.files), "range_m": [a_lo, a_hi],
                                              "nominal_set": bool(args.set_nominal)}
            written.append(save_modal_model(updated, target, provenance, load_shapes(args.model, updated.n_modes)))
    if args.json:
        sys.stdout.write(dumps(summary) + "\n")
    else:
        sys.stdout.write(f"{'a_base (m)':>11} {'f_r (Hz)':>10} {'D_hp (%)':>9} {'a_peak (mm)':>12}\n")
        for lv, h in zip(levels, halves):
            sys.stdout.write(f"{lv.a_base:>11.3g} {h.frequency_hz:>10.3f} {100 * h.damping_ratio:>9.4f} "
                             f"{1e3 * h.peak_amplitude:>12.4f}\n")
        sys.stdout.write(f"single nonlinear mode: f0 = {mode.omega_0 / (2 * np.pi):.3f} Hz, shift "
                         f"{100 * summary['frequency_shift']:+.3f} % at {1e3 * measured[1]:.3g} mm\n")
        sys.stdout.write(f"D_1 over {1e3 * a_lo:g}-{1e3 * a_hi:g} mm: {100 * interval.low:.4g}-{100 * interval.high:.4g} %, "
                         f"nominal {100 * interval.nominal:.4g} %\n")
    report_written(written, json_mode=args.json)
    return 0


# ---- ies synthetic-tests -----------------------------------------------------------------------------------------

def add_synthetic_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies synthetic-tests`."""
    parser.add_argument("--out", default="ies-out/rig-tests", metavar="DIR",
                        help="write hammer.csv, level-1.csv ... level-5.csv, truth.json (default ies-out/rig-tests)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the noise and the hits (default 1)")
    parser.add_argument("--force", action="store_true", help="write into a non-empty --out folder")


def synthetic_command(args: argparse.Namespace, output_folder: Callable[..., Any]) -> int:
    """`ies synthetic-tests`: the set of `sim.measured.synthetic.rig_test_set`, written."""
    from sim.common.files import report_written
    from sim.measured.synthetic import write_rig_test_set

    with output_folder(args.out, args.force) as folder:
        written = write_rig_test_set(folder, seed=args.seed)
    report_written(written)
    return 0


def commands(output_folder: Callable[..., Any]) -> tuple:
    """(name, help, add_arguments, run) of each command, for `sim.cli.COMMANDS`; output_folder: `sim.cli`'s --out
    handling (created up front, proved writable, removed after a failure)."""
    return (("identify", IDENTIFY_HELP, add_identify_arguments, lambda a: identify_command(a, output_folder)),
            ("update", UPDATE_HELP, add_update_arguments, update_command),
            ("linearity", LINEARITY_HELP, add_linearity_arguments, lambda a: linearity_command(a, output_folder)),
            ("synthetic-tests", SYNTHETIC_HELP, add_synthetic_arguments, lambda a: synthetic_command(a, output_folder)))
