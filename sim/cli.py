"""The simulation stage's words of the `ies` command line (`COMMANDS`): `modes`, `sweep`, `overview`, `trace`,
`orbits` (implemented in `sim.orbits.cli`), and `impacts`, `modal-fit` from `sim.analysis.cli`.

* `ies modes`: the modal model of the host structure (seed paper Sect. 3.1, Eq. 7, Appendix A), the built-in
  model of the seed rig (`sim.hosts.rig`) or a modal-model file (`sim.hosts.modal_file`); --save writes it as a file.
* `ies sweep`: a stepped-sine frequency response like Fig. 5 (Sects. 5.1, 5.2).
* `ies overview`: the resonant response level against the excitation level, like Fig. 6 (Sect. 5.3).
* `ies trace`: time histories of one stepped-sine point, like Figs. 4 and 9a (Sects. 5.1, 5.5; `sim.analysis.trace`).
* `ies orbits`: the periodic orbits with their stability and bifurcations (`sim.orbits`).
* `ies impacts`, `ies modal-fit`: the analyses of measured or simulated signals (`sim.analysis.cli`).
* `ies identify`, `ies update`, `ies linearity`, `ies synthetic-tests`: the host as measured, hammer and shaker tests
  to its modes, its updated model and its damping interval (Appendices A, B; `sim.measured.cli`).
* `ies cache`: where the compiled kernels are cached, how big the cache is, and emptying it (`sim.common.kernel_cache`).

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
from sim.measured import cli as measured_cli
from sim.common.errors import SimulationInputError
from sim.common.options import figure_file, positive_int

MODES_HELP = "modal model of the host structure: frequencies, damping, mode values, participation (built-in rig or file)"
SWEEP_HELP = "stepped-sine frequency response (mean and max amplitude per eta, spread over repetitions; Fig. 5)"
OVERVIEW_HELP = "resonant response level (largest mean and max over eta) vs excitation level a_base/a_base* (Fig. 6)"
TRACE_HELP = ("time histories of one stepped-sine point sampled at --fs: tip, walls, sphere, accelerations, contact "
              "forces (CSV + JSON; Figs. 4, 9a)")

ORBITS_HELP = ("periodic orbits (stable and unstable) with their bifurcations against eta at one or more levels, or "
               "against the level at one eta (orbits.csv, results.nc, figure; sim.orbits)")

SEQUENCE_CHOICES = ("up", "down", "up-down-up", "up-down-up-down-up")


# ---- ies modes ----------------------------------------------------------------------------------------------

def add_modes_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies modes`."""
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--save", metavar="FILE", help="write the model as a modal-model file (.toml)")
    from sim.hosts.sources import add_host_arguments
    from sim.model.sphere import add_sphere_arguments

    add_host_arguments(parser)  # sim.hosts.sources.HOST_SOURCES: --model, --solid, ...; --variant, --n-modes, FE options
    add_sphere_arguments(parser)  # the sphere the mass ratio and k_H* are reported for; --g-star for a_base*


def describe_modes(model: Any, rig: Any = None, sphere: Any = None, nominal: Any = None) -> dict:
    """The JSON object of `ies modes --json` (Sect. 3.1, Eq. 7; Sect. 5 for a_base*; SI units): the model's
    arrays, the host (its nominal D_1*, damping interval and wall material), the impactor (`sim.model.sphere.Sphere`:
    radius, material, mass, k_H* of Eq. 8 on the host's wall; the paper's by default) and its modal mass ratio,
    a_base* with the D* and g* it is normalised by, the paper's ode3 step dt = 2 pi/(15 omega_n), and with the
    built-in rig (`sim.hosts.rig.RigModes`) its updating summary (Appendix A)."""
    import numpy as np

    from sim.model.sphere import sphere_of
    from sim.model.system import Nominal, a_base_star

    sphere = sphere_of(host_wall=model.wall_material) if sphere is None else sphere
    nominal = Nominal.of(model) if nominal is None else nominal
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
        "modal_mass_ratio": sphere.mass * phi_c**2,
        "phi_tip_over_phi_c": float(model.phi_tip[0] / phi_c),
        "phi_floor": model.phi_floor,
        "beam_mass_kg": model.beam_mass,
        "host": host_data(model),
        "impactor": sphere.describe(),
        **nominal.describe(),
        "a_base_star": a_base_star(model, nominal),
        "dt": 2.0 * np.pi / (15.0 * float(model.omega[-1])),
        "units": {"frequencies_hz": "Hz", "damping_ratios": "1", "phi": "1/sqrt(kg)", "participation": "sqrt(kg)",
                  "beam_mass_kg": "kg (free length without block; null if unknown)", "a_base_star": "m", "dt": "s",
                  "modal_mass_ratio": "1 (sphere mass m_a = %g kg)" % sphere.mass, "D_star": "1", "g_star_m": "m"},
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
    sphere = data["impactor"]
    lines.append(host_text(data["host"], sphere["wall_material"]["name"]))
    lines.append(f"sphere R = {1e3 * sphere['radius_m']:.4g} mm {sphere['material']['name']}, m_a = "
                 f"{1e3 * sphere['mass_kg']:.4g} g, k_H* = {sphere['k_H_star_N_per_m1p5'] / 1e3**1.5:.6g} N/mm^1.5 (Eq. 8 "
                 f"on {sphere['wall_material']['name']})")
    lines.append(f"modal mass ratio m_a phi_c^2 = {100 * data['modal_mass_ratio']:.2f} %   "
                 f"phi_tip/phi_c = {data['phi_tip_over_phi_c']:.4f}")
    lines.append(f"a_base* = {data['a_base_star']:.4e} m (D* = {100 * data['D_star']:.4g} %, g* = "
                 f"{1e3 * data['g_star_m']:.4g} mm)   ode3 step dt = 2 pi/(15 omega_{data['n_modes']}) = {data['dt']:.4e} s")
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


