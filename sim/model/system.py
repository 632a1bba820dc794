"""The coupled system of the seed paper, Sect. 3.1: a modal model of the host structure (Eq. 7)
and a sphere with clearance and Hertzian contact at both cavity walls (Eqs. 3-6).

Conventions shared by every integrator in `sim`
------------------------------------------------
* SI units. Mode values are mass-normalised: phi in 1/sqrt(kg), participation phi^T M b in sqrt(kg).
* Both wall directions w_l, w_r are the +x unit vector at the wall (Sect. 3.1), so
  ``phi_wall_left[j] = phi_j^T w_l`` is the x-value of mode j at the left wall.
* Modal equations (Eq. 7):  s_j'' + 2 D_j w_j s_j' + w_j^2 s_j + phi_l,j f_l + phi_r,j f_r
  = -(phi_j^T M b) q_base''(t),  with q_base = a_base cos(Omega t).
* Sphere (Eq. 3): m_a q_a'' = f_l + f_r (q_a absolute).
* Indentations (Eqs. 5, 6) with absolute wall displacements q_c = phi^T s + q_base:
  delta_l = q_cl - q_a - g,  delta_r = q_cr - q_a + g.
  Forces (Eq. 4): f_l = k_H delta_l^1.5 if delta_l > 0;  f_r = -k_H (-delta_r)^1.5 if delta_r < 0.
  With the damped law (Eq. 10, `sim.model.contact_law`) each force gains c_damp delta^0.25 delta' while the wall
  approaches (delta' > 0 at the left wall, -delta_r' > 0 at the right), c_damp = 2 xi sqrt(k_H m_red).
* Dry friction (Appendix C, `sim.model.friction`): a Jenkins element between the sphere and the cavity floor, whose
  x-motion is phi_f^T s + q_base; its force f_t on the sphere enters Eq. 3 as + f_t and Eq. 7 as - phi_f,j f_t.
  Its slider is state carried from call to call in `SystemArrays.slider` (ode3 only).
* State exchanged between the integrators and the stepped-sine protocol, always at an excitation
  phase that is a multiple of 2 pi (q_base = a_base, q_base' = 0):
  ``y = [s_1..s_n, s_1'..s_n', u_a, u_a']`` with u_a = q_a - q_base (sphere relative to the base).
  y = 0 is the homogeneous initial condition (everything at rest, sphere centred).
* Integrator contract (both the paper's ode3 and the exact free-flight integrator):
  ``run_step(y, n_periods, Omega, a_base, sys: SystemArrays, record) -> (amplitudes, impacts)``
  advances y in place over n whole excitation periods starting at phase 0 and returns, per period,
  the magnitude |c_1| of the fundamental Fourier coefficient of q_tip = phi_tip^T s
  (c_1 = (2/T) int_period q_tip exp(-i Omega t) dt, in m) and the number of contact onsets
  (open -> closed transitions at either wall) in that period.
  ``record`` is None, or a float64 array of shape (n_periods * M + 1, len(y)) that receives the state
  at M equally spaced instants per period (first row: the initial state). Both integrators also take
  ``ledger=sim.integration.energy.Ledger()``, which receives the energy bookkeeping per period and (exact) the impact
  records of the call (Sect. 5.5, Appendix D).
* Normalisations (Sects. 5, 5.3) always use the *nominal* (starred) parameters, so that results
  with varied D, g, k_H stay on the paper's axes:
  a_noabs* = phi_tip,1 (phi_1^T M b) a_base / (2 D*),  a_base* = 2 D* g* / (phi_c,1 phi_1^T M b).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np

from sim.model.contact_law import HERTZ, ContactLaw, Law, contact_law_of
from sim.common.errors import SimulationInputError
from sim.model.materials import STEEL_WALL, Material
from sim.model.parameters import (CLEARANCE_NOMINAL, D1_INTERVAL, D1_NOMINAL, K_H_NOMINAL,  # noqa: F401 (re-exported)
                                  K_T_PAPER, PARAMETERS, SPHERE_MASS, SystemSettings)



@dataclass(frozen=True)
class ModalModel:
    """Modal model of the host structure without the sphere (Eq. 7), for the retained modes.

    Attributes (all arrays of length n_modes, ascending frequency):
        frequencies_hz: natural frequencies omega_j / (2 pi) in Hz.
        damping_ratios: modal damping ratios D_j (-).
        phi_wall_left, phi_wall_right: mass-normalised x-values at the cavity walls (1/sqrt(kg)).
        phi_tip: mass-normalised x-value at the measurement point (1/sqrt(kg)).
        participation: phi_j^T M b (sqrt(kg)), b = rigid unit x-translation of the base.
        source: where the model came from (built-in rig model or a file path).
        beam_mass: mass of the beam's free length without the block (kg), for d_H of Eq. 10; None if unknown.
        phi_floor: mass-normalised x-values at the cavity floor on the beam axis (1/sqrt(kg)), the host point
            under the sphere's friction contact (Appendix C); None if unknown.
        nominal_damping: the host's nominal damping ratio of mode 1, D_1* (-), by which every amplitude and level is
            normalised (Sect. 5); None: damping_ratios[0] (`D_star`). It stays when a study varies D_1 (`with_damping`).
        damping_interval: (low, high) of D_1 (-), the interval the studies and `ies design` propagate (Table 2 for
            the seed rig; measured: `ies linearity`); None: unknown (`damping_box` then states a default).
        wall: the material of the cavity walls (`sim.model.materials`; Eq. 8 takes its E and nu); None: the rig's
            steel (`wall_material`).
    """

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    phi_wall_left: np.ndarray
    phi_wall_right: np.ndarray
    phi_tip: np.ndarray
    participation: np.ndarray
    source: str = "unspecified"
    beam_mass: float | None = None
    phi_floor: np.ndarray | None = None
    nominal_damping: float | None = None
    damping_interval: tuple[float, float] | None = None
    wall: Material | None = None

    def __post_init__(self) -> None:
        names = ("frequencies_hz", "damping_ratios", "phi_wall_left", "phi_wall_right", "phi_tip", "participation")
        if self.phi_floor is not None:
            names += ("phi_floor",)
        arrays = {}
        for name in names:
            value = np.atleast_1d(np.asarray(getattr(self, name), dtype=float)).copy()
            value.setflags(write=False)
            object.__setattr__(self, name, value)
            arrays[name] = value
        n = arrays["frequencies_hz"].size
        if n == 0:
            raise SimulationInputError("modal model has no modes; give at least one frequency")
        for name, value in arrays.items():
            if value.ndim != 1 or value.size != n:
                raise SimulationInputError(f"modal model: '{name}' has {value.size} values but there are {n} modes")
            if not np.all(np.isfinite(value)):
                raise SimulationInputError(f"modal model: '{name}' contains non-finite values")
        if np.any(arrays["frequencies_hz"] <= 0) or np.any(np.diff(arrays["frequencies_hz"]) <= 0):
            raise SimulationInputError("modal model: frequencies must be positive and strictly ascending")
        d = arrays["damping_ratios"]
        if np.any(d <= 0) or np.any(d >= 1):
            raise SimulationInputError("modal model: damping ratios must lie in (0, 1), e.g. 0.001 for 0.1 %")
        if self.beam_mass is not None:
            mass = self.beam_mass
            if isinstance(mass, bool) or not isinstance(mass, (int, float)) or not math.isfinite(mass) or mass <= 0:
                raise SimulationInputError(f"modal model: beam mass must be a positive number (kg), got {mass!r}")
            object.__setattr__(self, "beam_mass", float(mass))
        if self.nominal_damping is not None:
            object.__setattr__(self, "nominal_damping", check_open_unit(self.nominal_damping, "modal model: the "
                                                                        "nominal damping ratio D_1*"))
        if self.damping_interval is not None:
            object.__setattr__(self, "damping_interval", check_damping_interval(self.damping_interval, self.D_star))

    @property
    def D_star(self) -> float:
        """D_1* (-): the host's nominal damping ratio of mode 1, the normalisation's (Sect. 5)."""
        return float(self.damping_ratios[0]) if self.nominal_damping is None else self.nominal_damping

    @property
    def wall_material(self) -> Material:
        """The cavity walls' material (Eq. 8): `wall`, or the rig's steel (Table 1) when the host names none."""
        return STEEL_WALL if self.wall is None else self.wall

    def damping_box(self) -> tuple[tuple[float, float], str]:
        """(low, high) of D_1 (-) to propagate, and where it comes from: the host's `damping_interval`, else Table 2's
        interval relative to its nominal value (0.075-0.09 % of 0.085 %: -11.8 % .. +5.9 %) around this host's D_1*."""
        if self.damping_interval is not None:
            return self.damping_interval, "the host's damping interval"
        low, high = (end / D1_NOMINAL * self.D_star for end in D1_INTERVAL)
        return (low, high), (f"no damping interval in the host: Table 2's relative interval (-11.8 % .. +5.9 %) "
                             f"around its D_1* = {100 * self.D_star:.4g} %")

    @property
    def n_modes(self) -> int:
        return int(self.frequencies_hz.size)

    @property
    def omega(self) -> np.ndarray:
        """Natural angular frequencies omega_j (rad/s)."""
        return 2.0 * np.pi * self.frequencies_hz

    @property
    def phi_contact(self) -> float:
        """phi_c of the resonant mode: mean of the two wall values (they coincide in a beam model)."""
        return 0.5 * float(self.phi_wall_left[0] + self.phi_wall_right[0])

    def with_damping(self, D1: float) -> "ModalModel":
        """Copy with the damping ratio of mode 1 replaced (the uncertain D of Table 2, checked by its row); the
        nominal D_1* stays the host's (`D_star`), so that varied damping stays on the same axes (Sect. 5)."""
        D1 = PARAMETERS["D"].check(D1)
        d = self.damping_ratios.copy()
        d[0] = D1
        return replace(self, damping_ratios=d, nominal_damping=self.D_star)


