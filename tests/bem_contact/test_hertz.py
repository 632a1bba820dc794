"""BEM against Hertz's closed-form solution (Johnson 1985, Sect. 4.2) and Hertz's elliptical contact.

Both references are analytic; the BEM is only ever compared with them, never with itself."""
import numpy as np
import pytest

from bem_contact import BRASS, STEEL, contact_modulus, hertz_force, hertz_pressure, hertz_radius, solve_contact, sphere_gap
from bem_contact.hertz import hertz_indentation_from_force
from bem_contact.references import elliptical_hertz_force

R = 7.92e-3
E_STAR = contact_modulus(STEEL, BRASS)
SIDE = 2.5e-3


def assert_signorini(result):
    """p >= 0, g >= -tol delta and p g = 0 (to tol) on the FFT displacement (the FFT equals the dense matrix)."""
    g = result.deformed_gap
    tol = result.tol * result.indentation
    kii = result._operator.self_compliance
    assert result.pressure.min() >= 0 and g.min() >= -tol
    assert np.max(np.abs(np.minimum(result.pressure * kii, g))) <= tol


@pytest.mark.parametrize("n", [127, 128])
def test_force_radius_and_pressure_of_a_paraboloid(n):
    gap, dx = sphere_gap(n, SIDE, R)
    delta = 20e-6
    result = solve_contact(gap, dx, E_STAR, indentation=delta)
    assert_signorini(result)
    assert result.force == pytest.approx(float(hertz_force(delta, R, E_STAR)), rel=3e-4)
    a = float(hertz_radius(delta, R))
    assert np.sqrt(result.contact_area / np.pi) == pytest.approx(a, rel=2 * dx / a)
    x = (np.arange(n) - n // 2) * dx
    r = np.hypot(x[:, None], x[None, :])
    inside = r < 0.85 * a
    p0 = 2 * E_STAR * a / (np.pi * R)
    assert np.max(np.abs(result.pressure[inside] - hertz_pressure(r[inside], delta, R, E_STAR))) < 0.01 * p0
    assert np.all(result.pressure[r > a + 2 * dx] == 0)


def test_load_control_reads_the_indentation_off_the_solution():
    gap, dx = sphere_gap(128, SIDE, R)
    W = 800.0  # N
    result = solve_contact(gap, dx, E_STAR, force=W)
    assert_signorini(result)
    assert result.force == pytest.approx(W, rel=1e-12)
    assert result.indentation == pytest.approx(float(hertz_indentation_from_force(W, R, E_STAR)), rel=3e-4)


def test_error_falls_with_refinement_like_dx_squared():
    delta = 30e-6
    errors = []
    for n in (64, 128, 256):
        gap, dx = sphere_gap(n, SIDE, R)
        errors.append(abs(solve_contact(gap, dx, E_STAR, indentation=delta).force / hertz_force(delta, R, E_STAR) - 1))
    order = np.polyfit(np.log([64, 128, 256]), np.log(errors), 1)[0]
    assert order < -1.5, errors


def test_elliptical_contact_of_a_non_spherical_gap():
    n, side = 192, 3e-3
    R1, R2 = 2 * R, R
    x = (np.arange(n) - n // 2) * (side / n)
    gap = x[:, None] ** 2 / (2 * R1) + x[None, :] ** 2 / (2 * R2)
    delta = 20e-6
    result = solve_contact(gap, side / n, E_STAR, indentation=delta)
    assert_signorini(result)
    assert result.force == pytest.approx(elliptical_hertz_force(delta, R1, R2, E_STAR), rel=5e-4)
    # sanity of the reference itself: nearly equal radii give the circular force with R = sqrt(R1 R2)
    R1 = 1.001 * R
    assert elliptical_hertz_force(delta, R1, R, E_STAR) == pytest.approx(float(hertz_force(delta, np.sqrt(R1 * R), E_STAR)), rel=1e-5)


def test_exact_sphere_is_slightly_softer_than_the_paraboloid():
    delta = 40e-6
    forces = [solve_contact(*sphere_gap(128, SIDE, R, shape), E_STAR, indentation=delta).force for shape in ("paraboloid", "sphere")]
    # the cap lies above the paraboloid by r^4 / (8 R^3): less material in the way, by O(delta / R)
    assert 0 < 1 - forces[1] / forces[0] < 5 * delta / R
