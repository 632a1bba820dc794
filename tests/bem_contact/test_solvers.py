"""The LCP solvers: agreement, complementarity, load control, warm starts, failures and bad input."""
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from bem_contact import BRASS, STEEL, ContactInputError, ConvergenceError, contact_modulus, normal_operator, solve_contact, sphere_gap

R = 7.92e-3
E_STAR = contact_modulus(STEEL, BRASS)
ALL = ["pk", "al-jacobi", "osqp", "cvxpy"]


def assert_complementarity(result, slack=1.0):
    """p >= 0, g >= -tol delta, p g = 0 up to tol, checked with the dense matrix (independent of the FFT)."""
    p = result.pressure
    K = normal_operator(p.shape, result.dx, result.E_star).dense()
    g = result.gap - result.indentation + (K @ p.ravel()).reshape(p.shape)
    tol = slack * result.tol * result.indentation
    assert p.min() >= 0
    assert g.min() >= -tol
    kii = K[0, 0]
    assert np.max(np.abs(np.minimum(p * kii, g))) <= tol
    assert np.sum(p * np.abs(g)) <= result.tol * result.indentation * p.sum() * slack


def test_all_solvers_agree_on_the_sphere_at_20um():
    gap, dx = sphere_gap(32, 2.5e-3, R)
    results = {name: solve_contact(gap, dx, E_STAR, indentation=20e-6, solver=name) for name in ALL}
    reference = results["pk"].force
    for name, result in results.items():
        assert result.converged and result.solver == name
        # acceptance asks 0.5 %; the interior-point reference cvxpy is held to its own tol (1e-5)
        assert result.force == pytest.approx(reference, rel=10 * max(result.tol, 1e-7)), name
        assert_complementarity(result)


@pytest.mark.parametrize("solver", ["pk", "al-jacobi", "osqp", "cvxpy"])
def test_load_control_matches_displacement_control(solver):
    gap, dx = sphere_gap(24, 2.0e-3, R)
    by_delta = solve_contact(gap, dx, E_STAR, indentation=15e-6, solver=solver)
    by_force = solve_contact(gap, dx, E_STAR, force=by_delta.force, solver=solver)
    assert by_force.force == pytest.approx(by_delta.force, rel=10 * by_force.tol)
    assert by_force.indentation == pytest.approx(15e-6, rel=1e-5)
    assert_complementarity(by_force)


def test_warm_start_gives_the_same_solution():
    gap, dx = sphere_gap(96, 2.5e-3, R)
    cold = solve_contact(gap, dx, E_STAR, indentation=30e-6)
    previous = solve_contact(gap, dx, E_STAR, indentation=25e-6)
    warm = solve_contact(gap, dx, E_STAR, indentation=30e-6, x0=previous.pressure)
    assert warm.force == pytest.approx(cold.force, rel=1e-8)


def test_warm_start_from_a_single_loaded_element_does_not_stall():
    """Regression: a converged one-element contact has zero gradient on its contact, so PK's step was 0."""
    gap, dx = sphere_gap(16, 2.5e-3, R)
    first = solve_contact(gap, dx, E_STAR, indentation=2e-6)
    assert np.count_nonzero(first.pressure) == 1
    warm = solve_contact(gap, dx, E_STAR, indentation=9.6e-6, x0=first.pressure, maxiter=200)
    assert warm.force == pytest.approx(solve_contact(gap, dx, E_STAR, indentation=9.6e-6).force, rel=1e-7)


def test_contact_outside_the_inner_box_is_found():
    """A low plateau (h = 0.8 delta) beside the first-touch bump: pk's first, smaller box misses it and the
    check on the full candidate box must bring it in (compared with the dense solver)."""
    n, dx, delta = 40, 2e-5, 10e-6
    gap = np.full((n, n), 5 * delta)
    gap[4:8, 4:8] = 0.0
    gap[20:36, 20:36] = 0.8 * delta
    pk = solve_contact(gap, dx, E_STAR, indentation=delta, solver="pk")
    dense = solve_contact(gap, dx, E_STAR, indentation=delta, solver="al-jacobi")
    assert pk.pressure[20:36, 20:36].sum() > 0
    assert pk.force == pytest.approx(dense.force, rel=1e-6)
    assert_complementarity(pk)


def test_non_convergence_is_reported_never_silent():
    gap, dx = sphere_gap(64, 2.5e-3, R)
    with pytest.raises(ConvergenceError, match="residual"):
        solve_contact(gap, dx, E_STAR, indentation=20e-6, maxiter=2)
    result = solve_contact(gap, dx, E_STAR, indentation=20e-6, maxiter=2, raise_on_failure=False)
    assert not result.converged and result.residual > result.tol
    with pytest.raises(ConvergenceError):
        solve_contact(gap[::2, ::2], 2 * dx, E_STAR, indentation=20e-6, solver="al-jacobi", maxiter=10)