def modes_command(args: argparse.Namespace) -> int:
    """`ies modes`: show (and with --save write) the built-in rig's model, a modal-model file, the 3D solid
    model or the modes of a CalculiX job."""
    from sim.common.files import dumps, report_written
    from sim.hosts.modal_file import load_shapes, save_modal_model
    from sim.hosts.sources import host_model

    if args.save:
        from sim.common.files import check_writable

        check_writable(args.save, "--save")  # before a solid model or a re-update takes minutes
    host = host_model(args)  # the row of sim.hosts.sources.HOST_SOURCES the options select
    model, rig, provenance, report = host.model, host.rig, host.provenance, host.report
    check_host_moves(model)
    data = describe_modes(model, rig, sphere_for(args, model), nominal_of(args, model))
    if provenance is not None:
        data["provenance"] = provenance
    if args.save:
        shapes = load_shapes(args.model, model.n_modes) if getattr(args, "model", None) else None
        data["saved_to"] = str(save_modal_model(model, args.save, provenance, shapes))
    print(dumps(data) if args.json else "\n".join([*report, modes_table(data)]))
    report_written([data["saved_to"]] if args.save else [], json_mode=args.json)
    return 0


# ---- the system and the protocol, shared by ies sweep and ies overview ---------------------------------------

def add_system_arguments(parser: argparse.ArgumentParser) -> None:
    """Host and impactor options: the host's (`sim.hosts.sources.add_host_arguments`: --model, --solid, ...), the
    sphere's (`sim.model.sphere.add_sphere_arguments`: --radius, --material, --mass, --wall-material, --g-star),
    --no-impactor, --contact-law and one option per parameter of `sim.model.parameters.PARAMETERS` that has one
    (Table 2's D, g, k_H; r_cont, friction, k_t; a contact law's own constant), with its aliases."""
    from sim.hosts.sources import add_host_arguments
    from sim.model.contact_law import DEFAULT_LAW, LAWS
    from sim.model.parameters import ALLOW_IMPLAUSIBLE, PARAMETERS
    from sim.model.sphere import add_sphere_arguments

    add_host_arguments(parser)
    add_sphere_arguments(parser)
    parser.add_argument("--no-impactor", action="store_true", help="simulate the host structure alone (linear)")
    laws = "; ".join(f"{name} ({law.summary}"
                     + (")" if law.collocation else ", the exact integrator takes its contacts by Dormand-Prince)")
                     for name, law in LAWS.items())
    parser.add_argument("--contact-law", dest="contact_law", choices=tuple(LAWS), default=None,
                        help=f"normal contact law at both walls (default {DEFAULT_LAW}): {laws}")
    for name, parameter in PARAMETERS.items():
        option = parameter.option
        if option is not None:
            parser.add_argument(*option.flags, dest=name, type=option.parse or parameter.option_value, default=None,
                                metavar=option.metavar, help=option.help_text())
    parser.add_argument(ALLOW_IMPLAUSIBLE, action="store_true",
                        help="compute with a value whose magnitude is implausible for its quantity (a clearance of "
                             "0.6 m, a damping ratio of 8.5 %%), refused by default as a unit slip")


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
                        help="what the offset perturbs: start (default, the paper's Sect. 5.1): one offset per run, "
                             "for a lead-in before the first point, then every point waits and holds at its nominal "
                             "frequency; each-point: every point its own offset, each sample interpolated back onto "
                             "the grid from the frequencies simulated")
    from sim.integration.integrators import DEFAULT_INTEGRATOR, INTEGRATORS

    choices = " or ".join(f"{name} ({'default; ' if name == DEFAULT_INTEGRATOR else ''}{record.summary})"
                          for name, record in INTEGRATORS.items())
    parser.add_argument("--integrator", default=DEFAULT_INTEGRATOR, metavar="NAME", help=f"time integrator: {choices}")
    scaled = " and ".join(name for name, record in INTEGRATORS.items() if record.dt_scale)
    parser.add_argument("--dt-scale", dest="dt_scale", type=float, default=1.0, metavar="X",
                        help=f"{scaled} step as a multiple of the paper's 2 pi/(15 omega_9) (default 1)")


def add_simulation_arguments(parser: argparse.ArgumentParser, *, default_reps: int, figure: str, stem: str) -> None:
    """Protocol, system and output options of `ies sweep` and `ies overview` (plot: `figure`; --out: STEM.*)."""
    add_protocol_arguments(parser, default_reps=default_reps)
    add_system_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help=f"write a {figure}-like plot (format by suffix: .png, .pdf, .svg, ...)")
    parser.add_argument("--out", metavar="DIR", help=f"write {stem}.csv (data) and {stem}.json (data + metadata)")
    add_force_argument(parser)


