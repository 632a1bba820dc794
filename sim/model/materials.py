"""The materials of the seed paper (Table 1) and Eq. 8, defined once for every stage: the sphere materials
(`MATERIALS`: density, Young's modulus, Poisson's ratio), the materials of the cavity walls (`WALL_MATERIALS`: the
host's steel of Table 1 and the usual alternatives), materials of one's own (`material_of`: ``E=70GPa,nu=0.33``), the
sphere's mass from its radius, and the Hertz constant k_H = (4/3) sqrt(R) E* of a sphere on a flat wall with the
contact modulus E* of Eq. 8's bracket, which takes **both** bodies' E and nu (`contact_modulus_of`,
`hertz_constant_of`; `bem_contact.materials` and `bem_contact.calibration` use them too).

Values are handbook values at room temperature (ASM Handbook vol. 2 and MatWeb for the alloys named): brass is the
free-cutting brass CuZn39Pb3 (CW614N / C38500) of turned balls, with the seed paper's E = 102 GPa (Table 1; handbooks
give 97-105 GPa); steel is AISI 52100 bearing steel of commercial balls; tungsten is a sintered tungsten heavy alloy
(W-Ni-Fe, 95 % W) that balls are made of, not pure tungsten (19.3 g/cm^3, 411 GPa, too brittle to make balls from).
The paper's brass sphere of radius 7.92 mm weighs 17.7 g (Table 1); 8470 kg/m^3 gives 17.6 g.
Walls: aluminium is the wrought alloy 6061-T6 (68.9 GPa, 0.33), titanium the alloy Ti-6Al-4V (113.8 GPa, 0.342), cast
iron the grey iron EN-GJL-250 / ASTM A48 class 35 (110 GPa, 0.26; its modulus falls with the load, 100-120 GPa).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from sim.common.errors import SimulationInputError


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material: density (kg/m^3; NaN where only E and nu are known, e.g. a wall of one's own),
    E (Pa), nu (-), and what it is."""

    name: str
    density: float
    E: float
    nu: float
    what: str

    def describe(self) -> dict[str, object]:
        """Its JSON keys: name, E_Pa, nu, density_kg_per_m3 (None when unknown)."""
        return {"name": self.name, "E_Pa": self.E, "nu": self.nu,
                "density_kg_per_m3": self.density if math.isfinite(self.density) else None}


#: Table 1: the host's steel (the rig and its cavity walls) and the sphere's brass, E in Pa and nu (-)
HOST_E, HOST_NU = 207e9, 0.30
BRASS_E, BRASS_NU = 102e9, 0.30

MATERIALS: dict[str, Material] = {m.name: m for m in (
    Material("brass", 8470.0, BRASS_E, BRASS_NU, "free-cutting brass CuZn39Pb3 (the seed paper's sphere, Table 1)"),
    Material("steel", 7810.0, HOST_E, HOST_NU, "bearing steel AISI 52100 (E as the paper's host, Table 1)"),
    Material("tungsten", 18000.0, 360e9, 0.29, "tungsten heavy alloy W-Ni-Fe, 95 % W"),
)}


#: the materials of the cavity walls (the host's, where the sphere strikes); steel is Table 1's host steel
WALL_MATERIALS: dict[str, Material] = {m.name: m for m in (
    Material("steel", 7850.0, HOST_E, HOST_NU, "the seed rig's steel (Table 1, E updated to 207 GPa, Appendix A)"),
    Material("aluminium", 2700.0, 68.9e9, 0.33, "wrought aluminium alloy 6061-T6"),
    Material("titanium", 4430.0, 113.8e9, 0.342, "titanium alloy Ti-6Al-4V"),
    Material("brass", 8470.0, BRASS_E, BRASS_NU, "free-cutting brass CuZn39Pb3 (as the seed paper's sphere)"),
    Material("cast-iron", 7200.0, 110e9, 0.26, "grey cast iron EN-GJL-250 (ASTM A48 class 35)"),
)}
#: the seed rig's wall (Table 1): every host without a wall material of its own
STEEL_WALL = WALL_MATERIALS["steel"]
#: aliases users type for a wall material
_WALL_ALIASES = {"aluminum": "aluminium", "al": "aluminium", "ti": "titanium", "cast iron": "cast-iron",
                 "cast_iron": "cast-iron", "castiron": "cast-iron", "iron": "cast-iron"}

#: the pressure units of a material of one's own (`material_of`)
_PRESSURE = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "gpa": 1e9}
_DENSITY = {"kg/m3": 1.0, "kg/m^3": 1.0, "g/cm3": 1e3, "g/cm^3": 1e3}
_NUMBER_UNIT = re.compile(r"^\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(.*?)\s*$")


def material(name: str) -> Material:
    """The sphere material called `name`, or one of one's own (`material_of`); one line naming the known ones
    otherwise."""
    return material_of(name, "sphere")


def wall_material(name: str) -> Material:
    """The wall material called `name` (`WALL_MATERIALS`, aliases such as aluminum), or one of one's own
    (`material_of`); one line naming the known ones otherwise."""
    return material_of(name, "wall")