def test_gap_is_shifted_to_first_touch():
    gap, dx = sphere_gap(32, 2.5e-3, R)
    a = solve_contact(gap, dx, E_STAR, indentation=10e-6)
    b = solve_contact(gap + 3e-6, dx, E_STAR, indentation=10e-6)
    assert b.force == pytest.approx(a.force, rel=1e-12)
    assert b.gap.min() == 0.0


GOOD = dict(indentation=1e-6)


@pytest.mark.parametrize(
    "gap, dx, E_star, kwargs, message",
    [
        (np.array([[0.0, np.nan], [1e-6, 0.0]]), 1e-5, E_STAR, GOOD, "non-finite"),
        (np.zeros((0, 4)), 1e-5, E_STAR, GOOD, "non-empty"),
        (np.zeros(5), 1e-5, E_STAR, GOOD, "2-D"),
        (np.zeros((4, 4)), 0.0, E_STAR, GOOD, "pitch"),
        (np.zeros((4, 4)), 1e-5, 0.0, GOOD, "modulus"),
        (np.zeros((4, 4)), 1e-5, -1.0, GOOD, "modulus"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=0.0), "indentation"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=-1e-6), "indentation"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(force=math.inf), "force"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=1.1e-315), "length resolution"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=1e-6, force=1.0), "exactly one"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=1e-6, solver="magic"), "unknown solver"),
        (np.zeros((33, 33)), 1e-5, E_STAR, dict(indentation=1e-6, solver="cvxpy"), "solver='pk'"),
        (np.zeros((65, 65)), 1e-5, E_STAR, dict(indentation=1e-6, solver="al-jacobi"), "solver='pk'"),
        (np.zeros((4, 4)), 1e-5, E_STAR, dict(indentation=1e-6, x0=np.zeros((3, 3))), "x0"),
    ],
)
def test_bad_input_is_one_clear_line(gap, dx, E_star, kwargs, message):
    with pytest.raises(ContactInputError, match=message) as info:
        solve_contact(gap, dx, E_star, **kwargs)
    assert "\n" not in str(info.value)


# ---- property-based: random small gap maps -------------------------------------------------------


@st.composite
def rough_problems(draw):
    n = draw(st.integers(3, 9))
    m = draw(st.integers(3, 9))
    heights = draw(arrays(np.float64, (n, m), elements=st.floats(0.0, 1.0, allow_nan=False, allow_subnormal=False, width=64)))
    scale = draw(st.sampled_from([1e-7, 1e-6, 1e-5]))  # m
    fraction = draw(st.floats(0.05, 2.0))
    gap = heights * scale
    spread = float(gap.max() - gap.min())
    # a spread below 1e-6 of the scale is round-off, not roughness (and its fraction could fall below the solvers'
    # length resolution, 1e-12 dx, which they refuse): treat the map as flat
    delta = fraction * (spread if spread > 1e-6 * scale else scale)
    return gap, 1e-5, delta


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rough_problems())
def test_solvers_agree_and_complementarity_holds_on_random_maps(problem):
    gap, dx, delta = problem
    results = [solve_contact(gap, dx, E_STAR, indentation=delta, solver=name) for name in ("pk", "al-jacobi", "osqp")]
    smaller = solve_contact(gap, dx, E_STAR, indentation=delta / 3)
    results.append(solve_contact(gap, dx, E_STAR, indentation=delta, x0=smaller.pressure))  # warm-started pk
    for result in results:
        assert_complementarity(result, slack=1.0)
    forces = [r.force for r in results]
    assert max(forces) - min(forces) <= 1e-6 * max(forces)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rough_problems())
def test_cvxpy_reference_agrees_on_random_maps(problem):
    gap, dx, delta = problem
    pk = solve_contact(gap, dx, E_STAR, indentation=delta, solver="pk")
    ref = solve_contact(gap, dx, E_STAR, indentation=delta, solver="cvxpy")
    assert ref.force == pytest.approx(pk.force, rel=10 * ref.tol)
    assert_complementarity(ref)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rough_problems(), st.floats(0.1, 10.0))
def test_load_control_on_random_maps(problem, load_factor):
    gap, dx, delta = problem
    W = load_factor * solve_contact(gap, dx, E_STAR, indentation=delta).force
    pk = solve_contact(gap, dx, E_STAR, force=W, solver="pk")
    aj = solve_contact(gap, dx, E_STAR, force=W, solver="al-jacobi")
    assert pk.force == pytest.approx(W, rel=1e-10)
    assert aj.indentation == pytest.approx(pk.indentation, rel=1e-5)
    assert_complementarity(pk)
