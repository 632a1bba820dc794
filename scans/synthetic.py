"""Seeded synthetic scans of a cavity wall with an impact crater (Sect. 4.1, Fig. 3b), for tests and examples.

The crater (:class:`CraterShape`) is a bowl with a pile-up ring, in the wall's frame (h outward):

    s = sqrt((x / sqrt(aspect))^2 + (y * sqrt(aspect))^2) / radius
    h(s) = -D_b (1 - s^2)^2  [s < 1]  +  pileup * exp(-((s - 1) * radius / rim_width)^2)

with D_b chosen so that h(0) = -depth exactly. The bowl's curvature at the bottom is 4 D_b / radius^2
and its slope is continuous at s = 1; the rim is a Gaussian ring on the bowl's edge.

The scanner (:func:`synthetic_scan`) samples it on a triangle mesh of a square patch: a regular grid of
the given triangle size whose interior nodes are jittered laterally (as scanner meshes are irregular),
Gaussian noise along the normal, then written in the crater orientation (the wall, outward normal up) or
the imprint orientation (the resin cast: heights negated and one lateral axis mirrored, outward normal
of the resin up), rotated about the normal, tilted and shifted. Everything is seeded.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scans.errors import ScanError
from scans.io import Scan


@dataclass(frozen=True)
class CraterShape:
    """An impact crater with pile-up. Lengths in m.

    depth: below the flat wall at the centre; radius: of the bowl; pileup: height of the rim ring;
    rim_width: Gaussian half-width of the rim; aspect: ratio of the x to the y semi-axis (1 = round).
    depth = 0 and pileup = 0 give a flat wall.
    """

    depth: float = 12e-6
    radius: float = 0.75e-3
    pileup: float = 6e-6
    rim_width: float = 0.2e-3
    aspect: float = 1.0

    def __post_init__(self) -> None:
        if min(self.depth, self.pileup) < 0 or min(self.radius, self.rim_width, self.aspect) <= 0:
            raise ScanError("crater shape: depth and pileup must be >= 0, radius, rim_width and aspect > 0")

    def height(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Wall height h(x, y) (m) relative to the flat wall; crater centre at the origin."""
        s = np.hypot(x / np.sqrt(self.aspect), y * np.sqrt(self.aspect)) / self.radius
        rim_at_centre = np.exp(-((self.radius / self.rim_width) ** 2))
        bowl_depth = self.depth + self.pileup * rim_at_centre
        bowl = np.where(s < 1.0, -bowl_depth * (1.0 - np.minimum(s, 1.0) ** 2) ** 2, 0.0)
        return bowl + self.pileup * np.exp(-(((s - 1.0) * self.radius / self.rim_width) ** 2))


#: a crater like the paper's (Sect. 4.1: 12 um deep, material pushed up around it); its rim height and
#: bowl radius were chosen so that the BEM with the ideal sphere gives k_H close to the paper's 1.52 k_H*
PAPER_CRATER = CraterShape()
FLAT_WALL = CraterShape(depth=0.0, pileup=0.0)


def synthetic_scan(
    shape: CraterShape = PAPER_CRATER,
    *,
    side: float = 4e-3,
    triangle: float = 30e-6,
    noise: float = 0.0,
    jitter: float = 0.3,
    tilt_deg: float = 0.0,
    tilt_azimuth_deg: float = 0.0,
    rotation_deg: float = 0.0,
    shift: tuple[float, float, float] = (0.0, 0.0, 0.0),
    crater_offset: tuple[float, float] = (0.0, 0.0),
    orientation: str = "crater",
    dropouts: tuple[tuple[float, float, float], ...] = (),
    seed: int = 0,
) -> Scan:
    """A scanned patch (side x side, m) of a wall with `shape`, as a triangle mesh in metres.

    triangle: grid spacing (m); noise: standard deviation (m) along the normal; jitter: lateral node
    jitter as a fraction of `triangle`; tilt_deg about the in-plane axis at tilt_azimuth_deg;
    rotation_deg about the normal; shift (m) of the whole scan; crater_offset: crater centre in the
    patch (m); orientation: "crater" (the wall) or "imprint" (its resin cast); dropouts: discs (x, y,
    radius) in m, in the patch's frame, where the scanner saw nothing (their triangles are removed);
    seed: the random seed.
    """
    if orientation not in ("crater", "imprint"):
        raise ScanError(f"orientation must be 'crater' or 'imprint', got {orientation!r}")
    if not (side > 0 and triangle > 0 and 2 * triangle <= side and noise >= 0 and 0 <= jitter < 0.5):
        raise ScanError("synthetic scan: need side >= 2 triangle > 0, noise >= 0 and 0 <= jitter < 0.5")
    rng = np.random.default_rng(seed)
    n = int(round(side / triangle)) + 1
    ticks = np.linspace(-side / 2, side / 2, n)
    yy, xx = np.meshgrid(ticks, ticks, indexing="ij")
    interior = np.zeros((n, n), bool)
    interior[1:-1, 1:-1] = True
    step = ticks[1] - ticks[0]
    xx = xx + np.where(interior, rng.uniform(-jitter, jitter, (n, n)) * step, 0.0)
    yy = yy + np.where(interior, rng.uniform(-jitter, jitter, (n, n)) * step, 0.0)
    zz = shape.height(xx - crater_offset[0], yy - crater_offset[1]) + noise * rng.standard_normal((n, n))
    vertices = np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])  # counter-clockwise: +z out
    for hx, hy, hr in dropouts:
        centroid = vertices[faces].mean(axis=1)
        faces = faces[np.hypot(centroid[:, 0] - hx, centroid[:, 1] - hy) > hr]
    if orientation == "imprint":
        vertices = vertices * np.array([1.0, -1.0, -1.0])  # 180 deg about x: the cast taken out and turned over
        faces = faces[:, ::-1]  # the resin's outward side is the other side of the same surface
    rot = _rotation_z(np.radians(rotation_deg))
    tilt = _rotation_axis(np.array([np.cos(np.radians(tilt_azimuth_deg)), np.sin(np.radians(tilt_azimuth_deg)), 0.0]),
                          np.radians(tilt_deg))
    vertices = vertices @ (tilt @ rot).T + np.asarray(shift, float)
    return Scan(vertices, faces.astype(np.int64), "mesh", f"synthetic {orientation} (seed {seed})", "m")


def _rotation_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rotation_axis(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about a unit axis."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
