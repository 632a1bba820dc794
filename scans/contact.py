"""The gap map between the sphere and a scanned wall, ready for the BEM (Sect. 4.1, Fig. 3c).

gap(x, y) = sphere(x, y) - h(x, y), shifted so that min(gap) = 0, where h is the levelled wall height
(crater negative, rim positive; see `scans.surface`) and sphere is the IES surface seen from the wall:

* ideal sphere (the paper's Fig. 3c): R - sqrt(R^2 - r^2), the exact spherical cap;
* flattened sphere: the same with its cap of height `flattening` cut off, max(R - sqrt(R^2 - r^2), f).
  The paper measured 15.80 mm across the flattened regions for a 15.84 mm sphere: 0.02 mm per side.

Where the sphere sits (the paper does not say; the IES moves along the wall normal only, so it hits
the crater where it made it):
* "centroid" (default): above the crater's depth-weighted centroid, sum(-h x) / sum(-h) over the
  connected depression below the noise threshold. Robust to noise and to the scanner's meshing.
* "deepest": above the deepest point of the (lightly smoothed) scan.
For a flat wall (no depression above the noise) both are the centre of the scanned area.

Scanner noise and the indentation reference. The indentation is measured from the sphere's first touch
(`bem_contact`'s convention). On a raw scan that touch lands on the highest noise peak, so every
indentation is overstated by a few noise sigmas and k_H comes out low (paper-like crater, 30 um
triangles: -0.6 % at 0.1 um noise, -3.4 % at 0.5 um, -7 % at 1 um). By default the wall is therefore
denoised before the gap is built, by a second-order (local-quadratic) Gaussian filter

    h_d = G_s * h - (s^2 / 2) lap(G_s * h)   (continuous form; `denoise` uses its exact discrete kernel),

the equivalent kernel G_s (2 - r^2 / (2 s^2)) of a Gaussian-weighted local quadratic regression: it
reproduces any quadratic surface exactly (a plain Gaussian raises a crater's bottom by
(s^2 / 2) lap(h), which cost -0.4 % of k_H at s = 30 um), so a smooth crater keeps its shape and only
the noise is averaged out. With s = DEFAULT_DENOISE = 90 um (3 triangles of a 30 um scan) k_H of the
paper-like crater moves by -0.1 % without noise; with noise it stays within -0.4 .. +0.7 % of the
noise-free value up to 0.5 um and within -0.9 .. +1.3 % at 1 um (4 noise samples each; the residual
noise, about 0.15 sigma over 90 um, still bends the crater's bottom a little; benchmark
tests/benchmarks/test_scans_calibrate.py); denoise = 0 restores the raw scan (the first touch on the
noisiest point). A filter wide against the crater's bottom would flatten it: s is checked against the
crater's radius by the caller (a warning in `ies calibrate`).

The BEM grid is centred there, with the node convention of `bem_contact` (element centres at
(i - n // 2) dx, axis 0 = x). Its side is chosen so that it holds every point that could touch at the
largest indentation: the elastic displacement K p is >= 0 everywhere, so the contact at indentation
delta lies inside {gap <= delta}; the side is that region's diameter times a safety margin.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.ndimage as ndi

from scans.errors import ScanError
from scans.raster import HoleReport, fill_holes
from scans.surface import LevelledSurface, outside_scan
from sim.model.parameters import CLEARANCE_NOMINAL, SPHERE_FLATTENING, SPHERE_RADIUS

#: the IES radius (Sect. 4.1: nominal diameter 15.84 mm), the sphere's flattening per side (Sect. 4.1: 15.84 mm ->
#: 15.80 mm across the flattened regions) and the nominal clearance (Sect. 4.1: (17 - 15.84) / 2 mm), from the one
#: vocabulary of the paper's quantities
PAPER_RADIUS, PAPER_FLATTENING, PAPER_CLEARANCE = SPHERE_RADIUS, SPHERE_FLATTENING, CLEARANCE_NOMINAL
#: the largest indentation of the paper's simulations (Sect. 4.1, Fig. 3c)
PAPER_DELTA_MAX = 40e-6
PLACEMENTS = ("centroid", "deepest")
#: width (standard deviation, m) of the default second-order Gaussian denoising of the wall (module docstring)
DEFAULT_DENOISE = 90e-6


def denoise(height: np.ndarray, width_px: float) -> np.ndarray:
    """Second-order Gaussian filter of a height map: width_px = s, the Gaussian's standard deviation in pixels.

    The equivalent kernel of a local quadratic regression with Gaussian weights,
    K = G(x) G(y) (a - b (x^2 + y^2)), continuous limit a = 2, b = 1 / (2 s^2), i.e. G * h - (s^2 / 2) lap(G * h).
    a and b are solved for the sampled, truncated (4 s) Gaussian so that the discrete kernel has sum 1 and zero
    second moments: quadratic surfaces pass unchanged to rounding (bias of order s^4 times the fourth
    derivatives), white noise keeps about 2.5 / (4 pi s^2) of its variance. width_px = 0 returns the map.
    """
    if width_px <= 0:
        return height
    x = np.arange(-math.ceil(4 * width_px), math.ceil(4 * width_px) + 1, dtype=float)
    g = np.exp(-0.5 * (x / width_px) ** 2)
    g /= g.sum()
    q = x**2 * g
    m2, m4 = float(g @ x**2), float(g @ x**4)
    # K = a g(x) g(y) - b (q(x) g(y) + g(x) q(y)): sum K = a - 2 b m2 = 1, sum K x^2 = a m2 - b (m4 + m2^2) = 0
    a, b = (m4 + m2**2) / (m4 - m2**2), m2 / (m4 - m2**2)

    def separable(k0: np.ndarray, k1: np.ndarray) -> np.ndarray:
        return ndi.correlate1d(ndi.correlate1d(height, k0, axis=0, mode="nearest"), k1, axis=1, mode="nearest")

    return a * separable(g, g) - b * (separable(q, g) + separable(g, q))


@dataclass(frozen=True)
class Sphere:
    """The IES surface facing the wall: radius R (m) and the height (m) of the cap cut off by flattening."""

    R: float = PAPER_RADIUS
    flattening: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.R) and self.R > 0):
            raise ScanError(f"sphere radius {self.R!r} m must be a finite number > 0 (the IES: 7.92e-3)")
        if not (math.isfinite(self.flattening) and 0 <= self.flattening < self.R):
            raise ScanError(f"flattening {self.flattening!r} m must be >= 0 and smaller than the radius (paper: 2e-5)")

    def surface(self, r2: np.ndarray) -> np.ndarray:
        """Height (m) of the sphere's surface above its lowest point at squared distance r2 (m^2) from the axis."""
        r2 = np.asarray(r2, float)
        inside = r2 < self.R**2
        cap = np.where(inside, r2 / (self.R + np.sqrt(np.where(inside, self.R**2 - r2, 0.0))), np.inf)
        return np.maximum(cap, self.flattening) - self.flattening

    @property
    def flat_radius(self) -> float:
        """Radius (m) of the flat disc left by the flattening."""
        f = self.flattening
        return math.sqrt(f * (2 * self.R - f))

    def describe(self) -> str:
        """Which geometry was used, for the output."""
        if self.flattening == 0:
            return f"ideal sphere, R = {self.R * 1e3:.4g} mm"
        return (f"flattened sphere, R = {self.R * 1e3:.4g} mm with a cap of {self.flattening * 1e3:.4g} mm cut off "
                f"(flat disc {2 * self.flat_radius * 1e3:.3g} mm across)")


