"""Materials of Table 1 and the combined moduli of Eq. 8 (checked against hand-computed values)."""
import math

import pytest

from bem_contact import BRASS, STEEL, ContactInputError, Material, contact_modulus, k_H_star, tangential_modulus


def test_contact_modulus_of_table_1():
    # 1 / ((1 - 0.3^2)/207 GPa + (1 - 0.3^2)/102 GPa), by hand
    expected = 1.0 / (0.91 / 207e9 + 0.91 / 102e9)
    assert contact_modulus(STEEL, BRASS) == pytest.approx(expected, rel=1e-14)
    assert contact_modulus(STEEL, BRASS) == pytest.approx(75.09e9, rel=1e-3)  # peers.md


def test_k_H_star_matches_the_papers_nominal_value():
    # Table 2 / Sect. 4.1: k_H* = 282e3 N/mm^1.5 for R = 7.92 mm
    k = k_H_star(7.92e-3, STEEL, BRASS)
    assert k / 1e3**1.5 == pytest.approx(282e3, rel=2e-3)


def test_tangential_modulus_is_mindlins_combination():
    G_steel, G_brass = 207e9 / 2.6, 102e9 / 2.6
    assert tangential_modulus(STEEL, BRASS) == pytest.approx(1.0 / (1.7 / G_steel + 1.7 / G_brass), rel=1e-14)


@pytest.mark.parametrize("E, nu", [(0.0, 0.3), (-1e9, 0.3), (math.nan, 0.3), (math.inf, 0.3), (1e9, 0.5), (1e9, -1.0), (1e9, math.nan)])
def test_bad_material_is_refused_with_one_line(E, nu):
    with pytest.raises(ContactInputError) as info:
        Material(E, nu)
    assert "\n" not in str(info.value)


def test_bad_radius_is_refused():
    with pytest.raises(ContactInputError):
        k_H_star(0.0, STEEL, BRASS)
