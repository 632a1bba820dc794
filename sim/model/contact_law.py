"""The normal contact laws of the sphere at a cavity wall (seed paper Eq. 4 and Eq. 10, Sect. 5.5), each defined
once in a registry (`LAWS`) and compiled per law into every integrator.

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
elastic approach path); beyond it the true r lies below r_cont,diss, by 1.1 % at r_cont,diss = 0.5 (checks in
tests/sim/model/test_contact_law.py).

Both walls use the same law; the sign conventions of sim/model/system.py apply (delta_l, delta_r of Eqs. 5, 6 with
delta_r < 0 in contact: the right wall's indentation is -delta_r).

Adding a law (the one place to edit): write its force, stiffness, potential, dissipation (if any) and single-impact
reference below and `register` a `Law`; every integrator compiles it on first use. A law with a constant of its own
(a linear spring's stiffness in N/m instead of k_H) declares it as a parameter row (`Law.constant`, a
`sim.model.parameters.UncertainParameter`): `register` adds the row to `PARAMETERS`, which gives it its option, study
key, JSON key and checks, and the kernels receive its value as the law's k. A law that does not grow like Hertz's
delta^1.5 at the onset declares its exponent (`Law.exponent`): the exact integrator's contact step predictors
(`sim.integration.dopri5.contact`, `sim.integration.exact._initial_contact_step`) are built on it. How a law reaches the kernels:
a `Law` is typed by numba as `LawType` (its name and a hash of its kernels' sources), so every kernel that is handed
one (in `SystemArrays.law`, `sim.integration.flight.Constants.law`) is compiled, and cached on disk, once per law,
and `wall_force`, `wall_stiffness`, `wall_dissipation` and `uses_rate` resolve to that law's kernels at compile
time, inlined into the caller (its fastmath flags apply): a law that is not used is not in the machine code, and
the elastic law computes no approach rate. The on-disk cache of the integrators follows edits of this file
(`sim.integration.jit.FINGERPRINT_FILES`) and, through the hash, of a law registered elsewhere (a test).
"""
from __future__ import annotations

import hashlib
import inspect
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numba
import numpy as np
from numba import types
from numba.core.errors import NumbaIRAssumptionWarning
from numba.core.extending import NativeValue, models, overload, register_model, typeof_impl, unbox
from numpy.typing import ArrayLike

from sim.common.errors import SimulationInputError
from sim.model.parameters import (DEFAULT_R_CONT, PARAMETERS,  # noqa: F401 (the paper's value, re-exported)
                                  UncertainParameter, register_parameter)


class ImpactReference(NamedTuple):
    """What a law predicts for one impact of a mass m (kg) closing at v0 (m/s) on a rigid, immovable wall: the
    coefficient of restitution (-) and the contact duration (s; NaN where no closed form is known)."""

    restitution: float
    duration: float


@dataclass(frozen=True, eq=False)
class Law:
    """One normal contact law at both walls, as the integrators and the tests use it.

    Every kernel takes the indentation delta (m, > 0 in contact), and the force kernels its rate delta' (m/s,
    > 0 in approach), the law's stiffness constant k (`SystemArrays.k_H`: N/m^1.5 for Hertz, N/m for a linear
    spring) and its damping constant c (`SystemArrays.c_damp`, 0 for a conservative law). They are
    ``numba.njit(inline="always")`` functions: compiled only inlined into the integrators' kernels.

    name: the law's name (CLI --contact-law, study files); summary: one line for the help.
    force(delta, rate, k, c): the compressive wall force (N); 0 for delta <= 0.
    stiffness(delta, k): d force / d delta of the conservative part (N/m), for the collocation Newton
        iteration and ode3's stability check.
    potential(delta, k): the energy stored in the contact (J), vectorised numpy (the energy ledger's stored
        energy, `sim.integration.energy`); 0 for delta <= 0.
    dissipation(delta, rate, k, c): the power the contact dissipates (W, the energy ledger's contact column),
        None for a conservative law (then the kernels never compute the approach rate).
    reference(m, v0, k, c): the `ImpactReference` the tests check the integrators against.
    takes_r_cont: c comes from r_cont,diss through Eq. 10 (`ContactLaw`); elastic: the registered law this one
        equals when c = 0 (compiled instead then, bit for bit); collocation: the exact integrator may take its
        contacts by `sim.integration.collocation` (which assumes Hertz's force and impact times), else all by
        Dormand-Prince.
    constant: the row (`sim.model.parameters.UncertainParameter`) of the law's own stiffness constant k, registered
        with the law; None: k is k_H (N/m^1.5).
    exponent: p of the force's growth k delta^p from an onset (1.5 for Hertz, 1 for a linear spring): the Dormand-Prince
        contact's step predictors assume an onset step's error ~ v^p s^(p+1) and an impact's largest indentation
        ((p + 1) m v^2 / (2 k))^(1 / (p + 1)); duration_factor: t_c v0 / delta_max of one impact on a rigid wall
        (None: 2 sqrt(pi) Gamma(1 + 1/(p+1)) / Gamma(1/2 + 1/(p+1)), the closed form for k delta^p; Hertz states the
        rounded 2.9432 of Johnson, Sect. 11.4).
    """

    name: str
    summary: str
    force: Callable
    stiffness: Callable
    potential: Callable
    reference: Callable
    dissipation: Callable | None = None
    takes_r_cont: bool = False
    elastic: str | None = None
    collocation: bool = False
    constant: UncertainParameter | None = None
    exponent: float = 1.5
    duration_factor: float | None = None
    key: str = field(default="", init=False)

    def __post_init__(self) -> None:
        if self.duration_factor is None:
            q = 1.0 / (self.exponent + 1.0)
            object.__setattr__(self, "duration_factor", 2.0 * math.sqrt(math.pi) * math.gamma(1.0 + q) / math.gamma(0.5 + q))
        digest = hashlib.sha256(f"{self.name} {self.exponent!r} {self.duration_factor!r}".encode())
        for kernel in (self.force, self.stiffness, self.dissipation):
            if kernel is not None:
                function = getattr(kernel, "py_func", kernel)
                try:
                    digest.update(inspect.getsource(function).encode())
                except (OSError, TypeError):  # no source file: the bytecode and its constants
                    digest.update(function.__code__.co_code + repr(function.__code__.co_consts).encode())
        object.__setattr__(self, "key", digest.hexdigest()[:16])