def material_of(text: str, kind: str = "sphere") -> Material:
    """A material of `kind` ("sphere": `MATERIALS`, "wall": `WALL_MATERIALS`) by its name, or of one's own as
    ``E=200GPa,nu=0.29[,density=7850]`` (E with a unit Pa, MPa or GPa, or a number in Pa; nu in [0, 0.5); the density in
    kg/m^3 or g/cm^3, required for a sphere, whose mass it gives). One `SimulationInputError` line otherwise."""
    known = MATERIALS if kind == "sphere" else WALL_MATERIALS
    text = str(text).strip()
    key = text.lower()
    key = _WALL_ALIASES.get(key, key) if kind == "wall" else key
    if key in known:
        return known[key]
    if "=" not in text:
        raise SimulationInputError(f"unknown {kind} material {text!r}; choose one of {', '.join(known)}, or give your "
                                   f"own as E=...GPa,nu=...{',density=...kg/m3' if kind == 'sphere' else ''}")
    return _own_material(text, kind)


def _own_material(text: str, kind: str) -> Material:
    """`material_of` for ``KEY=VALUE,...`` (E, nu, density)."""
    what = f"{kind} material {text!r}"
    values: dict[str, float] = {}
    for item in text.split(","):
        key, _, value = (part.strip() for part in item.partition("="))
        key = key.lower()
        units = {"e": _PRESSURE, "nu": {"": 1.0}, "density": _DENSITY, "rho": _DENSITY}.get(key)
        match = _NUMBER_UNIT.match(value)
        if units is None or not match:
            raise SimulationInputError(f"{what}: cannot read {item.strip()!r}; give E=...GPa,nu=...,density=...kg/m3")
        unit = match.group(2).lower().replace(" ", "")
        factor = units.get(unit, 1.0 if unit == "" else None)  # a bare number is SI
        if factor is None:
            raise SimulationInputError(f"{what}: unknown unit {match.group(2)!r} for {key}; use "
                                       f"{', '.join(u for u in units if u) or 'a plain number'}")
        values["density" if key == "rho" else key] = float(match.group(1)) * factor
    missing = [k for k in ("e", "nu", *(("density",) if kind == "sphere" else ())) if k not in values]
    if missing:
        raise SimulationInputError(f"{what}: missing {', '.join(missing)}; give E=...GPa,nu=..."
                                   f"{',density=...kg/m3 (its mass follows from it)' if kind == 'sphere' else ''}")
    E, nu, density = values["e"], values["nu"], values.get("density", math.nan)
    if not (math.isfinite(E) and 1e8 <= E <= 2e12):
        raise SimulationInputError(f"{what}: E = {E:.3g} Pa is not a solid's Young's modulus (0.1-2000 GPa); give "
                                   "it with its unit, e.g. E=70GPa")
    if not (math.isfinite(nu) and 0.0 <= nu < 0.5):
        raise SimulationInputError(f"{what}: nu = {nu:g} must lie in [0, 0.5)")
    if kind == "sphere" and not (math.isfinite(density) and 500.0 <= density <= 25000.0):
        raise SimulationInputError(f"{what}: density {density:.4g} kg/m^3 is not a solid's (500-25000 kg/m^3); give it "
                                   "with its unit, e.g. density=7850kg/m3")
    name = f"E={E / 1e9:.4g}GPa,nu={nu:g}" + (f",density={density:.6g}kg/m3" if math.isfinite(density) else "")
    return Material(name, density, E, nu, f"a {kind} material of one's own")


def ball_mass(radius: ArrayLike, density: float) -> np.ndarray | float:
    """Mass (kg) of a solid sphere of `radius` (m, a number or an array) and `density` (kg/m^3): (4/3) pi R^3 rho."""
    mass = 4.0 / 3.0 * math.pi * np.asarray(radius, dtype=float) ** 3 * float(density)
    return float(mass) if mass.ndim == 0 else mass


def sphere_mass(radius: ArrayLike, mat: Material) -> np.ndarray | float:
    """Mass (kg) of a solid sphere of `radius` (m, a number or an array) of the material `mat`."""
    return ball_mass(radius, mat.density)


def contact_modulus_of(E_a: float, nu_a: float, E_b: float, nu_b: float) -> float:
    """E* = [(1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b]^-1 in Pa of two bodies in contact (the bracket of Eq. 8; E in Pa)."""
    return 1.0 / ((1.0 - nu_a**2) / E_a + (1.0 - nu_b**2) / E_b)


def hertz_constant_of(radius: float, E_star: float) -> float:
    """Eq. 8: k_H = (4/3) sqrt(R) E* in N/m^1.5 of a sphere of radius R (m) on a flat wall, E* in Pa."""
    return 4.0 / 3.0 * math.sqrt(radius) * E_star


def contact_modulus(mat: Material, wall: Material = STEEL_WALL) -> float:
    """E* (Pa) of a sphere of `mat` on a wall of `wall` (the bracket of Eq. 8, both bodies' E and nu)."""
    return contact_modulus_of(mat.E, mat.nu, wall.E, wall.nu)


def hertz_constant(radius: float, mat: Material, wall: Material = STEEL_WALL) -> float:
    """k_H of a sphere of `radius` (m) and material `mat` on a flat wall of `wall` (default the rig's steel), Eq. 8:
    (4/3) sqrt(R) E*, in N/m^1.5."""
    return hertz_constant_of(radius, contact_modulus(mat, wall))
