"""One point of parameter space for the periodic orbits (seed paper Eqs. 3-7, 10; Sects. 5, 5.3): the host's modal
model, the sphere and its contact law, the excitation (level a_base/a_base*, eta = Omega/omega_1) and the
integrator, and the parameters a continuation may move.

Continuation parameters (`PARAMETERS`): each moves one number of the setting and is continued in a coordinate in
which equal steps mean comparable changes (`Parameter.to_coordinate`):

* ``eta``: Omega/omega_1 (-), linear;
* ``level``: a_base/a_base* (-, Sect. 5.3), linear;
* ``higher_damping``: a factor on the modal damping ratios of modes 2..N (-, 1 = the model's), in log; the
  homotopy that carries an orbit from a host whose higher modes ring out between impacts (a smooth, mildly
  unstable impact map that Newton's method reaches from the slow flow) to the nominal host (`sim.orbits.starts`);
* ``r_cont``: r_cont,diss of the damped law (Eq. 10, -), linear; needs the law "hertz-damped";
* ``k_H``: the Hertz constant (N/m^1.5, Eq. 4), in log.

The normalisations are the paper's (Sect. 5): a_base = level a_base*, a_noabs* at the nominal D*, g*
(`sim.model.system.a_base_star`, `a_noabs_star`), exactly as the stepped sine measures them, so that orbits and
sweeps overlay.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from sim.common.errors import SimulationInputError
from sim.model.contact_law import ContactLaw
from sim.model.system import Impactor, ModalModel, Nominal, SystemArrays, a_base_star, a_noabs_star, system_arrays
from sim.stepped_sine.dynamics import state_scales


@dataclass(frozen=True)
class OrbitSetting:
    """The system and excitation of one orbit (SI; Eqs. 3-7).

    model: the host's modal model (Eq. 7); impactor: the sphere, clearance, k_H and contact law (Eqs. 3-6, 10);
    level: a_base/a_base* (-); eta: Omega/omega_1 (-); higher_damping: factor on the damping ratios of modes 2..N
    (-, 1 keeps the model's); integrator: "exact" (default) or "ode3" (`sim.integration.integrators`); dt_scale: ode3's
    step as a multiple of the paper's (-); nominal: D*, g* of the normalisations (Sect. 5).
    """

    model: ModalModel
    impactor: Impactor
    level: float
    eta: float
    higher_damping: float = 1.0
    integrator: str = "exact"
    dt_scale: float = 1.0
    nominal: Nominal | None = None

    def __post_init__(self) -> None:
        for name in ("level", "eta", "higher_damping", "dt_scale"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise SimulationInputError(f"orbits: {name} must be a positive number, got {value!r}")
        if self.nominal is None:  # the host's own normalisation (its nominal D_1*, the paper's g*)
            object.__setattr__(self, "nominal", Nominal.of(self.model))
        if self.impactor.friction > 0:
            raise SimulationInputError("orbits: dry friction (--friction, Appendix C) makes the slider part of the "
                                       "state; the orbits are of the frictionless model: drop --friction")

    @property
    def Omega(self) -> float:
        """Excitation frequency Omega = eta omega_1 (rad/s)."""
        return self.eta * float(self.model.omega[0])

    @property
    def period(self) -> float:
        """Excitation period T = 2 pi / Omega (s)."""
        return 2.0 * math.pi / self.Omega

    @property
    def a_base(self) -> float:
        """Base amplitude a_base = level a_base* (m, Sect. 5.3)."""
        return self.level * a_base_star(self.model, self.nominal)

    @property
    def a_noabs(self) -> float:
        """a_noabs* at this level (m, Sect. 5): the amplitude unit of a/a_noabs*."""
        return a_noabs_star(self.model, self.a_base, self.nominal)

    @property
    def host(self) -> ModalModel:
        """The modal model with the damping ratios of modes 2..N multiplied by `higher_damping` (capped below 1)."""
        if self.higher_damping == 1.0:
            return self.model
        d = self.model.damping_ratios.copy()
        d[1:] = np.minimum(d[1:] * self.higher_damping, 0.5)
        return replace(self.model, damping_ratios=d)

    def system(self) -> SystemArrays:
        """The kernels' `SystemArrays` of this setting (Eqs. 3-7, 10)."""
        return system_arrays(self.host, self.impactor)

    @property
    def symmetric_walls(self) -> bool:
        """True when the walls move alike in every mode (phi_l = phi_r, a beam model): then the system is
        invariant under the mirror (x -> -x, t -> t + T/2) and symmetric orbits exist (`sim.orbits.shooting`)."""
        left, right = self.model.phi_wall_left, self.model.phi_wall_right
        return bool(np.allclose(left, right, rtol=1e-12, atol=0.0))

    def scales(self) -> np.ndarray:
        """The unit of each state component in the shooting's scaled variables (`sim.orbits.shooting`): mode j's
        displacement g / max(|phi_l,j|, |phi_r,j|, |phi_tip,j|) (m sqrt(kg); a motion of g at the walls or tip), its
        velocity that times omega_j, the sphere's g (m) and g omega_1 (m/s) (`sim.stepped_sine.dynamics.state_scales`,
        which the Lyapunov exponents share). Fixed along a continuation."""
        return state_scales(self.model, self.impactor.clearance)


@dataclass(frozen=True)
class Parameter:
    """A continuation parameter: its name, unit, how to read and set it on an `OrbitSetting`, the coordinate it is
    continued in (`to_coordinate`, `from_coordinate`: identity or log) and the change of that coordinate that counts
    as much as a change of the state by g in the arclength (`scale`, `sim.orbits.continuation`)."""

    name: str
    unit: str
    get: Callable[[OrbitSetting], float]
    set: Callable[[OrbitSetting, float], OrbitSetting]
    log: bool = False
    scale: float = 1.0

    def to_coordinate(self, value: float) -> float:
        """The continuation coordinate of a value (log for a multiplicative parameter)."""
        return math.log(value) if self.log else float(value)

    def from_coordinate(self, coordinate: float) -> float:
        """The value of a continuation coordinate."""
        return math.exp(coordinate) if self.log else float(coordinate)


def _get_eta(setting: OrbitSetting) -> float:
    return setting.eta


def _set_eta(setting: OrbitSetting, value: float) -> OrbitSetting:
    return replace(setting, eta=float(value))


def _get_level(setting: OrbitSetting) -> float:
    return setting.level


def _set_level(setting: OrbitSetting, value: float) -> OrbitSetting:
    return replace(setting, level=float(value))


def _get_higher_damping(setting: OrbitSetting) -> float:
    return setting.higher_damping


def _set_higher_damping(setting: OrbitSetting, value: float) -> OrbitSetting:
    return replace(setting, higher_damping=float(value))


def _get_r_cont(setting: OrbitSetting) -> float:
    return setting.impactor.contact_law.r_cont


def _set_r_cont(setting: OrbitSetting, r: float) -> OrbitSetting:
    law = setting.impactor.contact_law
    if not law.name == "hertz-damped":
        raise SimulationInputError("orbits: continuation in r_cont needs the damped contact law (--contact-law "
                                   "hertz-damped)")
    r = min(float(r), 1.0)
    return replace(setting, impactor=replace(setting.impactor, contact_law=ContactLaw(law.name, r)))


def _get_k_H(setting: OrbitSetting) -> float:
    return setting.impactor.k_H


def _set_k_H(setting: OrbitSetting, value: float) -> OrbitSetting:
    return replace(setting, impactor=replace(setting.impactor, k_H=float(value)))


#: The continuation parameters by name (module docstring).
PARAMETERS: dict[str, Parameter] = {
    "eta": Parameter("eta", "-", _get_eta, _set_eta, scale=2e-3),
    "level": Parameter("level", "a_base/a_base*", _get_level, _set_level, scale=0.2),
    "higher_damping": Parameter("higher_damping", "-", _get_higher_damping, _set_higher_damping, log=True, scale=0.2),
    "r_cont": Parameter("r_cont", "-", _get_r_cont, _set_r_cont, scale=0.02),
    "k_H": Parameter("k_H", "N/m^1.5", _get_k_H, _set_k_H, log=True, scale=0.2),
}


def parameter(name: str) -> Parameter:
    """The continuation parameter of this name; one line naming the choices if there is none."""
    try:
        return PARAMETERS[name]
    except KeyError:
        raise SimulationInputError(f"orbits: unknown continuation parameter {name!r}; choose one of "
                                   f"{', '.join(PARAMETERS)}") from None
