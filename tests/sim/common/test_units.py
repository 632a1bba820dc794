"""sim.common.units: numbers with units for g and k_H, and the magnitudes that are probably a unit slip."""
import pytest

from sim.common.errors import SimulationInputError
from sim.model.system import CLEARANCE_NOMINAL, K_H_NOMINAL
from sim.common.units import CLEARANCE, DAMPING, K_H, implausible, parse_quantity


@pytest.mark.parametrize("text, value", [
    ("0.58e-3", 0.58e-3), (0.58e-3, 0.58e-3), ("0.58mm", 0.58e-3), ("0.58 mm", 0.58e-3), ("580um", 0.58e-3),
    ("580 µm", 0.58e-3), ("5.8e-4 m", 0.58e-3), (".58mm", 0.58e-3)])
def test_clearance_with_and_without_unit(text, value):
    assert parse_quantity(text, CLEARANCE) == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("text", ["282e3N/mm^1.5", "282e3 N/mm^1.5", "282e3 N/mm**1.5", "282000 N/mm1.5",
                                  "8.917623001674832e9", "8.917623001674832e9 N/m^1.5"])
def test_k_H_with_and_without_unit(text):
    assert parse_quantity(text, K_H) == pytest.approx(K_H_NOMINAL, rel=1e-12)  # Eq. 8: 282e3 N/mm^1.5


@pytest.mark.parametrize("text, message", [("0.58in", "unknown unit 'in'"), ("mm", "cannot read"),
                                           ("1e9 N/cm^1.5", "unknown unit"), (True, "must be a number")])
def test_unreadable_values_name_the_accepted_units(text, message):
    with pytest.raises(SimulationInputError, match=message):
        parse_quantity(text, CLEARANCE if "N/" not in str(text) else K_H)


def test_plausible_values_pass_silently():
    for g in (CLEARANCE_NOMINAL, 0.612e-3, 1e-5, 1e-2):
        assert implausible(g, CLEARANCE) is None
    for k in (K_H_NOMINAL, 1.52 * K_H_NOMINAL, 1e6, 1e14):
        assert implausible(k, K_H) is None


def test_unit_slips_name_the_reading_probably_meant():
    assert implausible(0.58, CLEARANCE) == "0.58 m is implausible for a clearance g (above 10 mm); did you mean 0.58mm?"
    k = implausible(282e3, K_H, "282e3")
    assert "below 1e+06 N/m^1.5" in k and k.endswith("did you mean 282e3N/mm^1.5?")
    assert implausible(1e-7, CLEARANCE) == "1e-07 m is implausible for a clearance g (below 10 um)"  # no unit fits
    assert implausible(0.085, DAMPING) == "8.5 % is implausible for a damping ratio (above 5 %); did you mean 0.085%?"
    assert implausible(0.00085, DAMPING) is None and implausible(0.05, DAMPING) is None
    # a number typed with its unit is no slip of that unit: 8.5% stays 8.5 %, 0.6m may be 0.6mm
    assert implausible(0.085, DAMPING, "8.5%") == "8.5 % is implausible for a damping ratio (above 5 %)"
    assert implausible(0.6, CLEARANCE, "0.6m").endswith("did you mean 0.6mm?")


def test_a_damping_ratio_takes_percent():
    assert parse_quantity("0.085%", DAMPING) == pytest.approx(0.00085, rel=1e-15)
    assert parse_quantity("0.085 %", DAMPING) == parse_quantity(0.00085, DAMPING)
    with pytest.raises(SimulationInputError, match="unknown unit 'mm'"):
        parse_quantity("0.085mm", DAMPING)
