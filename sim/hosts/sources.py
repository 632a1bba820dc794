"""Where `ies modes` takes the modal model of the host structure from (seed paper Sect. 3.1, Eq. 7): `HOST_SOURCES`,
one row per source.

A row (`HostSource`) names the source, the option that selects it (argparse keywords; None for the default, the
built-in rig) and the function that builds its `HostModel` from the command's options. `ies modes` adds every row's
option to one group of mutually exclusive choices and builds the model through `host_model`, which holds the checks
shared by all sources. Adding a source (another FE tool, a measured modal model) is adding a row.

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
    """What a source gives `ies modes`: the modal model, the built-in rig's updating summary (`sim.hosts.rig.RigModes`,
    or None), the provenance written with --save (or None) and report lines printed above the table."""

    model: ModalModel
    rig: Any = None
    provenance: dict | None = None
    report: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class HostSource:
    """One row of `HOST_SOURCES`: name; flag, the option that selects it (None: the default source) with its argparse
    keywords `flag_kwargs` (dest = the name's identifier unless given); fe_options: whether it reads the FE options
    (--mesh, --geometry, --wall-left, ...; refused with the other sources); build: the model from the options."""

    name: str
    flag: str | None
    flag_kwargs: Mapping[str, Any]
    build: Callable[[argparse.Namespace], HostModel]
    fe_options: bool = False

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
    --joint-stiffness re-updated with that joint stiffness. Carries its updating summary (f1..f9)."""
    from sim.hosts.rig import DEFAULT_VARIANT, rig_modes, seed_rig_model, variant_parameters

    variant = args.variant or DEFAULT_VARIANT
    provenance, report = None, []
    if args.joint_stiffness is not None:
        model, params, provenance, report = fixed_joint_model(args.joint_stiffness, variant, args.n_modes)
    else:
        model, params = seed_rig_model(n_modes=args.n_modes, variant=variant), variant_parameters(variant)
    rig = rig_modes(params, n_modes=max(args.n_modes, 9))  # its updating summary needs f1..f9
    return HostModel(model, rig, provenance, report)


def modal_model_file(args: argparse.Namespace) -> HostModel:
    """A modal-model file (--model FILE, `sim.hosts.modal_file`)."""
    if args.variant is not None:
        raise SimulationInputError("--variant selects a built-in rig model; it cannot be used with --model")
    return HostModel(model_file(args.model))


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
                                   "help": "read a modal-model file instead of the built-in seed rig"}, modal_model_file),
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


def host_model(args: argparse.Namespace) -> HostModel:
    """The model `ies modes` shows: the row of `HOST_SOURCES` its options select (the first row without one), after
    the checks every source shares (the number of modes, the options that belong to another source); one
    `SimulationInputError` line for anything wrong."""
    if not 1 <= args.n_modes <= 30:
        raise SimulationInputError(f"--n-modes must lie in 1..30, got {args.n_modes}")
    chosen = [row for row in HOST_SOURCES.values() if row.selected(args)]
    source = chosen[0] if chosen else next(row for row in HOST_SOURCES.values() if row.flag is None)
    if args.joint_stiffness is not None and source.flag is not None:
        others = [row.flag for row in HOST_SOURCES.values() if row.flag is not None]
        raise SimulationInputError("--joint-stiffness re-updates the built-in rig; drop "
                                   + ", ".join(others[:-1]) + f" and {others[-1]}")
    if not source.fe_options and any(getattr(args, dest, None) not in (None, False) for dest, _ in FE_OPTIONS):
        owners = [row.flag for row in HOST_SOURCES.values() if row.fe_options]
        flags = [flag for _, flag in FE_OPTIONS]
        raise SimulationInputError(", ".join(flags[:-1]) + f" and {flags[-1]} belong to " + " or ".join(owners))
    return source.build(args)
