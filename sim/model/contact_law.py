"""The normal contact laws of the sphere at a cavity wall (seed paper Eq. 4 and Eq. 10, Sect. 5.5).

* "hertz" (Eq. 4): f = k_H delta^1.5 for delta > 0, conservative.
* "hertz-damped" (Eq. 10): f = k_H delta^1.5 + d_H delta' in approach (delta' > 0, delta > 0) and
  f = k_H delta^1.5 in restitution (delta' < 0), with
  d_H = 2 xi sqrt(k_H sqrt(delta) m_beam m_a / (m_beam + m_a)) and
  xi = (9 sqrt(5) / 2) (1 - r^2) / (r (r (9 pi - 16) + 16)),  r = r_cont,diss in (0, 1].
  r_cont,diss = 1 gives xi = 0: exactly the conservative law.

d_H is the critical damping 2 sqrt(k m) of the Hertz spring linearised at delta (k = k_H sqrt(delta)) on the
reduced mass of sphere and beam, scaled by xi. With delta measured in units of the largest indentation of an
elastic impact and time in units of that indentation over the approach speed, the impact equation becomes
x'' = -x^1.5 - 2 xi x^0.25 x' (x' > 0): the coefficient of restitution depends on xi alone, not on the approach
speed, the masses or k_H. Its exact value `restitution(xi)` follows from the energy lost in approach (the
restitution is conservative): r^2 = (4/5) x_max^2.5, x_max the largest indentation of that equation. The
paper's xi(r) is this relation to first order in xi (1 - r = (pi / sqrt 5) xi + O(xi^2), the energy lost on the
elastic approach path); beyond it the true r lies below r_cont,diss, by 1.1 % at r_cont,diss = 0.5 (table in
tests/README.md, checks in tests/sim/test_contact_law.py).

Both walls use the same law; the sign conventions of sim/model/system.py apply (delta_l, delta_r of Eqs. 5, 6 with
delta_r < 0 in contact: the right wall's indentation is -delta_r).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from sim.common.errors import SimulationInputError
from sim.model.parameters import DEFAULT_R_CONT  # noqa: F401 (the paper's value, re-exported)

CONTACT_LAWS = ("hertz", "hertz-damped")


def xi_of_r_cont(r_cont: ArrayLike) -> np.ndarray:
    """Damping factor xi(r_cont,diss) of Eq. 10 (-), exactly as printed:
    xi = (9 sqrt(5) / 2) (1 - r^2) / (r (r (9 pi - 16) + 16)); xi(1) = 0."""
    r = np.asarray(r_cont, dtype=float)
    return 4.5 * math.sqrt(5.0) * (1.0 - r * r) / (r * (r * (9.0 * math.pi - 16.0) + 16.0))


def reduced_mass(m_beam: float, m_a: float) -> float:
    """m_beam m_a / (m_beam + m_a) in kg, the mass under the square root of d_H (Eq. 10)."""
    return m_beam * m_a / (m_beam + m_a)


def damping_coefficient(delta: ArrayLike, k_H: float, xi: float, m_red: float) -> np.ndarray:
    """d_H of Eq. 10 in N s/m: 2 xi sqrt(k_H sqrt(|delta|) m_red); delta (m), k_H (N/m^1.5), m_red (kg)."""
    return 2.0 * xi * np.sqrt(k_H * np.sqrt(np.abs(np.asarray(delta, dtype=float))) * m_red)


def damped_hertz_force(delta: ArrayLike, delta_dot: ArrayLike, k_H: float, xi: float, m_red: float) -> np.ndarray:
    """Eq. 10 for one wall, vectorised: the compressive force (N) for indentation delta (m, > 0 in contact)
    and its rate delta_dot (m/s, > 0 in approach); k_H (N/m^1.5), xi (-), m_red = reduced_mass(...) (kg).

    f = k_H delta^1.5 + d_H delta_dot if delta > 0 and delta_dot > 0; k_H delta^1.5 if delta > 0 and
    delta_dot <= 0; 0 otherwise. With xi = 0 the result equals Eq. 4 bit for bit.
    """
    d = np.asarray(delta, dtype=float)
    v = np.asarray(delta_dot, dtype=float)
    closed = d > 0
    depth = np.where(closed, d, 0.0)
    elastic = k_H * depth**1.5
    if xi == 0.0:
        return elastic
    approach = closed & (v > 0)
    return elastic + np.where(approach, damping_coefficient(depth, k_H, xi, m_red) * np.where(approach, v, 0.0), 0.0)


@dataclass(frozen=True)
class ContactLaw:
    """Which normal contact law acts at both walls (Eq. 4 or Eq. 10) and its restitution parameter.

    name: "hertz" (Eq. 4) or "hertz-damped" (Eq. 10); r_cont: r_cont,diss in (0, 1] (only "hertz-damped"
    takes a value other than 1; 1 is the conservative law).
    """

    name: str = "hertz"
    r_cont: float = 1.0

    def __post_init__(self) -> None:
        if self.name not in CONTACT_LAWS:
            raise SimulationInputError(f"unknown contact law {self.name!r}; choose one of {', '.join(CONTACT_LAWS)}")
        r = self.r_cont
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not math.isfinite(r) or not 0.0 < r <= 1.0:
            raise SimulationInputError(f"r_cont must lie in (0, 1] (1 = elastic, e.g. 0.99), got {r!r}")
        if self.name == "hertz" and r != 1.0:
            raise SimulationInputError(f"r_cont = {r!r} needs the contact law 'hertz-damped'; 'hertz' is elastic (r_cont = 1)")
        object.__setattr__(self, "r_cont", float(r))

    @property
    def xi(self) -> float:
        """xi(r_cont) of Eq. 10 (-); 0.0 for the conservative law."""
        return float(xi_of_r_cont(self.r_cont)) if self.dissipative else 0.0

    @property
    def dissipative(self) -> bool:
        """True if the law dissipates energy (hertz-damped with r_cont < 1)."""
        return self.name == "hertz-damped" and self.r_cont < 1.0

    def reduced_mass(self, beam_mass: float | None, m_a: float, source: str = "the modal model") -> float:
        """The reduced mass of d_H (kg) from the beam's mass (kg, free length without block; None if unknown)
        and the sphere's m_a (kg). The damped law refuses a model without beam mass with one line."""
        if self.name == "hertz-damped" and beam_mass is None:
            raise SimulationInputError(f"the contact law 'hertz-damped' needs the beam mass (Eq. 10): {source} has no "
                                       "'beam_mass_kg'; add it to the modal file (kg, free length without block) or "
                                       "save the built-in rig with `ies modes --save`")
        return reduced_mass(beam_mass, m_a) if beam_mass is not None else math.nan

    def force(self, delta: ArrayLike, delta_dot: ArrayLike, k_H: float, m_red: float) -> np.ndarray:
        """The compressive wall force (N) of this law, vectorised (see damped_hertz_force)."""
        return damped_hertz_force(delta, delta_dot, k_H, self.xi, m_red)


def restitution(xi: float, rtol: float = 1e-12) -> float:
    """Exact coefficient of restitution (-) of one impact under Eq. 10 with damping factor xi (>= 0), from the
    normalised approach x'' = -x^1.5 - 2 xi x^0.25 x', x(0) = 0, x'(0) = 1 (scipy DOP853 to the turning point
    x' = 0) and the conservative restitution: r = sqrt((4/5) x_max^2.5). Velocity-, mass- and k_H-independent."""
    from scipy.integrate import solve_ivp

    if not (math.isfinite(xi) and xi >= 0):
        raise SimulationInputError(f"xi must be a finite number >= 0, got {xi!r}")
    if xi == 0.0:
        return 1.0

    def rhs(_t, y):
        x = max(y[0], 0.0)
        return [y[1], -x**1.5 - 2.0 * xi * x**0.25 * y[1]]

    def turning(_t, y):
        return y[1]

    turning.terminal, turning.direction = True, -1.0
    sol = solve_ivp(rhs, (0.0, 20.0), [0.0, 1.0], method="DOP853", rtol=rtol, atol=1e-16, events=turning)
    x_max = float(sol.y_events[0][0][0])
    return math.sqrt(0.8 * x_max**2.5)
