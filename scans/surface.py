"""Levelling a scanned wall: normal by principal axes, robust plane fit on the flat region (Sect. 4.1).

Conventions of the levelled surface (:class:`LevelledSurface`):

* local right-handed frame (x, y, h): h along the wall's outward normal (towards the sphere), so the
  crater is negative and the pile-up rim positive; h = 0 is the plane fitted to the flat wall;
* x is the scanner's x axis projected onto the wall plane (so maps look like the file), y = h-axis x x;
* an imprint (the resin cast of the crater, as in the paper) is viewed from the other side: its
  outward normal is reversed, which negates the heights and mirrors one lateral axis, exactly what
  putting the cast back into the crater does.

The outward side of a mesh comes from its triangle winding (area-weighted mean face normal); a point
cloud or height map has no winding, so its +z axis is taken as the outward side.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.ndimage as ndi
from scipy.spatial import Delaunay

from scans.errors import ScanError
from scans.io import Scan
from scans.raster import HoleReport, fill_holes, rasterize

#: the flat region must cover at least this share of the scanned area
MIN_FLAT_FRACTION = 0.10
#: flat region starts this factor outside the crater-and-rim radius
FLAT_MARGIN = 1.25
#: finest overview map: at most this many pixels per side
MAX_OVERVIEW = 1024


@dataclass(frozen=True)
class LevelledSurface:
    """A scan levelled on its flat wall, in the local frame described in the module docstring.

    points: (N, 3) local (x, y, h) in m; faces: (M, 3) triangles; origin/axes: the frame in scanner
    coordinates (m; rows e_x, e_y, normal); pitch: typical triangle size (m); overview: height map (m,
    NaN where not scanned) on nodes (x0 + i pitch, y0 + j pitch); noise: robust standard deviation (m)
    of the flat wall about its plane; threshold: heights beyond it are features, not noise (m);
    feature_radius: radius (m) of crater and rim around `centre`, 0 for a flat wall; centre: (x, y) of
    the crater's depth-weighted centroid (m) or the scan's centre for a flat wall; deepest: (x, y) of the
    deepest point (m); flat_fraction: share of the scanned area used to level; imprint: whether the
    surface was inverted; spikes: scanner spikes removed (points departing from the plane through their
    neighbours by more than spike_threshold, m); their triangles become holes, filled on resampling.
    """

    points: np.ndarray
    faces: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    pitch: float
    overview: np.ndarray
    x0: float
    y0: float
    noise: float
    threshold: float
    feature_radius: float
    centre: tuple[float, float]
    deepest: tuple[float, float]
    flat_fraction: float
    imprint: bool
    source: str
    spikes: int = 0
    spike_threshold: float = float("inf")

    @property
    def has_crater(self) -> bool:
        """True if a depression deeper than the noise threshold was found."""
        return self.feature_radius > 0.0

    def tilt_deg(self) -> float:
        """Angle (deg) between the wall normal and the scanner's z axis."""
        return float(np.degrees(np.arccos(min(1.0, abs(self.axes[2, 2])))))

    def to_scanner(self, x: float, y: float, h: float = 0.0) -> np.ndarray:
        """The point (x, y, h) of the levelled frame in the scanner's coordinates (m)."""
        return self.origin + x * self.axes[0] + y * self.axes[1] + h * self.axes[2]

    def resample(self, centre: tuple[float, float], side: float, n: int) -> tuple[np.ndarray, float, HoleReport]:
        """Levelled heights (m) on the n x n BEM grid of pitch dx = side / n around `centre` (m).

        Grid convention of `bem_contact` (element centres at (i - n // 2) dx from the centre, axis 0 = x),
        so a body centred on `centre` has its apex on node (n // 2, n // 2). Returns (height, dx, holes);
        missing nodes are filled (see :func:`scans.raster.fill_holes`). A grid reaching beyond the
        scanned area is refused.
        """
        dx = side / n
        start = -(n // 2) * dx
        height = rasterize(self.points, self.faces, centre[0] + start, centre[1] + start, dx, n, n).T
        missing = ~np.isfinite(height)
        if missing.any():
            if outside_scan(height).sum() > 0.02 * n * n:
                raise ScanError(
                    f"{self.source}: the {side * 1e3:.3g} mm grid around the crater reaches beyond the scanned area; "
                    "scan a larger area around the crater or use a smaller grid side"
                )
            if missing.all():
                raise ScanError(f"{self.source}: the grid does not overlap the scan")
        filled, holes = fill_holes(height, dx)
        if missing.any():  # how close the filled nodes come to the sphere's axis (node n // 2, n // 2)
            jj, ii = np.nonzero(missing)
            nearest = float(np.hypot(ii - n // 2, jj - n // 2).min() * dx)
            holes = dataclasses.replace(holes, nearest=nearest)
        return filled, dx, holes


def level_scan(scan: Scan, imprint: bool = False, iterations: int = 3) -> LevelledSurface:
    """Level a scan on its flat wall (Sect. 4.1: heights measured from the nominally flat part of the wall).

    1. normal = principal axis of least variance of the points, oriented to the outward side
       (reversed for an imprint); scanner spikes are removed after the first plane fit (see `_spikes`);
    2. robust plane fit (trimmed least squares) to find the crater, then an ordinary least-squares plane on
       the flat region outside the crater and its rim (radius x FLAT_MARGIN), repeated `iterations` times,
       each time rotating the frame onto the fitted plane.

    Raises ScanError if the scan is degenerate or has no flat region around the crater.
    """
    vertices = np.asarray(scan.vertices, float)
    origin = vertices.mean(axis=0)
    centred = vertices - origin
    _, sing, vt = np.linalg.svd(centred[:: max(1, len(centred) // 200_000)], full_matrices=False)
    if sing[1] <= 1e-9 * sing[0]:
        raise ScanError(f"{scan.source}: all points lie on a line; this is not a surface scan")
    normal = vt[2]
    faces = scan.faces
    if faces is None:
        faces = _triangulate(centred @ vt[0], centred @ vt[1], scan.source)
    outward = _outward_hint(vertices, scan.faces)
    if normal @ outward < 0:
        normal = -normal
    if scan.faces is not None:
        _check_one_sided(vertices, scan.faces, normal, scan.source)
    if imprint:
        normal = -normal
    axes = _frame(normal)
    for it in range(iterations + 1):
        local = (vertices - origin) @ axes.T
        if it == 0:
            coef = _trimmed_plane(local)
        else:
            coef = np.linalg.lstsq(_design(local[flat]), local[flat, 2], rcond=None)[0]
        tilt = np.array([-coef[1], -coef[2], 1.0])
        tilt /= np.linalg.norm(tilt)
        origin = origin + coef[0] * axes[2]
        axes = _frame(tilt @ axes)
        local = (vertices - origin) @ axes.T
        if it == 0:
            keep, spike_threshold = _spikes(local, faces)
            spikes = int((~keep).sum())
            if spikes:
                vertices, faces = _drop_vertices(vertices, faces, keep, scan.source)
                local = local[keep]
        overview, x0, y0, pitch = _overview(local, faces)
        found = _features(local, overview, x0, y0, pitch, scan.source, None if it == 0 else found["noise"])
        r2 = (local[:, 0] - found["centre"][0]) ** 2 + (local[:, 1] - found["centre"][1]) ** 2
        flat = r2 > (FLAT_MARGIN * found["feature_radius"]) ** 2
        flat_fraction = _flat_fraction(overview, x0, y0, pitch, found["centre"], FLAT_MARGIN * found["feature_radius"])
        if flat_fraction < MIN_FLAT_FRACTION or flat.sum() < 10:
            raise ScanError(
                f"{scan.source}: no flat region around the crater to level on (crater and rim cover "
                f"{100 * (1 - flat_fraction):.0f}% of the scan); scan a larger area of the flat wall around the crater"
            )
    return LevelledSurface(
        points=local, faces=faces, origin=origin, axes=axes, pitch=pitch, overview=overview, x0=x0, y0=y0,
        noise=found["noise"], threshold=found["threshold"], feature_radius=found["feature_radius"],
        centre=found["centre"], deepest=found["deepest"], flat_fraction=flat_fraction, imprint=imprint,
        source=scan.source, spikes=spikes, spike_threshold=spike_threshold,
    )


def _spikes(local: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, float]:
    """Mask of the points to keep, and the threshold (m) beyond which a point is a scanner spike.

    Each point's height is compared with the least-squares plane through its mesh neighbours (exact for
    any sloped surface; a smooth crater departs by curvature x edge^2 / 2, about 0.2 um at 30 um
    triangles). Spikes depart by more than max(8 robust sigmas of that departure, 5 % of the height span)
    and more than twice as much as any of their neighbours (isolated points; a cluster is left alone).
    """
    n = len(local)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    keys = np.sort(edges[:, 0].astype(np.int64) * n + edges[:, 1])
    keys = keys[np.concatenate([[True], keys[1:] != keys[:-1]])]  # each edge once
    a, b = keys // n, keys % n
    i, j = np.concatenate([a, b]), np.concatenate([b, a])
    d = local[j] - local[i]  # neighbour offsets (dx, dy, dh) seen from point i
    design = np.stack([np.ones(len(i)), d[:, 0], d[:, 1]], axis=1)
    normal = np.empty((n, 3, 3))
    rhs = np.empty((n, 3))
    for r in range(3):
        rhs[:, r] = np.bincount(i, weights=design[:, r] * d[:, 2], minlength=n)
        for c in range(3):
            normal[:, r, c] = np.bincount(i, weights=design[:, r] * design[:, c], minlength=n)
    solvable = np.bincount(i, minlength=n) >= 3
    solvable[solvable] = np.abs(np.linalg.det(normal[solvable])) > 1e-30 * np.abs(normal[solvable]).max(axis=(1, 2)) ** 3
    departure = np.zeros(n)
    departure[solvable] = -np.linalg.solve(normal[solvable], rhs[solvable][:, :, None])[:, 0, 0]  # h_i - plane(i)
    resid = departure[solvable]
    if resid.size < 10:
        return np.ones(n, bool), np.inf
    sigma = 1.4826 * float(np.median(np.abs(resid - np.median(resid))))
    lo, hi = np.percentile(local[:, 2], [0.5, 99.5])
    threshold = max(8.0 * sigma, 0.05 * (hi - lo), 1e-12)
    # a spike stands alone: its neighbours depart far less (they see it as one of ~6 points), whereas on
    # a sharp but real ridge the neighbours along the ridge depart as much
    order = np.argsort(i, kind="stable")
    starts = np.searchsorted(i[order], np.arange(n))
    has = np.bincount(i, minlength=n) > 0
    neighbours = np.zeros(n)
    neighbours[has] = np.maximum.reduceat(np.abs(departure[j[order]]), starts[has])
    spike = (np.abs(departure) > threshold) & (np.abs(departure) > 2.0 * neighbours)
    return ~spike, threshold


def _drop_vertices(vertices: np.ndarray, faces: np.ndarray, keep: np.ndarray, source: str) -> tuple[np.ndarray, np.ndarray]:
    """Remove points (and their triangles): what remains is a mesh with holes where they were."""
    faces = faces[keep[faces].all(axis=1)]
    if len(faces) == 0:
        raise ScanError(f"{source}: nothing left after removing scanner spikes")
    remap = np.cumsum(keep) - 1
    return vertices[keep], remap[faces]


def outside_scan(height: np.ndarray) -> np.ndarray:
    """Mask of the missing (NaN) pixels connected to the map's border: beyond the scan's outline.

    Missing pixels enclosed by scanned ones are dropouts (holes) to be filled, not outside.
    """
    labels, _ = ndi.label(~np.isfinite(height))
    border = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    return np.isin(labels, border[border > 0])


def _frame(normal: np.ndarray) -> np.ndarray:
    """Rows e_x, e_y, n: e_x = scanner x projected on the plane (or y if x is nearly normal)."""
    normal = normal / np.linalg.norm(normal)
    ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    ex = ref - (ref @ normal) * normal
    ex /= np.linalg.norm(ex)
    return np.array([ex, np.cross(normal, ex), normal])


def _outward_hint(vertices: np.ndarray, faces: np.ndarray | None) -> np.ndarray:
    """Area-weighted mean face normal of a mesh (its outward side); +z for points."""
    if faces is not None:
        tri = vertices[faces]
        mean = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).sum(axis=0)
        area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()
        if area2 > 0 and np.linalg.norm(mean) > 0.1 * area2:
            return mean
    return np.array([0.0, 0.0, 1.0])


def _check_one_sided(vertices: np.ndarray, faces: np.ndarray, outward: np.ndarray, source: str) -> None:
    """Refuse a mesh that is not one surface seen from one side (a closed body, a folded or two-sided scan)."""
    tri = vertices[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(normals, axis=1)
    away = float(area[normals @ outward < 0].sum() / max(area.sum(), 1e-300))
    if away > 0.05:
        raise ScanError(
            f"{source}: {100 * away:.0f}% of the surface faces away from the wall (a closed body, or sides and back "
            "scanned too); crop the scan to the wall around the crater"
        )


def _triangulate(u: np.ndarray, v: np.ndarray, source: str) -> np.ndarray:
    """Delaunay triangles of a point cloud in its plane, without the long edges that bridge gaps."""
    try:
        tri = Delaunay(np.column_stack([u, v])).simplices
    except Exception:  # qhull errors on degenerate input
        raise ScanError(f"{source}: the points cannot be triangulated (all on a line or duplicated)") from None
    pts = np.column_stack([u, v])
    edges = np.stack([np.linalg.norm(pts[tri[:, k]] - pts[tri[:, (k + 1) % 3]], axis=1) for k in range(3)], axis=1)
    longest = edges.max(axis=1)
    keep = longest <= 4.0 * np.median(edges)
    if keep.sum() == 0:
        raise ScanError(f"{source}: the point cloud is too sparse to form a surface")
    return tri[keep].astype(np.int64)


def _design(local: np.ndarray) -> np.ndarray:
    return np.column_stack([np.ones(len(local)), local[:, 0], local[:, 1]])


def _trimmed_plane(local: np.ndarray, iterations: int = 30) -> np.ndarray:
    """Plane h = a + b x + c y by least squares, iteratively dropping points beyond 3 robust sigmas.

    The scale is 1.4826 x the median absolute deviation about the median residual, floored at 1e-3 of
    the height span so that a noise-free scan converges too.
    """
    design = _design(local)
    h = local[:, 2]
    keep = np.ones(h.size, bool)
    coef = np.linalg.lstsq(design, h, rcond=None)[0]
    for _ in range(iterations):
        resid = h - design @ coef
        centre = np.median(resid[keep])
        scale = max(3.0 * 1.4826 * np.median(np.abs(resid[keep] - centre)), 1e-3 * np.ptp(resid), 1e-12)
        new_keep = np.abs(resid - centre) <= scale
        if new_keep.sum() < 3:
            break
        coef = np.linalg.lstsq(design[new_keep], h[new_keep], rcond=None)[0]
        if np.array_equal(new_keep, keep):
            break
        keep = new_keep
    return coef


def _overview(local: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Height map of the whole scan at about its own triangle size."""
    tri = local[faces, :2]
    edge = np.median(np.linalg.norm(tri[:, 1] - tri[:, 0], axis=1))
    lo, hi = local[:, :2].min(axis=0), local[:, :2].max(axis=0)
    pitch = max(edge, (hi - lo).max() / MAX_OVERVIEW)
    nx, ny = int((hi[0] - lo[0]) / pitch) + 1, int((hi[1] - lo[1]) / pitch) + 1
    return rasterize(local, faces, lo[0], lo[1], pitch, nx, ny), float(lo[0]), float(lo[1]), float(pitch)


def _features(local: np.ndarray, overview: np.ndarray, x0: float, y0: float, pitch: float, source: str,
              noise_hint: float | None) -> dict:
    """Noise level, crater centre and the radius of crater plus rim, from the overview map.

    noise_hint: the flat wall's noise from the previous levelling pass (None on the first pass).
    """
    valid = np.isfinite(overview)
    if valid.sum() < 16:
        raise ScanError(f"{source}: the scan covers too small an area to level (fewer than 16 grid points)")
    h = local[:, 2]
    noise = _local_noise(overview, valid) if noise_hint is None else noise_hint
    smooth = _smooth(overview, valid, 1.0)
    span = float(np.nanmax(smooth) - np.nanmin(smooth))
    threshold = max(4.0 * noise, 1e-3 * span, 1e-9)
    yy, xx = np.mgrid[0 : overview.shape[0], 0 : overview.shape[1]]
    xs, ys = x0 + xx * pitch, y0 + yy * pitch
    deep = np.where(valid, smooth, np.inf)
    j, i = np.unravel_index(np.argmin(deep), deep.shape)
    deepest = (float(xs[j, i]), float(ys[j, i]))
    depression = valid & (smooth < -threshold)
    if not depression[j, i]:
        centre = (float(xs[valid].mean()), float(ys[valid].mean()))
        return dict(noise=noise, threshold=threshold, feature_radius=0.0, centre=centre, deepest=centre)
    labels, _ = ndi.label(depression)
    crater = labels == labels[j, i]
    weight = -smooth[crater]
    centre = (float((xs[crater] * weight).sum() / weight.sum()), float((ys[crater] * weight).sum() / weight.sum()))
    radius = np.hypot(xs - centre[0], ys - centre[1])
    ring = np.floor(radius / (2 * pitch)).astype(int)
    sq = np.where(valid, smooth**2, 0.0)
    count = np.bincount(ring[valid], minlength=ring.max() + 1)
    rms = np.sqrt(np.bincount(ring.ravel(), weights=sq.ravel(), minlength=ring.max() + 1) / np.maximum(count, 1))
    above = np.nonzero((rms > threshold) & (count > 0))[0]
    feature_radius = float((above.max() + 1) * 2 * pitch)
    noise = _flat_noise(h[np.hypot(local[:, 0] - centre[0], local[:, 1] - centre[1]) > FLAT_MARGIN * feature_radius], noise)
    return dict(noise=noise, threshold=threshold, feature_radius=feature_radius, centre=centre, deepest=deepest)


def _local_noise(height: np.ndarray, valid: np.ndarray) -> float:
    """Noise from the map's roughness alone, blind to smooth features (craters) of any size.

    The 5-point residual h - mean(4 neighbours) of white noise of deviation s has deviation s sqrt(5/4);
    a smooth surface contributes only curvature x pitch^2 / 4. Robust (MAD) over the valid pixels.
    """
    inner = valid[1:-1, 1:-1] & valid[2:, 1:-1] & valid[:-2, 1:-1] & valid[1:-1, 2:] & valid[1:-1, :-2]
    if inner.sum() < 16:
        return 0.0
    resid = height[1:-1, 1:-1] - 0.25 * (height[2:, 1:-1] + height[:-2, 1:-1] + height[1:-1, 2:] + height[1:-1, :-2])
    resid = resid[inner]
    return 1.4826 * float(np.median(np.abs(resid - np.median(resid)))) / np.sqrt(1.25)


def _flat_noise(h: np.ndarray, fallback: float) -> float:
    if h.size < 10:
        return fallback
    return 1.4826 * float(np.median(np.abs(h - np.median(h))))


def _smooth(height: np.ndarray, valid: np.ndarray, sigma_px: float) -> np.ndarray:
    """NaN-aware Gaussian smoothing (normalised convolution)."""
    filled = np.where(valid, height, 0.0)
    num = ndi.gaussian_filter(filled, sigma_px, mode="constant")
    den = ndi.gaussian_filter(valid.astype(float), sigma_px, mode="constant")
    out = np.full(height.shape, np.nan)
    out[valid] = num[valid] / den[valid]
    return out


def _flat_fraction(overview: np.ndarray, x0: float, y0: float, pitch: float, centre: tuple[float, float], radius: float) -> float:
    valid = np.isfinite(overview)
    yy, xx = np.mgrid[0 : overview.shape[0], 0 : overview.shape[1]]
    far = np.hypot(x0 + xx * pitch - centre[0], y0 + yy * pitch - centre[1]) > radius
    return float((valid & far).sum() / max(valid.sum(), 1))
