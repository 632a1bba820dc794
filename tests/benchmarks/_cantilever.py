"""A host that is not the rig, for the design benchmarks: a uniform steel cantilever (Euler-Bernoulli, closed-form
modes) of another length, section and mass than the seed rig, its cavity walls and measurement point near the free
end, saved as a modal-model file (`sim.hosts.modal_file`) as a user would bring one.

Closed form (clamped at z = 0, free at z = L; e.g. Blevins, Formulas for Natural Frequency and Mode Shape, Table 8-1):
beta_j L are the roots of 1 + cos(beta L) cosh(beta L) = 0, omega_j = (beta_j L)^2 sqrt(E I / (rho A L^4)), the
shapes phi_j(z) = [cosh(beta z) - cos(beta z) - sigma_j (sinh(beta z) - sin(beta z))] / sqrt(m) with
sigma_j = (cosh(beta L) + cos(beta L)) / (sinh(beta L) + sin(beta L)) are mass-normalised (int rho A phi^2 dz = 1,
m = rho A L), and the participation phi_j^T M b = int rho A phi_j dz = sqrt(m) 2 sigma_j / (beta_j L).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from sim.model.system import ModalModel

RHO_STEEL = 7850.0  # kg/m^3
E_STEEL = 210e9  # Pa


@dataclass(frozen=True)
class Cantilever:
    """A uniform cantilever: free length (m), section width_x (bending direction) x width_y (m), steel; the cavity walls'
    contact height and the measurement point as distances below the free end (m)."""

    length: float = 0.55
    width_x: float = 0.020
    width_y: float = 0.015
    contact_below_tip: float = 0.008
    measurement_below_tip: float = 0.020
    E: float = E_STEEL
    rho: float = RHO_STEEL

    @property
    def mass(self) -> float:
        """The beam's mass rho A L (kg)."""
        return self.rho * self.width_x * self.width_y * self.length

    @property
    def second_moment(self) -> float:
        """I for bending in x (m^4)."""
        return self.width_y * self.width_x**3 / 12.0


def beta_L(n_modes: int) -> np.ndarray:
    """The first n roots of 1 + cos(x) cosh(x) = 0 (-), the j-th in ((j - 1) pi, j pi), by Brent's method on
    cos(x) + 1/cosh(x) (the same roots, without the overflow of cosh)."""
    f = lambda x: math.cos(x) + 1.0 / math.cosh(x)  # noqa: E731
    return np.array([brentq(f, (j - 1) * math.pi, j * math.pi, xtol=1e-15) for j in range(1, n_modes + 1)])


def shape(bL: float, zeta: np.ndarray) -> np.ndarray:
    """The unnormalised shape cosh - cos - sigma (sinh - sin) at zeta = z / L (int_0^1 shape^2 dzeta = 1), written with
    e^{beta z} and 1 - sigma so that high modes do not lose their digits to cancellation."""
    x = bL * np.asarray(zeta, dtype=float)
    one_minus_sigma = (math.sin(bL) - math.cos(bL) - math.exp(-bL)) / (math.sinh(bL) + math.sin(bL))
    sigma = 1.0 - one_minus_sigma
    hyperbolic = 0.5 * (one_minus_sigma * np.exp(x) + (1.0 + sigma) * np.exp(-x))  # cosh x - sigma sinh x
    return hyperbolic - np.cos(x) + sigma * np.sin(x)


def cantilever_model(beam: Cantilever = Cantilever(), n_modes: int = 9,
                     damping: tuple[float, ...] = (0.00085, 0.004, 0.002, 0.003, 0.001, 0.001, 0.001, 0.001, 0.001)
                     ) -> ModalModel:
    """The cantilever's modal model (Eq. 7): closed-form frequencies, mass-normalised values at the walls and the
    measurement point, participations; D_1 nominal as Table 2, the higher modes' damping as the rig's order."""
    roots = beta_L(n_modes)
    m, L = beam.mass, beam.length
    omega = roots**2 * math.sqrt(beam.E * beam.second_moment / (beam.rho * beam.width_x * beam.width_y * L**4))
    wall = np.array([shape(b, 1.0 - beam.contact_below_tip / L) for b in roots]) / math.sqrt(m)
    tip = np.array([shape(b, 1.0 - beam.measurement_below_tip / L) for b in roots]) / math.sqrt(m)
    sigma = np.array([(math.cosh(b) + math.cos(b)) / (math.sinh(b) + math.sin(b)) for b in roots])
    participation = math.sqrt(m) * 2.0 * sigma / roots
    sign = np.sign(wall)  # each mode positive at the walls (sim/model/system.py's convention)
    return ModalModel(frequencies_hz=omega / (2.0 * math.pi), damping_ratios=np.array(damping[:n_modes]),
                      phi_wall_left=wall * sign, phi_wall_right=wall * sign, phi_tip=tip * sign,
                      participation=participation * sign, beam_mass=m,
                      source=f"uniform steel cantilever {L * 1e3:g} mm, {beam.width_x * 1e3:g} x {beam.width_y * 1e3:g} mm "
                             "(Euler-Bernoulli, closed form)")


def save_cantilever(path, beam: Cantilever = Cantilever()):
    """The cantilever as a modal-model file (`ies modes --save` format) at `path`; returns the path."""
    from sim.hosts.modal_file import save_modal_model

    return save_modal_model(cantilever_model(beam), path, provenance={"model": "uniform Euler-Bernoulli cantilever, "
                                                                               "closed-form modes (tests/benchmarks)"})
