"""The sphere as described (`sim.model.sphere`): its mass and k_H* from Eq. 8 with both bodies' E and nu, the paper's
sphere kept at Tables 1-2's values, materials of one's own, and the options of every simulation command."""
import math

import pytest

from sim.common.errors import SimulationInputError
from sim.model.materials import MATERIALS, WALL_MATERIALS, material_of, wall_material
from sim.model.parameters import K_H_NOMINAL, SPHERE_MASS
from sim.model.sphere import Sphere, sphere_of


def eq8(R: float, E_a: float, nu_a: float, E_s: float, nu_s: float) -> float:
    """Eq. 8 written out: k_H* = 4/3 sqrt(R_a) ((1 - nu_a^2)/E_a + (1 - nu_s^2)/E_s)^-1."""
    return 4.0 / 3.0 * math.sqrt(R) / ((1 - nu_a**2) / E_a + (1 - nu_s**2) / E_s)


def test_a_steel_sphere_on_aluminium_over_steel_is_eq8s_contact_modulus_ratio():
    """The issue's check: k_H(steel on aluminium) / k_H(steel on steel) = E*(steel, Al) / E*(steel, steel), with the
    handbook values of 6061-T6 (68.9 GPa, 0.33) and of the paper's steel (207 GPa, 0.30): 0.5074."""
    on_al = sphere_of(5e-3, "steel", wall="aluminium")
    on_steel = sphere_of(5e-3, "steel", wall="steel")
    expected = (1 / (0.91 / 207e9 + (1 - 0.33**2) / 68.9e9)) / (1 / (2 * 0.91 / 207e9))
    assert on_al.k_H_star / on_steel.k_H_star == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(0.5074, abs=1e-4)
    assert on_steel.k_H_star == pytest.approx(eq8(5e-3, 207e9, 0.3, 207e9, 0.3), rel=1e-12)


def test_the_papers_sphere_keeps_tables_1_and_2():
    paper = Sphere()
    assert paper.is_paper and paper.mass == SPHERE_MASS and paper.k_H_star == K_H_NOMINAL
    # Eq. 8 with Table 1's materials gives 281.76e3 N/mm^1.5, which Table 2 rounds to 282e3
    assert eq8(7.92e-3, 102e9, 0.3, 207e9, 0.3) / 1e3**1.5 == pytest.approx(281.76e3, rel=1e-4)
    other = sphere_of(7.92e-3, "brass", wall="aluminium")
    assert not other.is_paper and other.mass == pytest.approx(4 / 3 * math.pi * 7.92e-3**3 * 8470)
    assert other.k_H_star == pytest.approx(eq8(7.92e-3, 102e9, 0.3, 68.9e9, 0.33), rel=1e-12)


def test_materials_of_ones_own():
    own = material_of("E=200GPa,nu=0.29,density=7.85g/cm3", "sphere")
    assert (own.E, own.nu, own.density) == (200e9, 0.29, pytest.approx(7850.0))
    wall = wall_material("E=70e9,nu=0.33")
    assert (wall.E, wall.nu) == (70e9, 0.33) and math.isnan(wall.density)
    assert wall_material("Aluminum") is WALL_MATERIALS["aluminium"]
    sphere = sphere_of(4e-3, own, wall=wall)
    assert sphere.mass == pytest.approx(4 / 3 * math.pi * 4e-3**3 * 7850.0)
    assert sphere.k_H_star == pytest.approx(eq8(4e-3, 200e9, 0.29, 70e9, 0.33), rel=1e-12)


@pytest.mark.parametrize("text, kind, message", [
    ("unobtainium", "wall", "unknown wall material 'unobtainium'; choose one of steel, aluminium, titanium, brass, cast-iron"),
    ("gold", "sphere", "unknown sphere material 'gold'; choose one of " + ", ".join(MATERIALS)),
    ("E=200,nu=0.3,density=7800", "sphere", "is not a solid's Young's modulus"),
    ("E=200GPa,nu=0.6,density=7800", "sphere", "nu = 0.6 must lie in [0, 0.5)"),
    ("E=200GPa,nu=0.3", "sphere", "missing density"),
    ("E=200GPa,nu=0.3,density=7.8", "sphere", "is not a solid's (500-25000 kg/m^3)"),
    ("E=70Gbar,nu=0.3", "wall", "unknown unit 'Gbar' for e"),
])
def test_a_bad_material_is_one_line(text, kind, message):
    with pytest.raises(SimulationInputError, match=None) as caught:
        material_of(text, kind)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_mass_that_disagrees_with_radius_and_material_is_refused():
    with pytest.raises(SimulationInputError, match="disagrees with a solid steel sphere of R = 5 mm"):
        sphere_of(5e-3, "steel", mass=1e-3)
    assert sphere_of(5e-3, "steel", mass=4.1e-3).mass == 4.1e-3  # within 2 %: the weighed mass wins
    assert sphere_of(5e-3, mass=1e-3).mass == 1e-3  # a hollow sphere: the mass alone is taken as given
