"""The sphere as a user describes it (seed paper Sect. 2, Table 1, Eq. 8): its radius and material, the material of the
cavity walls it strikes, and what follows from them, its mass m_a (Eq. 3) and its Hertz constant k_H* (Eq. 8, with
**both** bodies' E and nu). Every command takes it the same way (`--radius`, `--material`, `--mass`, `--wall-material`;
a study's or a design's [impactor] table), and `build_system` (`sim.model.system`) turns it into the simulated
`Impactor` through the settings it feeds (`Sphere.settings`); `--k-H` given outright still wins over Eq. 8.

The seed paper's sphere (R = 7.92 mm, brass, on the rig's steel walls) keeps Table 1's weighed mass, 17.7 g (its
density gives 17.6 g), and Table 2's rounded k_H* = 282e3 N/mm^1.5 (Eq. 8 gives 281.76e3): so the rig's results stay
the paper's to the last bit. Any other sphere takes the solid sphere's mass and Eq. 8.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Callable

from sim.common.errors import SimulationInputError
from sim.model.materials import (MATERIALS, STEEL_WALL, Material, contact_modulus, hertz_constant, material_of,
                                 sphere_mass)
from sim.model.parameters import K_H_NOMINAL, SPHERE_MASS, SPHERE_RADIUS, SystemSettings

if TYPE_CHECKING:
    import argparse

    from sim.common.units import Quantity

#: the seed paper's sphere material (Table 1)
PAPER_MATERIAL = MATERIALS["brass"]
#: a given mass may differ this much (relative) from the solid sphere of the given radius and material
MASS_TOLERANCE = 0.02


@dataclass(frozen=True)
class Sphere:
    """The impactor as described: radius (m), material (`sim.model.materials.Material`), the wall it strikes (its E
    and nu enter Eq. 8) and, optionally, its mass given outright (kg: a hollow or a weighed sphere)."""

    radius: float = SPHERE_RADIUS
    material: Material = PAPER_MATERIAL
    wall: Material = STEEL_WALL
    mass_given: float | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise SimulationInputError(f"the sphere radius must be a positive length, got {self.radius!r} m")
        if self.mass_given is not None and not (math.isfinite(self.mass_given) and self.mass_given > 0):
            raise SimulationInputError(f"the sphere mass must be a positive mass, got {self.mass_given!r} kg")
        if self.mass_given is None and not math.isfinite(self.material.density):
            raise SimulationInputError(f"the sphere material {self.material.name} has no density: give it "
                                       "(density=...kg/m3) or the mass (--mass)")

    @property
    def is_paper(self) -> bool:
        """The seed paper's sphere on the rig's steel (Table 1): the values of Tables 1 and 2 apply."""
        return (self.radius == SPHERE_RADIUS and self.material == PAPER_MATERIAL
                and (self.wall.E, self.wall.nu) == (STEEL_WALL.E, STEEL_WALL.nu))

    @property
    def mass(self) -> float:
        """m_a (kg): given, Table 1's 17.7 g for the paper's sphere, else the solid sphere's (4/3) pi R^3 rho."""
        if self.mass_given is not None:
            return self.mass_given
        return SPHERE_MASS if self.is_paper else float(sphere_mass(self.radius, self.material))

    @property
    def contact_modulus(self) -> float:
        """E* (Pa) of Eq. 8's bracket, sphere on wall."""
        return contact_modulus(self.material, self.wall)

    @property
    def k_H_star(self) -> float:
        """k_H* (N/m^1.5) of Eq. 8, (4/3) sqrt(R) E*; Table 2's 282e3 N/mm^1.5 for the paper's sphere."""
        return K_H_NOMINAL if self.is_paper else hertz_constant(self.radius, self.material, self.wall)

    def settings(self, base: SystemSettings = SystemSettings()) -> SystemSettings:
        """`base` with this sphere's mass and k_H* (the settings the parameters' options then override)."""
        return replace(base, mass=self.mass, k_H=self.k_H_star)

    def describe(self) -> dict[str, object]:
        """Its JSON keys (SI): radius_m, material (name, E_Pa, nu, density), mass_kg, k_H_star_N_per_m1p5 (Eq. 8),
        E_star_Pa, wall_material (name, E_Pa, nu)."""
        return {"radius_m": self.radius, "material": self.material.describe(), "mass_kg": self.mass,
                "k_H_star_N_per_m1p5": self.k_H_star, "E_star_Pa": self.contact_modulus,
                "wall_material": self.wall.describe()}

    def text(self) -> str:
        """One line: the sphere, its mass and k_H*, the wall."""
        return (f"sphere R = {1e3 * self.radius:.4g} mm {self.material.name}, m_a = {1e3 * self.mass:.4g} g, on "
                f"{self.wall.name} walls: k_H* = {self.k_H_star / 1e3**1.5 / 1e3:.1f}e3 N/mm^1.5 (Eq. 8"
                f"{', Table 2' if self.is_paper else ''})")