class LawType(types.Type):
    """numba's type of a `Law`: equal for the same name and kernel sources, so a kernel handed a law is compiled
    and cached once per law (the value itself carries no data)."""

    def __init__(self, name: str, key: str) -> None:
        self.law_name = name
        super().__init__(name=f"ContactLaw({name}, {key})")


register_model(LawType)(models.OpaqueModel)


@typeof_impl.register(Law)
def _typeof_law(value: Law, _context) -> LawType:
    return LawType(value.name, value.key)


@unbox(LawType)
def _unbox_law(_typ, _obj, c):
    return NativeValue(c.context.get_dummy_value())


#: The registered laws by name (`register`).
LAWS: dict[str, Law] = {}


def register(law: Law) -> Law:
    """Add (or replace) a law in `LAWS`, and its own constant's row in `sim.model.parameters.PARAMETERS`; returns it."""
    if law.constant is not None:
        register_parameter(law.constant)
    LAWS[law.name] = law
    return law


def law_named(name: str) -> Law:
    """The registered law of this name; one line naming the choices if there is none."""
    try:
        return LAWS[name]
    except KeyError:
        raise SimulationInputError(f"unknown contact law {name!r}; choose one of {', '.join(LAWS)}") from None


# the kernels' view of a law: resolved per law at compile time (stand-ins for Python, never called there)
def wall_force(law: Law, delta: float, rate: float, k: float, c: float) -> float:
    """The law's compressive wall force (N) at indentation delta (m) and rate (m/s); in kernels only."""
    return law.force(delta, rate, k, c)


def wall_stiffness(law: Law, delta: float, k: float) -> float:
    """d force / d delta of the law's conservative part (N/m); in kernels only."""
    return law.stiffness(delta, k)


def wall_dissipation(law: Law, delta: float, rate: float, k: float, c: float) -> float:
    """The power (W) the law dissipates at one wall; 0 for a conservative law; in kernels only."""
    return 0.0 if law.dissipation is None else law.dissipation(delta, rate, k, c)


def uses_rate(law: Law) -> bool:
    """True if the law's force depends on the approach rate (a compile-time constant in kernels)."""
    return law.dissipation is not None


def onset_exponent(law: Law) -> float:
    """p of the law's growth k delta^p from an onset (`Law.exponent`; a compile-time constant in kernels)."""
    return law.exponent


def duration_factor(law: Law) -> float:
    """t_c v0 / delta_max of one impact on a rigid wall (`Law.duration_factor`; a compile-time constant in kernels)."""
    return law.duration_factor


def _law_of(typ) -> Law:
    return LAWS[typ.law_name]


def _calling(kernel: Callable | None, arguments: str, passed: str, default: str = "0.0") -> Callable:
    """The implementation of an overload below: a function of `arguments` that returns kernel(`passed`) (or
    `default` without a kernel). The kernel is a global of the function, not a closure variable: numba inlines
    it into the caller's IR without a free variable (which its inliner warns about)."""
    namespace = {"kernel": kernel}
    body = f"kernel({passed})" if kernel is not None else default
    exec(f"def implementation({arguments}):\n    return {body}\n", namespace)  # noqa: S102 (text of this module)
    return namespace["implementation"]


