"""Crater metrics and the clearance interval they imply (Sect. 4.1, Table 2).

Definitions (heights from the levelled flat wall, `scans.surface`):

* depth: how far the crater's bottom lies below the flat wall. The bottom is located on the lightly
  smoothed overview map, then a quadratic surface is fitted by least squares to the scan points of the
  bottom's lowest tenth of the depth (at least 3 triangle sizes across) and its minimum is taken, so that scanner noise
  does not deepen the crater (the minimum of noisy points would be biased by about -3 sigma).
* rim_height: highest point of the pile-up: located on the smoothed map, then refined by a parabola
  in the distance from the crater's centre fitted to the points there (a ring is curved across only).
* diameter: diameter of the circle with the same area as the connected depression around the bottom,
  where the smoothed wall lies below the noise threshold.
* clearance interval (Sect. 4.1): [nominal, nominal + depth + flattening]; the paper's
  0.58 mm + 0.012 mm + 0.02 mm = 0.612 mm. The pile-up rim is ignored, as in the paper.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.ndimage as ndi

from scans.errors import ScanError
from scans.surface import FLAT_MARGIN, LevelledSurface, _smooth


#: noise (m) up to which the default denoising (scans.contact.DEFAULT_DENOISE) is verified to keep k_H within
#: 1 % of the noise-free scan (30 um triangles, 4 noise seeds: -0.4 .. +0.7 %); beyond it a warning
NOISY = 0.5e-6


@dataclass(frozen=True)
class CraterMetrics:
    """Measured crater (all in m): depth below the flat wall (0 for a flat wall), rim height above it,
    diameter of the depression, centre of the depression, robust noise of the flat wall, and warnings."""

    depth: float
    rim_height: float
    diameter: float
    centre: tuple[float, float]
    noise: float
    warnings: list[str] = field(default_factory=list)


def crater_metrics(surface: LevelledSurface) -> CraterMetrics:
    """Depth, rim height and diameter of the crater of a levelled scan (see the module docstring)."""
    overview, pitch = surface.overview, surface.pitch
    valid = np.isfinite(overview)
    smooth = _smooth(overview, valid, 1.0)
    yy, xx = np.mgrid[0 : overview.shape[0], 0 : overview.shape[1]]
    xs, ys = surface.x0 + xx * pitch, surface.y0 + yy * pitch
    warnings: list[str] = []
    if not surface.has_crater:
        rim = float(np.nanmax(smooth))
        return CraterMetrics(0.0, max(rim, 0.0), 0.0, surface.centre, surface.noise,
                             ["no crater deeper than the noise threshold: treated as a flat wall"])
    near = valid & (np.hypot(xs - surface.centre[0], ys - surface.centre[1]) <= FLAT_MARGIN * surface.feature_radius)
    crest = np.unravel_index(np.argmax(np.where(near, smooth, -np.inf)), smooth.shape)
    rim = max(_crest_height(surface, (float(xs[crest]), float(ys[crest])), float(smooth[crest])), 0.0)
    depth = -_bottom_height(surface, float(np.nanmin(smooth)))
    depression = valid & (smooth < -surface.threshold)
    labels, _ = ndi.label(depression)
    j = int(round((surface.deepest[1] - surface.y0) / pitch))
    i = int(round((surface.deepest[0] - surface.x0) / pitch))
    area = float((labels == labels[j, i]).sum()) * pitch**2 if labels[j, i] else 0.0
    diameter = 2.0 * math.sqrt(area / math.pi)
    if surface.noise > NOISY:
        warnings.append(
            f"scanner noise {surface.noise * 1e6:.2g} um: more than the 0.5 um up to which the default denoising (90 um) "
            "keeps k_H within 1 % (at 1 um: -0.9 to +1.3 % over 4 noise samples); compare k_H with a wider --denoise"
        )
    if rim > depth:
        warnings.append(
            f"the pile-up ({rim * 1e6:.3g} um) stands higher than the crater is deep ({depth * 1e6:.3g} um): "
            "if this scan is an imprint (a resin cast of the crater), use --imprint"
        )
    return CraterMetrics(depth, rim, diameter, surface.centre, surface.noise, warnings)


def _fit_radius(surface: LevelledSurface) -> float:
    return max(4.0 * surface.pitch, 0.1 * surface.feature_radius)


def _bottom_height(surface: LevelledSurface, fallback: float) -> float:
    """Minimum (m) of a quadratic surface fitted to the scan points around the deepest point.

    The fit covers the bottom's lowest tenth of the depth (a quadratic's own scale, so the bowl's
    higher-order terms stay small), at least 3 triangle sizes. Falls back to the smoothed map's
    minimum when the points do not form a bowl at that scale.
    """
    bx, by = surface.deepest
    smooth = _smooth(surface.overview, np.isfinite(surface.overview), 1.0)
    low = np.nan_to_num(smooth, nan=np.inf) < fallback + 0.1 * abs(fallback)
    labels, _ = ndi.label(low)
    j = int(round((by - surface.y0) / surface.pitch))
    i = int(round((bx - surface.x0) / surface.pitch))
    area = float((labels == labels[j, i]).sum()) * surface.pitch**2 if labels[j, i] else 0.0
    radius = max(3.0 * surface.pitch, np.sqrt(area / np.pi))
    x, y, h = (surface.points[:, k] for k in range(3))
    near = np.hypot(x - bx, y - by) <= radius
    if near.sum() >= 12:
        u, v = (x[near] - bx) / radius, (y[near] - by) / radius
        design = np.column_stack([np.ones_like(u), u, v, u * u, u * v, v * v])
        c = np.linalg.lstsq(design, h[near], rcond=None)[0]
        hessian = np.array([[2 * c[3], c[4]], [c[4], 2 * c[5]]])
        if np.all(np.linalg.eigvalsh(hessian) > 0):
            uv = np.linalg.solve(hessian, -c[1:3])
            if np.hypot(*uv) <= 1.0:
                return float(c[0] + c[1] * uv[0] + c[2] * uv[1] + c[3] * uv[0] ** 2 + c[4] * uv[0] * uv[1] + c[5] * uv[1] ** 2)
    return fallback


def _crest_height(surface: LevelledSurface, at: tuple[float, float], fallback: float) -> float:
    """Maximum (m) of a parabola in the radial direction fitted to the scan points around the rim's crest.

    A ring's crest is curved across it, not along it, hence a 1-D fit in the distance from the crater's
    centre. Falls back to the smoothed map's value when the points do not form a crest at that scale.
    """
    radius = _fit_radius(surface)
    x, y, h = (surface.points[:, k] for k in range(3))
    near = np.hypot(x - at[0], y - at[1]) <= radius
    if near.sum() >= 12:
        crest_r = np.hypot(at[0] - surface.centre[0], at[1] - surface.centre[1])
        t = (np.hypot(x[near] - surface.centre[0], y[near] - surface.centre[1]) - crest_r) / radius
        c = np.polynomial.polynomial.polyfit(t, h[near], 2)
        if c[2] < 0 and abs(c[1] / (2 * c[2])) <= 1.0:
            return float(c[0] - c[1] ** 2 / (4 * c[2]))
    return fallback


def clearance_bounds(depth: float, flattening: float, nominal: float) -> tuple[float, float]:
    """Clearance interval (m) of Sect. 4.1: [nominal, nominal + crater depth + sphere flattening]."""
    for name, value in (("crater depth", depth), ("flattening", flattening), ("nominal clearance", nominal)):
        if not (math.isfinite(value) and value >= 0):
            raise ScanError(f"{name} {value!r} m must be a finite number >= 0")
    return nominal, nominal + depth + flattening
