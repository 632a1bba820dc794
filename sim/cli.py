"""The simulation stage's words of the `ies` command line: `modes`, `sweep`, `overview`, `trace`.

* `ies modes`: the modal model of the host structure (seed paper Sect. 3.1, Eq. 7, Appendix A), the built-in
  model of the seed rig (`sim.hosts.rig`) or a modal-model file (`sim.hosts.modal_file`); --save writes it as a file.
* `ies sweep`: a stepped-sine frequency response like Fig. 5 (Sects. 5.1, 5.2).
* `ies overview`: the resonant response level against the excitation level, like Fig. 6 (Sect. 5.3).
* `ies trace`: time histories of one stepped-sine point, like Figs. 4 and 9a (Sects. 5.1, 5.5; `sim.analysis.trace`).
* `ies impacts`, `ies modal-fit`: the analyses of measured or simulated signals (`sim.analysis.cli`).

`add_commands(subparsers)` (at the end) registers them with the front door (`uq.cli`), which only dispatches. Heavy
imports (numpy, numba) stay inside the functions, so that `ies --help` stays fast. Every bad value ends in
one `SimulationInputError` line.
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Sequence

from sim.analysis import cli as signal_cli
from sim.common.errors import SimulationInputError
from sim.common.options import clearance, figure_file, friction_coefficient, hertz_constant, positive_int, tangential_stiffness

MODES_HELP = "modal model of the host structure: frequencies, damping, mode values, participation (built-in rig or file)"
SWEEP_HELP = "stepped-sine frequency response (mean and max amplitude per eta, spread over repetitions; Fig. 5)"
OVERVIEW_HELP = "resonant response level (largest mean and max over eta) vs excitation level a_base/a_base* (Fig. 6)"
TRACE_HELP = ("time histories of one stepped-sine point sampled at --fs: tip, walls, sphere, accelerations, contact "
              "forces (CSV + JSON; Figs. 4, 9a)")

SEQUENCE_CHOICES = ("up", "down", "up-down-up", "up-down-up-down-up")


# ---- ies modes ----------------------------------------------------------------------------------------------

def add_modes_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies modes`."""
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--save", metavar="FILE", help="write the model as a modal-model file (.toml)")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--model", metavar="FILE", help="read a modal-model file instead of the built-in seed rig")
    source.add_argument("--solid", action="store_true",
                        help="the rig as a 3D solid finite-element model (sim.hosts.solid; needs pip install '.[solid]')")
    source.add_argument("--from-calculix", dest="from_calculix", metavar="JOB.frd",
                        help="mode shapes of a CalculiX *FREQUENCY job (ASCII .frd; with --mesh JOB.inp and the node "
                             "sets --wall-left, --wall-right, --tip; participation from JOB.dat)")
    parser.add_argument("--variant", default=None, metavar="NAME",
                        help="updating variant of the built-in rig: joint-spring (default) or effective-modulus; "
                             "with --solid a variant of the solid model (sim.hosts.variants.SOLID_VARIANTS: beam-neck, "
                             "updated, updated-400, updated-contact+2mm, updated-contact+4mm, updated-hertz-patch, "
                             "updated-patch-3mm)")
    parser.add_argument("--n-modes", dest="n_modes", type=int, default=9, metavar="N",
                        help="x-bending modes to keep (default 9, as the paper; built-in rig, --solid, --from-calculix)")
    parser.add_argument("--joint-stiffness", dest="joint_stiffness", type=float, default=None, metavar="N_PER_M",
                        help="built-in rig, variant joint-spring: fix the beam-block joint's translational stiffness "
                             "(N/m; inf = rigid) and re-update E and the neck to f1..f4 and f9 (10-60 s)")
    solid = parser.add_argument_group("3D solid model (--solid) and CalculiX (--from-calculix)")
    solid.add_argument("--mesh", metavar="LEVEL|JOB.inp",
                       help="--solid: mesh level coarse (default, ~1 min), medium or fine; --from-calculix: the job's .inp")
    solid.add_argument("--geometry", metavar="FILE",
                       help="--solid: TOML file with [geometry] (sim.hosts.solid.SolidGeometry fields, m) and [material] "
                            "(E in Pa, nu, rho in kg/m^3) tables; missing keys keep the rig's defaults")
    solid.add_argument("--patch-radius", dest="patch_radius", type=float, default=0.0, metavar="M",
                       help="--solid: average the wall values over a circle of this radius (m) on each wall face")
    solid.add_argument("--wall-left", dest="wall_left", metavar="NSET", help="--from-calculix: node set of the left wall")
    solid.add_argument("--wall-right", dest="wall_right", metavar="NSET", help="--from-calculix: node set of the right wall")
    solid.add_argument("--tip", metavar="NSET", help="--from-calculix: node set of the measurement point")
    solid.add_argument("--dat", metavar="JOB.dat", help="--from-calculix: the job's .dat (default: beside the .frd)")
    solid.add_argument("--floor", metavar="NSET",
                       help="--from-calculix: node set of the cavity floor under the sphere (phi_floor, for friction)")
    solid.add_argument("--beam-mass", dest="beam_mass", type=float, metavar="KG",
                       help="--from-calculix: mass of the beam's free length without the block in kg (for Eq. 10)")
    solid.add_argument("--units", default="m-kg-s", choices=("m-kg-s", "mm-t-s"),
                       help="--from-calculix: the job's consistent units (default m-kg-s)")


