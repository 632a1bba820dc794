"""Elastic materials of the two bodies in contact and their combined moduli (seed paper, Table 1, Eq. 8). Table 1's
values and Eq. 8 are `sim.model.materials`'s (the one vocabulary); this module adds the shear modulus and Mindlin's
tangential combination that the BEM needs."""
from __future__ import annotations

import math
from dataclasses import dataclass

from bem_contact.errors import ContactInputError
from sim.model.materials import BRASS_E, BRASS_NU, HOST_E, HOST_NU, contact_modulus_of, hertz_constant_of


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Attributes:
        E: Young's modulus (Pa), finite and > 0.
        nu: Poisson's ratio (-), in (-1, 0.5).
        name: label used in reports.
    """

    E: float
    nu: float
    name: str = ""

    def __post_init__(self) -> None:
        if not (isinstance(self.E, (int, float)) and math.isfinite(self.E) and self.E > 0):
            raise ContactInputError(f"Young's modulus E = {self.E!r} Pa must be a finite number > 0 (steel: 207e9)")
        if not (isinstance(self.nu, (int, float)) and -1.0 < self.nu < 0.5):
            raise ContactInputError(f"Poisson's ratio nu = {self.nu!r} must lie in (-1, 0.5) (steel, brass: 0.3)")

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + nu)) in Pa."""
        return self.E / (2.0 * (1.0 + self.nu))


# Table 1 of the seed paper.
STEEL = Material(E=HOST_E, nu=HOST_NU, name="steel (host structure, Table 1)")
BRASS = Material(E=BRASS_E, nu=BRASS_NU, name="brass (IES sphere, Table 1)")


def contact_modulus(a: Material, b: Material) -> float:
    """Contact modulus E* = [(1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b]^-1 in Pa (the bracket of Eq. 8)."""
    return contact_modulus_of(a.E, a.nu, b.E, b.nu)


def tangential_modulus(a: Material, b: Material) -> float:
    """Tangential contact modulus G* = [(2 - nu_a)/G_a + (2 - nu_b)/G_b]^-1 in Pa (Mindlin; k_t = 8 G* a)."""
    return 1.0 / ((2.0 - a.nu) / a.G + (2.0 - b.nu) / b.G)


def k_H_star(R: float, a: Material, b: Material) -> float:
    """Hertzian spring constant of a sphere of radius R (m) on a flat wall, Eq. 8: (4/3) sqrt(R) E*, in N/m^1.5."""
    if not (math.isfinite(R) and R > 0):
        raise ContactInputError(f"sphere radius R = {R!r} m must be a finite number > 0 (the IES: 7.92e-3)")
    return hertz_constant_of(R, contact_modulus(a, b))
