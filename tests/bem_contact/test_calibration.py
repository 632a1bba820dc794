"""k_H calibration: the fit, the grid-refinement error bar, any gap map (Sect. 4.1, Fig. 3c)."""
import numpy as np
import pytest

from bem_contact import BRASS, STEEL, ContactInputError, calibrate_k_H, contact_modulus, fit_k_H, k_H_star, sphere_gap
from bem_contact.references import elliptical_hertz_force

R = 7.92e-3
E_STAR = contact_modulus(STEEL, BRASS)
DELTAS = np.linspace(2e-6, 40e-6, 20)


def test_fit_recovers_an_exact_power_law_and_measures_misfit():
    d = np.linspace(1e-6, 4e-5, 12)
    k, residual = fit_k_H(d, 3.3e9 * d**1.5)
    assert k == pytest.approx(3.3e9, rel=1e-13) and residual < 1e-14
    _, residual = fit_k_H(d, 3.3e9 * d**1.5 * (1 + 0.01 * np.sin(d / 3e-6)))
    assert 1e-3 < residual < 2e-2


@pytest.mark.parametrize("grid", [64, 128])
def test_flat_wall_matches_eq_8_within_the_error_bar(grid):
    cal = calibrate_k_H(lambda n: sphere_gap(n, 2.5e-3, R), grid, E_STAR, DELTAS, R=R)
    assert cal.k_H_star == pytest.approx(k_H_star(R, STEEL, BRASS), rel=1e-14)
    true_error = abs(cal.k_H - cal.k_H_star)
    assert true_error <= cal.k_H_error  # the bar is conservative
    assert cal.k_H_error <= 6 * true_error + 1e-6 * cal.k_H_star  # ... but not absurdly so
    assert abs(cal.k_H_ratio - 1) < {64: 1e-3, 128: 2e-4}[grid]
    assert cal.fit_residual < 1e-3
    assert cal.grid == grid and cal.solver == "pk"
    assert len(cal.forces) == 20 and np.all(np.diff(cal.forces) > 0)


def test_calibrates_a_non_spherical_gap_map():
    """An elliptical paraboloid (R1 = 2 R2): Hertz's elliptical force is also ~ delta^1.5, so k_H is known."""
    side, R1, R2 = 3e-3, 2 * R, R

    def gap_at(n):
        x = (np.arange(n) - n // 2) * (side / n)
        return x[:, None] ** 2 / (2 * R1) + x[None, :] ** 2 / (2 * R2), side / n

    cal = calibrate_k_H(gap_at, 96, E_STAR, np.linspace(5e-6, 30e-6, 6))
    expected = elliptical_hertz_force(1.0, R1, R2, E_STAR)  # force at delta = 1 m is k_H (exact power law)
    assert cal.k_H == pytest.approx(expected, abs=max(cal.k_H_error, 1e-4 * expected))
    assert cal.k_H_ratio is None


def test_contact_reaching_the_edge_is_refused():
    with pytest.raises(ContactInputError, match="edge"):
        calibrate_k_H(lambda n: sphere_gap(n, 0.6e-3, R), 32, E_STAR, DELTAS, R=R)


@pytest.mark.parametrize(
    "grid, deltas, message",
    [(4, DELTAS, "grid"), (32, [1e-5], "at least 2"), (32, [0.0, 1e-5], "> 0"), (32, [np.nan, 1e-5], "> 0")],
)
def test_bad_calibration_input(grid, deltas, message):
    with pytest.raises(ContactInputError, match=message):
        calibrate_k_H(lambda n: sphere_gap(n, 2.5e-3, R), grid, E_STAR, deltas, R=R)
