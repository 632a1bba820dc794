"""Where every command and study takes the modal model of the host structure from (seed paper Sect. 3.1, Eq. 7):
`HOST_SOURCES`, one row per source, and `resolve_host`, the one resolver that serves `ies modes`, `ies sweep` /
`overview` / `trace` (`sim.cli`), the studies (`uq.problem.models.IESModel`) and `ies design` (`uq.design.problem`).

A row (`HostSource`) names the source, the option that selects it (argparse keywords; None for the default, the
built-in rig), the function that builds its `HostModel` from the options, and the file kinds it reads (suffixes;
`reads`, `load`): a path given to ``--model`` or a study's ``modal_model`` goes to the source that reads its kind (a
modal-model file by default). Every simulation command adds every row's option to one group of mutually exclusive
choices (`add_host_arguments`) and builds the model through `resolve_host`, which holds the checks shared by all
sources; the studies and the design name a file. Adding a source (another FE tool, a measured modal model) is adding
a row: it reaches every command by its option and, when it reads a file kind, every study and design by its files.

The rows: the built-in Timoshenko model of the seed rig (`sim.hosts.rig`, Appendix A; optionally re-updated with a
fixed joint stiffness), a modal-model file (`sim.hosts.modal_file`), the 3D solid model (`sim.hosts.solid`, its
variants in `sim.hosts.variants`) and the modes of a CalculiX job (`sim.hosts.calculix`).
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

from sim.common.errors import SimulationInputError
from sim.model.system import ModalModel


@dataclass(frozen=True)
class HostModel:
    """What a source gives: the modal model, the built-in rig's updating summary (`sim.hosts.rig.RigModes`, or None;
    computed for `ies modes` only), the provenance written with --save (or None) and report lines printed above
    `ies modes`'s table."""

    model: ModalModel
    rig: Any = None
    provenance: dict | None = None
    report: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class HostSource:
    """One row of `HOST_SOURCES`: name; flag, the option that selects it (None: the default source) with its argparse
    keywords `flag_kwargs` (dest = the name's identifier unless given); fe_options: whether it reads the FE options
    (--mesh, --geometry, --wall-left, ...; refused with the other sources); build: the model from the options;
    reads: the file suffixes it reads (".frd"), load: the model of such a file (a path given to --model or to a
    study's modal_model goes there)."""

    name: str
    flag: str | None
    flag_kwargs: Mapping[str, Any]
    build: Callable[[argparse.Namespace], HostModel]
    fe_options: bool = False
    reads: tuple[str, ...] = ()
    load: Callable[[str], HostModel] | None = None

    @property
    def dest(self) -> str:
        """The argparse destination of the selecting option."""
        return self.flag_kwargs.get("dest", (self.flag or self.name).lstrip("-").replace("-", "_"))

    def selected(self, args: argparse.Namespace) -> bool:
        """Whether the options select this source (its option given)."""
        return self.flag is not None and bool(getattr(args, self.dest, None))


#: the FE options of --solid and --from-calculix (argparse dests and how the message names them)
FE_OPTIONS = (("mesh", "--mesh"), ("geometry", "--geometry"), ("wall_left", "--wall-left"),
              ("wall_right", "--wall-right"), ("tip", "--tip"), ("dat", "--dat"), ("floor", "--floor"),
              ("beam_mass", "--beam-mass"))


def model_file(path: str) -> ModalModel:
    """The modal model of a file (`sim.hosts.modal_file`), its source naming the file first: ``file PATH (what the file
    says it holds)``, so that a saved built-in model is reported as the file it now is."""
    from sim.hosts.modal_file import load_modal_model

    model = load_modal_model(path)
    return dataclasses.replace(model, source=f"file {path} ({model.source})")


def host_file(path: str | Path) -> HostModel:
    """The host of a file: the row of `HOST_SOURCES` that reads its suffix (`HostSource.reads`), a modal-model file
    (`model_file`) otherwise."""
    path = str(path)
    suffix = Path(path).suffix.lower()
    for row in HOST_SOURCES.values():
        if row.load is not None and suffix in row.reads:
            return row.load(path)
    return HostModel(model_file(path))


def solid_geometry(path: str | None) -> tuple[Any, Any]:
    """(SolidGeometry, SolidMaterial) of a --geometry TOML file (the rig's defaults without one): [geometry]
    (`sim.hosts.solid.SolidGeometry` fields, m) and [material] (E in Pa, nu, rho in kg/m^3)."""
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


def fixed_joint_model(stiffness: float, variant: str, n_modes: int) -> tuple[ModalModel, Any, dict, list[str]]:
    """The built-in rig re-updated (`sim.hosts.rig.update_rig_fixed_joint`, Appendix A) with the joint's translational
    stiffness fixed at `stiffness` (N/m; inf = rigid): (model, updated RigParameters, provenance, report lines)."""
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


