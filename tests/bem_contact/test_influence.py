"""Love's and Cerruti's closed-form element coefficients against quadrature of the point-load solutions,
and the dense and FFT operators against each other (the references are in bem_contact.references)."""
import numpy as np
import pytest

from bem_contact import BRASS, STEEL, ContactInputError, TangentialOperator, contact_modulus, normal_operator
from bem_contact.influence import cerruti_kernels, love_kernel
from bem_contact.references import boussinesq_displacement, cerruti_displacements, element_quadrature

DX = 1e-5
E_STAR = contact_modulus(STEEL, BRASS)


OFFSETS = [(0, 0), (1, 0), (0, 1), (1, 1), (3, -2), (-5, 4), (12, 0)]


@pytest.mark.parametrize("i, j", OFFSETS)
def test_love_equals_quadrature_of_boussinesq(i, j):
    table = love_kernel(13, 13, DX, E_STAR)
    boussinesq = lambda x, y: boussinesq_displacement(x, y, E_STAR)  # point load, combined bodies
    expected = element_quadrature(boussinesq, i * DX, j * DX, DX)
    assert table[12 + i, 12 + j] == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("i, j", OFFSETS)
def test_cerruti_equals_quadrature_of_point_force(i, j):
    kxx, kyy, kxy = cerruti_kernels(13, 13, DX, STEEL, BRASS)
    mats = (STEEL, BRASS)
    uxx = lambda x, y: cerruti_displacements(x, y, mats)[0]
    uyy = lambda x, y: cerruti_displacements(x, y, mats)[1]
    uxy = lambda x, y: cerruti_displacements(x, y, mats)[2]
    X, Y = i * DX, j * DX
    scale = abs(kxx[12, 12])
    assert kxx[12 + i, 12 + j] == pytest.approx(element_quadrature(uxx, X, Y, DX), rel=1e-8)
    assert kyy[12 + i, 12 + j] == pytest.approx(element_quadrature(uyy, X, Y, DX), rel=1e-8)
    assert kxy[12 + i, 12 + j] == pytest.approx(element_quadrature(uxy, X, Y, DX), rel=1e-8, abs=1e-12 * scale)


def test_far_field_is_the_point_load():
    table = love_kernel(41, 41, DX, E_STAR)
    r = 40 * DX
    assert table[80, 40] == pytest.approx(DX * DX / (np.pi * E_STAR * r), rel=2e-4)


@pytest.mark.parametrize("shape", [(1, 1), (7, 5), (8, 8), (16, 9), (33, 32)])
def test_dense_and_fft_operators_agree_to_round_off(shape):
    rng = np.random.default_rng(1)
    p = rng.random(shape)
    op = normal_operator(shape, DX, E_STAR)
    dense = (op.dense() @ p.ravel()).reshape(shape)
    assert np.max(np.abs(op(p) - dense)) <= 1e-10 * np.max(np.abs(dense))
    tang = TangentialOperator(shape, DX, STEEL, BRASS)
    q = rng.standard_normal((2, *shape))
    ux, uy = tang(q[0], q[1])
    stacked = tang.dense() @ q.reshape(2, -1).ravel()
    ref = stacked.reshape(2, *shape)
    assert np.max(np.abs(ux - ref[0])) <= 1e-10 * np.max(np.abs(ref))
    assert np.max(np.abs(uy - ref[1])) <= 1e-10 * np.max(np.abs(ref))


def test_matrices_are_symmetric_positive_definite():
    K = normal_operator((9, 8), DX, E_STAR).dense()
    assert np.allclose(K, K.T, rtol=0, atol=1e-15 * K.max())
    assert np.linalg.eigvalsh(K).min() > 0
    T = TangentialOperator((7, 6), DX, STEEL, BRASS).dense()
    assert np.allclose(T, T.T, rtol=0, atol=1e-15 * T.max())
    assert np.linalg.eigvalsh(T).min() > 0


def test_restricted_operator_equals_the_operator_of_the_window():
    big = normal_operator((20, 17), DX, E_STAR)
    small = normal_operator((6, 9), DX, E_STAR)
    assert np.array_equal(big.restricted(6, 9).table, small.table)


def test_empty_grid_and_bad_modulus_are_refused():
    with pytest.raises(ContactInputError):
        normal_operator((0, 5), DX, E_STAR)
    with pytest.raises(ContactInputError):
        normal_operator((5, 5), DX, -1.0)
    with pytest.raises(ContactInputError):
        normal_operator((5, 5), 0.0, E_STAR)
