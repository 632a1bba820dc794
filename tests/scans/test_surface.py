"""Rasterising, hole filling, levelling and crater metrics against exact references."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar
from scipy.spatial import Delaunay

from scans import (
    PAPER_CRATER,
    CraterShape,
    ScanError,
    clearance_bounds,
    crater_metrics,
    fill_holes,
    level_scan,
    rasterize,
    synthetic_scan,
)
from scans.synthetic import _rotation_axis


def test_rasterize_is_exact_for_a_plane_and_leaves_uncovered_nodes_nan():
    rng = np.random.default_rng(1)
    xy = rng.uniform(-1.0, 1.0, (400, 2))
    z = 0.3 + 2.0 * xy[:, 0] - 0.7 * xy[:, 1]
    faces = Delaunay(xy).simplices
    out = rasterize(np.column_stack([xy, z]), faces, -1.2, -1.2, 0.05, 49, 49)
    xs = -1.2 + 0.05 * np.arange(49)
    exact = 0.3 + 2.0 * xs[None, :] - 0.7 * xs[:, None]
    covered = np.isfinite(out)
    assert covered.sum() > 0.6 * 49 * 49
    np.testing.assert_allclose(out[covered], exact[covered], rtol=0, atol=1e-12)
    assert not covered[0, 0] and not covered[-1, -1]  # outside the convex hull of the points


def test_fill_holes_is_exact_for_quadratics_even_at_the_edge():
    # a crater's bottom is curved: a plain Laplace fill would flatten it, this fill must not
    x = np.arange(40.0)
    h = 0.3 * x[None, :] ** 2 + 0.1 * x[:, None] ** 2 + 0.05 * x[None, :] * x[:, None] + 3 * x[None, :]
    holed = h.copy()
    holed[10:14, 5:9] = np.nan
    holed[0:3, 0:2] = np.nan
    filled, report = fill_holes(holed, dx=1e-5)
    np.testing.assert_allclose(filled, h, rtol=0, atol=1e-12 * np.abs(h).max())
    assert report.n_holes == 2


def test_fill_holes_is_exact_for_a_discrete_harmonic_surface():
    # a cubic harmonic, x^3 - 3 x y^2, satisfies the 5-point Laplace equation exactly; no quadratic fits it
    x = np.arange(40.0) - 20.0
    h = x[None, :] ** 3 - 3 * x[None, :] * x[:, None] ** 2
    holed = h.copy()
    holed[10:14, 5:9] = np.nan
    holed[25, 30] = np.nan
    filled, report = fill_holes(holed, dx=1e-5)
    np.testing.assert_allclose(filled, h, rtol=0, atol=1e-9 * np.abs(h).max())
    assert (report.n_holes, report.n_nodes) == (2, 17)
    assert report.largest == pytest.approx(2 * np.sqrt(16 / np.pi) * 1e-5)
    assert "2 hole(s), 17 grid node(s)" in report.describe()


@pytest.mark.parametrize("orientation", ["crater", "imprint"])
def test_levelling_recovers_the_wall_normal_of_a_tilted_scan(orientation):
    tilt = _rotation_axis(np.array([np.cos(0.5), np.sin(0.5), 0.0]), np.radians(5.0))
    scan = synthetic_scan(noise=0.1e-6, tilt_deg=5.0, tilt_azimuth_deg=np.degrees(0.5), rotation_deg=15.0,
                          shift=(2e-3, 1e-3, 7e-3), orientation=orientation, seed=4)
    surface = level_scan(scan, imprint=orientation == "imprint")
    expected = tilt @ np.array([0.0, 0.0, 1.0 if orientation == "crater" else -1.0])
    angle = np.arccos(np.clip(surface.axes[2] @ expected, -1, 1))
    assert angle < 2e-5  # rad: 0.02 um over a millimetre
    assert surface.tilt_deg() == pytest.approx(5.0, abs=1e-3)
    assert surface.noise == pytest.approx(0.1e-6, rel=0.1)


@pytest.mark.parametrize("orientation", ["crater", "imprint"])
def test_levelled_heights_match_the_generator(orientation):
    scan = synthetic_scan(triangle=20e-6, tilt_deg=4.0, tilt_azimuth_deg=200.0, rotation_deg=-30.0,
                          shift=(-3e-3, 5e-3, 1e-3), orientation=orientation, seed=8)
    surface = level_scan(scan, imprint=orientation == "imprint")
    height, dx, holes = surface.resample(surface.centre, 2.4e-3, 96)
    offsets = (np.arange(96) - 48) * dx
    exact = PAPER_CRATER.height(offsets[:, None], offsets[None, :])  # axisymmetric: frame rotation is irrelevant
    assert holes.n_nodes == 0
    # linear interpolation on jittered 20 um triangles: error <= s^2 max|h''| / 8 with |h''| up to
    # 470 1/m where bowl and rim meet (r = 0.75 mm): below 0.1 um there, a few nm elsewhere
    error = np.abs(height - exact)
    assert error.max() < 0.1e-6 and error.mean() < 10e-9


def test_crater_centre_is_found_where_the_generator_put_it():
    scan = synthetic_scan(crater_offset=(0.3e-3, -0.2e-3), side=4.5e-3, noise=0.1e-6, seed=2)
    surface = level_scan(scan)
    mean_xy = scan.vertices[:, :2].mean(axis=0)
    assert np.hypot(*(np.array(surface.centre) + mean_xy - (0.3e-3, -0.2e-3))) < 3e-6


def test_a_crater_filling_the_scan_has_no_flat_region():
    with pytest.raises(ScanError, match="no flat region"):
        level_scan(synthetic_scan(CraterShape(radius=1.6e-3, rim_width=0.3e-3), side=3e-3, triangle=50e-6))


def test_a_line_of_points_is_not_a_surface():
    from scans import Scan

    line = np.column_stack([np.linspace(0, 1e-3, 50), np.zeros(50), np.zeros(50)])
    with pytest.raises(ScanError, match="line"):
        level_scan(Scan(line, None, "points", "line.xyz"))


@pytest.mark.parametrize("noise, tilt", [(0.0, 0.0), (0.1e-6, 5.0), (0.3e-6, 2.0)])
def test_crater_depth_within_half_a_micrometre_of_the_generator(noise, tilt):
    for shape in (PAPER_CRATER, CraterShape(depth=5e-6, radius=0.5e-3, pileup=1e-6, rim_width=0.1e-3, aspect=1.3)):
        scan = synthetic_scan(shape, noise=noise, tilt_deg=tilt, tilt_azimuth_deg=70.0, seed=11)
        depth = crater_metrics(level_scan(scan)).depth
        assert abs(depth - (-shape.height(np.zeros(1), np.zeros(1))[0])) < 0.5e-6


def test_rim_height_and_diameter_match_the_profile():
    shape = PAPER_CRATER
    metrics = crater_metrics(level_scan(synthetic_scan(shape, triangle=20e-6, seed=3)))
    profile = lambda r: shape.height(np.array([r]), np.array([0.0]))[0]  # noqa: E731
    crest = -minimize_scalar(lambda r: -profile(r), bounds=(0.5 * shape.radius, 2 * shape.radius), method="bounded").fun
    zero = brentq(profile, 1e-6, shape.radius)  # where the bowl rises through the flat wall's level
    assert metrics.rim_height == pytest.approx(crest, abs=0.1e-6)
    assert metrics.diameter == pytest.approx(2 * zero, abs=4 * 20e-6)
    assert not metrics.warnings


def test_flat_wall_has_no_crater_and_an_imprint_read_as_a_wall_is_flagged():
    flat = crater_metrics(level_scan(synthetic_scan(CraterShape(depth=0, pileup=0), noise=0.05e-6)))
    assert flat.depth == 0.0 and flat.diameter == 0.0 and "flat wall" in flat.warnings[0]
    inverted = crater_metrics(level_scan(synthetic_scan(orientation="imprint")))
    assert any("--imprint" in w for w in inverted.warnings)


def test_clearance_bounds_reproduce_the_paper():
    lo, hi = clearance_bounds(12e-6, 0.02e-3, 0.58e-3)  # Sect. 4.1: 0.58 mm + 0.012 mm + 0.02 mm
    assert lo == pytest.approx(0.58e-3) and hi == pytest.approx(0.612e-3, rel=1e-12)
    with pytest.raises(ScanError):
        clearance_bounds(-1e-6, 0.0, 0.58e-3)


def test_a_closed_body_is_refused():
    import trimesh

    from scans import Scan

    box = trimesh.creation.box(extents=(4e-3, 4e-3, 1e-3))
    with pytest.raises(ScanError, match="faces away from the wall"):
        level_scan(Scan(np.asarray(box.vertices), np.asarray(box.faces, dtype=np.int64), "mesh", "box.stl"))
