"""Tangential stiffness of a stuck contact (Cerruti) against Mindlin's k_t = 8 G* a (seed paper, Appendix C)."""
import numpy as np
import pytest

from bem_contact import BRASS, STEEL, ContactInputError, tangential_modulus, tangential_stiffness
from bem_contact.tangential import sphere_tangential_stiffness

SPHERE_WEIGHT = 0.0177 * 9.81  # N, Sect. 2


def test_stuck_disk_converges_to_mindlin():
    a = 1e-4
    errors = []
    for n in (24, 48):
        dx = 2.4 * a / n
        x = (np.arange(n) - n / 2 + 0.5) * dx
        disk = np.hypot(x[:, None], x[None, :]) < a
        # equal-area radius of the stair-stepped disk, so that only the elasticity is compared
        a_eff = np.sqrt(disk.sum() * dx * dx / np.pi)
        errors.append(abs(tangential_stiffness(disk, dx, STEEL, BRASS) / (8 * tangential_modulus(STEEL, BRASS) * a_eff) - 1))
    assert errors[1] < 0.01 and errors[1] < errors[0]


def test_sphere_under_its_own_weight_matches_mindlin():
    check = sphere_tangential_stiffness(SPHERE_WEIGHT, 7.92e-3, STEEL, BRASS, grid=64)
    assert check.k_t == pytest.approx(check.k_t_mindlin, rel=0.01)
    # Appendix C's input: the sphere's weight gives a Hertz radius of about 24 um
    assert check.contact_radius == pytest.approx(2.395e-5, rel=2e-3)


def test_tangential_input_is_checked():
    with pytest.raises(ContactInputError):
        tangential_stiffness(np.zeros((4, 4), bool), 1e-5, STEEL, BRASS)
    with pytest.raises(ContactInputError):
        sphere_tangential_stiffness(0.0, 7.92e-3, STEEL, BRASS)