def describe_modes(model: Any, rig: Any = None) -> dict:
    """The JSON object of `ies modes --json` (Sect. 3.1, Eq. 7; Sect. 5 for a_base*; SI units): the model's
    arrays, the modal mass ratio, a_base*, the paper's ode3 step dt = 2 pi/(15 omega_n), and with the
    built-in rig (`sim.hosts.rig.RigModes`) its updating summary (Appendix A)."""
    import numpy as np

    from sim.model.system import SPHERE_MASS, a_base_star

    phi_c = model.phi_contact
    data = {
        "source": model.source,
        "n_modes": model.n_modes,
        "frequencies_hz": model.frequencies_hz,
        "damping_ratios": model.damping_ratios,
        "phi_wall_left": model.phi_wall_left,
        "phi_wall_right": model.phi_wall_right,
        "phi_tip": model.phi_tip,
        "participation": model.participation,
        "modal_mass_ratio": SPHERE_MASS * phi_c**2,
        "phi_tip_over_phi_c": float(model.phi_tip[0] / phi_c),
        "phi_floor": model.phi_floor,
        "beam_mass_kg": model.beam_mass,
        "a_base_star": a_base_star(model),
        "dt": 2.0 * np.pi / (15.0 * float(model.omega[-1])),
        "units": {"frequencies_hz": "Hz", "damping_ratios": "1", "phi": "1/sqrt(kg)", "participation": "sqrt(kg)",
                  "beam_mass_kg": "kg (free length without block; null if unknown)", "a_base_star": "m", "dt": "s", "modal_mass_ratio": "1 (sphere mass m_a = %g kg)" % SPHERE_MASS},
    }
    if rig is not None:
        data["rig"] = rig.summary()
    return data


def modes_table(data: dict) -> str:
    """The table `ies modes` prints, from `describe_modes`."""
    lines = [f"modal model: {data['source']}",
             f"{'mode':>4} {'f (Hz)':>11} {'D (%)':>7} {'phi_l':>9} {'phi_r':>9} {'phi_tip':>9} {'phi^T M b':>10}"]
    for j in range(data["n_modes"]):
        lines.append(f"{j + 1:>4} {data['frequencies_hz'][j]:>11.2f} {100 * data['damping_ratios'][j]:>7.3f} "
                     f"{data['phi_wall_left'][j]:>9.4f} {data['phi_wall_right'][j]:>9.4f} {data['phi_tip'][j]:>9.4f} "
                     f"{data['participation'][j]:>10.4f}")
    lines.append("mode values in 1/sqrt(kg), participation in sqrt(kg)")
    if data["phi_floor"] is not None:
        lines.append("phi at the cavity floor (friction, App. C): " + " ".join(f"{v:.4f}" for v in data["phi_floor"]))
    if data["beam_mass_kg"] is not None:
        paper = f" (paper: ca. {data['rig']['beam_mass_paper_kg']:g} kg)" if data.get("rig") else ""
        lines.append(f"beam mass (free length without block, Eq. 10): {data['beam_mass_kg']:.4f} kg{paper}")
    lines.append(f"modal mass ratio m_a phi_c^2 = {100 * data['modal_mass_ratio']:.2f} %   "
                 f"phi_tip/phi_c = {data['phi_tip_over_phi_c']:.4f}")
    lines.append(f"a_base* = {data['a_base_star']:.4e} m   ode3 step dt = 2 pi/(15 omega_{data['n_modes']}) = {data['dt']:.4e} s")
    rig = data.get("rig")
    if rig:
        errors = ", ".join(f"{round(100 * e, 4) + 0.0:+.4f} %" for e in rig["f_model_error"])
        p = rig["updated_parameters"]
        joint = p.get("joint_translational_stiffness_N_per_m")
        lines.append(f"updated: E = {p['E_Pa'] / 1e9:.2f} GPa, neck {1e3 * p['neck_length_m']:.2f} mm long, "
                     f"{1e3 * p['neck_width_x_m']:.2f} x {1e3 * p['neck_width_y_m']:.2f} mm (x, y), joint "
                     + ("rigid" if joint is None else f"spring {joint:.4g} N/m"))
        lines.append(f"f1..f4 vs Table A.1: {errors}")
        if "f9_hz" in rig:
            lines.append(f"f9 = {rig['f9_hz']:.0f} Hz (paper's 3D model: {rig['f9_paper_hz']:.0f} Hz)")
    return "\n".join(lines)