@dataclass(frozen=True)
class Impactor:
    """The sphere and its contacts (Eqs. 3-6): mass m_a (kg), clearance g (m), k_H (N/m^1.5), and the normal
    contact law at both walls (Eq. 4 by default, or the damped law of Eq. 10); inputs: (name, value) of the
    parameters it was built from (`SystemSettings.inputs`; a contact law's own constant is read from there); sphere:
    the described sphere (`sim.model.sphere.Sphere`: radius, material, wall) its mass and k_H* came from, or None.
    Every value is checked against its row of `sim.model.parameters.PARAMETERS` (one line each)."""

    mass: float = SPHERE_MASS
    clearance: float = CLEARANCE_NOMINAL
    k_H: float = K_H_NOMINAL
    contact_law: ContactLaw = ContactLaw()
    friction: float = 0.0  # Coulomb coefficient mu of the floor contact (Appendix C); 0: no friction
    k_t: float = K_T_PAPER  # N/m, tangential stiffness of the floor contact (Appendix C: 22 kN/mm)
    inputs: tuple[tuple[str, float], ...] = ()
    sphere: Any = field(default=None, compare=False)  # the described sphere it was built from (`sim.model.sphere`)

    def __post_init__(self) -> None:
        for row in PARAMETERS.values():
            if row.feeds.field in _IMPACTOR_FIELDS and not row.feeds.scale:
                row.check(getattr(self, row.feeds.field))

    def input(self, name: str) -> float:
        """The value of the parameter `name` this sphere was built with (its row's nominal value if none was given)."""
        return dict(self.inputs).get(name, PARAMETERS[name].nominal)

    @property
    def stiffness(self) -> float:
        """The contact law's stiffness constant k (`sim.model.contact_law.Law.constant`): k_H (N/m^1.5) for the
        Hertz laws, the value of the law's own parameter otherwise."""
        constant = self.contact_law.law.constant
        return self.k_H if constant is None else self.input(constant.name)


