"""Shipped example scans: reproducible from their recipe, small, and described truthfully."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from scans import (
    EXAMPLES,
    CraterShape,
    crater_metrics,
    example_path,
    example_scan,
    level_scan,
    read_scan,
    scan_contact,
    synthetic_scan,
    write_examples,
)


def test_shipped_files_match_their_recipe_and_stay_small(tmp_path):
    total = 0
    for path in write_examples(tmp_path):
        shipped = example_path(next(k for k, v in EXAMPLES.items() if v[0] == path.name))
        total += shipped.stat().st_size
        a, b = read_scan(shipped), read_scan(path)
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.faces, b.faces)
    assert total < 3e6  # bytes: "a few MB at most"


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_examples_read_back_as_generated(name):
    filename, imprint, recipe = EXAMPLES[name]
    metrics = crater_metrics(level_scan(read_scan(example_path(name)), imprint=imprint))
    depth = -recipe["shape"].height(np.zeros(1), np.zeros(1))[0]
    assert metrics.depth == pytest.approx(depth, abs=0.5e-6)
    assert not [w for w in metrics.warnings if "--imprint" in w]
    assert example_scan(name).vertices.shape[1] == 3


@settings(max_examples=12, deadline=None, derandomize=True, phases=[Phase.explicit, Phase.generate])
@given(
    depth=st.floats(3e-6, 25e-6),
    radius=st.floats(0.4e-3, 0.8e-3),
    pileup_share=st.floats(0.0, 0.6),
    aspect=st.floats(0.8, 1.25),
    tilt=st.floats(0.0, 5.0),
    azimuth=st.floats(0.0, 360.0),
    rotation=st.floats(-180.0, 180.0),
    imprint=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_depth_and_placement_for_random_craters_and_scans(*, depth, radius, pileup_share, aspect, tilt, azimuth, rotation, imprint, seed):
    shape = CraterShape(depth=depth, radius=radius, pileup=pileup_share * depth, rim_width=0.25 * radius, aspect=aspect)
    scan = synthetic_scan(shape, side=4.5e-3, triangle=40e-6, noise=0.05e-6, tilt_deg=tilt, tilt_azimuth_deg=azimuth,
                          rotation_deg=rotation, orientation="imprint" if imprint else "crater", seed=seed)
    surface = level_scan(scan, imprint=imprint)
    assert surface.tilt_deg() == pytest.approx(tilt, abs=0.01)
    assert crater_metrics(surface).depth == pytest.approx(depth, abs=0.5e-6)
    # the sphere's axis goes through the crater's centre, which the generator put at the scanner's origin
    axis_point = surface.origin + surface.centre[0] * surface.axes[0] + surface.centre[1] * surface.axes[1]
    off_axis = axis_point - (axis_point @ surface.axes[2]) * surface.axes[2]
    assert np.linalg.norm(off_axis) < 5e-6
    assert scan_contact(surface).side < 4.5e-3