def _solid_geometry(path: str | None) -> tuple[Any, Any]:
    """(SolidGeometry, SolidMaterial) of a --geometry TOML file (the rig's defaults without one)."""
    import dataclasses
    import tomllib

    from sim.hosts.solid import SolidGeometry, SolidMaterial

    if path is None:
        return SolidGeometry(), SolidMaterial()
    try:
        doc = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise SimulationInputError(f"{path}: not valid TOML ({exc})") from None
    unknown = set(doc) - {"geometry", "material"}
    if unknown:
        raise SimulationInputError(f"{path}: unknown table(s) {', '.join(sorted(unknown))}; use [geometry] and [material]")
    built = []
    for table, cls in (("geometry", SolidGeometry), ("material", SolidMaterial)):
        values = doc.get(table, {})
        fields = {f.name for f in dataclasses.fields(cls)}
        wrong = set(values) - fields
        if wrong:
            raise SimulationInputError(f"{path}: unknown key(s) {', '.join(sorted(wrong))} in [{table}]; "
                                       f"known: {', '.join(sorted(fields))}")
        built.append(cls(**values))
    return tuple(built)


def _external_model(args: argparse.Namespace) -> tuple[Any, dict | None, list[str]]:
    """(model, provenance, report lines) of --solid or --from-calculix."""
    import sys

    if args.variant is not None and not args.solid:
        raise SimulationInputError("--variant with --from-calculix: the job defines the model; drop --variant")
    if args.solid:
        from sim.hosts.solid import MESH_LEVELS, solid_rig_model
        from sim.hosts.variants import SOLID_VARIANTS, solid_variant_model

        level = args.mesh or "coarse"
        if level not in MESH_LEVELS:
            raise SimulationInputError(f"--mesh {level!r}: with --solid give a mesh level ({', '.join(MESH_LEVELS)})")
        if not (args.patch_radius >= 0):
            raise SimulationInputError(f"--patch-radius must be >= 0 (m), got {args.patch_radius!r}")
        if args.variant is not None and args.variant not in SOLID_VARIANTS:
            raise SimulationInputError(f"--variant {args.variant!r} is not a solid-model variant; choose one of "
                                       f"{', '.join(SOLID_VARIANTS)}")
        if args.variant is not None and (args.geometry or args.patch_radius):
            raise SimulationInputError("--variant fixes the solid model's geometry and contact point; drop --geometry "
                                       "and --patch-radius, or drop --variant")
        geometry, material = _solid_geometry(args.geometry)  # a bad geometry file: one line before any work
        sys.stderr.write(f"solving the 3D solid model ({level} mesh and a coarser one for the convergence check; "
                         "about 1-3 min) ...\n")
        if args.variant is not None:
            result = solid_variant_model(args.variant, level, n_modes=args.n_modes)
        else:
            result = solid_rig_model(level, geometry, material, n_modes=args.n_modes, patch_radius=args.patch_radius)
        return result.model, result.provenance, result.report
    from sim.hosts.calculix import calculix_modal_model

    missing = [o for o, v in (("--mesh JOB.inp", args.mesh), ("--wall-left", args.wall_left),
                              ("--wall-right", args.wall_right), ("--tip", args.tip)) if not v]
    if missing:
        raise SimulationInputError(f"--from-calculix also needs {', '.join(missing)}")
    result = calculix_modal_model(args.from_calculix, args.mesh, args.wall_left, args.wall_right, args.tip,
                                  dat=args.dat, units=args.units, n_modes=args.n_modes, floor=args.floor,
                                  beam_mass=args.beam_mass)
    return result.model, result.provenance, result.report


def _fixed_joint_model(stiffness: float, variant: str, n_modes: int) -> tuple[Any, Any, dict, list[str]]:
    """`ies modes --joint-stiffness K`: the built-in rig re-updated (sim.hosts.rig.update_rig) with the joint's
    translational stiffness fixed at K (N/m; sim.hosts.rig.update_rig_fixed_joint): (model, updated RigParameters,
    provenance, report lines)."""
    import math

    from sim.common.files import to_jsonable
    from sim.hosts.rig import rig_modal_model, update_rig_fixed_joint

    if not (stiffness > 0):  # also refuses NaN
        raise SimulationInputError(f"--joint-stiffness must be positive in N/m (inf = rigid), got {stiffness!r}")
    fit = update_rig_fixed_joint(stiffness, variant=variant)
    label = "rigid" if math.isinf(stiffness) else f"{stiffness:.4g} N/m"
    model = rig_modal_model(fit.params, n_modes, f"built-in seed rig (sim.hosts.rig, Timoshenko beam, variant {variant} "
                                                  f"re-updated with the joint stiffness fixed at {label})")
    errors = [100 * e for e in fit.frequency_errors]
    plain = {"model": "built-in Timoshenko beam (sim.hosts.rig), re-updated (sim.hosts.rig.update_rig_fixed_joint)",
             "variant": variant,
             "joint_translational_stiffness_N_per_m": stiffness if math.isfinite(stiffness) else "rigid",
             "updated_parameters": fit.params.as_dict(), "f1_f4_error_percent": errors,
             "f9_hz": fit.f9_hz, "cost": fit.cost, "on_bounds": list(fit.on_bounds)}
    report = [f"joint stiffness fixed at {label}; re-updated: E = {fit.params.E / 1e9:.2f} GPa, neck "
              f"{1e3 * fit.params.neck_length:.2f} mm x {1e3 * fit.params.neck_width_y:.2f} mm (y); f1..f4 "
              + ", ".join(f"{e:+.3f}" for e in errors) + f" %, f9 = {fit.f9_hz:.0f} Hz"
              + (f"; on bounds: {', '.join(fit.on_bounds)}" if fit.on_bounds else "")]
    return model, fit.params, to_jsonable(plain), report


