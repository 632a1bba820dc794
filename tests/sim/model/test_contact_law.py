"""Eq. 10 (damped Hertz law, Sect. 5.5) against independent references: the two-body impact by scipy DOP853
with events (sim.integration.references.two_body_impact), the first-order energy loss of the elastic approach (quadrature),
and the conservative law of Eq. 4."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from sim.model.contact_law import ContactLaw, damped_hertz_force, restitution, xi_of_r_cont
from sim.common.errors import SimulationInputError
from sim.integration.references import two_body_impact
from sim.model.system import K_H_NOMINAL, SPHERE_MASS

M_BEAM = 1.57  # kg, the built-in rig's free length (sim.hosts.rig)
K_H = 1.25 * K_H_NOMINAL  # best estimate of Sect. 5.4, as in Fig. 11
R_CONT = (0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 1.0)
SPEEDS = (0.01, 0.1, 1.0)  # m/s


@pytest.fixture(scope="module")
def impacts() -> dict:
    return {(r, v): two_body_impact(r, v, SPHERE_MASS, M_BEAM, K_H) for r in R_CONT for v in SPEEDS}


def test_restitution_is_within_two_percent_of_r_cont(impacts):
    """The issue's acceptance: r within 2 % of r_cont,diss over [0.5, 1]; the measured offset is at most 1.1 %
    (at 0.5) and r lies below r_cont for r_cont < 1."""
    for (r_cont, _), out in impacts.items():
        assert abs(out["r"] / r_cont - 1) < 0.02
        assert out["r"] <= r_cont + 1e-9
    assert impacts[(0.5, 0.1)]["r"] / 0.5 - 1 == pytest.approx(-0.0108, abs=2e-4)
    assert impacts[(0.99, 0.1)]["r"] / 0.99 - 1 == pytest.approx(0.0, abs=1e-5)


def test_restitution_does_not_depend_on_the_approach_speed(impacts):
    for r_cont in R_CONT:
        rs = [impacts[(r_cont, v)]["r"] for v in SPEEDS]
        assert max(rs) - min(rs) < 1e-9


def test_dissipated_energy_equals_the_loss_of_kinetic_energy(impacts):
    for out in impacts.values():
        loss = out["kinetic_before"] - out["kinetic_after"]
        assert abs(loss - out["dissipated"]) <= 1e-8 * out["kinetic_before"]


def test_the_normalised_restitution_matches_the_two_body_impact(impacts):
    """sim.model.contact_law.restitution (one normalised equation) against the bodies' own coordinates."""
    for (r_cont, v), out in impacts.items():
        assert restitution(float(xi_of_r_cont(r_cont))) == pytest.approx(out["r"], abs=1e-9)


def test_xi_formula_is_the_first_order_energy_loss_of_the_elastic_approach():
    """1 - r = 2 xi int_0^x_m x^(1/4) sqrt(1 - (4/5) x^(5/2)) dx + O(xi^2) (the damper's work on the elastic
    approach path, normalised). The paper's xi(r) has exactly this slope, pi / sqrt(5)."""
    x_m = 1.25**0.4
    slope = 2 * quad(lambda x: x**0.25 * math.sqrt(max(1 - 0.8 * x**2.5, 0.0)), 0, x_m, limit=200)[0]
    assert slope == pytest.approx(math.pi / math.sqrt(5), rel=1e-10)
    r = 1 - 1e-4
    assert (1 - r) / float(xi_of_r_cont(r)) == pytest.approx(slope, rel=1e-4)
    xi = 1e-4
    assert (1 - restitution(xi)) / xi == pytest.approx(slope, rel=2e-4)


def test_xi_is_as_printed():
    r = np.array([0.5, 0.8, 0.99, 1.0])
    expected = 9 * math.sqrt(5) / 2 * (1 - r**2) / (r * (r * (9 * math.pi - 16) + 16))
    assert np.array_equal(xi_of_r_cont(r), expected)
    assert xi_of_r_cont(1.0) == 0.0


def test_force_is_eq_10():
    m_red = M_BEAM * SPHERE_MASS / (M_BEAM + SPHERE_MASS)
    xi = float(xi_of_r_cont(0.8))
    delta = np.array([-1e-6, 0.0, 1e-5, 1e-5, 2e-5])
    rate = np.array([0.3, 0.3, 0.3, -0.3, 0.0])
    d_H = 2 * xi * np.sqrt(K_H * np.sqrt(2e-5 / 2) * m_red)
    expected = [0.0, 0.0, K_H * 1e-5**1.5 + d_H * 0.3, K_H * 1e-5**1.5, K_H * 2e-5**1.5]
    np.testing.assert_allclose(damped_hertz_force(delta, rate, K_H, xi, m_red), expected, rtol=1e-14)


def test_r_cont_one_is_exactly_the_elastic_law():
    rng = np.random.default_rng(1)
    delta = rng.normal(0, 2e-5, 1000)
    rate = rng.normal(0, 1, 1000)
    elastic = ContactLaw("hertz").force(delta, rate, K_H, 0.0175)
    damped_one = ContactLaw("hertz-damped", 1.0).force(delta, rate, K_H, 0.0175)
    assert np.array_equal(elastic, damped_one)
    assert np.array_equal(elastic, np.where(delta > 0, K_H * np.clip(delta, 0, None) ** 1.5, 0.0))
    assert not ContactLaw("hertz-damped", 1.0).dissipative
    assert ContactLaw("hertz-damped", 0.99).dissipative


@pytest.mark.parametrize("name, r_cont, words", [
    ("hertz-damped", 0.0, "(0, 1]"), ("hertz-damped", 1.2, "(0, 1]"), ("hertz-damped", -0.5, "(0, 1]"),
    ("hertz-damped", math.nan, "(0, 1]"), ("hertz-damped", "0.9", "(0, 1]"), ("hertz", 0.9, "hertz-damped"),
    ("kelvin", 1.0, "unknown contact law"),
])
def test_bad_contact_law_is_one_line(name, r_cont, words):
    with pytest.raises(SimulationInputError) as err:
        ContactLaw(name, r_cont)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_damped_law_needs_the_beam_mass():
    with pytest.raises(SimulationInputError, match="beam_mass_kg") as err:
        ContactLaw("hertz-damped", 0.9).reduced_mass(None, SPHERE_MASS, "model.toml")
    assert "\n" not in str(err.value)
    assert ContactLaw("hertz-damped", 0.9).reduced_mass(1.57, 0.0177) == pytest.approx(1.57 * 0.0177 / 1.5877)
    assert math.isnan(ContactLaw("hertz").reduced_mass(None, SPHERE_MASS))