def add_force_argument(parser: argparse.ArgumentParser) -> None:
    """--force: write into a non-empty --out folder (its files of the same names are replaced); --allow-large: run work
    estimated above an hour (`sim.stepped_sine.cost`)."""
    from sim.stepped_sine.cost import LIMIT_S, duration_text

    parser.add_argument("--force", action="store_true",
                        help="write into a non-empty --out folder, replacing its files of the same names (default: refuse)")
    parser.add_argument("--allow-large", action="store_true",
                        help=f"run work whose cost estimate (measured here before it starts) exceeds "
                             f"{duration_text(LIMIT_S)} (refused by default)")


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


class BaseAmplitude(float):
    """An excitation given as the base amplitude a_base (m, with its unit: ``3.3um``) instead of a level
    a_base/a_base*; `level_of` turns it into the level of the host's normalisation."""


def level_value(text: str, option: str = "--level") -> float:
    """An excitation level a_base/a_base* (a plain number > 0), or a base amplitude with a length unit (``3.3um``,
    a `BaseAmplitude` in m); one `SimulationInputError` line otherwise."""
    from sim.common.units import LENGTH_UNITS, Quantity, parse_quantity
    from sim.stepped_sine.protocol import check_level

    text = str(text).strip()
    if text[:1] in "0123456789.+-" and text and text[-1].isalpha():  # a number with its unit
        quantity = Quantity("base amplitude a_base", "m", {**LENGTH_UNITS, "nm": 1e-9}, (1e-10, 1e-2), "3.3um")
        value = parse_quantity(text, quantity)
        if not value > 0:
            raise SimulationInputError(f"{option} {text!r}: a base amplitude must be positive")
        return BaseAmplitude(value)
    try:
        level = float(text)
    except ValueError:
        raise SimulationInputError(f"{option} must be a level a_base/a_base* like 7.4 or a base amplitude like 3.3um, "
                                   f"got {text!r}") from None
    return check_level(level)


def level_option(text: str) -> float:
    """argparse type of --level (`level_value`)."""
    try:
        return level_value(text)
    except SimulationInputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def level_of(value: float, model: Any, nominal: Any) -> float:
    """The level a_base/a_base* (Sect. 5.3) of a `level_value`: a base amplitude over a_base* of `nominal`."""
    from sim.model.system import a_base_star

    return value / a_base_star(model, nominal) if isinstance(value, BaseAmplitude) else float(value)


def parse_levels(text: str) -> list[float]:
    """Excitation levels a_base/a_base* (Sect. 5.3) from '1.26,5.3' or 'START:STOP:N', or base amplitudes with their
    unit ('1um,3um', '0.66um:6.6um:10'; `BaseAmplitude`); each must be positive."""
    import numpy as np

    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise SimulationInputError(f"--levels must look like START:STOP:N (e.g. 2:8:13), got {text!r}")
        start, stop = (level_value(part, "--levels") for part in parts[:2])
        _, _, n = parse_grid(f"0:1:{parts[2]}", "--levels")
        if isinstance(start, BaseAmplitude) != isinstance(stop, BaseAmplitude):
            raise SimulationInputError(f"--levels {text!r}: give START and STOP both as levels or both with a unit")
        if n < 1 or (n > 1 and stop <= start):
            raise SimulationInputError(f"--levels {text!r} is empty or reversed; give START < STOP and N >= 1")
        kind = BaseAmplitude if isinstance(start, BaseAmplitude) else float
        values = [kind(v) for v in np.linspace(start, stop, n)]
    else:
        items = text.split(",")
        if len(items) > 1 and any(not v.strip() for v in items):
            raise SimulationInputError(f"--levels {text!r} has an empty entry; give numbers like 1.26,5.3,6.7")
        values = [level_value(v, "--levels") for v in items if v.strip()]
    if not values:
        raise SimulationInputError("--levels is empty; give at least one excitation level")
    if len({isinstance(v, BaseAmplitude) for v in values}) > 1:
        raise SimulationInputError(f"--levels {text!r}: give every value as a level or every one with a unit")
    repeated = sorted({v for v in values if values.count(v) > 1})
    if repeated:
        raise SimulationInputError(f"--levels {text!r} repeats {', '.join(f'{v:g}' for v in repeated)}; give each "
                                   "excitation level once (more repetitions: --reps)")
    return values


def host_data(model: Any) -> dict:
    """The JSON key `host` of every simulation command: the host's nominal D_1* (`D_star`), its damping interval and
    where it comes from (`sim.model.system.ModalModel.damping_box`), its wall material (Eq. 8)."""
    interval, said = model.damping_box()
    return {"D_star": model.D_star, "damping_interval": list(interval), "damping_interval_source": said,
            "wall_material": model.wall_material.describe(), "wall_material_given": model.wall is not None}