def modes_command(args: argparse.Namespace) -> int:
    """`ies modes`: show (and with --save write) the built-in rig's model, a modal-model file, the 3D solid
    model or the modes of a CalculiX job."""
    from sim.common.files import dumps, report_written
    from sim.hosts.modal_file import save_modal_model

    rig = provenance = None
    report: list[str] = []
    if not 1 <= args.n_modes <= 30:
        raise SimulationInputError(f"--n-modes must lie in 1..30, got {args.n_modes}")
    if args.joint_stiffness is not None and (args.solid or args.from_calculix or args.model):
        raise SimulationInputError("--joint-stiffness re-updates the built-in rig; drop --model, --solid and "
                                   "--from-calculix")
    if args.solid or args.from_calculix:
        model, provenance, report = _external_model(args)
    elif args.mesh or args.geometry or args.wall_left or args.wall_right or args.tip or args.dat or args.floor \
            or args.beam_mass is not None:
        raise SimulationInputError("--mesh, --geometry, --wall-left, --wall-right, --tip and --dat belong to --solid "
                                   "or --from-calculix")
    elif args.model:
        if args.variant is not None:
            raise SimulationInputError("--variant selects a built-in rig model; it cannot be used with --model")
        model = model_file(args.model)
    else:
        from sim.hosts.rig import DEFAULT_VARIANT, rig_modes, seed_rig_model, variant_parameters

        variant = args.variant or DEFAULT_VARIANT
        if args.joint_stiffness is not None:
            model, params, provenance, report = _fixed_joint_model(args.joint_stiffness, variant, args.n_modes)
        else:
            model, params = seed_rig_model(n_modes=args.n_modes, variant=variant), variant_parameters(variant)
        rig = rig_modes(params, n_modes=max(args.n_modes, 9))  # its updating summary needs f1..f9
    data = describe_modes(model, rig)
    if provenance is not None:
        data["provenance"] = provenance
    if args.save:
        data["saved_to"] = str(save_modal_model(model, args.save, provenance))
    print(dumps(data) if args.json else "\n".join([*report, modes_table(data)]))
    report_written([data["saved_to"]] if args.save else [], json_mode=args.json)
    return 0


# ---- the system and the protocol, shared by ies sweep and ies overview ---------------------------------------

def add_system_arguments(parser: argparse.ArgumentParser) -> None:
    """Model and impactor options (Table 2 parameters)."""
    parser.add_argument("--model", metavar="FILE", help="modal-model file (default: the built-in model of the seed rig)")
    parser.add_argument("--D", type=float, metavar="D1", help="modal damping ratio of mode 1 (-), default the model's (0.00085)")
    parser.add_argument("--g", type=clearance, metavar="G",
                        help="clearance g in m, or with a unit: 0.58mm, 580um (default 0.58 mm)")
    parser.add_argument("--k-H", dest="k_H", type=hertz_constant, metavar="K_H",
                        help="Hertz constant k_H in N/m^1.5, or with a unit: 282e3N/mm^1.5 (default 282e3 N/mm^1.5 = "
                             "8.918e9 N/m^1.5)")
    parser.add_argument("--no-impactor", action="store_true", help="simulate the host structure alone (linear)")
    from sim.model.contact_law import DEFAULT_LAW, LAWS

    laws = "; ".join(f"{name} ({law.summary}"
                     + (")" if law.collocation else ", the exact integrator takes its contacts by Dormand-Prince)")
                     for name, law in LAWS.items())
    parser.add_argument("--contact-law", dest="contact_law", choices=tuple(LAWS), default=None,
                        help=f"normal contact law at both walls (default {DEFAULT_LAW}): {laws}")
    parser.add_argument("--r-cont", dest="r_cont", type=float, default=None, metavar="R",
                        help="r_cont,diss of Eq. 10 in (0, 1]: the coefficient of restitution a damped law is designed "
                             "for (1 = elastic, bit for bit); implies the damped law (default there 0.99)")
    parser.add_argument("--friction", type=friction_coefficient, default=0.0, metavar="MU",
                        help="Coulomb coefficient of dry friction between the sphere and the cavity floor (Appendix C; "
                             "0 = off, the default; the paper: 0.07); needs --integrator ode3 and the model's phi_floor")
    parser.add_argument("--k-t", dest="k_t", type=tangential_stiffness, default=22e6, metavar="K_T",
                        help="tangential stiffness of the floor contact in N/m, or with a unit: 22kN/mm (default, "
                             "Appendix C)")