def sphere_of(radius: float | None = None, material: str | Material | None = None, mass: float | None = None,
              wall: str | Material | None = None, *, host_wall: Material | None = None) -> Sphere:
    """The sphere of what a user gave (each None: not given): radius (m), material (a name or `Material`), mass (kg),
    wall (a name or `Material`; default the host's, `host_wall`, else the rig's steel). A mass given together with both
    the radius and the material must be the solid sphere's within MASS_TOLERANCE; one `SimulationInputError` line
    otherwise, naming what to drop."""
    mat = material_of(material, "sphere") if isinstance(material, str) else (material or PAPER_MATERIAL)
    wall_mat = material_of(wall, "wall") if isinstance(wall, str) else (wall or host_wall or STEEL_WALL)
    sphere = Sphere(SPHERE_RADIUS if radius is None else float(radius), mat, wall_mat,
                    None if mass is None else float(mass))
    if mass is not None and radius is not None and material is not None and math.isfinite(mat.density):
        solid = float(sphere_mass(sphere.radius, mat))
        if abs(mass / solid - 1.0) > MASS_TOLERANCE:
            raise SimulationInputError(
                f"--mass {1e3 * mass:.4g} g disagrees with a solid {mat.name} sphere of R = {1e3 * sphere.radius:.4g} mm "
                f"({1e3 * solid:.4g} g, {100 * (mass / solid - 1):+.1f} %); give --mass alone (a hollow or weighed "
                "sphere) or --radius and --material alone")
    return sphere


# ---- the options of every simulation command ------------------------------------------------------------------

def add_sphere_arguments(parser: "argparse.ArgumentParser") -> None:
    """The impactor's options of `ies modes`, `sweep`, `overview`, `trace`, `orbits`: --radius, --material, --mass,
    --wall-material (each None when not given: `sphere_from_options`), and --g-star, the nominal clearance g* of the
    normalisation (Sect. 5.3)."""
    from sim.model.materials import WALL_MATERIALS

    group = parser.add_argument_group("the sphere (the impactor) and its walls; default the seed paper's: R = 7.92 mm "
                                      "brass, 17.7 g, on steel")
    group.add_argument("--radius", type=_option(_radius), default=None, metavar="R",
                       help="sphere radius with its unit, e.g. 5mm (default 7.92 mm)")
    group.add_argument("--material", type=_option(lambda t: material_of(t, "sphere")), default=None, metavar="NAME",
                       help=f"sphere material: {', '.join(MATERIALS)}, or your own E=200GPa,nu=0.29,density=7850kg/m3 "
                            "(default brass)")
    group.add_argument("--mass", type=_option(_mass), default=None, metavar="M",
                       help="sphere mass with its unit, e.g. 4g (default: the solid sphere's; the paper's 17.7 g); with "
                            "--radius and --material it must agree with them within 2 %%")
    group.add_argument("--wall-material", dest="wall_material", type=_option(lambda t: material_of(t, "wall")),
                       default=None, metavar="NAME",
                       help=f"the cavity walls' material for Eq. 8: {', '.join(WALL_MATERIALS)}, or your own "
                            "E=70GPa,nu=0.33 (default: the host's [host] wall_material, else steel)")
    group.add_argument("--g-star", dest="g_star", type=_option(_clearance), default=None, metavar="G",
                       help="nominal clearance g* by which the levels a_base/a_base* are normalised (Sect. 5.3), e.g. "
                            "1.25mm (default the paper's 0.58 mm, whatever --g simulates)")


def sphere_from_options(args: "argparse.Namespace", host_wall: Material | None = None) -> Sphere:
    """The sphere of a command's options (`add_sphere_arguments`; the host's wall material when --wall-material is
    not given); one `SimulationInputError` line for a mass that disagrees with the radius and the material."""
    return sphere_of(getattr(args, "radius", None), getattr(args, "material", None), getattr(args, "mass", None),
                     getattr(args, "wall_material", None), host_wall=host_wall)


def _radius(text: str) -> float:
    from sim.common.units import RADIUS

    return _positive(text, RADIUS)


def _mass(text: str) -> float:
    from sim.common.units import MASS

    return _positive(text, MASS)


def _clearance(text: str) -> float:
    from sim.common.units import CLEARANCE

    return _positive(text, CLEARANCE)


def _positive(text: str, quantity: "Quantity") -> float:
    """A positive quantity with its unit (a bare number is SI), refused when implausible for the quantity."""
    from sim.common.units import implausible, parse_quantity

    value = parse_quantity(text, quantity)
    if not (math.isfinite(value) and value > 0):
        raise SimulationInputError(f"{quantity.name} must be positive, got {text!r}")
    if (why := implausible(value, quantity)) is not None:
        raise SimulationInputError(why)
    return value


def _option(parse: Callable[[str], object]) -> Callable[[str], object]:
    """An argparse type from a parser that raises SimulationInputError (one line ``argument --X: ...``)."""
    import argparse

    def value(text: str) -> object:
        try:
            return parse(text)
        except SimulationInputError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    value.__name__ = getattr(parse, "__name__", "value")
    return value