_IMPACTOR_FIELDS = ("mass", "clearance", "k_H", "friction", "k_t")


@dataclass(frozen=True)
class Nominal:
    """The starred parameters used for normalisation (Sect. 5): D* (-) and g* (m). `Nominal.of(model)` is the host's
    own: its nominal D_1* (`ModalModel.D_star`: Table 2's 0.085 % for the seed rig) and the paper's g* = 0.58 mm
    unless a nominal clearance is given; `Nominal()` alone is the seed paper's."""

    D1: float = D1_NOMINAL
    clearance: float = CLEARANCE_NOMINAL

    @classmethod
    def of(cls, model: "ModalModel", clearance: float | None = None) -> "Nominal":
        """The host's normalisation: D* = the model's nominal D_1*, g* = `clearance` (m; default the paper's g*)."""
        return cls(D1=model.D_star, clearance=CLEARANCE_NOMINAL if clearance is None else float(clearance))

    def describe(self) -> dict[str, float]:
        """Its JSON keys: D_star (-), g_star_m (m)."""
        return {"D_star": self.D1, "g_star_m": self.clearance}

    def text(self) -> str:
        """One line saying what the amplitudes and levels are normalised by."""
        return f"normalised by D* = {100 * self.D1:.4g} % (the host's nominal D_1) and g* = {1e3 * self.clearance:.4g} mm"


