"""Tangential stiffness of a stuck contact from the Cerruti operator (seed paper, Appendix C).

Appendix C of the paper adds an elastic dry-friction element whose stiffness follows Cattaneo-Mindlin
theory for the sphere on the flat wall under the sphere's weight. Here the stuck contact area (from
the normal BEM solution) is given a unit rigid slip u_x = 1, u_y = 0; the tractions follow from the
Cerruti influence operator (`bem_contact.influence.TangentialOperator`, solved by conjugate
gradients), and k_t = sum(q_x) dx^2 / u_x. For a circle of radius a this converges to Mindlin's
k_t = 8 G* a (Johnson, Contact Mechanics, Eq. 7.41); Dundurs' normal-tangential coupling is
neglected, as in Mindlin's solution.

The paper's 22 kN/mm is not reproduced, and it stays the friction element's default with this caveat. Under the
sphere's weight (N = m_a g = 0.174 N, a = 23.9 um) the stuck sphere on the flat gives 2.965 kN/mm (BEM, grid 96)
and 2.962 kN/mm (Mindlin), 7.43x below it. No assumption found gives 22 kN/mm for a physical reason: Mindlin
reaches it at N = 71 N (410x the weight); E* instead of G* gives 14.4 kN/mm (E*/G* = 4.86 for nu = 0.3); the
groove's two edge contacts (30 deg from the vertical, 0.58 N each) give 4.9 kN/mm with G* (24.0 with E*, and an
edge is not a Hertz contact); Mindlin's secant stiffness to full slip at mu = 0.07 is 2.0 kN/mm; the Hertz
contact at the largest simulated indentation, 40 um, would give 69.6 kN/mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from bem_contact.errors import ContactInputError, ConvergenceError
from bem_contact.geometry import sphere_gap
from bem_contact.hertz import hertz_indentation_from_force, hertz_radius, mindlin_tangential_stiffness
from bem_contact.influence import TangentialOperator
from bem_contact.materials import Material, contact_modulus, tangential_modulus
from bem_contact.solvers import solve_contact


def tangential_stiffness(contact: np.ndarray, dx: float, a: Material, b: Material, *, tol: float = 1e-10) -> float:
    """Stiffness (N/m) of a fully stuck contact area against a rigid slip in x (axis 0 of the grid).

    Args:
        contact: boolean map of the stuck elements (e.g. ``result.pressure > 0``).
        dx: grid pitch (m); a, b: the two materials.
    """
    mask = np.asarray(contact, dtype=bool)
    if mask.ndim != 2 or not mask.any():
        raise ContactInputError("contact map must be a 2-D boolean array with at least one element in contact")
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    sub = mask[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    op = TangentialOperator(sub.shape, dx, a, b)
    n = int(sub.sum())
    unit = dx / tangential_modulus(a, b)  # compliance scale: keeps the CG system O(1)

    def apply(v: np.ndarray) -> np.ndarray:
        qx = np.zeros(sub.shape)
        qy = np.zeros(sub.shape)
        qx[sub], qy[sub] = v[:n], v[n:]
        ux, uy = op(qx, qy)
        return np.concatenate([ux[sub], uy[sub]]) / unit

    rhs = np.concatenate([np.ones(n), np.zeros(n)])  # unit slip in x, none in y
    solution, info = spla.cg(spla.LinearOperator((2 * n, 2 * n), matvec=apply), rhs, rtol=tol, maxiter=20 * n + 100)
    if info != 0:
        raise ConvergenceError(f"tangential CG did not converge (info {info}); loosen tol or use a coarser grid")
    return float(solution[:n].sum() / unit * dx * dx)


@dataclass(frozen=True)
class TangentialCheck:
    """BEM tangential stiffness of a sphere on a flat wall beside Mindlin's k_t = 8 G* a (N/m, m, N)."""

    k_t: float
    k_t_mindlin: float
    contact_radius: float
    normal_force: float
    grid: int


def sphere_tangential_stiffness(normal_force: float, R: float, a: Material, b: Material, *, grid: int = 96) -> TangentialCheck:
    """Tangential stiffness of a sphere (radius R, m) pressed on a flat wall by normal_force (N) (Appendix C).

    The normal contact is solved by BEM (paraboloid, load control) on a domain of 4 Hertz radii, then the
    stuck area is slipped by the Cerruti operator.
    """
    if not (math.isfinite(normal_force) and normal_force > 0):
        raise ContactInputError(f"normal force = {normal_force!r} N must be a finite number > 0")
    E_star = contact_modulus(a, b)
    radius = float(hertz_radius(hertz_indentation_from_force(normal_force, R, E_star), R))
    gap, dx = sphere_gap(grid, 4.0 * radius, R)
    normal = solve_contact(gap, dx, E_star, force=normal_force)
    k_t = tangential_stiffness(normal.pressure > 0, dx, a, b)
    return TangentialCheck(k_t, float(mindlin_tangential_stiffness(radius, tangential_modulus(a, b))), radius, normal_force, grid)
