"""Resampling a triangulated surface onto a regular grid, and filling the holes (Sect. 4.1, Fig. 3b).

Each grid node takes the height of the scan's own triangle above it (linear interpolation inside the
triangle, the scanner's surface as delivered); where several triangles cover a node (a fold or an
overlap) the highest wins, the side the sphere sees. Nodes no triangle covers are holes; they are
filled by harmonic (Laplace) interpolation from the surrounding surface and reported.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import scipy.ndimage as ndi
import scipy.sparse as sp
import scipy.sparse.linalg as spla


@numba.njit(cache=True)
def _rasterize(x, y, z, faces, x0, y0, dx, nx, ny, out, hits):  # pragma: no cover - numba
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        xa, ya, xb, yb, xc, yc = x[a], y[a], x[b], y[b], x[c], y[c]
        det = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
        if det == 0.0:
            continue
        i_lo = max(int(np.ceil((min(xa, xb, xc) - x0) / dx)), 0)
        i_hi = min(int(np.floor((max(xa, xb, xc) - x0) / dx)), nx - 1)
        j_lo = max(int(np.ceil((min(ya, yb, yc) - y0) / dx)), 0)
        j_hi = min(int(np.floor((max(ya, yb, yc) - y0) / dx)), ny - 1)
        tol = -1e-12
        for j in range(j_lo, j_hi + 1):
            py = y0 + j * dx
            for i in range(i_lo, i_hi + 1):
                px = x0 + i * dx
                wb = ((px - xa) * (yc - ya) - (xc - xa) * (py - ya)) / det
                wc = ((xb - xa) * (py - ya) - (px - xa) * (yb - ya)) / det
                wa = 1.0 - wb - wc
                if wa >= tol and wb >= tol and wc >= tol:
                    h = wa * z[a] + wb * z[b] + wc * z[c]
                    if hits[j, i] == 0 or h > out[j, i]:
                        out[j, i] = h
                    hits[j, i] += 1


def rasterize(points: np.ndarray, faces: np.ndarray, x0: float, y0: float, dx: float, nx: int, ny: int) -> np.ndarray:
    """Heights (m) of the triangulated surface at nodes (x0 + i dx, y0 + j dx); NaN where no triangle.

    points: (N, 3) local coordinates (x, y, h) in m; faces: (M, 3) triangles. Returns an (ny, nx) array.
    """
    out = np.zeros((ny, nx))
    hits = np.zeros((ny, nx), dtype=np.int32)
    p = np.ascontiguousarray(points, dtype=float)
    _rasterize(p[:, 0].copy(), p[:, 1].copy(), p[:, 2].copy(), np.ascontiguousarray(faces, dtype=np.int64),
               float(x0), float(y0), float(dx), int(nx), int(ny), out, hits)
    out[hits == 0] = np.nan
    return out


@dataclass(frozen=True)
class HoleReport:
    """Grid nodes the scan did not cover and how they were filled.

    n_holes: connected missing regions; n_nodes: missing nodes; largest: the largest region's size
    across (m, equivalent-circle diameter); method: how they were filled.
    """

    n_holes: int
    n_nodes: int
    largest: float
    method: str = "harmonic (Laplace) interpolation from the surrounding surface"

    def describe(self) -> str:
        """One line for the command output."""
        if self.n_nodes == 0:
            return "no holes"
        return (f"{self.n_holes} hole(s), {self.n_nodes} grid node(s), largest {self.largest * 1e6:.0f} um across, "
                f"filled by {self.method}")


def fill_holes(height: np.ndarray, dx: float) -> tuple[np.ndarray, HoleReport]:
    """Fill NaN nodes by solving Laplace's equation with the known nodes as boundary values.

    Returns the filled map and a :class:`HoleReport`. Grid edges act as zero-flux boundaries.
    """
    missing = ~np.isfinite(height)
    if not missing.any():
        return height, HoleReport(0, 0, 0.0)
    if missing.all():
        raise ValueError("no valid height on the grid")
    labels, n_holes = ndi.label(missing)
    sizes = np.bincount(labels.ravel())[1:]
    ny, nx = height.shape
    index = -np.ones(height.shape, dtype=np.int64)
    index[missing] = np.arange(missing.sum())
    rows, cols, vals = [], [], []
    rhs = np.zeros(missing.sum())
    jj, ii = np.nonzero(missing)
    unknown = index[jj, ii]
    degree = np.zeros(unknown.size)
    for dj, di in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        nj, ni = jj + dj, ii + di
        inside = (nj >= 0) & (nj < ny) & (ni >= 0) & (ni < nx)
        degree += inside
        nj_c, ni_c = np.clip(nj, 0, ny - 1), np.clip(ni, 0, nx - 1)
        neighbour_missing = inside & missing[nj_c, ni_c]
        known = inside & ~missing[nj_c, ni_c]
        rows.append(unknown[neighbour_missing])
        cols.append(index[nj_c, ni_c][neighbour_missing])
        vals.append(-np.ones(neighbour_missing.sum()))
        np.add.at(rhs, unknown[known], height[nj_c, ni_c][known])
    rows.append(unknown)
    cols.append(unknown)
    vals.append(degree)
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(unknown.size,) * 2)
    filled = height.copy()
    filled[jj, ii] = spla.spsolve(matrix.tocsc(), rhs)
    largest = 2.0 * np.sqrt(sizes.max() * dx * dx / np.pi)
    return filled, HoleReport(int(n_holes), int(missing.sum()), float(largest))