def a_noabs_star(model: ModalModel, a_base: float, nominal: Nominal | None = None) -> float:
    """Resonant amplitude without absorber (Sect. 5): phi_tip (phi^T M b) a_base / (2 D*), in m; D* the host's nominal
    damping (`Nominal.of`) unless `nominal` is given."""
    nominal = Nominal.of(model) if nominal is None else nominal
    return abs(model.phi_tip[0] * model.participation[0]) * a_base / (2.0 * nominal.D1)


def a_base_star(model: ModalModel, nominal: Nominal | None = None) -> float:
    """Base amplitude reaching the clearance at the contact (Sect. 5.3): 2 D* g* / (phi_c phi^T M b), in m; D* the
    host's nominal damping and g* the paper's (`Nominal.of`) unless `nominal` is given."""
    check_resonant_mode(model)
    nominal = Nominal.of(model) if nominal is None else nominal
    return 2.0 * nominal.D1 * nominal.clearance / abs(model.phi_contact * model.participation[0])


def check_resonant_mode(model: ModalModel) -> None:
    """One line (SimulationInputError) when `model` cannot host an IES for its mode 1, the resonance it mitigates
    (Sect. 5): its cavity walls do not move in that mode (phi_c = 0: the IES sits at a node, the sphere is never struck
    by the mode and cannot scatter its energy), or the base does not excite it (phi^T M b = 0: there is no resonance
    to mitigate); a_base* would be infinite either way."""
    scale = max(float(np.max(np.abs(model.phi_wall_left))), float(np.max(np.abs(model.phi_wall_right))),
                float(np.max(np.abs(model.phi_tip))), 1e-300)
    if abs(model.phi_contact) <= 1e-9 * scale:
        raise SimulationInputError(
            f"the cavity walls do not move in mode 1 ({model.frequencies_hz[0]:.4g} Hz: phi_wall_left "
            f"{model.phi_wall_left[0]:g}, phi_wall_right {model.phi_wall_right[0]:g}): the IES sits at a node of the "
            "resonance it is to mitigate, its sphere is never struck by it and scatters nothing; give the wall values "
            "of a cavity where mode 1 moves (and check the order and signs of the modes)")
    if model.participation[0] == 0.0:
        raise SimulationInputError(
            f"the base does not excite mode 1 ({model.frequencies_hz[0]:.4g} Hz: participation 0): there is no "
            "resonance for the IES to mitigate; check the participation factors phi^T M b of the modes")


def check_open_unit(value: float, name: str) -> float:
    """Validate a damping ratio in (0, 1)."""
    value = float(value)
    if not np.isfinite(value) or not 0.0 < value < 1.0:
        raise SimulationInputError(f"{name} must lie in (0, 1) (a damping ratio, e.g. 0.00085), got {value!r}")
    return value


def check_damping_interval(interval: object, nominal: float) -> tuple[float, float]:
    """A damping interval (low, high) of D_1 (-): two ratios in (0, 1), low <= high, containing the nominal D_1*; one
    `SimulationInputError` line otherwise."""
    try:
        low, high = (float(v) for v in interval)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise SimulationInputError(f"the damping interval must be two damping ratios [low, high], e.g. [0.00075, "
                                   f"0.0009], got {interval!r}") from None
    low = check_open_unit(low, "the damping interval's low end")
    high = check_open_unit(high, "the damping interval's high end")
    if low > high:
        raise SimulationInputError(f"the damping interval [{low:g}, {high:g}] is reversed; give [low, high]")
    if not low <= nominal <= high:
        raise SimulationInputError(f"the damping interval [{100 * low:.4g} %, {100 * high:.4g} %] does not contain the "
                                   f"host's nominal D_1 = {100 * nominal:.4g} %; widen it or correct mode 1's damping ratio")
    return low, high