# numba's inliner checks its own IR pedantically and warns that the variables of a law's conditional expression are
# "not in scope" after the law is inlined into a loop; the compiled code is right (tests/sim/model/test_contact_law_seam.py
# against scipy), the warning is noise for the user of a first compilation
warnings.filterwarnings("ignore", message=r"variable '.*' is not in scope", category=NumbaIRAssumptionWarning)


@overload(wall_force, inline="always")
def _wall_force(law, delta, rate, k, c):
    if isinstance(law, LawType):
        return _calling(_law_of(law).force, "law, delta, rate, k, c", "delta, rate, k, c")


@overload(wall_stiffness, inline="always")
def _wall_stiffness(law, delta, k):
    if isinstance(law, LawType):
        return _calling(_law_of(law).stiffness, "law, delta, k", "delta, k")


@overload(wall_dissipation, inline="always")
def _wall_dissipation(law, delta, rate, k, c):
    if isinstance(law, LawType):
        return _calling(_law_of(law).dissipation, "law, delta, rate, k, c", "delta, rate, k, c")


@overload(uses_rate, inline="always")
def _uses_rate(law):
    if isinstance(law, LawType):
        return _calling(None, "law", "", "True" if _law_of(law).dissipation is not None else "False")


@overload(onset_exponent, inline="always")
def _onset_exponent(law):
    if isinstance(law, LawType):
        return _calling(None, "law", "", repr(float(_law_of(law).exponent)))


@overload(duration_factor, inline="always")
def _duration_factor(law):
    if isinstance(law, LawType):
        return _calling(None, "law", "", repr(float(_law_of(law).duration_factor)))


# ----------------------------------------------------------------------------------------------------------
# Eq. 4 and Eq. 10
# ----------------------------------------------------------------------------------------------------------
@numba.njit(inline="always")
def hertz_force(delta: float, rate: float, k: float, c: float) -> float:
    """Eq. 4: k_H delta^1.5 (N) for delta > 0 (m), k = k_H (N/m^1.5)."""
    return k * delta * math.sqrt(delta) if delta > 0.0 else 0.0


@numba.njit(inline="always")
def hertz_stiffness(delta: float, k: float) -> float:
    """d/d delta of Eq. 4: 1.5 k_H delta^0.5 (N/m) for delta > 0."""
    return 1.5 * k * math.sqrt(delta) if delta > 0.0 else 0.0


def hertz_potential(delta: ArrayLike, k: float) -> np.ndarray:
    """The Hertz potential (2/5) k_H delta^2.5 (J) of Eq. 4, vectorised."""
    return 0.4 * k * np.clip(np.asarray(delta, dtype=float), 0.0, None) ** 2.5


#: t_c v0 / delta_max of an elastic Hertz impact (Johnson, Contact Mechanics, Sect. 11.4; 2.9432)
HERTZ_CONTACT_TIME = 2.9432


def hertz_reference(m: float, v0: float, k: float, c: float) -> ImpactReference:
    """One elastic Hertz impact on a rigid wall (Johnson, Sect. 11.4): r = 1, t_c = 2.9432 delta_max / v0 with
    delta_max = (5 m v0^2 / (4 k_H))^(2/5)."""
    return ImpactReference(1.0, HERTZ_CONTACT_TIME * (5.0 * m * v0 * v0 / (4.0 * k)) ** 0.4 / v0)


@numba.njit(inline="always")
def _damping_force(delta: float, rate: float, c: float) -> float:
    """The damping of Eq. 10, d_H delta' = c delta^0.25 delta' (N) while the wall approaches (delta, delta' > 0)."""
    return c * math.sqrt(math.sqrt(delta)) * rate if delta > 0.0 and rate > 0.0 else 0.0


@numba.njit(inline="always")
def damped_hertz_force_kernel(delta: float, rate: float, k: float, c: float) -> float:
    """Eq. 10: k_H delta^1.5 + c delta^0.25 delta' in approach, k_H delta^1.5 in restitution (N)."""
    return hertz_force(delta, rate, k, c) + _damping_force(delta, rate, c)


@numba.njit(inline="always")
def damped_hertz_dissipation(delta: float, rate: float, k: float, c: float) -> float:
    """The power (W) Eq. 10's damping dissipates: c delta^0.25 delta'^2 in approach."""
    return _damping_force(delta, rate, c) * rate


