"""Resampling a triangulated surface onto a regular grid, and filling the holes (Sect. 4.1, Fig. 3b).

Each grid node takes the height of the scan's own triangle above it (linear interpolation inside the
triangle, the scanner's surface as delivered); where several triangles cover a node (a fold or an
overlap) the highest wins, the side the sphere sees. Nodes no triangle covers are holes; they are
filled from the surrounding surface (local quadratic plus harmonic correction) and reported.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.ndimage as ndi
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from sim.common.kernel_cache import cached_njit


@cached_njit
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
    across (m, equivalent-circle diameter); method: how they were filled; nearest: distance (m) from the grid's
    centre (on a BEM grid the sphere's axis) to the nearest filled node, inf when there is none or it is unknown.
    """

    n_holes: int
    n_nodes: int
    largest: float
    method: str = "a quadratic fitted around each hole plus a harmonic (Laplace) correction"
    nearest: float = float("inf")

    def describe(self) -> str:
        """One line for the command output."""
        if self.n_nodes == 0:
            return "no holes"
        return (f"{self.n_holes} hole(s), {self.n_nodes} grid node(s), largest {self.largest * 1e6:.0f} um across, "
                f"filled by {self.method}")


def fill_holes(height: np.ndarray, dx: float, ring: int = 3) -> tuple[np.ndarray, HoleReport]:
    """Fill the NaN nodes of a height map, hole by hole, and report them.

    For each connected hole: a quadratic surface is fitted by least squares to the known nodes within
    `ring` nodes of it, and the departure from that quadratic is interpolated harmonically (discrete
    Laplace equation, known nodes as boundary values, zero flux across the map's edge). Quadratics and
    discrete-harmonic surfaces are reproduced exactly; a crater's curved bottom is not flattened, as a
    plain Laplace fill would do (by curvature x radius^2 / 2).
    """
    missing = ~np.isfinite(height)
    if not missing.any():
        return height, HoleReport(0, 0, 0.0)
    if missing.all():
        raise ValueError("no valid height on the grid")
    labels, n_holes = ndi.label(missing)
    filled = height.copy()
    for k, box in enumerate(ndi.find_objects(labels), start=1):
        rows = slice(max(box[0].start - ring, 0), min(box[0].stop + ring, height.shape[0]))
        cols = slice(max(box[1].start - ring, 0), min(box[1].stop + ring, height.shape[1]))
        hole = labels[rows, cols] == k
        window = height[rows, cols]
        near = ndi.binary_dilation(hole, iterations=ring) & np.isfinite(window)
        jj, ii = np.mgrid[rows, cols]
        base = _quadratic_fit(ii[near], jj[near], window[near], ii, jj)
        residual = np.where(np.isfinite(window), window - base, 0.0)
        filled[rows, cols] = np.where(hole, base + _laplace_fill(residual, hole), filled[rows, cols])
    sizes = np.bincount(labels.ravel())[1:]
    largest = 2.0 * np.sqrt(sizes.max() * dx * dx / np.pi)
    return filled, HoleReport(int(n_holes), int(missing.sum()), float(largest))


def _quadratic_fit(i: np.ndarray, j: np.ndarray, h: np.ndarray, ii: np.ndarray, jj: np.ndarray) -> np.ndarray:
    """Least-squares quadratic (or lower order if too few points) through (i, j, h), evaluated at (ii, jj)."""
    i0, j0 = i.mean(), j.mean()
    terms = [lambda a, b: np.ones_like(a, dtype=float), lambda a, b: a - i0, lambda a, b: b - j0,
             lambda a, b: (a - i0) ** 2, lambda a, b: (a - i0) * (b - j0), lambda a, b: (b - j0) ** 2]
    use = 6 if h.size >= 12 else 3 if h.size >= 3 else 1
    design = np.column_stack([t(i, j) for t in terms[:use]])
    coef = np.linalg.lstsq(design, h, rcond=None)[0]
    return sum(c * t(ii, jj) for c, t in zip(coef, terms[:use]))


def _laplace_fill(values: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """Solve the 5-point Laplace equation on `hole` with `values` elsewhere (zero flux at the window edge)."""
    ny, nx = values.shape
    index = -np.ones(values.shape, dtype=np.int64)
    index[hole] = np.arange(hole.sum())
    jj, ii = np.nonzero(hole)
    unknown = index[jj, ii]
    rows, cols, vals = [], [], []
    rhs = np.zeros(unknown.size)
    degree = np.zeros(unknown.size)
    for dj, di in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        nj, ni = jj + dj, ii + di
        inside = (nj >= 0) & (nj < ny) & (ni >= 0) & (ni < nx)
        degree += inside
        nj_c, ni_c = np.clip(nj, 0, ny - 1), np.clip(ni, 0, nx - 1)
        other_hole = inside & hole[nj_c, ni_c]
        known = inside & ~hole[nj_c, ni_c]
        rows.append(unknown[other_hole])
        cols.append(index[nj_c, ni_c][other_hole])
        vals.append(-np.ones(other_hole.sum()))
        np.add.at(rhs, unknown[known], values[nj_c, ni_c][known])
    rows.append(unknown)
    cols.append(unknown)
    vals.append(degree)
    matrix = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(unknown.size,) * 2)
    out = np.zeros(values.shape)
    out[hole] = spla.spsolve(matrix.tocsc(), rhs) if unknown.size > 1 else rhs / degree
    return out