class SystemArrays(NamedTuple):
    """Flat, numba-friendly view of the coupled system, passed to the integrator kernels.

    omega, D, phi_l, phi_r, phi_tip, gamma: float64 arrays (n_modes,), gamma = phi^T M b;
    m_a (kg), k_H (N/m^1.5), g (m): floats; c_damp (N s / m^1.25): the damping factor of Eq. 10,
    d_H = c_damp delta^0.25 = 2 xi sqrt(k_H m_red) delta^0.25 (0 for the elastic law of Eq. 4).
    Friction (Appendix C): phi_f the mode values at the cavity floor (1/sqrt(kg)), k_t (N/m), slip_force = mu m_a g
    (N; 0: off), and slider = [z, sense]: the slider's position relative to the base (m) and the phase (0 stick,
    +-1 slip in that sense), advanced in place by the integrator like y (a fresh system starts relaxed, in stick).
    law: the registered normal contact law (`sim.model.contact_law.Law`; k_H and c_damp are its constants k and c);
    the kernels are compiled per law.
    """

    omega: np.ndarray
    D: np.ndarray
    phi_l: np.ndarray
    phi_r: np.ndarray
    phi_tip: np.ndarray
    gamma: np.ndarray
    m_a: float
    k_H: float
    g: float
    c_damp: float = 0.0
    phi_f: np.ndarray = np.zeros(0)
    k_t: float = 0.0
    slip_force: float = 0.0
    slider: np.ndarray = np.zeros(2)
    law: Law = HERTZ


def damping_factor(model: ModalModel, impactor: Impactor) -> float:
    """c_damp = 2 xi sqrt(k_H m_red) of Eq. 10 (N s / m^1.25), m_red = m_beam m_a / (m_beam + m_a); 0 for the
    elastic law. The damped law refuses a model without beam mass with one line (`ContactLaw.reduced_mass`)."""
    law = impactor.contact_law
    if not law.dissipative:
        return 0.0
    m_red = law.reduced_mass(model.beam_mass, impactor.mass, model.source)
    return 2.0 * law.xi * math.sqrt(impactor.stiffness * m_red)


def system_arrays(model: ModalModel, impactor: Impactor) -> SystemArrays:
    """Pack a modal model and an impactor for the kernels (contiguous float64 copies)."""
    as_f8 = lambda a: np.ascontiguousarray(a, dtype=np.float64).copy()  # noqa: E731
    phi_f, k_t, slip_force, slider = friction_arrays(model, impactor)
    return SystemArrays(
        omega=as_f8(model.omega), D=as_f8(model.damping_ratios), phi_l=as_f8(model.phi_wall_left),
        phi_r=as_f8(model.phi_wall_right), phi_tip=as_f8(model.phi_tip), gamma=as_f8(model.participation),
        m_a=float(impactor.mass), k_H=float(impactor.stiffness), g=float(impactor.clearance),
        c_damp=damping_factor(model, impactor), phi_f=phi_f, k_t=k_t, slip_force=slip_force, slider=slider,
        law=impactor.contact_law.law,
    )


def friction_arrays(model: ModalModel, impactor: Impactor) -> tuple[np.ndarray, float, float, np.ndarray]:
    """(phi_f, k_t, slip_force, slider) of `SystemArrays` for the impactor's friction (Appendix C): the floor values
    of the model (one line if it has none and friction is on), k_t (N/m), mu m_a g (N) and a relaxed slider."""
    from sim.model.friction import GRAVITY, floor_values

    n = model.n_modes
    if impactor.friction == 0.0:
        return np.zeros(n), float(impactor.k_t), 0.0, np.zeros(2)
    phi_f = np.ascontiguousarray(floor_values(model, model.source), dtype=np.float64).copy()
    return phi_f, float(impactor.k_t), float(impactor.friction * impactor.mass * GRAVITY), np.zeros(2)


def build_impactor(settings: SystemSettings) -> Impactor:
    """The sphere of Eqs. 3-6 from `sim.model.parameters.SystemSettings` (what the parameters of `PARAMETERS` feed):
    mass (kg), g (m), k_H (N/m^1.5), the contact law (Eq. 4, or Eq. 10 with r_cont) and friction (Appendix C).
    Every value is checked here, one line each (`Impactor`, `ContactLaw`)."""
    law = contact_law_of(settings.contact_law, settings.r_cont)
    return Impactor(mass=settings.mass, clearance=settings.clearance, k_H=settings.k_H, contact_law=law,
                    friction=settings.friction, k_t=settings.k_t, inputs=settings.inputs)


def settings_of(model: ModalModel, impactor: Impactor) -> SystemSettings:
    """The `SystemSettings` a built system stands for (the inverse of `build_system`): what the rows of `PARAMETERS`
    report about it (`UncertainParameter.reported`, the JSON of `ies sweep`)."""
    law = impactor.contact_law
    return SystemSettings(D1=float(model.damping_ratios[0]), mass=impactor.mass, clearance=impactor.clearance,
                          k_H=impactor.k_H, contact_law=law.name, r_cont=law.r_cont, friction=impactor.friction,
                          k_t=impactor.k_t, inputs=impactor.inputs)


