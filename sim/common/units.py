"""Quantities typed by people: a plain SI number or a number with its unit, and a check of its magnitude.

The uncertain contact parameters of the seed paper (Table 2) are easy to type in the wrong unit: the
clearance g* = 0.58 mm and the Hertzian spring constant k_H* = 282e3 N/mm^1.5 (Eq. 8) are quoted in mm, while
the code works in SI units (m, N/m^1.5). `parse_quantity` reads ``0.58e-3``, ``"0.58mm"``, ``"580 um"``,
``"282e3 N/mm^1.5"`` or a damping ratio ``"0.085%"`` and returns SI; `implausible` names a magnitude outside the
physically plausible range and the reading that would make it plausible (``--g 0.58`` is 0.58 m, probably 0.58 mm;
``--D 0.085`` is 8.5 %, probably 0.085 %). Such a value is refused, not computed with (`sim.model.parameters`,
`--allow-implausible`): a unit slip computes a different experiment without a word. The rows of
`sim.model.parameters.PARAMETERS` name their quantity here: the command line, the study files (`uq.problem.space`) and
`ies design` (`uq.design.problem`) read D, g, k_H, k_t and R through this module.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal

from sim.common.errors import SimulationInputError


@dataclass(frozen=True)
class Quantity:
    """A kind of quantity: its SI unit, the units accepted (factor to SI) and the plausible SI range."""

    name: str
    si_unit: str
    units: dict[str, float]
    plausible: tuple[float, float]
    example: str

    def format(self, value: float) -> str:
        """`value` (SI) in the accepted unit that gives the shortest number, e.g. 0.58 mm (a ratio: in %)."""
        return min((f"{value / factor:.4g} {unit}" for unit, factor in self.units.items()), key=len)


#: the units of a length
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6}
#: a length such as the clearance g (Table 2: 0.58-0.612 mm); plausible 0.01-10 mm, on the command line, in study
#: files and in `ies design`'s ranges alike
CLEARANCE = Quantity("clearance g", "m", LENGTH_UNITS, (1e-5, 1e-2), "0.58mm")
#: the sphere's radius R (Sect. 2: 7.92 mm); plausible 0.5-100 mm
RADIUS = Quantity("sphere radius R", "m", LENGTH_UNITS, (0.5e-3, 0.1), "7.92mm")
#: the sphere's mass m_a (Table 1: 17.7 g); plausible 0.1 g - 10 kg
MASS = Quantity("sphere mass m_a", "kg", {"kg": 1.0, "g": 1e-3}, (1e-4, 10.0), "17.7g")
#: the Hertzian spring constant k_H (Eq. 8: 282e3 N/mm^1.5 = 8.918e9 N/m^1.5); plausible 1e6-1e14 N/m^1.5
K_H = Quantity("Hertzian spring constant k_H", "N/m^1.5", {"N/m^1.5": 1.0, "N/mm^1.5": 1e3**1.5}, (1e6, 1e14), "282e3N/mm^1.5")
#: the tangential stiffness k_t of the floor contact (Appendix C: 22 kN/mm = 2.2e7 N/m); plausible 1e4-1e10 N/m
K_T = Quantity("tangential stiffness k_t", "N/m", {"N/m": 1.0, "N/mm": 1e3, "kN/mm": 1e6}, (1e4, 1e10), "22kN/mm")
#: a modal damping ratio (Table 2: D_1 = 0.085 %), a plain ratio or in %; plausible 0.001-5 %: a lightly damped
#: structure's resonant mode, whose vibration an IES is built to mitigate (above 5 % there is little to mitigate,
#: and 0.085 typed for 0.085 % is the slip this catches)
DAMPING = Quantity("damping ratio", "", {"%": 1e-2}, (1e-5, 0.05), "0.085%")

_NUMBER = re.compile(r"^\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(.*?)\s*$")


def _unit_key(unit: str) -> str:
    """Spelling variants of a unit made one: N/m**1.5 and N/m1.5 as N/m^1.5, the Greek mu as the micro sign."""
    return unit.replace("**", "^").replace("m1.5", "m^1.5").replace("μ", "µ")


def parse_quantity(text: str | float, quantity: Quantity) -> float:
    """The SI value of `text`: a plain number (taken as SI) or a number followed by one of the quantity's units
    (``"0.58mm"``, ``"282e3 N/mm^1.5"``). Raises SimulationInputError naming the accepted units."""
    if isinstance(text, bool):
        raise SimulationInputError(f"{quantity.name} must be a number, got {text!r}")
    if isinstance(text, (int, float)):
        return float(text)
    match = _NUMBER.match(str(text))
    units = ", ".join(u for u in quantity.units if u != "µm")
    if not match:
        raise SimulationInputError(f"{quantity.name}: cannot read {text!r}; give a number in {quantity.si_unit} "
                                   f"or a number with a unit ({units}), e.g. {quantity.example}")
    number, unit = float(match.group(1)), _unit_key(match.group(2))
    if not unit:
        return number
    factors = {_unit_key(u): f for u, f in quantity.units.items()}
    if unit not in factors:
        raise SimulationInputError(f"{quantity.name}: unknown unit {match.group(2)!r} in {text!r}; use one of {units}")
    # in decimal, then rounded once: "0.085%" is the same float as 0.00085, "0.58mm" as 0.58e-3
    return float(Decimal(match.group(1)) * Decimal(repr(factors[unit])))


def implausible(value: float, quantity: Quantity, typed: str | None = None) -> str | None:
    """None when `value` (SI) lies in the quantity's plausible range; otherwise one sentence saying so and, when the
    number as typed read in another accepted unit lies in range (0.58 as mm, 0.085 as %), the reading probably meant,
    e.g. "0.58 m is implausible for a clearance g (above 10 mm); did you mean 0.58mm?". typed: the text the value was
    read from ("300e3", "0.6m", "8.5%"; None: a bare number, the SI value): its number is kept, its own unit is no
    other reading (8.5% is no slip for 0.085%)."""
    lo, hi = quantity.plausible
    if not math.isfinite(value) or value <= 0 or lo <= value <= hi:
        return None
    side = f"above {quantity.format(hi)}" if value > hi else f"below {quantity.format(lo)}"
    shown = quantity.format(value) if not quantity.si_unit else f"{value:.4g} {quantity.si_unit}"
    message = f"{shown} is implausible for a {quantity.name} ({side})"
    match = _NUMBER.match(typed) if typed is not None else None
    number, text, own = (float(match.group(1)), match.group(1), _unit_key(match.group(2))) if match else \
        (value, f"{value:g}", "")
    readings = {unit: factor for unit, factor in quantity.units.items() if _unit_key(unit) != own}
    if own:  # a number typed with a unit: read bare (SI) too
        readings[""] = 1.0
    centre = math.sqrt(lo * hi)
    meant = [(unit, number * factor) for unit, factor in readings.items() if lo <= number * factor <= hi]
    if meant:
        unit, _ = min(meant, key=lambda m: abs(math.log(m[1] / centre)))
        message += f"; did you mean {text}{unit}?"
    return message