def add_protocol_arguments(parser: argparse.ArgumentParser, *, default_reps: int) -> None:
    """Stepped-sine options (Sect. 5.1) of a sweep: the grid, the run's options and the repetitions."""
    parser.add_argument("--eta", default="0.96:1.02:31", metavar="START:STOP:N",
                        help="grid of eta = Omega/omega_1 (default 0.96:1.02:31)")
    add_run_arguments(parser)
    parser.add_argument("--repetition", default="leg", choices=("leg", "run"),
                        help="what counts as one repetition: each leg (the experiment's counting, default) or each run from rest")
    parser.add_argument("--reps", type=positive_int, default=default_reps, metavar="N",
                        help=f"stepped-sine runs, each from the initial conditions of --start with its own random "
                             f"perturbation (--perturb) (default {default_reps})")


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of one stepped-sine run (Sect. 5.1): sequence, start, wait, hold, randomness, integrator."""
    parser.add_argument("--sequence", default="up", choices=SEQUENCE_CHOICES, help="sweep legs per run (default up)")
    parser.add_argument("--start", default="base-velocity", choices=("base-velocity", "rest"),
                        help="initial conditions of each run: homogeneous relative ICs under the sine excitation, "
                             "the sphere starting with the base's peak velocity so it rattles from the first point "
                             "(default; reproduces Figs. 5-6), or at rest (the sphere stays idle until the response "
                             "exceeds the clearance: an up-sweep then stays linear far into the resonance)")
    parser.add_argument("--wait", type=float, default=None, metavar="S",
                        help="wait time per frequency in s (default 3, or 15 with --no-impactor, Sect. 5.1)")
    parser.add_argument("--hold", type=float, default=5.0, metavar="S", help="hold time per frequency in s (default 5)")
    parser.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default 0)")
    parser.add_argument("--perturbation", type=float, default=5e-4, metavar="REL",
                        help="half-width of the uniform random relative frequency offset (default 5e-4)")
    parser.add_argument("--perturb", default="start", choices=("start", "each-point"),
                        help="what the offset perturbs: the first wait of each run, every hold at the nominal "
                             "frequency (default, the paper's Sect. 5.1), or every point, each sample interpolated "
                             "back onto the grid from the frequencies simulated")
    parser.add_argument("--integrator", default="exact", metavar="NAME",
                        help="time integrator: exact (default; closed-form free flight, located contacts) or ode3 (the paper's fixed step)")
    parser.add_argument("--dt-scale", dest="dt_scale", type=float, default=1.0, metavar="X",
                        help="ode3 step as a multiple of the paper's 2 pi/(15 omega_9) (default 1)")


def add_simulation_arguments(parser: argparse.ArgumentParser, *, default_reps: int, figure: str, stem: str) -> None:
    """Protocol, system and output options of `ies sweep` and `ies overview` (plot: `figure`; --out: STEM.*)."""
    add_protocol_arguments(parser, default_reps=default_reps)
    add_system_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help=f"write a {figure}-like plot (format by suffix: .png, .pdf, .svg, ...)")
    parser.add_argument("--out", metavar="DIR", help=f"write {stem}.csv (data) and {stem}.json (data + metadata)")


def parse_grid(text: str, option: str) -> tuple[float, float, int]:
    """'START:STOP:N' -> (start, stop, n); one value 'X' -> (X, X, 1). One-line error otherwise."""
    parts = text.split(":")
    try:
        if len(parts) == 1:
            value = float(parts[0])
            return value, value, 1
        if len(parts) == 3:
            return float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        pass
    raise SimulationInputError(f"{option} must look like START:STOP:N (e.g. 0.96:1.02:31), got {text!r}")


def parse_levels(text: str) -> list[float]:
    """Excitation levels a_base/a_base* (Sect. 5.3) from '1.26,5.3' or 'START:STOP:N'; each must be positive."""
    import numpy as np

    from sim.stepped_sine.protocol import check_level

    if ":" in text:
        start, stop, n = parse_grid(text, "--levels")
        if n < 1 or (n > 1 and stop <= start):
            raise SimulationInputError(f"--levels {text!r} is empty or reversed; give START < STOP and N >= 1")
        values = list(np.linspace(start, stop, n))
    else:
        try:
            values = [float(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise SimulationInputError(
                f"--levels must be numbers like 1.26,5.3,6.7 or a grid START:STOP:N, got {text!r}") from None
    if not values:
        raise SimulationInputError("--levels is empty; give at least one excitation level")
    return [check_level(v) for v in values]


def model_file(path: str) -> Any:
    """The modal model of a file (`sim.hosts.modal_file`), its source naming the file first: ``file PATH (what the file
    says it holds)``, so that a saved built-in model is reported as the file it now is."""
    import dataclasses

    from sim.hosts.modal_file import load_modal_model

    model = load_modal_model(path)
    return dataclasses.replace(model, source=f"file {path} ({model.source})")


def build_system(args: argparse.Namespace) -> tuple[Any, Any]:
    """(modal model, impactor or None) of the system and impactor options (Eqs. 3-7, Table 2)."""
    from sim.hosts.rig import seed_rig_model
    from sim.model.system import CLEARANCE_NOMINAL, K_H_NOMINAL, SPHERE_MASS, Impactor, system_arrays

    model = model_file(args.model) if args.model else seed_rig_model(n_modes=9)
    if args.D is not None:
        model = model.with_damping(args.D)
    clearance = CLEARANCE_NOMINAL if args.g is None else args.g
    k_H = K_H_NOMINAL if args.k_H is None else args.k_H
    impactor = Impactor(SPHERE_MASS, clearance, k_H, contact_law(args), args.friction, args.k_t)  # validated even
    if not args.no_impactor:                                                                    # with --no-impactor
        system_arrays(model, impactor)  # Eq. 10 needs the beam mass, friction phi_floor: fail before any work
        if impactor.friction > 0 and args.integrator != "ode3":
            raise SimulationInputError(f"dry friction (--friction {args.friction:g}, Appendix C) is in the ode3 integrator "
                                       f"only; add --integrator ode3")
    return model, (None if args.no_impactor else impactor)


def contact_law(args: argparse.Namespace) -> Any:
    """The `sim.model.contact_law.ContactLaw` of --contact-law and --r-cont (--r-cont alone implies the damped law)."""
    from sim.model.contact_law import contact_law_of

    return contact_law_of(args.contact_law, args.r_cont)


def system_data(model: Any, impactor: Any) -> dict:
    """The JSON keys of the simulated system: `model` (its source), `impactor` (`mass_kg`, `g_m`,
    `k_H_N_per_m1p5`, `contact_law`, `r_cont`, `friction` (mu), `k_t_N_per_m`; None without impactor) and `D1`
    (damping ratio of mode 1)."""
    return {"model": model.source, "D1": float(model.damping_ratios[0]),
            "impactor": None if impactor is None else {"mass_kg": impactor.mass, "g_m": impactor.clearance,
                                                       "k_H_N_per_m1p5": impactor.k_H,
                                                       "contact_law": impactor.contact_law.name,
                                                       "r_cont": impactor.contact_law.r_cont,
                                                       "friction": impactor.friction, "k_t_N_per_m": impactor.k_t}}


def build_protocol(args: argparse.Namespace) -> Any:
    """The `sim.stepped_sine.protocol.SteppedSine` of the protocol options (Sect. 5.1; 15 s wait without impactor)."""
    from sim.stepped_sine.protocol import SteppedSine

    start, stop, n = parse_grid(args.eta, "--eta")
    wait = args.wait if args.wait is not None else (15.0 if args.no_impactor else 3.0)
    return SteppedSine(eta_start=start, eta_stop=stop, n_eta=n, sequence=args.sequence, wait=wait,
                       hold=args.hold, perturbation=args.perturbation, perturb=args.perturb,
                       repetition=getattr(args, "repetition", "leg"),
                       integrator=args.integrator, dt_scale=args.dt_scale, start=args.start)


@contextmanager
def output_folder(path: str | None) -> Iterator[Path | None]:
    """--out DIR, created up front (a clear error if it cannot be a folder) and removed again if the command
    fails before writing anything into it (no empty result folders after a bad input)."""
    if path is None:
        yield None
        return
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise SimulationInputError(f"--out {folder} exists and is not a folder; choose another path")
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    except BaseException:
        if created and not any(folder.iterdir()):
            folder.rmdir()
        raise


#: a single sweep shows a progress bar when it simulates more than this (s of simulated time, on a terminal)
LONG_SWEEP_S = 60.0


@contextmanager
def simulation(args: argparse.Namespace, levels: Sequence[float], *, label: str) -> Iterator[tuple]:
    """(--out folder or None, protocol, model, impactor, one `sim.stepped_sine.protocol.sweep` result per level) of the
    options (Sects. 5.1-5.3), the sweeps run inside `output_folder` so that a failure leaves no empty folder.
    The integrator's kernels are warmed up (compiled on the first run) before one progress bar, `label`, counts
    the stepped-sine points of every level and repetition (on a terminal; for one level only when it is long)."""
    import sys

    from tqdm import tqdm

    from sim.integration.integrators import warm_up
    from sim.stepped_sine.protocol import sweep

    protocol = build_protocol(args)
    model, impactor = build_system(args)
    total = len(levels) * args.reps * len(protocol.legs) * protocol.n_eta
    long_run = len(levels) > 1 or total * (protocol.wait + protocol.hold) > LONG_SWEEP_S
    with output_folder(args.out) as folder:
        warm_up(protocol.integrator)
        with tqdm(total=total, desc=label, unit="pt", disable=not (long_run and sys.stderr.isatty()), leave=False,
                  file=sys.stderr, dynamic_ncols=True) as bar:
            results = [sweep(model, impactor, level, protocol, reps=args.reps, seed=args.seed, progress=bar.update)
                       for level in levels]
        yield folder, protocol, model, impactor, results


def write_results(folder: Path | None, stem: str, header: Sequence[str], rows: Any, data: dict) -> list[Path]:
    """With --out: the table as STEM.csv (data) and `data` as STEM.json (data + metadata); the paths written."""
    from sim.common.files import dumps, write_csv, write_text

    if folder is None:
        return []
    return [write_csv(folder / f"{stem}.csv", header, rows), write_text(folder / f"{stem}.json", dumps(data) + "\n")]


def report(args: argparse.Namespace, data: dict, written: list, plot: Any, text: str) -> int:
    """End of `ies sweep`/`ies overview`: draw `--plot` with plot(path), then print the JSON object (`--json`)
    or the text table, and a `wrote PATH` line per file written; exit code 0."""
    from sim.common.files import dumps, report_written

    if args.plot:
        plot(args.plot)
        written.append(args.plot)
    print(dumps(data) if args.json else text)
    report_written(written, json_mode=args.json)
    return 0


# ---- ies sweep ----------------------------------------------------------------------------------------------

def add_sweep_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies sweep`."""
    parser.add_argument("--level", type=float, required=True, metavar="L",
                        help="excitation level a_base/a_base* (-), a_base* = 2 D* g*/(phi_c phi^T M b)")
    add_simulation_arguments(parser, default_reps=5, figure="Fig. 5", stem="sweep")