def build_system(model: ModalModel, settings: SystemSettings, *, integrator: Any = None) -> tuple[ModalModel, Impactor]:
    """The one impactor builder of the workbench, used by `ies sweep/overview/trace` (`sim.cli`) and by studies
    (`uq.problem.models.IESModel`): (the model with D_1 = settings.D1 when given, the impactor of `build_impactor`).

    The checks that need the model and the integrator live here, once, so that a bad combination fails before any
    work with one line: the damped law (Eq. 10) needs the model's beam mass, dry friction (Appendix C) the model's
    floor values; `integrator`, the protocol's record (`sim.integration.integrators.Integrator`; None skips the
    check), says whether it can run this impactor (its law, friction).
    """
    if settings.D1 is not None:
        model = model.with_damping(settings.D1)
    impactor = build_impactor(settings)
    if integrator is not None:
        integrator.check(impactor)
    if impactor.contact_law.dissipative or impactor.friction > 0:
        system_arrays(model, impactor)  # beam mass (Eq. 10) and phi_floor (friction): one line if missing
    return model, impactor


def contact_forces(s: np.ndarray, u_a: float, sys: SystemArrays, s_dot: np.ndarray | None = None,
                   u_a_dot: float = 0.0) -> tuple[float, float]:
    """Eqs. 4-6 (or the law of sys.law) in relative coordinates (q_base cancels): returns (f_l, f_r) in N.

    delta_l = phi_l^T s - u_a - g,  delta_r = phi_r^T s - u_a + g; the rates from s_dot (1/s units of s) and u_a_dot
    (m/s) for a law that depends on them (zero when not given). The law's own force (`sim.model.contact_law`),
    evaluated in Python: the kernels inline the same function.
    """
    force = sys.law.force.py_func
    delta_l = float(sys.phi_l @ s) - u_a - sys.g
    delta_r = float(sys.phi_r @ s) - u_a + sys.g
    rate_l = rate_r = 0.0
    if s_dot is not None:
        rate_l = float(sys.phi_l @ s_dot) - u_a_dot
        rate_r = float(sys.phi_r @ s_dot) - u_a_dot
    f_l = force(delta_l, rate_l, sys.k_H, sys.c_damp) if delta_l > 0 else 0.0
    f_r = -force(-delta_r, -rate_r, sys.k_H, sys.c_damp) if delta_r < 0 else 0.0
    return f_l, f_r


def check_run_step(y: np.ndarray, n_periods: int, Omega: float, a_base: float, sys: SystemArrays,
                   record: np.ndarray | None) -> tuple[int, float, float, np.ndarray, int]:
    """Validate the integrator contract's arguments (shared by every integrator).

    Returns (n_periods, Omega (rad/s), a_base (m), record array (0 rows when not recording),
    samples per period M). Raises SimulationInputError with one line for anything malformed.
    """
    n = sys.omega.size
    if not isinstance(y, np.ndarray) or y.dtype != np.float64 or y.shape != (2 * n + 2,) or not y.flags.c_contiguous:
        raise SimulationInputError(f"state y must be a contiguous float64 array of length {2 * n + 2} (2 n_modes + 2)")
    n_periods = int(n_periods)
    if n_periods < 1:
        raise SimulationInputError(f"n_periods must be at least 1, got {n_periods}")
    Omega, a_base = float(Omega), float(a_base)
    if not np.isfinite(Omega) or Omega <= 0:
        raise SimulationInputError(f"excitation frequency Omega must be positive (rad/s), got {Omega!r}")
    if not np.isfinite(a_base) or a_base < 0:
        raise SimulationInputError(f"base amplitude a_base must be >= 0 (m), got {a_base!r}")
    if not np.all(np.isfinite(y)):
        raise SimulationInputError("state y contains non-finite values")
    if record is None:
        return n_periods, Omega, a_base, np.empty((0, 2 * n + 2)), 1
    rows = record.shape[0] - 1 if record.ndim == 2 else -1
    if (record.dtype != np.float64 or record.ndim != 2 or record.shape[1] != 2 * n + 2 or rows < n_periods
            or rows % n_periods or not record.flags.c_contiguous):
        raise SimulationInputError(f"record must be a contiguous float64 array of shape (n_periods * M + 1, {2 * n + 2})")
    return n_periods, Omega, a_base, record, rows // n_periods