def host_text(host: dict, sphere_wall: str | None = None) -> str:
    """One line of `host_data`: nominal damping, interval and wall (and the wall the sphere is pressed on by Eq. 8
    when --wall-material overrides the host's)."""
    low, high = host["damping_interval"]
    wall = host["wall_material"]["name"] + ("" if host["wall_material_given"] else " (none given: the rig's)")
    if sphere_wall is not None and sphere_wall != host["wall_material"]["name"]:
        wall += f"; --wall-material {sphere_wall} used for Eq. 8"
    source = "" if host["damping_interval_source"] == "the host's damping interval" else " (Table 2's, relative)"
    return (f"host: D_1* = {100 * host['D_star']:.4g} %, interval {100 * low:.4g}-{100 * high:.4g} %{source}; walls "
            f"{wall}")


def sphere_for(args: argparse.Namespace, model: Any) -> Any:
    """The sphere of the options (`sim.model.sphere.sphere_from_options`) on the host's walls unless --wall-material."""
    from sim.model.sphere import sphere_from_options

    return sphere_from_options(args, host_wall=model.wall_material)


def nominal_of(args: argparse.Namespace, model: Any) -> Any:
    """The normalisation of a command (Sect. 5): the host's nominal D_1* and g* = --g-star (the paper's 0.58 mm)."""
    from sim.model.system import Nominal

    return Nominal.of(model, getattr(args, "g_star", None))


def check_host_moves(model: Any) -> None:
    """Walls at a node of mode 1, or a mode 1 the base does not excite: one line naming the host, before any work
    (`sim.model.system.check_resonant_mode`)."""
    from sim.model.system import check_resonant_mode

    try:
        check_resonant_mode(model)
    except SimulationInputError as exc:
        raise SimulationInputError(f"{model.source}: {exc}") from None


def build_system(args: argparse.Namespace) -> tuple[Any, Any]:
    """(modal model, impactor or None) of the host and impactor options (Eqs. 3-7, Table 2): the host through the
    one resolver (`sim.hosts.sources.resolve_host`), the sphere of --radius, --material, --mass and --wall-material
    (`sim.model.sphere`: its mass and Eq. 8's k_H*), then the options of `sim.model.parameters.PARAMETERS` (--g, --k-H
    given outright, ...), built and checked by `sim.model.system.build_system` with the integrator's record (its law,
    friction)."""
    from sim.hosts.sources import resolve_host
    from sim.integration.integrators import integrator_named
    from sim.model.parameters import PARAMETERS, SystemSettings, check_plausible, system_settings
    from sim.model.system import build_impactor
    from sim.model.system import build_system as build

    values = {name: getattr(args, name, None) for name in PARAMETERS}
    check_plausible(values, allow=args.allow_implausible)  # a unit slip is refused, not computed with
    integrator = integrator_named(args.integrator)
    model = resolve_host(args).model
    check_host_moves(model)
    sphere = sphere_for(args, model)  # radius, material, mass, walls: the mass and Eq. 8's k_H* the options start from
    settings = system_settings(values, sphere.settings(SystemSettings(contact_law=args.contact_law)))
    if args.no_impactor:  # the impactor's values are checked all the same
        build_impactor(settings)
        return (model if settings.D1 is None else model.with_damping(settings.D1)), None
    model, impactor = build(model, settings, integrator=integrator)
    return model, dataclasses.replace(impactor, sphere=sphere)


def system_data(model: Any, impactor: Any, nominal: Any = None) -> dict:
    """The JSON keys of the simulated system: `model` (its source), the host's parameters (`D1`, the damping ratio of
    mode 1 simulated) and `host` (`host_data`: its nominal D_1*, damping interval, wall), the normalisation (`D_star`,
    `g_star_m`: `sim.model.system.Nominal`, the host's own unless `nominal` is given) and `impactor`: `contact_law`,
    every other row's key (`sim.model.parameters.UncertainParameter.json_key`: `mass_kg`, `g_m`, `k_H_N_per_m1p5`,
    `r_cont`, `friction` (mu), `k_t_N_per_m`, a law's own constant, ...; a row that feeds no field of its own only when
    it was given) and `sphere` (`sim.model.sphere.Sphere.describe`: radius, material, k_H* of Eq. 8, wall); None
    without impactor."""
    from sim.model.parameters import PARAMETERS, SystemSettings
    from sim.model.system import Nominal, settings_of

    host_rows = [row for row in PARAMETERS.values() if row.feeds.field == "D1"]
    nominal = Nominal.of(model) if nominal is None else nominal
    data = {"model": model.source, **{row.json_key: float(model.damping_ratios[0]) for row in host_rows},
            "host": host_data(model), **nominal.describe()}
    if impactor is None:
        return {**data, "impactor": None}
    settings: SystemSettings = settings_of(model, impactor)
    values = {"contact_law": impactor.contact_law.name}
    for row in PARAMETERS.values():
        if row not in host_rows and (value := row.reported(settings)) is not None:
            values[row.json_key] = value
    if impactor.sphere is not None:
        values["sphere"] = impactor.sphere.describe()
    return {**data, "impactor": values}