def built_in_rig(args: argparse.Namespace) -> HostModel:
    """The built-in Timoshenko model of the seed rig (Appendix A), variant --variant, --n-modes modes; with
    --joint-stiffness re-updated with that joint stiffness. Carries its updating summary (f1..f9) when asked
    (`resolve_host`'s summary)."""
    from sim.hosts.rig import DEFAULT_VARIANT, rig_modes, seed_rig_model, variant_parameters

    variant = args.variant or DEFAULT_VARIANT
    provenance, report = None, []
    if args.joint_stiffness is not None:
        model, params, provenance, report = fixed_joint_model(args.joint_stiffness, variant, args.n_modes)
    else:
        model, params = seed_rig_model(n_modes=args.n_modes, variant=variant), variant_parameters(variant)
    rig = rig_modes(params, n_modes=max(args.n_modes, 9)) if args.summary else None  # the summary needs f1..f9
    return HostModel(model, rig, provenance, report)


def modal_model_file(args: argparse.Namespace) -> HostModel:
    """A model file (--model FILE): a modal-model file (`sim.hosts.modal_file`) or a file kind another row reads."""
    if args.variant is not None:
        raise SimulationInputError("--variant selects a built-in rig model; it cannot be used with --model")
    return host_file(args.model)


def solid_model(args: argparse.Namespace) -> HostModel:
    """The rig as a 3D solid finite-element model (--solid, `sim.hosts.solid`), or one of its variants
    (`sim.hosts.variants.SOLID_VARIANTS`); a bad geometry file fails with one line before any work."""
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
    geometry, material = solid_geometry(args.geometry)
    sys.stderr.write(f"solving the 3D solid model ({level} mesh and a coarser one for the convergence check; "
                     "about 1-3 min) ...\n")
    if args.variant is not None:
        result = solid_variant_model(args.variant, level, n_modes=args.n_modes)
    else:
        result = solid_rig_model(level, geometry, material, n_modes=args.n_modes, patch_radius=args.patch_radius)
    return HostModel(result.model, None, result.provenance, result.report)


def calculix_job(args: argparse.Namespace) -> HostModel:
    """The modes of a CalculiX *FREQUENCY job (--from-calculix JOB.frd with --mesh JOB.inp and the node sets,
    `sim.hosts.calculix`)."""
    from sim.hosts.calculix import calculix_modal_model

    if args.variant is not None:
        raise SimulationInputError("--variant with --from-calculix: the job defines the model; drop --variant")
    missing = [o for o, v in (("--mesh JOB.inp", args.mesh), ("--wall-left", args.wall_left),
                              ("--wall-right", args.wall_right), ("--tip", args.tip)) if not v]
    if missing:
        raise SimulationInputError(f"--from-calculix also needs {', '.join(missing)}")
    result = calculix_modal_model(args.from_calculix, args.mesh, args.wall_left, args.wall_right, args.tip,
                                  dat=args.dat, units=args.units, n_modes=args.n_modes, floor=args.floor,
                                  beam_mass=args.beam_mass)
    return HostModel(result.model, None, result.provenance, result.report)


#: the sources of `ies modes`, the default (no option) first
HOST_SOURCES: dict[str, HostSource] = {row.name: row for row in (
    HostSource("rig", None, {}, built_in_rig),
    HostSource("file", "--model", {"dest": "model", "metavar": "FILE",
                                   "help": "read a modal-model file (`ies modes --save`; or a file kind another "
                                           "source reads) instead of the built-in seed rig"}, modal_model_file),
    HostSource("solid", "--solid", {"action": "store_true",
                                    "help": "the rig as a 3D solid finite-element model (sim.hosts.solid; needs pip "
                                            "install '.[solid]')"}, solid_model, fe_options=True),
    HostSource("calculix", "--from-calculix", {"dest": "from_calculix", "metavar": "JOB.frd",
                                               "help": "mode shapes of a CalculiX *FREQUENCY job (ASCII .frd; with --mesh "
                                                       "JOB.inp and the node sets --wall-left, --wall-right, --tip; "
                                                       "participation from JOB.dat)"}, calculix_job, fe_options=True),
)}


def add_source_options(group: Any) -> None:
    """Add every row's selecting option to `group` (an argparse mutually exclusive group)."""
    for row in HOST_SOURCES.values():
        if row.flag is not None:
            group.add_argument(row.flag, **{"dest": row.dest, **row.flag_kwargs})