def sweep_command(args: argparse.Namespace) -> int:
    """`ies sweep`: one stepped-sine frequency response (Sects. 5.1, 5.2; Fig. 5)."""
    from sim.plots.figures import plot_sweep, sweep_title
    from sim.stepped_sine.protocol import check_level
    from sim.stepped_sine.tables import SWEEP_COLUMNS, sweep_rows

    started = time.perf_counter()
    level = check_level(args.level)
    with simulation(args, [level], label=f"sweep {level:g}") as (folder, protocol, model, impactor, (result,)):
        data = result.to_dict()
        data.update(wall_time_s=time.perf_counter() - started, seed=args.seed, reps=args.reps, **system_data(model, impactor))
        written = write_results(folder, "sweep", SWEEP_COLUMNS, sweep_rows(result), data)
    lines = [f"# a_base/a_base* = {level:g}: {result.n_runs} runs, {result.n_samples} samples, "
             f"{protocol.integrator}, {data['wall_time_s']:.1f} s",
             f"{'eta':>7} {'mean':>8} {'max':>8} {'cv':>6} {'imp/T':>6}  regime"]
    for i, eta in enumerate(result.eta):
        lines.append(f"{eta:7.4f} {result.mean[i]:8.4f} {result.max[i]:8.4f} {result.cv[i]:6.3f} "
                     f"{result.impacts_per_period[i]:6.2f}  {result.regime_per_eta[i]}")
    lines.append(f"resonant mean {result.resonant_mean:.4f} at eta {result.eta_resonant_mean:.4f} ({result.regime}); "
                 f"resonant max {result.resonant_max:.4f} at eta {result.eta_resonant_max:.4f}")
    return report(args, data, written, lambda path: plot_sweep(data, path, sweep_title(data)), "\n".join(lines))