def build_protocol(args: argparse.Namespace) -> Any:
    """The `sim.stepped_sine.protocol.SteppedSine` of the protocol options (Sect. 5.1; 15 s wait without impactor)."""
    from sim.integration.integrators import integrator_named
    from sim.stepped_sine.protocol import SteppedSine

    integrator_named(args.integrator).check_dt_scale(args.dt_scale)
    start, stop, n = parse_grid(args.eta, "--eta")
    wait = args.wait if args.wait is not None else (15.0 if args.no_impactor else 3.0)
    return SteppedSine(eta_start=start, eta_stop=stop, n_eta=n, sequence=args.sequence, wait=wait,
                       hold=args.hold, perturbation=args.perturbation, perturb=args.perturb,
                       repetition=getattr(args, "repetition", "leg"),
                       integrator=args.integrator, dt_scale=args.dt_scale, start=args.start)


@contextmanager
def output_folder(path: str | None, force: bool = False) -> Iterator[Path | None]:
    """--out DIR, created up front, proved writable and locked for this run (`sim.common.folder_lock`: a second run
    into it is refused, naming this one) (a clear error if it cannot be a folder, is in use, holds earlier results and
    `force` is not given, or the disk refuses a file) and removed again if the command fails before writing anything
    into it (no empty result folders after a bad input)."""
    from sim.common.errors import ResourceFailure
    from sim.common.files import RESOURCE_ERRNOS, check_writable
    from sim.common.folder_lock import LOCK_FILE, locked

    if path is None:
        yield None
        return
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise SimulationInputError(f"--out {folder} exists and is not a folder; choose another path")
    created = not folder.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        error = ResourceFailure if exc.errno in RESOURCE_ERRNOS else SimulationInputError
        raise error(f"cannot create --out {folder} ({exc.strerror or exc}); choose another folder (nothing was "
                    "computed)") from None
    try:
        check_writable(folder, "--out", folder=True)
        with locked(folder):
            if not force and any(p.name != LOCK_FILE for p in folder.iterdir()):
                raise SimulationInputError(f"--out {folder} is not empty (earlier results?); choose another folder or "
                                           "pass --force to replace its files")
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
    options (Sects. 5.1-5.3), the sweeps run inside `output_folder` so that a failure leaves no empty folder. Levels
    are a_base/a_base* or base amplitudes (`BaseAmplitude`), normalised by the host's own D_1* and --g-star
    (`nominal_of`); each result carries its level.
    The integrator's kernels are warmed up (compiled on the first run) before one progress report, `label`, counts
    the stepped-sine points of every level and repetition (`sim.common.progress`: a bar on a terminal, plain lines in a
    log; for one level only when it is long)."""
    from sim.common.files import check_writable
    from sim.common.progress import progress
    from sim.integration.integrators import warm_up
    from sim.stepped_sine.cost import check_estimate, estimate, seconds_per_run, simulated_seconds, worth_probing
    from sim.stepped_sine.protocol import sweep

    protocol = build_protocol(args)
    model, impactor = build_system(args)
    nominal = nominal_of(args, model)
    levels = [level_of(value, model, nominal) for value in levels]
    lyapunov = getattr(args, "lyapunov", False)
    if lyapunov:
        from sim.stepped_sine.protocol import check_lyapunov_holds

        check_lyapunov_holds(model, protocol)
    if args.plot:
        check_writable(args.plot, "--plot")
    total = len(levels) * args.reps * len(protocol.legs) * protocol.n_eta
    long_run = len(levels) > 1 or total * (protocol.wait + protocol.hold) > LONG_SWEEP_S
    with output_folder(args.out, args.force) as folder:
        warm_up(protocol.integrator, law="hertz" if impactor is None else impactor.contact_law.law.name)
        if worth_probing(len(levels) * args.reps, simulated_seconds(protocol, float(model.omega[0]))):
            cost = seconds_per_run(model, impactor, levels, protocol, nominal)  # measured here, before the first run
            check_estimate(estimate({level: args.reps for level in levels}, cost),
                           "lower --reps, the --eta points, --wait/--hold or the number of levels",
                           allow_large=args.allow_large)
        with progress(total, label, "pt", enabled=long_run, leave=False) as bar:
            results = [sweep(model, impactor, level, protocol, reps=args.reps, seed=args.seed, nominal=nominal,
                             progress=bar.update, lyapunov=lyapunov) for level in levels]
        yield folder, protocol, model, impactor, results


def write_results(folder: Path | None, stem: str, header: Sequence[str], rows: Any, data: dict) -> list[Path]:
    """With --out: the table as STEM.csv (data) and `data` as STEM.json (data + metadata); the paths written."""
    from sim.common.files import write_csv, write_json, write_or_fallback

    if folder is None:
        return []
    rows = list(rows)
    return write_or_fallback(lambda where: [write_csv(where / f"{stem}.csv", header, rows),
                                            write_json(where / f"{stem}.json", data)], folder, stem)


def report(args: argparse.Namespace, data: dict, written: list, plot: Any, text: str) -> int:
    """End of `ies sweep`/`ies overview`: print the JSON object (`--json`) or the text table, draw `--plot` with
    plot(path) (into a named fallback folder if the disk refuses it), and a `wrote PATH` line per file written;
    exit code 0."""
    from sim.common.files import dumps, report_written, write_or_fallback

    print(dumps(data) if args.json else text, flush=True)  # the results first: a figure the disk refuses loses nothing
    if args.plot:
        target = Path(args.plot)
        write_or_fallback(lambda where: plot(target if where == target.parent else where / target.name), target.parent,
                          "plot")
        written.append(args.plot)
    report_written(written, json_mode=args.json)
    return 0


# ---- ies sweep ----------------------------------------------------------------------------------------------

def add_sweep_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies sweep`."""
    parser.add_argument("--level", type=level_option, required=True, metavar="L",
                        help="excitation level a_base/a_base* (-), a_base* = 2 D* g*/(phi_c phi^T M b) with the host's "
                             "nominal D* and g* (--g-star); or the base amplitude with its unit, e.g. 3.3um")
    add_simulation_arguments(parser, default_reps=5, figure="Fig. 5", stem="sweep")
    parser.add_argument("--lyapunov", action="store_true",
                        help="each hold's largest Lyapunov exponent and dynamics (periodic, quasi-periodic, chaotic) "
                             "as columns beside the regime (sim.stepped_sine.dynamics; about 0.2 s more per point)")


