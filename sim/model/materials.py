"""The materials of the seed paper (Table 1) and Eq. 8, defined once for every stage: the host's steel, the sphere
materials of `ies design` (density, Young's modulus, Poisson's ratio), the sphere's mass from its radius, and the
Hertz constant k_H = (4/3) sqrt(R) E* of a sphere on a flat wall with the contact modulus E* of Eq. 8's bracket
(`contact_modulus_of`, `hertz_constant_of`; `bem_contact.materials` and `bem_contact.calibration` use them too).

Values are handbook values at room temperature (ASM Handbook vol. 2 and MatWeb for the alloys named): brass is the
free-cutting brass CuZn39Pb3 (CW614N / C38500) of turned balls, with the seed paper's E = 102 GPa (Table 1; handbooks
give 97-105 GPa); steel is AISI 52100 bearing steel of commercial balls; tungsten is a sintered tungsten heavy alloy
(W-Ni-Fe, 95 % W) that balls are made of, not pure tungsten (19.3 g/cm^3, 411 GPa, too brittle to make balls from).
The paper's brass sphere of radius 7.92 mm weighs 17.7 g (Table 1); 8470 kg/m^3 gives 17.6 g.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from sim.common.errors import SimulationInputError


@dataclass(frozen=True)
class SphereMaterial:
    """An isotropic sphere material: density (kg/m^3), E (Pa), nu (-), and what it is."""

    name: str
    density: float
    E: float
    nu: float
    what: str


#: Table 1: the host's steel (the rig and its cavity walls) and the sphere's brass, E in Pa and nu (-)
HOST_E, HOST_NU = 207e9, 0.30
BRASS_E, BRASS_NU = 102e9, 0.30

MATERIALS: dict[str, SphereMaterial] = {m.name: m for m in (
    SphereMaterial("brass", 8470.0, BRASS_E, BRASS_NU, "free-cutting brass CuZn39Pb3 (the seed paper's sphere, Table 1)"),
    SphereMaterial("steel", 7810.0, HOST_E, HOST_NU, "bearing steel AISI 52100 (E as the paper's host, Table 1)"),
    SphereMaterial("tungsten", 18000.0, 360e9, 0.29, "tungsten heavy alloy W-Ni-Fe, 95 % W"),
)}


def material(name: str) -> SphereMaterial:
    """The sphere material called `name` (one line naming the known ones otherwise)."""
    try:
        return MATERIALS[name.strip().lower()]
    except KeyError:
        raise SimulationInputError(f"unknown sphere material {name!r}; choose one of {', '.join(MATERIALS)}") from None


def ball_mass(radius: ArrayLike, density: float) -> np.ndarray | float:
    """Mass (kg) of a solid sphere of `radius` (m, a number or an array) and `density` (kg/m^3): (4/3) pi R^3 rho."""
    mass = 4.0 / 3.0 * math.pi * np.asarray(radius, dtype=float) ** 3 * float(density)
    return float(mass) if mass.ndim == 0 else mass


def sphere_mass(radius: ArrayLike, mat: SphereMaterial) -> np.ndarray | float:
    """Mass (kg) of a solid sphere of `radius` (m, a number or an array) of the material `mat`."""
    return ball_mass(radius, mat.density)


def contact_modulus_of(E_a: float, nu_a: float, E_b: float, nu_b: float) -> float:
    """E* = [(1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b]^-1 in Pa of two bodies in contact (the bracket of Eq. 8; E in Pa)."""
    return 1.0 / ((1.0 - nu_a**2) / E_a + (1.0 - nu_b**2) / E_b)


def hertz_constant_of(radius: float, E_star: float) -> float:
    """Eq. 8: k_H = (4/3) sqrt(R) E* in N/m^1.5 of a sphere of radius R (m) on a flat wall, E* in Pa."""
    return 4.0 / 3.0 * math.sqrt(radius) * E_star


def contact_modulus(mat: SphereMaterial, host_E: float = HOST_E, host_nu: float = HOST_NU) -> float:
    """E* (Pa) of a sphere of `mat` on the host's wall (the bracket of Eq. 8)."""
    return contact_modulus_of(mat.E, mat.nu, host_E, host_nu)


def hertz_constant(radius: float, mat: SphereMaterial) -> float:
    """k_H of a sphere of `radius` (m) on the host's flat steel wall, Eq. 8: (4/3) sqrt(R) E*, in N/m^1.5."""
    return hertz_constant_of(radius, contact_modulus(mat))
