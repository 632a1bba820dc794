"""Interval layer against analytic functions: exact corners when monotone, a flag when not."""
import numpy as np
import pytest

from uq.errors import StudyError
from uq.methods.interval import axis_design, band, box_design, propagate
from uq.problem.space import Parameter, ParameterSpace, table2_space


def unit_space(n=3):
    return ParameterSpace(tuple(Parameter(f"x{i}", 0.5, 0.1, 1.0) for i in range(n)))


def test_monotone_function_band_is_exact_extremes():
    # f increasing in x0, decreasing in x1, increasing in x2: extremes known in closed form
    f = lambda p: np.exp(p["x0"]) - 3 * p["x1"] ** 3 + np.log(p["x2"])  # noqa: E731
    space = unit_space()
    result = propagate(f, box_design(space, n_interior=16, seed=1))
    exact_min = np.exp(0.1) - 3 * 1.0 + np.log(0.1)
    exact_max = np.exp(1.0) - 3 * 0.1**3 + np.log(1.0)
    assert result.monotone
    assert result.lower[0] == pytest.approx(exact_min, rel=1e-14)
    assert result.upper[0] == pytest.approx(exact_max, rel=1e-14)
    np.testing.assert_array_equal(result.lower, result.corner_lower)


def test_monotone_axis_gives_endpoints_of_each_parameter():
    f = lambda p: np.array([p["x0"] ** 2 + p["x1"], -p["x0"]])  # noqa: E731  two outputs
    space = unit_space(2)
    result = propagate(f, axis_design(space, "x0", n_interior=3))
    assert result.monotone
    np.testing.assert_allclose(result.lower, [0.1**2 + 0.5, -1.0])
    np.testing.assert_allclose(result.upper, [1.0 + 0.5, -0.1])


def test_non_monotone_box_is_flagged_and_widened():
    # a valley in x0 at the centre of the box: every corner misses the minimum
    f = lambda p: (p["x0"] - 0.55) ** 2 + 0.1 * p["x1"]  # noqa: E731
    space = unit_space(2)
    result = propagate(f, box_design(space, n_interior=1))
    assert not result.monotone
    assert result.corner_lower[0] == pytest.approx(0.45**2 + 0.01)
    # the centre (0.55, 0.55) and the nominal point (0.5, 0.5) are checked; the lower one widens the band
    assert result.lower[0] == pytest.approx(min(f({"x0": 0.55, "x1": 0.55}), f({"x0": 0.5, "x1": 0.5})))
    assert result.upper[0] == result.corner_upper[0]  # the upper side holds
    assert "outside the corner band" in result.notes[0]


def test_non_monotone_axis_is_flagged():
    f = lambda p: np.sin(4 * p["x0"])  # noqa: E731  rises then falls on [0.1, 1]
    result = propagate(f, axis_design(unit_space(1), "x0", n_interior=3))
    assert not result.monotone
    assert result.upper[0] == pytest.approx(max(np.sin(4 * x) for x in np.linspace(0.1, 1, 5)))
    assert "not monotone in x0" in result.notes[0]


def test_noise_tolerance_suppresses_insignificant_violations():
    space = ParameterSpace((Parameter("x0", 0.1, 0.1, 1.0),))
    design = axis_design(space, "x0", n_interior=1)
    values = np.array([[1.0], [1.05], [0.99]])  # wiggle of 0.05 on top of a flat response
    assert not band(design, values).monotone
    assert band(design, values, np.full_like(values, 0.05), z=2.0).monotone


def test_nominal_inside_interval_joins_the_axis():
    design = axis_design(table2_space(), "D", n_interior=0)
    assert [p.values["D"] for p in design.points] == [0.00075, 0.00085, 0.00090]
    assert [p.role for p in design.points] == ["corner", "interior", "corner"]


def test_residual_band_fixes_k_H_at_best_estimate():
    space = table2_space()
    fixed = space.fix(k_H=space.extras["k_H_best_estimate"])
    design = box_design(fixed, n_interior=1)
    assert len([p for p in design.points if p.role == "corner"]) == 4
    assert {p.values["k_H"] for p in design.points} == {1.25 * 282e3 * 1e3**1.5}


def test_nan_values_are_refused():
    design = axis_design(unit_space(1), "x0", n_interior=0)
    with pytest.raises(StudyError, match="NaN"):
        band(design, np.array([1.0, np.nan, 2.0]))


def test_noise_is_pooled_over_the_design_points():
    # one point's own standard error is 0 (two equal repetitions by chance); the design's pooled noise counts
    space = ParameterSpace((Parameter("x0", 0.1, 0.1, 1.0),))
    design = axis_design(space, "x0", n_interior=2)
    values = np.array([[1.0], [1.0], [1.05], [0.99]])
    noise = np.array([[0.06], [0.0], [0.0], [0.0]])  # RMS 0.03: steps of 0.05-0.06 are within 2 sqrt(2) 0.03
    assert band(design, values, noise, pool=True).monotone
    assert not band(design, values, noise, pool=False).monotone


def test_without_a_noise_estimate_monotonicity_is_not_tested():
    """One repetition of a chaotic response has no noise estimate (NaN): a wiggle cannot be judged, so nothing is
    flagged or widened and a note says that the check could not be made; a deterministic function (noise 0) is
    still checked."""
    space = ParameterSpace((Parameter("x0", 0.1, 0.1, 1.0),))
    design = axis_design(space, "x0", n_interior=1)
    values = np.array([[1.0, 1.0], [1.5, 1.5], [0.9, 0.9]])  # not monotone in either column
    noise = np.array([[np.nan, 0.0], [np.nan, 0.0], [np.nan, 0.0]])
    result = band(design, values, noise, output_labels=["level 5", "level 6"])
    np.testing.assert_array_equal(result.tested, [False, True])
    np.testing.assert_array_equal(result.flagged, [False, True])
    assert np.isnan(result.violation[0]) and result.violation[1] > 0
    assert result.upper[0] == result.corner_upper[0] == 1.0  # the corner band, not widened
    assert not result.fully_tested and not result.monotone
    assert any("could not be tested at level 5: no noise estimate" in note for note in result.notes)
    assert not any("level 5" in note and "not monotone" in note for note in result.notes)
