"""Hertz's and Mindlin's closed-form solutions for a sphere (paraboloid) on a flat half-space.

These are the analytic references the BEM is checked against (seed paper, Sect. 3.1 and 4.1, Eq. 8;
Johnson, Contact Mechanics, 1985, Sect. 4.2 and 7.2). Symbols: R sphere radius (m), E* contact
modulus (Pa), G* tangential modulus (Pa), delta rigid approach (m), a contact radius (m).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def hertz_force(delta: ArrayLike, R: float, E_star: float) -> np.ndarray:
    """Normal force f = (4/3) E* sqrt(R) delta^1.5 in N (Eq. 4 with k_H* of Eq. 8)."""
    d = np.asarray(delta, dtype=float)
    return 4.0 / 3.0 * E_star * np.sqrt(R) * np.clip(d, 0.0, None) ** 1.5


def hertz_radius(delta: ArrayLike, R: float) -> np.ndarray:
    """Contact radius a = sqrt(R delta) in m."""
    return np.sqrt(R * np.clip(np.asarray(delta, dtype=float), 0.0, None))


def hertz_indentation_from_force(force: ArrayLike, R: float, E_star: float) -> np.ndarray:
    """Approach delta = (3 f / (4 E* sqrt(R)))^(2/3) in m for a normal force f in N."""
    f = np.clip(np.asarray(force, dtype=float), 0.0, None)
    return (3.0 * f / (4.0 * E_star * np.sqrt(R))) ** (2.0 / 3.0)


def hertz_pressure(r: ArrayLike, delta: float, R: float, E_star: float) -> np.ndarray:
    """Pressure p(r) = p0 sqrt(1 - r^2/a^2) in Pa, p0 = 2 E* a / (pi R), zero outside the contact."""
    a = float(hertz_radius(delta, R))
    p0 = 2.0 * E_star * a / (np.pi * R)
    rr = np.asarray(r, dtype=float)
    return p0 * np.sqrt(np.clip(1.0 - (rr / a) ** 2, 0.0, None))


def mindlin_tangential_stiffness(a: ArrayLike, G_star: float) -> np.ndarray:
    """Initial tangential stiffness of a stuck circular contact, k_t = 8 G* a in N/m (Mindlin 1949).

    Used in the seed paper's Appendix C (Cattaneo-Mindlin, normal load from gravity).
    """
    return 8.0 * G_star * np.asarray(a, dtype=float)