def sweep_command(args: argparse.Namespace) -> int:
    """`ies sweep`: one stepped-sine frequency response (Sects. 5.1, 5.2; Fig. 5)."""
    from sim.plots.figures import plot_sweep, sweep_title
    from sim.stepped_sine.tables import sweep_columns, sweep_rows

    started = time.perf_counter()
    with simulation(args, [args.level], label="sweep") as (folder, protocol, model, impactor, (result,)):
        nominal = nominal_of(args, model)
        data = result.to_dict()
        data.update(wall_time_s=time.perf_counter() - started, seed=args.seed, reps=args.reps,
                    **system_data(model, impactor, nominal))
        written = write_results(folder, "sweep", sweep_columns(result), sweep_rows(result), data)
    lines = [f"# a_base/a_base* = {result.level:g}: {result.n_runs} runs, {result.n_samples} samples, "
             f"{protocol.integrator}, {data['wall_time_s']:.1f} s",
             f"# {nominal.text()}; a_base = {result.a_base * 1e6:.4g} um",
             f"{'eta':>7} {'mean':>8} {'max':>8} {'cv':>6} {'imp/T':>6}  regime"
             + ("  lyapunov/T  dynamics" if result.dynamics is not None else "")]
    for i, eta in enumerate(result.eta):
        lines.append(f"{eta:7.4f} {result.mean[i]:8.4f} {result.max[i]:8.4f} {result.cv[i]:6.3f} "
                     f"{result.impacts_per_period[i]:6.2f}  {result.regime_per_eta[i]}"
                     + (f"{'':<{6 - len(result.regime_per_eta[i])}} {result.lyapunov_per_period[i]:11.4g}  "
                        f"{result.dynamics[i]}" if result.dynamics is not None else ""))
    lines.append(f"resonant mean {result.resonant_mean:.4f} at eta {result.eta_resonant_mean:.4f} ({result.regime}); "
                 f"resonant max {result.resonant_max:.4f} at eta {result.eta_resonant_max:.4f}")
    return report(args, data, written, lambda path: plot_sweep(data, path, sweep_title(data)), "\n".join(lines))


# ---- ies overview -------------------------------------------------------------------------------------------

