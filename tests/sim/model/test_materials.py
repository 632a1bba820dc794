"""sim.model.materials against handbook values and the seed paper's own sphere (Table 1, Eq. 8)."""
import math

import pytest

from sim.common.errors import SimulationInputError
from sim.model.materials import MATERIALS, hertz_constant, material, sphere_mass
from sim.model.parameters import K_H_NOMINAL, SPHERE_MASS

# handbook ranges (ASM Handbook vol. 2; MatWeb): density kg/m^3, E GPa, nu
HANDBOOK = {"brass": ((8400, 8550), (96, 106), (0.28, 0.35)),
            "steel": ((7750, 7850), (190, 215), (0.27, 0.30)),
            "tungsten": ((16500, 19300), (310, 411), (0.27, 0.30))}


@pytest.mark.parametrize("name", sorted(HANDBOOK))
def test_each_material_lies_within_its_handbook_range(name):
    (rho_lo, rho_hi), (E_lo, E_hi), (nu_lo, nu_hi) = HANDBOOK[name]
    m = MATERIALS[name]
    assert rho_lo <= m.density <= rho_hi and E_lo <= m.E / 1e9 <= E_hi and nu_lo <= m.nu <= nu_hi


def test_the_papers_sphere_gets_the_papers_mass_and_k_H():
    """R = 7.92 mm brass on steel: 17.7 g (Table 1) and k_H* = 282 N/mm^1.5 x 1e3 (Eq. 8)."""
    brass = material("Brass")
    assert sphere_mass(7.92e-3, brass) == pytest.approx(SPHERE_MASS, rel=0.01)
    assert hertz_constant(7.92e-3, brass) == pytest.approx(K_H_NOMINAL, rel=0.005)


def test_eq8_scales_with_the_root_of_the_radius_and_mass_with_its_cube():
    steel = material("steel")
    assert hertz_constant(4e-3, steel) / hertz_constant(1e-3, steel) == pytest.approx(2.0)
    assert sphere_mass(2e-3, steel) == pytest.approx(8 * sphere_mass(1e-3, steel))
    assert sphere_mass(1e-3, steel) == pytest.approx(4 / 3 * math.pi * 1e-9 * 7810)


def test_an_unknown_material_names_the_known_ones():
    with pytest.raises(SimulationInputError, match="unknown sphere material 'gold'; choose one of brass, steel, tungsten"):
        material("gold")


def test_table2s_k_H_is_eq8_of_table1_rounded_and_every_stage_computes_eq8_alike():
    """k_H* = 282e3 N/mm^1.5 of Table 2 is Eq. 8 with Table 1's brass on steel (281.76e3) rounded to three digits;
    bem_contact's Eq. 8 is sim's, bit for bit (one definition)."""
    from bem_contact.materials import BRASS, STEEL, k_H_star

    from sim.model.parameters import N_PER_MM15, SPHERE_RADIUS

    k = hertz_constant(SPHERE_RADIUS, MATERIALS["brass"])
    assert k / N_PER_MM15 == pytest.approx(281.755e3, rel=1e-5)
    assert round(k / N_PER_MM15, -3) == K_H_NOMINAL / N_PER_MM15
    assert k_H_star(SPHERE_RADIUS, BRASS, STEEL) == k

