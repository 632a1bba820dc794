"""Gap maps of ideal geometries on a regular grid (seed paper, Sect. 4.1: the ideal sphere on a flat wall)."""
from __future__ import annotations

import math

import numpy as np

from bem_contact.errors import ContactInputError

SHAPES = ("paraboloid", "sphere")
MAX_GRID = 4096  # elements across; the zero-padded FFT operator of a larger grid needs > 1 GB


def grid_coordinates(n: int, side: float) -> tuple[np.ndarray, float]:
    """Element-centre coordinates (m) of n elements across a side (m), and the pitch dx = side / n (m).

    Node n // 2 sits at 0, so the apex of a centred body is on a node for odd and even n alike.
    """
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ContactInputError(f"grid size n = {n!r} must be a whole number >= 1 (for example 256)")
    if n > MAX_GRID:
        raise ContactInputError(f"grid size n = {n} is too large (at most {MAX_GRID}: the FFT operator would need > 1 GB); 512 is already accurate to ~1e-5")
    if not (math.isfinite(side) and side > 0):
        raise ContactInputError(f"domain side = {side!r} m must be a finite number > 0 (for example 2.5e-3)")
    dx = side / n
    return (np.arange(n) - n // 2) * dx, dx


def sphere_gap(n: int, side: float, R: float, shape: str = "paraboloid") -> tuple[np.ndarray, float]:
    """Initial gap (m) between a sphere of radius R (m) and a flat wall on an n x n grid of the given side (m).

    shape "paraboloid": h = r^2 / (2R), Hertz's geometry (validates against Eq. 8);
    shape "sphere": h = R - sqrt(R^2 - r^2), the exact spherical cap (differs by O((a/R)^2)).
    The apex (h = 0) is on node (n//2, n//2). Returns (gap, dx).
    """
    if shape not in SHAPES:
        raise ContactInputError(f"unknown shape {shape!r}; choose one of {', '.join(SHAPES)}")
    if not (math.isfinite(R) and R > 0):
        raise ContactInputError(f"sphere radius R = {R!r} m must be a finite number > 0 (the IES: 7.92e-3)")
    x, dx = grid_coordinates(n, side)
    r2 = x[:, None] ** 2 + x[None, :] ** 2
    if shape == "paraboloid":
        return r2 / (2.0 * R), dx
    if r2.max() >= R**2:
        raise ContactInputError(f"domain side {side:g} m is too large for a sphere of radius {R:g} m; use side < {R * math.sqrt(2):g} m")
    # R - sqrt(R^2 - r^2) written without cancellation
    return r2 / (R + np.sqrt(R**2 - r2)), dx