def add_overview_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies overview`."""
    parser.add_argument("--levels", required=True, metavar="L1,L2,..|START:STOP:N",
                        help="excitation levels a_base/a_base* (-), a list like 1.26,5.3,6.7,7.4 or a grid 2:8:13; or "
                             "base amplitudes with their unit, e.g. 1um,3um or 0.66um:6.6um:10")
    add_simulation_arguments(parser, default_reps=3, figure="Fig. 6", stem="overview")


def overview_command(args: argparse.Namespace) -> int:
    """`ies overview`: the resonant level at each excitation level (Sect. 5.3; Fig. 6)."""
    from sim.plots.figures import overview_title, plot_overview
    from sim.stepped_sine.tables import OVERVIEW_COLUMNS, dissipation_key, overview_data, overview_rows, overview_text

    started = time.perf_counter()
    with simulation(args, parse_levels(args.levels), label="overview") as (folder, protocol, model, impactor, results):
        levels = [result.level for result in results]
        data = {**overview_data(levels, results), "sweeps": [r.to_dict() for r in results], "reps": args.reps,
                "seed": args.seed, **system_data(model, impactor, nominal_of(args, model)),
                "wall_time_s": time.perf_counter() - started}
        data["dissipation"] = dissipation_key(data)
        written = write_results(folder, "overview", OVERVIEW_COLUMNS, overview_rows(data), data)
    return report(args, data, written, lambda path: plot_overview(data, path, overview_title(data)),
                  f"# {nominal_of(args, model).text()}\n{overview_text(data)}")


# ---- ies trace ----------------------------------------------------------------------------------------------

def add_trace_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies trace`."""
    from sim.analysis.trace import DEFAULT_FS, DEFAULT_PERIODS, LYAPUNOV_PERIODS

    parser.add_argument("--level", type=level_option, required=True, metavar="L",
                        help="excitation level a_base/a_base* (-), or the base amplitude with its unit, e.g. 3.3um")
    parser.add_argument("--eta", required=True, metavar="ETA|START:STOP:N",
                        help="eta = Omega/omega_1 of the traced point, or a grid: the run visits it as ies sweep does "
                             "(--sequence) and traces its last point")
    parser.add_argument("--periods", type=positive_int, default=None, metavar="N",
                        help=f"excitation periods recorded from the start of the traced point's hold (default "
                             f"{DEFAULT_PERIODS}, {LYAPUNOV_PERIODS} with --lyapunov)")
    parser.add_argument("--fs", type=float, default=DEFAULT_FS, metavar="HZ",
                        help=f"sampling rate in Hz (default {DEFAULT_FS:g}, the paper's); rounded to a whole number "
                             "of samples per excitation period (the JSON's fs is the rate used)")
    add_run_arguments(parser)
    add_system_arguments(parser)
    parser.add_argument("--out", required=True, metavar="DIR", help="write trace.csv (the signals) and trace.json")
    add_force_argument(parser)
    parser.add_argument("--json", action="store_true", help="print trace.json's object")
    parser.add_argument("--plot", type=figure_file, metavar="FILE",
                        help="write Figs. 4 (tip response, amplitudes, mean and max) and 9a (tip velocity, impacts) "
                             "as two panels of one figure")
    parser.add_argument("--lyapunov", action="store_true",
                        help="the largest Lyapunov exponent over the recorded periods (per period, with its "
                             "convergence) and the dynamics: periodic, quasi-periodic or chaotic (sim.stepped_sine.dynamics)")
    parser.add_argument("--poincare", action="store_true",
                        help="the Poincare section (the tip once per period) and the per-period amplitudes' spectrum: "
                             "poincare.png in --out and 'poincare' in trace.json")


def trace_command(args: argparse.Namespace) -> int:
    """`ies trace`: time histories of one stepped-sine point (Sects. 5.1, 5.5; Figs. 4, 9a)."""
    from sim.analysis.trace import (DEFAULT_PERIODS, LYAPUNOV_PERIODS, SAMPLE_COST_S, check_nature_settings,
                                    check_trace_settings, record_trace, trace_nature, trace_samples, write_trace)
    from sim.plots.figures import plot_trace
    from sim.plots.dynamics import plot_poincare
    from sim.common.files import check_writable, dumps, report_written, write_or_fallback
    from sim.integration.integrators import warm_up
    from sim.stepped_sine.cost import ANNOUNCE_AFTER_S, check_estimate, check_trace_memory, estimate, probe_cost, \
        simulated_seconds, worth_probing

    started = time.perf_counter()
    protocol = build_protocol(args)
    model, impactor = build_system(args)
    nominal = nominal_of(args, model)
    level = level_of(args.level, model, nominal)
    if args.periods is None:
        args.periods = LYAPUNOV_PERIODS if args.lyapunov else DEFAULT_PERIODS
    check_trace_settings(model, protocol, args.periods, args.fs)  # before the kernels compile
    check_nature_settings(args.periods, args.lyapunov, args.poincare)
    samples = trace_samples(model, protocol, args.periods, args.fs)
    check_trace_memory(samples, model.n_modes, "lower --periods or --fs")
    if args.plot:
        check_writable(args.plot, "--plot")
    with output_folder(args.out, args.force) as folder:
        warm_up(protocol.integrator, law="hertz" if impactor is None else impactor.contact_law.law.name)
        simulated = (simulated_seconds(protocol, float(model.omega[0]))
                     + args.periods / (protocol.eta[-1] * model.frequencies_hz[0]))  # the recorded periods
        if worth_probing(1, simulated) or samples * SAMPLE_COST_S > ANNOUNCE_AFTER_S:
            seconds = simulated * probe_cost(model, impactor, level, protocol, nominal) + samples * SAMPLE_COST_S
            check_estimate(estimate({level: 1}, {level: seconds}), "lower --periods, --fs, the --eta points or "
                           "--wait/--hold", allow_large=args.allow_large)
        trace = record_trace(model, impactor, level, protocol, periods=args.periods, fs=args.fs, seed=args.seed,
                             nominal=nominal)
        nature = trace_nature(trace, model, impactor, protocol, lyapunov=args.lyapunov, poincare=args.poincare,
                              seed=args.seed)
        settings = {"integrator": protocol.integrator, "seed": args.seed, "protocol": dataclasses.asdict(protocol),
                    "fs_requested": args.fs, **system_data(model, impactor, nominal)}
        plot = Path(args.plot) if args.plot else None
        data, written = write_or_fallback(
            lambda where: write_trace(where, trace, settings, plot if where == folder or plot is None else where / plot.name,
                                      started, draw=plot_trace, nature=nature, draw_poincare=plot_poincare),
            folder, "trace")
    if args.json:
        print(dumps(data))
        report_written(written, json_mode=True)
        return 0
    print(f"# a_base/a_base* = {level:g}, eta = {trace.eta_actual:.5f} ({protocol.integrator}): {trace.amplitudes.size} "
          f"periods at fs = {trace.fs:.1f} Hz ({trace.samples_per_period} samples per period; requested {args.fs:g} Hz), "
          f"{data['wall_time_s']:.1f} s")
    print(f"# {nominal.text()}")
    print(f"a/a_noabs*: mean {data['mean']:.4f}, max {data['max']:.4f}, cv {data['cv']:.3f}; "
          f"{data['impacts_per_period']:.2f} contact onsets per period, {len(data['impacts'])} impacts between samples")
    if args.lyapunov:
        from sim.analysis.trace import nature_line

        print(nature_line(data))
    report_written(written)
    return 0


# ---- ies orbits (sim.orbits.cli) --------------------------------------------------------------------------------

def add_orbits_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies orbits`: its own (`sim.orbits.cli`) and the system's."""
    from sim.orbits.cli import add_arguments

    add_arguments(parser)
    add_system_arguments(parser)