# ---- ies overview -------------------------------------------------------------------------------------------

def add_overview_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies overview`."""
    parser.add_argument("--levels", required=True, metavar="L1,L2,..|START:STOP:N",
                        help="excitation levels a_base/a_base* (-), a list like 1.26,5.3,6.7,7.4 or a grid 2:8:13")
    add_simulation_arguments(parser, default_reps=3, figure="Fig. 6", stem="overview")


def overview_command(args: argparse.Namespace) -> int:
    """`ies overview`: the resonant level at each excitation level (Sect. 5.3; Fig. 6)."""
    from sim.plots.figures import overview_title, plot_overview
    from sim.stepped_sine.tables import OVERVIEW_COLUMNS, dissipation_key, overview_data, overview_rows, overview_text

    started = time.perf_counter()
    levels = parse_levels(args.levels)
    with simulation(args, levels, label="overview") as (folder, protocol, model, _, results):
        data = {**overview_data(levels, results), "sweeps": [r.to_dict() for r in results], "reps": args.reps,
                "seed": args.seed, "model": model.source, "wall_time_s": time.perf_counter() - started}
        data["dissipation"] = dissipation_key(data)
        written = write_results(folder, "overview", OVERVIEW_COLUMNS, overview_rows(data), data)
    return report(args, data, written, lambda path: plot_overview(data, path, overview_title(data)),
                  overview_text(data))


# ---- ies trace ----------------------------------------------------------------------------------------------

def add_trace_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies trace`."""
    from sim.analysis.trace import DEFAULT_FS, DEFAULT_PERIODS

    parser.add_argument("--level", type=float, required=True, metavar="L", help="excitation level a_base/a_base* (-)")
    parser.add_argument("--eta", required=True, metavar="ETA|START:STOP:N",
                        help="eta = Omega/omega_1 of the traced point, or a grid: the run visits it as ies sweep does "
                             "(--sequence) and traces its last point")
    parser.add_argument("--periods", type=positive_int, default=DEFAULT_PERIODS, metavar="N",
                        help=f"excitation periods recorded from the start of the traced point's hold (default "
                             f"{DEFAULT_PERIODS})")
    parser.add_argument("--fs", type=float, default=DEFAULT_FS, metavar="HZ",
                        help=f"sampling rate in Hz (default {DEFAULT_FS:g}, the paper's); rounded to a whole number "
                             "of samples per excitation period (the JSON's fs is the rate used)")
    add_run_arguments(parser)
    add_system_arguments(parser)
    parser.add_argument("--out", required=True, metavar="DIR", help="write trace.csv (the signals) and trace.json")
    parser.add_argument("--json", action="store_true", help="print trace.json's object")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help="write Figs. 4 (tip response, amplitudes, mean and max) and 9a (tip velocity, impacts) "
                             "as two panels of one figure")


def trace_command(args: argparse.Namespace) -> int:
    """`ies trace`: time histories of one stepped-sine point (Sects. 5.1, 5.5; Figs. 4, 9a)."""
    from sim.common.files import dumps, report_written
    from sim.integration.integrators import warm_up
    from sim.stepped_sine.protocol import check_level
    from sim.analysis.trace import check_trace_settings, record_trace, write_trace

    started = time.perf_counter()
    level = check_level(args.level)
    protocol = build_protocol(args)
    model, impactor = build_system(args)
    check_trace_settings(model, protocol, args.periods, args.fs)  # before the kernels compile
    if args.plot and not Path(args.plot).resolve().parent.is_dir():
        raise SimulationInputError(f"--plot {args.plot}: folder {Path(args.plot).parent} does not exist")
    with output_folder(args.out) as folder:
        warm_up(protocol.integrator)
        trace = record_trace(model, impactor, level, protocol, periods=args.periods, fs=args.fs, seed=args.seed)
        settings = {"integrator": protocol.integrator, "seed": args.seed, "protocol": dataclasses.asdict(protocol),
                    "fs_requested": args.fs, **system_data(model, impactor)}
        data, written = write_trace(folder, trace, settings, args.plot, started)
    if args.json:
        print(dumps(data))
        report_written(written, json_mode=True)
        return 0
    print(f"# a_base/a_base* = {level:g}, eta = {trace.eta_actual:.5f} ({protocol.integrator}): {trace.amplitudes.size} "
          f"periods at fs = {trace.fs:.1f} Hz ({trace.samples_per_period} samples per period; requested {args.fs:g} Hz), "
          f"{data['wall_time_s']:.1f} s")
    print(f"a/a_noabs*: mean {data['mean']:.4f}, max {data['max']:.4f}, cv {data['cv']:.3f}; "
          f"{data['impacts_per_period']:.2f} contact onsets per period, {len(data['impacts'])} impacts between samples")
    report_written(written)
    return 0


# ---- registration with the front door -------------------------------------------------------------------------

COMMANDS = (("modes", MODES_HELP, add_modes_arguments, modes_command),
            ("sweep", SWEEP_HELP, add_sweep_arguments, sweep_command),
            ("overview", OVERVIEW_HELP, add_overview_arguments, overview_command),
            ("trace", TRACE_HELP, add_trace_arguments, trace_command),
            ("impacts", signal_cli.IMPACTS_HELP, signal_cli.add_impacts_arguments, signal_cli.impacts_command),
            ("modal-fit", signal_cli.MODAL_FIT_HELP, signal_cli.add_modal_fit_arguments, signal_cli.modal_fit_command))


def add_commands(subparsers: Any) -> None:
    """Register `modes`, `sweep`, `overview`, `trace`, `impacts` and `modal-fit` (COMMANDS) on the front door's subparsers (argparse)."""
    for name, help_text, add_arguments, run in COMMANDS:
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)