def damped_hertz_reference(m: float, v0: float, k: float, c: float) -> ImpactReference:
    """One impact under Eq. 10 on a rigid wall (m_red = m): r = `restitution`(xi), xi = c / (2 sqrt(k_H m))."""
    return ImpactReference(restitution(c / (2.0 * math.sqrt(k * m))), math.nan)


HERTZ = register(Law("hertz", "Eq. 4, elastic", hertz_force, hertz_stiffness, hertz_potential, hertz_reference,
                     collocation=True, duration_factor=HERTZ_CONTACT_TIME))
HERTZ_DAMPED = register(Law("hertz-damped", "Eq. 10, Hertz with damping in approach; needs the model's beam mass",
                            damped_hertz_force_kernel, hertz_stiffness, hertz_potential, damped_hertz_reference,
                            dissipation=damped_hertz_dissipation, takes_r_cont=True, elastic="hertz",
                            duration_factor=HERTZ_CONTACT_TIME))
#: The law of a run that names none (Eq. 4), and the law that an r_cont,diss without a law name implies (Eq. 10).
DEFAULT_LAW = "hertz"
DEFAULT_DAMPED_LAW = "hertz-damped"


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

    name: a registered law (`LAWS`: "hertz", Eq. 4, or "hertz-damped", Eq. 10); r_cont: r_cont,diss in (0, 1] (only
    a law that `takes_r_cont` takes a value other than 1; 1 is the conservative law).
    """

    name: str = "hertz"
    r_cont: float = 1.0

    def __post_init__(self) -> None:
        law = law_named(self.name)
        r = self.r_cont
        row = PARAMETERS["r_cont"]
        if isinstance(r, bool) or not isinstance(r, (int, float)):
            raise SimulationInputError(f"r_cont must be a number; r_cont {row.bounds.text()} ({row.hint}), got {r!r}")
        row.check(r)
        if not law.takes_r_cont and r != 1.0:
            damped = " or ".join(repr(name) for name, other in LAWS.items() if other.takes_r_cont)
            raise SimulationInputError(f"r_cont = {r!r} needs the contact law {damped}; {self.name!r} takes no r_cont "
                                       "(it is elastic, r_cont = 1)")
        object.__setattr__(self, "r_cont", float(r))

    @property
    def xi(self) -> float:
        """xi(r_cont) of Eq. 10 (-); 0.0 for the conservative law."""
        return float(xi_of_r_cont(self.r_cont)) if self.dissipative else 0.0

    @property
    def dissipative(self) -> bool:
        """True if the law dissipates energy (a law that takes r_cont, with r_cont < 1)."""
        return LAWS[self.name].takes_r_cont and self.r_cont < 1.0

    @property
    def law(self) -> Law:
        """The registered `Law` the integrators compile: the law's elastic counterpart when it dissipates nothing
        (r_cont = 1), so that the result is that law's bit for bit."""
        law = LAWS[self.name]
        return LAWS[law.elastic] if law.elastic is not None and not self.dissipative else law

    def reduced_mass(self, beam_mass: float | None, m_a: float, source: str = "the modal model") -> float:
        """The reduced mass of d_H (kg) from the beam's mass (kg, free length without block; None if unknown)
        and the sphere's m_a (kg). The damped law refuses a model without beam mass with one line."""
        if LAWS[self.name].takes_r_cont and beam_mass is None:
            raise SimulationInputError(f"the contact law {self.name!r} needs the beam mass (Eq. 10): {source} has no "
                                       "'beam_mass_kg'; add it to the modal file (kg, free length without block) or "
                                       "save the built-in rig with `ies modes --save`")
        return reduced_mass(beam_mass, m_a) if beam_mass is not None else math.nan

    def force(self, delta: ArrayLike, delta_dot: ArrayLike, k_H: float, m_red: float) -> np.ndarray:
        """The compressive wall force (N) of this law, vectorised (see damped_hertz_force)."""
        return damped_hertz_force(delta, delta_dot, k_H, self.xi, m_red)


def contact_law_of(name: str | None, r_cont: float | None) -> ContactLaw:
    """The `ContactLaw` of a law's name and r_cont,diss (either may be None, as on the command line): r_cont alone
    implies DEFAULT_DAMPED_LAW, no name DEFAULT_LAW; a law that takes r_cont gets DEFAULT_R_CONT when none is given,
    one that does not gets 1. Unknown names and values give one line (SimulationInputError)."""
    if name is None:
        name = DEFAULT_DAMPED_LAW if r_cont is not None else DEFAULT_LAW
    if r_cont is None:
        r_cont = DEFAULT_R_CONT if law_named(name).takes_r_cont else 1.0
    return ContactLaw(name, r_cont)


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