#: the host options every source may read, with their defaults (`add_host_arguments`); the defaults are what a
#: study or a design gets (`resolve_host` with a mapping)
HOST_OPTIONS: dict[str, Any] = {"variant": None, "n_modes": 9, "joint_stiffness": None, "mesh": None, "geometry": None,
                                "patch_radius": 0.0, "wall_left": None, "wall_right": None, "tip": None, "dat": None,
                                "floor": None, "beam_mass": None, "units": "m-kg-s"}


def add_host_arguments(parser: argparse.ArgumentParser) -> None:
    """The host options of every simulation command (`ies modes`, `sweep`, `overview`, `trace`): one option per row of
    `HOST_SOURCES` (mutually exclusive), the built-in rig's variant, modes and joint stiffness, and the FE options."""
    add_source_options(parser.add_mutually_exclusive_group())
    parser.add_argument("--variant", default=None, metavar="NAME",
                        help="updating variant of the built-in rig: joint-spring (default) or effective-modulus; "
                             "with --solid a variant of the solid model (sim.hosts.variants.SOLID_VARIANTS: beam-neck, "
                             "updated, updated-400, updated-contact+2mm, updated-contact+4mm, updated-hertz-patch, "
                             "updated-patch-3mm)")
    parser.add_argument("--n-modes", dest="n_modes", type=int, default=HOST_OPTIONS["n_modes"], metavar="N",
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
    solid.add_argument("--patch-radius", dest="patch_radius", type=float, default=HOST_OPTIONS["patch_radius"],
                       metavar="M", help="--solid: average the wall values over a circle of this radius (m) on each wall face")
    solid.add_argument("--wall-left", dest="wall_left", metavar="NSET", help="--from-calculix: node set of the left wall")
    solid.add_argument("--wall-right", dest="wall_right", metavar="NSET", help="--from-calculix: node set of the right wall")
    solid.add_argument("--tip", metavar="NSET", help="--from-calculix: node set of the measurement point")
    solid.add_argument("--dat", metavar="JOB.dat", help="--from-calculix: the job's .dat (default: beside the .frd)")
    solid.add_argument("--floor", metavar="NSET",
                       help="--from-calculix: node set of the cavity floor under the sphere (phi_floor, for friction)")
    solid.add_argument("--beam-mass", dest="beam_mass", type=float, metavar="KG",
                       help="--from-calculix: mass of the beam's free length without the block in kg (for Eq. 10)")
    solid.add_argument("--units", default=HOST_OPTIONS["units"], choices=("m-kg-s", "mm-t-s"),
                       help="--from-calculix: the job's consistent units (default m-kg-s)")


def resolve_host(options: argparse.Namespace | Mapping[str, Any] | None = None, *, summary: bool = False) -> HostModel:
    """The host model of a command's options or of a study's or a design's settings (a mapping such as
    {"model": "rig.toml", "n_modes": 9}; missing options take `HOST_OPTIONS`' defaults): the row of `HOST_SOURCES`
    the options select (the first row without an option when none does), after the checks every source shares (the
    number of modes, the options that belong to another source); one `SimulationInputError` line for anything wrong.
    summary: also the built-in rig's updating summary (`ies modes`)."""
    given = vars(options) if isinstance(options, argparse.Namespace) else dict(options or {})
    args = argparse.Namespace(**{**HOST_OPTIONS, **{row.dest: None for row in HOST_SOURCES.values()}, **given,
                                 "summary": summary})
    if not 1 <= args.n_modes <= 30:
        raise SimulationInputError(f"--n-modes must lie in 1..30, got {args.n_modes}")
    chosen = [row for row in HOST_SOURCES.values() if row.selected(args)]
    source = chosen[0] if chosen else next(row for row in HOST_SOURCES.values() if row.flag is None)
    if args.joint_stiffness is not None and source.flag is not None:
        others = [row.flag for row in HOST_SOURCES.values() if row.flag is not None]
        raise SimulationInputError("--joint-stiffness re-updates the built-in rig; drop "
                                   + ", ".join(others[:-1]) + f" and {others[-1]}")
    if not source.fe_options and any(getattr(args, dest, None) not in (None, False, HOST_OPTIONS.get(dest))
                                     for dest, _ in FE_OPTIONS):
        owners = [row.flag for row in HOST_SOURCES.values() if row.fe_options]
        flags = [flag for _, flag in FE_OPTIONS]
        raise SimulationInputError(", ".join(flags[:-1]) + f" and {flags[-1]} belong to " + " or ".join(owners))
    return source.build(args)


def host_model(args: argparse.Namespace) -> HostModel:
    """The model `ies modes` shows (`resolve_host` with the rig's updating summary)."""
    return resolve_host(args, summary=True)