@dataclass(frozen=True)
class ScanContact:
    """A scanned wall and a sphere placed above it: builds the BEM gap map at any grid size.

    centre: sphere axis in the levelled frame (m); placement: how it was chosen; side: BEM domain side
    (m); reach: radius (m) of {gap <= delta_max} around the centre, the largest possible contact.
    """

    surface: LevelledSurface
    sphere: Sphere
    centre: tuple[float, float]
    placement: str
    side: float
    reach: float
    delta_max: float
    smoothing: float = 0.0
    denoise: float = 0.0
    holes: dict[int, HoleReport] = field(default_factory=dict, compare=False)

    def gap_at(self, n: int) -> tuple[np.ndarray, float]:
        """Initial gap (m, min 0) on the n x n grid of side `self.side`, and the pitch dx (m).

        The signature `calibrate_k_H` expects; the hole report for each n is kept in `self.holes`.
        The wall is first denoised (`denoise`, m; module docstring) and, with `smoothing` > 0, then
        filtered by a plain Gaussian of that standard deviation (m). min(gap) = 0 is then the first touch
        on that (denoised) wall: the indentation reference.
        """
        height, dx = self.height_at(n)
        offsets = (np.arange(n) - n // 2) * dx
        gap = self.sphere.surface(offsets[:, None] ** 2 + offsets[None, :] ** 2) - height
        return gap - gap.min(), dx

    def height_at(self, n: int) -> tuple[np.ndarray, float]:
        """Levelled, denoised (and, if asked, smoothed) wall height (m) on the grid of `gap_at(n)`."""
        height, dx, holes = self.surface.resample(self.centre, self.side, n)
        self.holes[n] = holes
        height = denoise(height, self.denoise / dx)
        if self.smoothing > 0:
            height = ndi.gaussian_filter(height, self.smoothing / dx, mode="nearest")
        return height, dx


def scan_contact(
    surface: LevelledSurface,
    sphere: Sphere = Sphere(),
    *,
    placement: str = "centroid",
    delta_max: float = PAPER_DELTA_MAX,
    side: float | None = None,
    margin: float = 1.15,
    smoothing: float = 0.0,
    denoise: float = DEFAULT_DENOISE,
) -> ScanContact:
    """Place the sphere above the crater and size the BEM domain (see the module docstring).

    side: BEM domain side (m); None chooses margin x the diameter of {gap <= delta_max}.
    denoise: width (standard deviation, m) of the second-order Gaussian filter against scanner noise
    (module docstring; default DEFAULT_DENOISE = 90 um); 0 uses the scan as it is, the first touch then
    sits on the highest noise peak and k_H comes out low (paper-like crater: -3.4 % at 0.5 um noise).
    smoothing: standard deviation (m) of an extra plain Gaussian filter; 0 (default) applies none. It
    rounds the crater (-0.4 % on a noise-free scan at 30 um), so it is only kept for comparison. Raises
    ScanError if that region reaches the edge of the scan (the crater is larger than the scanned area)
    or does not fit in the given side.
    """
    if placement not in PLACEMENTS:
        raise ScanError(f"unknown sphere placement {placement!r}; use one of {', '.join(PLACEMENTS)}")
    if not (math.isfinite(smoothing) and smoothing >= 0):
        raise ScanError(f"smoothing {smoothing!r} m must be a finite number >= 0")
    if not (math.isfinite(denoise) and denoise >= 0):
        raise ScanError(f"denoising width {denoise!r} m must be a finite number >= 0 (default {DEFAULT_DENOISE:g}, 0 = off)")
    if not (math.isfinite(delta_max) and delta_max > 0):
        raise ScanError(f"largest indentation {delta_max!r} m must be > 0 (paper: 40e-6)")
    centre = surface.centre if placement == "centroid" else surface.deepest
    pitch = surface.pitch
    # scanner dropouts inside the scan are filled; only what lies beyond the scan's outline is unknown
    valid = ~outside_scan(surface.overview)
    overview, _ = fill_holes(surface.overview, pitch)
    yy, xx = np.mgrid[0 : overview.shape[0], 0 : overview.shape[1]]
    dx_c, dy_c = surface.x0 + xx * pitch - centre[0], surface.y0 + yy * pitch - centre[1]
    gap = np.where(valid, sphere.surface(dx_c**2 + dy_c**2) - np.where(valid, overview, 0.0), np.inf)
    j, i = np.unravel_index(np.argmin(gap), gap.shape)
    touching = gap - gap[j, i] <= delta_max
    labels, _ = ndi.label(touching)
    region = labels == labels[j, i]
    reach = float(np.hypot(dx_c[region], dy_c[region]).max() + pitch)
    edge = ndi.binary_dilation(region) & ~valid
    on_border = region[0].any() or region[-1].any() or region[:, 0].any() or region[:, -1].any()
    if edge.any() or on_border:
        raise ScanError(
            f"{surface.source}: at {delta_max * 1e6:.3g} um indentation the sphere could touch up to the edge of the "
            f"scanned area (crater larger than the scan); scan a larger area around the crater"
        )
    needed = 2.0 * reach
    if side is None:
        side = margin * needed
    elif not (math.isfinite(side) and side > 0):
        raise ScanError(f"grid side {side!r} m must be a finite number > 0")
    elif side < needed:
        raise ScanError(
            f"the grid side {side * 1e3:.3g} mm is smaller than the region the sphere can touch at "
            f"{delta_max * 1e6:.3g} um indentation ({needed * 1e3:.3g} mm across); use a larger side or the automatic one"
        )
    return ScanContact(surface=surface, sphere=sphere, centre=centre, placement=placement, side=float(side),
                       reach=reach, delta_max=float(delta_max), smoothing=float(smoothing), denoise=float(denoise))