def orbits_command(args: argparse.Namespace) -> int:
    """`ies orbits`: periodic orbits with their stability and bifurcations (`sim.orbits`)."""
    from sim.orbits.cli import run

    return run(args, build_system, output_folder, system_data, nominal_of=nominal_of, level_value=level_value,
               level_of=level_of)


# ---- ies cache -------------------------------------------------------------------------------------------------

CACHE_HELP = "where the compiled kernels are cached and how big the cache is; --clear empties it"


def add_cache_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies cache`."""
    parser.add_argument("--clear", action="store_true",
                        help="delete every cached kernel (the next run compiles the kernels again)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")


def _megabytes(size: int) -> str:
    return f"{size / 1e6:.1f} MB"


def _ago(seconds: float) -> str:
    for unit, length in (("d", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= length:
            return f"{seconds / length:.0f} {unit} ago"
    return "just now"


def cache_command(args: argparse.Namespace) -> int:
    """`ies cache`: the kernel cache's folder (`sim.common.kernel_cache`: per user, keyed by the code, never in the
    installed package), one line per code version with its size, and `--clear` to empty it."""
    from sim.common import kernel_cache
    from sim.common.files import dumps
    from sim.integration import jit

    root, chosen_by = kernel_cache.cache_root()
    current = kernel_cache.folder_name(jit.CACHE_GROUP, kernel_cache.code_version())  # as `ies --version` names it
    if args.clear:
        removed, freed = kernel_cache.clear(root)
        left = kernel_cache.version_folders(root)
        data = {"folder": root, "removed_folders": removed, "freed_bytes": freed, "left_folders": [e.path for e in left]}
        if args.json:
            print(dumps(data))
            return 0
        print(f"kernel cache {root}: removed {removed} code version(s), {_megabytes(freed)}; the next run compiles the "
              "kernels again" + (f"; {len(left)} folder(s) in use or holding other files were left" if left else ""))
        return 0
    folders = kernel_cache.version_folders(root)
    now = time.time()
    data = {"folder": root, "chosen_by": chosen_by, "total_bytes": kernel_cache.disk_size(folders),
            "versions": [{"folder": e.path.name, "group": e.group, "bytes": e.size, "files": e.files,
                          "last_used": e.last_used, "current": e.path.name == current} for e in folders]}
    if args.json:
        print(dumps(data))
        return 0
    moved = "" if chosen_by == kernel_cache.SETTING else f"; {kernel_cache.SETTING}=DIR moves it"
    print(f"kernel cache: {root} ({chosen_by}{moved})")
    labels = {"sim": "simulator", "bem_contact": "contact solver", "scans": "scan resampling"}
    for entry in folders:
        version = " (this version)" if entry.path.name == current else " (another version)"
        what = labels.get(entry.group, entry.group) + (version if entry.group == "sim" else "")
        print(f"  {entry.path.name:<30} {_megabytes(entry.size):>9} {entry.files:>5} files  {what}, last used "
              f"{_ago(now - entry.last_used)}")
    if not folders:
        print("  empty: the next run compiles the kernels (once per version of the code)")
    print(f"total {_megabytes(data['total_bytes'])} on disk in {len(folders)} folder(s) (the versions share the machine "
          "code of the same kernel sources); `ies cache --clear` empties it")
    return 0


# ---- registration with the front door -------------------------------------------------------------------------

COMMANDS = (("modes", MODES_HELP, add_modes_arguments, modes_command),
            ("sweep", SWEEP_HELP, add_sweep_arguments, sweep_command),
            ("overview", OVERVIEW_HELP, add_overview_arguments, overview_command),
            ("trace", TRACE_HELP, add_trace_arguments, trace_command),
            ("orbits", ORBITS_HELP, add_orbits_arguments, orbits_command),
            ("impacts", signal_cli.IMPACTS_HELP, signal_cli.add_impacts_arguments, signal_cli.impacts_command),
            ("modal-fit", signal_cli.MODAL_FIT_HELP, signal_cli.add_modal_fit_arguments, signal_cli.modal_fit_command),
            ("cache", CACHE_HELP, add_cache_arguments, cache_command),
            *measured_cli.commands(output_folder))


def add_commands(subparsers: Any) -> None:
    """Register `modes`, `sweep`, `overview`, `trace`, `orbits`, `impacts`, `modal-fit`, `cache` and the measured host's
    `identify`, `update`, `linearity`, `synthetic-tests` (COMMANDS) on the front door's subparsers (argparse)."""
    for name, help_text, add_arguments, run in COMMANDS:
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(_run=run)
