r"""One-mode slow flow of the IES on a flexible host: the symmetric 1:1 orbit with two impacts per period
(one per wall), its existence and stability, the predicted switch from strongly modulated (SMR) to almost
periodic response (APR), a vectorised screening of designs, and the map of which orbits exist and are stable
(`ies design`'s screening).

Source followed
---------------
The averaging of a linear oscillator carrying a vibro-impact NES with Newton's impact law, 1:1 resonance,
two symmetric impacts per cycle, and the slow invariant manifold (SIM) it gives: O.V. Gendelman, "Analytic
treatment of a system with a vibro-impact nonlinear energy sink", J. Sound Vib. 331 (2012) 4599-4608, and
O.V. Gendelman, A. Alloni, "Dynamics of forced system with vibro-impact energy sink", J. Sound Vib. 358 (2015)
301-314 (the multiple-scales form of the same SIM: B. Youssef, A.Y. Karoui, R.I. Leine, arXiv:2505.04420).
The fast stability is the impact map of a sphere between harmonically moving walls, as in the classical
impact-damper analysis (S.F. Masri, T.K. Caughey, J. Appl. Mech. 33 (1966) 586-592), whose exact symmetric
orbit (`exact_orbit`, shooting) is also the slow flow's reference. The derivation below, for this workbench's
modal host (Eq. 7 of the seed paper) with base excitation and the host's recoil, is ours.

Equations (SI; seed paper Eqs. 2-7 reduced to mode 1 and rigid walls)
------------------------------------------------------------------------
Mode 1 with omega (rad/s), D, phi_c (1/sqrt(kg)) at the walls, gamma = phi^T M b (sqrt(kg)); x = phi_c s the
wall displacement relative to the base, w = x + q_base the absolute wall motion, q_base = a_base cos(Omega t),
F the contact force on the sphere (mass m_a, absolute position u):

  (1)  x'' + 2 D omega x' + omega^2 x = phi_c gamma Omega^2 a_base cos(Omega t) - phi_c^2 F,   m_a u'' = F.

The host seen at the walls is a mass M = 1/phi_c^2; eps = m_a phi_c^2 is the modal mass ratio. Impacts follow
Newton's law with the modal coefficient of restitution r (seed paper Eq. D.1), momentum kept. Units:
A^ = A/g, tau = omega t, eta = Omega/omega, b = a_base/g.

(2) Fast scale. On the 1:1 orbit the wall's fundamental is A_w cos(phi), phi = Omega t + psi_w, and the sphere
    flies at constant speed V between the walls. Symmetric orbit: the left wall hits at phi = theta (its
    harmonic velocity v0 = -A_w Omega sin(theta) > 0), the right wall at theta + pi. Each impulse P = 2 m_a V
    adds to the wall's fundamental a square wave of velocity +-eps V (jumping at the impacts) and a triangle
    wave of displacement, eps V pi (1 - 8/pi^2) / (2 Omega) at the impacts (the part beyond the fundamental).
    Travel 2g - 2 A_w cos(theta) - 2 x_res in half a period:
      V = 2 Omega (g - A_w cos(theta)) / (pi (1 + eps'))   with eps' = eps (1 - 8/pi^2).
(3) Newton's law at the impact, the wall at v0 + eps V just before and v0 - eps V just after:
      V = v0 (1 + r) / ((1 - r)(1 + eps)).
(4) SIM: (2) = (3):  1 = A^_w (cos(theta) - k_eps sin(theta)),  k = pi (1 + r) / (2 (1 - r)),
    (4b) k_eps = k (1 + eps') / (1 + eps). With alpha = atan(k_eps): theta = -alpha - arccos(1/(A^_w
    sqrt(1 + k_eps^2))), the branch with sin(theta) < 0, for every A^_w >= A^_min = 1/sqrt(1 + k_eps^2)
    (the other root, theta in (-alpha, 0), is never fast-stable, see (10)).
(5) Slow scale. The fundamental of the impulse train acts on x as a complex dynamic stiffness on the wall
    motion a_w (complex amplitude of w / g):  -C a_w,  C = eta^2 (8 eps k / (pi^2 (1 + eps))) (-sin(theta))
    e^{-i theta}. Re C < 0 (softening: the resonance moves below omega); Im C >= 0 is the impact damping.
(6) Averaged host (first-order averaging, x^ = Re(a e^{i eta tau}), a_w = a + b):
      2 i eta a' = phi_c gamma eta^2 b - Z0 a - C(|a_w|) a_w,   Z0 = 1 - eta^2 + 2 i D eta.
(7) Fixed points: (Z0 + C) a_w = b (phi_c gamma eta^2 + Z0), so the orbit with wall amplitude A^_w exists at
      b(A^_w, eta) = A^_w |Z0 + C| / |phi_c gamma eta^2 + Z0|,
    and the excitation level is a_base / a_base* = b g / a_base*, a_base* = 2 D* g* / (phi_c gamma) (Sect. 5.3).
    Tip amplitude (relative to the base): (phi_tip / phi_c) |a_w - b| g; impact phase of the left wall
    Omega t = theta - arg(a_w) (mod 2 pi).
(8) Energy lost per period (J) = work of the impulses on the walls = pi M omega^2 g^2 Im(C) A^_w^2
    = 4 m_a V v0; it vanishes like (1 - r) as r -> 1 at fixed A^_w (Im C ~ 1/k).
(9) Switch (existence). Over A^_w, b(A^_w, eta) minimised over eta falls from the SIM's end, has one minimum
    b_fold and rises again: no two-impact orbit exists below b_fold (the response relaxes: SMR), and from
    b_fold on the rising part carries the almost periodic response. The predicted switch level is
    b_fold g / a_base*; the almost periodic branch's resonant level is the rising part's largest A^_w over eta.
    On the falling part the fixed points are saddles of (6) (Jacobian of (6)).
(10) Fast stability, eps -> 0 (rigid walls of frozen amplitude): the impact map (theta_n, V_n) -> (theta_{n+1},
    V_{n+1}) has det = r^2 exactly and trace 2r - (pi (1 - r^2)/2) cot(theta): stable for cot(theta) < 4k/pi^2,
    beyond it a multiplier passes -1: the two flights become unequal (symmetry breaking; asymmetric and
    multi-impact orbits take over). At the rig's eps = 3.5 % the exact multipliers (`exact_orbit`) move that
    boundary: the symmetric orbit is stable only below the resonance (eta <= 0.96 at r = 0.86, `orbit_map`) and
    breaks its symmetry near it, as the direct simulation confirms. Where the stepped sine's resonant point lies
    (one run at a_base/a_base* = 7.5, eta 0.96:1.0:21 up): with mode 1 alone the response is almost periodic
    with 2.0 significant impacts per period for eta = 0.960-0.970 and its resonant maximum at eta = 0.980 has
    3.7; the rig (9 modes) is almost periodic only at 0.972-0.980, maximum at 0.980 with 4.0. The maximum thus
    sits beyond the symmetric two-impact orbit's stable range, on a multi-impact branch.

Accuracy (tests/sim/reduced/test_slow_flow.py): against the exact orbit of the one-mode Newton model at the rig's eps
the slow flow is within 0.15 % in tip amplitude and 0.003 rad in impact phase (the recoil terms of (2)-(4b)
matter at that eps); a direct solve_ivp simulation settles on the exact orbit to 1e-4. Assumed: one mode, rigid walls with a
fixed r (k_H does not enter; the similarity law then makes the response depend on g only through a_base/g),
first-order averaging in eps and D, no friction, no gravity along x.

Validity against the full simulator, measured (first table: an earlier run of 1 repetition per level and a design's
r measured from its own runs; second: tests/benchmarks/test_slow_flow_switch.py, 2 repetitions): stepped sine as
the fidelity studies (eta 0.96:1.0:21 up, 3 s + 5 s, exact integrator, seed 2024), levels 2-9 step 0.5 in units of
each design's own a_base* (own g), r = the simulator's Eq. D.1 value at the wall; switch = (last SMR level, first
APR level] of `sim.stepped_sine.landmarks.landmarks`; "agrees" = within one grid step.

  design       g (mm)  m_a (g)  r (Eq. D.1)  simulated switch  slow flow (9)  agrees   APR level at 7.5 sim / (9)
  rig          0.580   17.7     0.857        5.5 -> 6.0        4.00           no       0.364 / 0.410
  g*/2         0.290   17.7     0.861        4.5 -> 5.0        3.89           no       0.389 / 0.421
  2 g*         1.160   17.7     0.830        5.5 -> 6.0        4.67           no       0.321 / 0.347
  m_a/2        0.580    8.85    0.892        2.5 -> 3.0        1.84           no       0.666 / 0.699
  2 m_a        0.580   35.4     0.783 (SMR)  none up to 9      12.9           beyond the grid (both > 9)
  mode 1 only  0.580   17.7     0.851        6.5 -> 7.0        4.15           no       0.326 / 0.395
  (the last row is a diagnostic: the rig's mode 1 alone with the damped contact law, r_cont = 0.86)

  host, design          r      simulated switch  slow flow (9)  fold / switch
  rig                   0.845  5.0 -> 5.5        4.29           0.82
  rig m_a/2             0.901  2.0 -> 2.5        1.73           0.77
  rig 2 m_a             0.784  none up to 9      12.87          (both beyond 9)
  rig 2 g*              0.838  5.5 -> 6.0        4.47           0.78
  cantilever m_a/2      0.831  4.5 -> 5.0        3.63           0.76
  3D solid rig          0.843  5.5 -> 6.0        4.32           0.75

The fold (9) comes out at 0.67-0.82 times the middle of the simulated switch interval on every design that
switches (0.6-2.6 levels low; with mode 1 alone 2.6 levels low, so the higher modes are not the cause): the
fold is where the two-impact orbit starts to exist, a lower bound of the switch, and the stepped sine stays
strongly modulated above it (the slow flow's boundary of the relaxation cycle is not modelled here); it follows
the simulator's trends (clearance: weak; lighter sphere: much earlier; heavier: later) and the almost periodic level
within 5-13 %. The switch that `ies design` uses is therefore not this fold but the similarity law of the full model
(`sim.reduced.similarity`), which agrees with the simulated switch on every design above; the slow flow screens.
The simulated switches correspond to the fold at an r 0.02-0.09 below the measured one (rig: 0.78-0.80). With the
paper's r = 0.8 the fold of the rig lies at 5.43 (4.00 at the simulator's 0.857): lowering r by that much moves the
switch up by 1.4 levels, the size of the gap between the paper's 6.7 and the simulator's 5.3-5.5; scaled by the
same ratio (1.36) the simulator's switch would move to 7.2-7.5. So the lower r of the experiment can account for
the paper's later switch.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from sim.common.errors import SimulationInputError
from sim.model.materials import ball_mass
from sim.stepped_sine.measures import APR, LINEAR, SMR
from sim.model.system import Impactor, ModalModel, Nominal

#: Amplitude grid of the SIM used to locate the fold and to invert (7): A^_w from A^_min to at least
#: _GRID_TOP (and A^_min * _GRID_SPAN), log-spaced: far above any level of the paper (A^_w ~ 4 at a_base/a_base* = 10).
_GRID_POINTS = 1200
_GRID_SPAN = 2000.0
_GRID_TOP = 50.0
#: The paper's starred values (D*, g*) that define a_base* (Sect. 5.3) unless a model says otherwise.
NOMINAL = Nominal()


def _sim_grid(r: float, eps: float, n: int = _GRID_POINTS) -> np.ndarray:
    """Log-spaced wall amplitudes / g on the SIM (Eq. 4), from just above its end."""
    A_min = float(sim_min_amplitude(r, eps))
    return np.geomspace(A_min * (1.0 + 1e-9), max(A_min * _GRID_SPAN, _GRID_TOP), n)


@dataclass(frozen=True)
class HostMode:
    """The host's resonant mode as the slow flow needs it (Eq. 7 of the seed paper, mode 1).

    omega: natural angular frequency (rad/s); D: damping ratio (-); phi_c: mass-normalised value at the
    cavity walls (1/sqrt(kg)); phi_tip: at the measurement point (1/sqrt(kg)); participation: phi^T M b
    (sqrt(kg)), b the base's rigid unit translation along the walls' normal.
    """

    omega: float
    D: float
    phi_c: float
    phi_tip: float
    participation: float

    def __post_init__(self) -> None:
        for name in ("omega", "D", "phi_c", "phi_tip", "participation"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SimulationInputError(f"host mode: {name} must be a finite number, got {value!r}")
        if self.omega <= 0 or not 0 < self.D < 1 or self.phi_c == 0 or self.participation == 0:
            raise SimulationInputError("host mode: need omega > 0 (rad/s), 0 < D < 1 and non-zero phi_c and "
                                       "participation (the mode must move the walls and be excited by the base)")

    @property
    def coupling(self) -> float:
        """|phi_c gamma| (-): the base forcing's projection on the wall motion, Eq. 7."""
        return abs(self.phi_c * self.participation)


def host_mode(model: ModalModel) -> HostMode:
    """The resonant mode (mode 1) of any `ModalModel` as a `HostMode`."""
    return HostMode(omega=float(model.omega[0]), D=float(model.damping_ratios[0]), phi_c=abs(model.phi_contact),
                    phi_tip=abs(float(model.phi_tip[0])), participation=abs(float(model.participation[0])))


@dataclass(frozen=True)
class SlowFlowModel:
    """Inputs of the slow flow: the host mode, sphere mass m_a (kg), clearance g (m), modal restitution r (-,
    Eq. D.1), and the starred values (D*, g*) that define a_base* for the excitation level (Sect. 5.3)."""

    host: HostMode
    m_a: float
    g: float
    r: float
    nominal: Nominal = NOMINAL

    def __post_init__(self) -> None:
        for name, label in (("m_a", "sphere mass m_a (kg)"), ("g", "clearance g (m)")):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise SimulationInputError(f"slow flow: {label} must be a positive number, got {value!r}")
        check_restitution(self.r)

    @property
    def eps(self) -> float:
        """Modal mass ratio m_a phi_c^2 (-)."""
        return self.m_a * self.host.phi_c**2

    @property
    def a_base_star(self) -> float:
        """a_base* = 2 D* g* / (phi_c gamma) (m), Sect. 5.3."""
        return 2.0 * self.nominal.D1 * self.nominal.clearance / self.host.coupling

    def level(self, b: float | np.ndarray) -> float | np.ndarray:
        """Excitation level a_base/a_base* (-) of the base ratio b = a_base/g, Eq. 7."""
        return np.asarray(b) * self.g / self.a_base_star


def slow_flow_model(model: ModalModel, impactor: Impactor, r: float, nominal: Nominal | None = None) -> SlowFlowModel:
    """The slow-flow inputs of a modal model and an impactor (its mass and clearance; k_H does not enter: rigid
    walls) with the modal restitution r (Eq. D.1, e.g. the simulator's `restitution_wall`)."""
    return SlowFlowModel(host_mode(model), float(impactor.mass), float(impactor.clearance), float(r),
                         Nominal.of(model) if nominal is None else nominal)


def check_restitution(r: float) -> float:
    """Validate a modal coefficient of restitution in (0, 1) (r = 1 has no two-impact orbit of finite speed)."""
    if isinstance(r, bool) or not isinstance(r, (int, float, np.floating)) or not 0.0 < float(r) < 1.0:
        raise SimulationInputError(f"slow flow: the restitution r must lie in (0, 1), e.g. 0.85, got {r!r}")
    return float(r)


def restitution_factor(r: float | np.ndarray) -> float | np.ndarray:
    """k = pi (1 + r) / (2 (1 - r)) of Eq. 4 (-)."""
    r = np.asarray(r, dtype=float)
    return np.pi * (1.0 + r) / (2.0 * (1.0 - r))


def effective_factor(r: float | np.ndarray, eps: float | np.ndarray = 0.0) -> np.ndarray:
    """k_eps = k (1 + eps (1 - 8/pi^2)) / (1 + eps) of Eq. 4b (-): k of Eq. 4 with the host's O(eps) recoil."""
    eps = np.asarray(eps, dtype=float)
    return restitution_factor(r) * (1.0 + eps * (1.0 - 8.0 / np.pi**2)) / (1.0 + eps)


def sim_min_amplitude(r: float | np.ndarray, eps: float | np.ndarray = 0.0) -> np.ndarray:
    """A^_min = 1 / sqrt(1 + k_eps^2) (-, wall amplitude / g): the SIM's end, Eq. 4."""
    return 1.0 / np.sqrt(1.0 + effective_factor(r, eps) ** 2)


def sim_phase(A: float | np.ndarray, r: float | np.ndarray, eps: float | np.ndarray = 0.0) -> np.ndarray:
    """Impact phase theta (rad) of the wall motion on the SIM, Eq. 4 (NaN below A^_min); A = A_w / g."""
    k = effective_factor(r, eps)
    A = np.asarray(A, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = 1.0 / (A * np.sqrt(1.0 + k * k))
        return np.where(rho <= 1.0, -np.arctan(k) - np.arccos(np.minimum(rho, 1.0)), np.nan)


def impact_stiffness(A: float | np.ndarray, r: float | np.ndarray, eps: float | np.ndarray) -> np.ndarray:
    """C / eta^2 of Eq. 5 (complex, -): the impacts' dynamic stiffness on the wall motion per unit host stiffness."""
    theta = sim_phase(A, r, eps)
    eps = np.asarray(eps, dtype=float)
    return 8.0 * eps * restitution_factor(r) / (np.pi**2 * (1.0 + eps)) * (-np.sin(theta)) * np.exp(-1j * theta)


def fast_multipliers(A: float | np.ndarray, r: float | np.ndarray) -> np.ndarray:
    """The two multipliers of the frozen-wall impact map at the SIM point A = A_w/g (Eq. 10), shape (..., 2):
    roots of lambda^2 - (2r - pi (1 - r^2) cot(theta) / 2) lambda + r^2."""
    r = np.asarray(r, dtype=float)
    theta = sim_phase(A, r)
    trace = 2.0 * r - 0.5 * np.pi * (1.0 - r * r) / np.tan(theta)
    disc = np.sqrt((trace * trace - 4.0 * r * r).astype(complex))
    return np.stack([(trace + disc) / 2.0, (trace - disc) / 2.0], axis=-1)


def fast_stable(A: float | np.ndarray, r: float | np.ndarray) -> np.ndarray:
    """True where the two-impact orbit is stable on the fast scale, cot(theta) < 4k/pi^2 (Eq. 10)."""
    theta = sim_phase(A, r)
    with np.errstate(invalid="ignore"):
        return 1.0 / np.tan(theta) < 4.0 * restitution_factor(r) / np.pi**2


def fast_stability_limit(r: float) -> float:
    """A^_c (-): the largest wall amplitude / g with a fast-stable two-impact orbit (Eqs. 4, 10)."""
    k = float(restitution_factor(r))
    theta = -np.pi + math.atan(np.pi**2 / (4.0 * k))
    return 1.0 / (math.cos(theta) - k * math.sin(theta))


def base_ratio(A: np.ndarray, eta: np.ndarray, eps: float | np.ndarray, r: float | np.ndarray, D: float,
               coupling: float) -> np.ndarray:
    """b = a_base/g (-) at which the orbit of wall amplitude A = A_w/g exists at eta = Omega/omega (Eq. 7)."""
    eta = np.asarray(eta, dtype=float)
    Z0 = 1.0 - eta**2 + 2j * D * eta
    C = eta**2 * impact_stiffness(A, r, eps)
    return np.asarray(A) * np.abs(Z0 + C) / np.abs(coupling * eta**2 + Z0)


def _best_eta(C1: np.ndarray, D: float, eta_range: tuple[float, float] | None) -> np.ndarray:
    """eta minimising |Z0 + eta^2 C1| (Eq. 7's numerator; the denominator ~ phi_c gamma barely varies), by
    Newton on u = 1/eta for (u^2 - c)^2 + (2 D u + I)^2, c = 1 - Re C1, clipped to eta_range."""
    c, im = 1.0 - C1.real, C1.imag
    u = np.sqrt(np.maximum(c, 1e-6))
    for _ in range(8):
        f1 = 4.0 * u * (u * u - c) + 4.0 * D * (2.0 * D * u + im)
        f2 = 12.0 * u * u - 4.0 * c + 8.0 * D * D
        u = u - f1 / f2
    eta = 1.0 / u
    if eta_range is not None:
        eta = np.clip(eta, eta_range[0], eta_range[1])
    return eta


@dataclass(frozen=True)
class FoldCurve:
    """b_min(A) of Eq. 9 on the SIM grid: A (wall amplitude / g), b (a_base/g minimised over eta), eta there."""

    A: np.ndarray
    b: np.ndarray
    eta: np.ndarray

    @property
    def fold(self) -> int:
        """Index of the curve's minimum (the fold, Eq. 9)."""
        return int(np.argmin(self.b))


def fold_curve(eps: float, r: float, D: float, coupling: float,
               eta_range: tuple[float, float] | None = None, n: int = _GRID_POINTS) -> FoldCurve:
    """Eq. 9: the smallest base ratio b over eta for each wall amplitude on the SIM (log grid from A^_min)."""
    A = _sim_grid(r, eps, n)
    C1 = impact_stiffness(A, r, eps)
    eta = _best_eta(C1, D, eta_range)
    return FoldCurve(A, base_ratio(A, eta, eps, r, D, coupling), eta)


@dataclass(frozen=True)
class TwoImpactOrbit:
    """One symmetric two-impact 1:1 orbit of the slow flow at (level, eta) (Eqs. 4-10).

    A_wall: absolute wall amplitude (m); tip_amplitude: |c_1| of the tip relative to the base (m);
    normalised: tip_amplitude / a_noabs* (-, Sect. 5); impact_phase: Omega t of the left-wall impact (rad in
    [0, 2 pi)), the excitation being a_base cos(Omega t); theta: the wall's phase at that impact (rad);
    sphere_speed: V (m/s); energy_loss: per period (J, Eq. 8); fast_multipliers (Eq. 10) and slow_eigenvalues
    (Jacobian of Eq. 6, 1/s scaled by omega: per unit tau); stable: both scales stable.
    """

    level: float
    eta: float
    A_wall: float
    tip_amplitude: float
    normalised: float
    impact_phase: float
    theta: float
    sphere_speed: float
    energy_loss: float
    fast_multipliers: tuple[complex, complex]
    slow_eigenvalues: tuple[complex, complex]

    @property
    def fast_stable(self) -> bool:
        return bool(max(abs(m) for m in self.fast_multipliers) < 1.0)

    @property
    def slow_stable(self) -> bool:
        return bool(max(e.real for e in self.slow_eigenvalues) < 0.0)

    @property
    def stable(self) -> bool:
        return self.fast_stable and self.slow_stable


def _slow_rhs(a: complex, b: float, eta: float, model: SlowFlowModel) -> complex:
    """da/dtau of Eq. 6 (host amplitude relative to the base, units of g); no impacts below the SIM's end."""
    h = model.host
    Z0 = 1.0 - eta**2 + 2j * h.D * eta
    a_w = a + b
    A = abs(a_w)
    C = complex(eta**2 * impact_stiffness(A, model.r, model.eps)) if A >= sim_min_amplitude(model.r, model.eps) else 0j
    return (h.coupling * eta**2 * b - Z0 * a - C * a_w) / (2j * eta)


def _slow_eigenvalues(a: complex, b: float, eta: float, model: SlowFlowModel) -> tuple[complex, complex]:
    """Eigenvalues of the Jacobian of Eq. 6 in (Re a, Im a) at a fixed point (central differences)."""
    step = 1e-7 * max(abs(a), 1.0)
    J = np.empty((2, 2))
    for j, da in enumerate((step, 1j * step)):
        d = (_slow_rhs(a + da, b, eta, model) - _slow_rhs(a - da, b, eta, model)) / (2.0 * step)
        J[:, j] = d.real, d.imag
    ev = np.linalg.eigvals(J)
    return complex(ev[0]), complex(ev[1])


def _orbit(model: SlowFlowModel, A: float, b: float, eta: float) -> TwoImpactOrbit:
    h = model.host
    Z0 = 1.0 - eta**2 + 2j * h.D * eta
    C = complex(eta**2 * impact_stiffness(A, model.r, model.eps))
    a_w = b * (h.coupling * eta**2 + Z0) / (Z0 + C)  # Eq. 7 (|a_w| = A at the root)
    a = a_w - b
    theta = float(sim_phase(A, model.r, model.eps))
    Omega = eta * h.omega
    tip = abs(h.phi_tip / h.phi_c) * abs(a) * model.g
    level = float(model.level(b))
    a_noabs = h.phi_tip * h.participation * level * model.a_base_star / (2.0 * model.nominal.D1)
    speed = 2.0 * Omega * model.g * (1.0 - A * math.cos(theta)) / (math.pi * (1.0 + model.eps * (1.0 - 8.0 / math.pi**2)))
    loss = math.pi * h.omega**2 * model.g**2 * C.imag * A * A / h.phi_c**2
    mult = fast_multipliers(A, model.r)
    return TwoImpactOrbit(
        level=level, eta=eta, A_wall=A * model.g, tip_amplitude=tip, normalised=tip / a_noabs,
        impact_phase=float((theta - np.angle(a_w)) % (2.0 * math.pi)), theta=theta, sphere_speed=speed,
        energy_loss=loss, fast_multipliers=(complex(mult[0]), complex(mult[1])),
        slow_eigenvalues=_slow_eigenvalues(a, b, eta, model))


def periodic_orbits(model: SlowFlowModel, level: float, eta: float) -> list[TwoImpactOrbit]:
    """All two-impact 1:1 orbits of the slow flow at excitation level a_base/a_base* and eta = Omega/omega_1
    (Eq. 7 solved for the wall amplitude), by ascending amplitude; empty when none exists (below the fold)."""
    if not (math.isfinite(level) and level > 0 and math.isfinite(eta) and eta > 0):
        raise SimulationInputError(f"slow flow: level and eta must be positive, got {level!r}, {eta!r}")
    h = model.host
    b_target = level * model.a_base_star / model.g
    A = _sim_grid(model.r, model.eps)

    def f(x: float | np.ndarray) -> float | np.ndarray:
        return base_ratio(x, eta, model.eps, model.r, h.D, h.coupling) - b_target

    values = f(A)
    roots = [brentq(f, A[i], A[i + 1], xtol=1e-14, rtol=1e-13)
             for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]
    return [_orbit(model, float(x), b_target, eta) for x in roots]


@dataclass(frozen=True)
class SwitchPrediction:
    """Eq. 9: level (a_base/a_base*) of the fold, where the two-impact orbit first exists (the SMR -> APR switch);
    eta there; A_wall at the fold (m); fast_stable: whether the orbit at the fold is fast-stable (Eq. 10);
    stable_level: the lowest level with a fast-stable orbit on the rising part (NaN if it has none)."""

    level: float
    eta: float
    A_wall: float
    fast_stable: bool
    stable_level: float


def switch_level(model: SlowFlowModel, eta_range: tuple[float, float] | None = None) -> SwitchPrediction:
    """The predicted SMR -> APR switch of Eq. 9, over eta in eta_range (None: the whole resonance)."""
    h = model.host
    curve = fold_curve(model.eps, model.r, h.D, h.coupling, eta_range)
    i = curve.fold
    rising = np.arange(curve.A.size) >= i
    ok = rising & fast_stable(curve.A, model.r)
    stable_level = float(model.level(curve.b[ok].min())) if ok.any() else math.nan
    return SwitchPrediction(level=float(model.level(curve.b[i])), eta=float(curve.eta[i]),
                            A_wall=float(curve.A[i] * model.g), fast_stable=bool(fast_stable(curve.A[i], model.r)),
                            stable_level=stable_level)


def apr_branch(model: SlowFlowModel, levels: np.ndarray,
               eta_range: tuple[float, float] | None = None) -> np.ndarray:
    """Resonant level a/a_noabs* (-) of the almost periodic branch against a_base/a_base* (Eq. 9: the rising
    part's largest amplitude over eta); NaN below the switch."""
    levels = np.asarray(levels, dtype=float)
    h = model.host
    curve = fold_curve(model.eps, model.r, h.D, h.coupling, eta_range)
    tip = _tip_on_curve(curve, model.eps, model.r, h)
    i = curve.fold
    b = levels * model.a_base_star / model.g
    rising = np.maximum.accumulate(curve.b[i:])  # monotone even where eta_range clips the best eta
    A_tip = np.interp(b, rising, tip[i:], left=np.nan, right=np.nan)
    a_noabs = h.phi_tip * h.participation * levels * model.a_base_star / (2.0 * model.nominal.D1)
    return A_tip * model.g / a_noabs


def _tip_on_curve(curve: FoldCurve, eps: float | np.ndarray, r: float | np.ndarray, h: HostMode) -> np.ndarray:
    """|a| (tip relative to base, units of g, times phi_tip/phi_c) along a fold curve, Eq. 7."""
    Z0 = 1.0 - curve.eta**2 + 2j * h.D * curve.eta
    C = curve.eta**2 * impact_stiffness(curve.A, r, eps)
    b = curve.b
    a_w = b * (h.coupling * curve.eta**2 + Z0) / (Z0 + C)
    return np.abs(a_w - b) * abs(h.phi_tip / h.phi_c)


@dataclass(frozen=True)
class Screening:
    """Result of `screen`, arrays of shape (n_clearances, n_masses, n_levels): tip (resonant tip amplitude
    relative to the base, m), regime ('linear', 'SMR', 'APR'), two_impact_stable (the APR's two-impact orbit is
    fast-stable by the eps -> 0 criterion of Eq. 10, False elsewhere; at eps of a few % the exact orbit breaks
    its symmetry earlier, `orbit_map`); switch_a_base (n_clearances, n_masses): the base amplitude of the
    switch (m)."""

    tip: np.ndarray
    regime: np.ndarray
    two_impact_stable: np.ndarray
    switch_a_base: np.ndarray


def screen(host: HostMode, clearances: np.ndarray, masses: np.ndarray | None, a_base: np.ndarray, r: float,
           eta_range: tuple[float, float] | None = None, *, radii: np.ndarray | None = None,
           density: float | None = None) -> Screening:
    """Vectorised screening of designs (`ies design`): for every clearance g (m), sphere mass m_a (kg)
    and base amplitude a_base (m) the predicted resonant tip amplitude (m) and regime.

    linear: the wall's linear resonant amplitude stays below g (no impacts), tip from the mode's frequency
    response; APR: at or above the switch (Eq. 9), tip of the rising branch at its best eta; SMR: between the
    first impacts and the switch, tip estimated by the orbit at the fold, a pessimistic stand-in for the
    relaxation cycle (the rig at a_base/a_base* = 5: simulated resonant mean 0.14 mm, fold orbit 0.35 mm).
    The switch itself is the fold, a lower bound (module docstring, validity). Each mass costs one fold curve; clearances and levels are interpolations on it
    (the slow flow with rigid walls depends on g and a_base only through b = a_base/g). Give the spheres as
    masses (kg), or masses=None with radii (m) and density (kg/m^3). eta_range: the stepped sine's eta range.
    """
    if masses is None:
        if radii is None or density is None or not (isinstance(density, (int, float)) and density > 0):
            raise SimulationInputError("screening: give sphere masses (kg), or radii (m) with a positive density (kg/m^3)")
        masses = ball_mass(radii, density)
    g = np.asarray(clearances, dtype=float)[:, None, None]
    m = np.asarray(masses, dtype=float)
    L = np.asarray(a_base, dtype=float)[None, None, :]
    if g.size == 0 or m.size == 0 or L.size == 0:
        raise SimulationInputError("screening: empty clearance, mass or excitation range")
    if np.any(~np.isfinite(g)) or np.any(g <= 0) or np.any(~np.isfinite(m)) or np.any(m <= 0) or np.any(L <= 0):
        raise SimulationInputError("screening: clearances, masses and base amplitudes must be positive numbers")
    r = check_restitution(r)
    b = L / g  # (ng, 1, nl)
    shape = (g.shape[0], m.size, L.shape[2])
    tip = np.empty(shape)
    regime = np.empty(shape, dtype=object)
    stable = np.zeros(shape, dtype=bool)
    switch = np.empty((g.shape[0], m.size))
    # linear response of the mode at its resonance (within eta_range): wall amplitude per unit b, tip per unit b
    eta_lin = np.linspace(*(eta_range or (0.9, 1.1)), 2001)
    Z0 = 1.0 - eta_lin**2 + 2j * host.D * eta_lin
    wall_lin = np.abs((host.coupling * eta_lin**2 + Z0) / Z0).max()
    tip_lin = (abs(host.phi_tip / host.phi_c) * host.coupling * eta_lin**2 / np.abs(Z0)).max()
    for j, m_a in enumerate(m):
        eps = m_a * host.phi_c**2
        curve = fold_curve(eps, r, host.D, host.coupling, eta_range)
        i = curve.fold
        tip_curve = _tip_on_curve(curve, eps, r, host)
        b_fold = curve.b[i]
        rising_b, rising_tip = np.maximum.accumulate(curve.b[i:]), tip_curve[i:]
        stable_curve = fast_stable(curve.A[i:], r)
        bj = b[:, 0, :]
        gj = g[:, 0, :]
        apr = bj >= b_fold
        linear = bj * wall_lin < 1.0
        tip_apr = np.interp(bj, rising_b, rising_tip) * gj
        idx = np.clip(np.searchsorted(rising_b, bj), 0, rising_b.size - 1)
        tip[:, j, :] = np.where(apr, tip_apr, np.where(linear, bj * tip_lin * gj,
                                                       np.minimum(tip_curve[i], bj * tip_lin) * gj))
        regime[:, j, :] = np.where(apr, APR, np.where(linear, LINEAR, SMR))
        stable[:, j, :] = apr & stable_curve[idx]
        switch[:, j] = b_fold * g[:, 0, 0]
    return Screening(tip=tip, regime=regime, two_impact_stable=stable, switch_a_base=switch)



# --- The exact symmetric orbit of the one-mode Newton model (the slow flow's reference) ---------------------

def _flight(x0: float, v0: float, tau0: float, tau: np.ndarray, D: float, eta: float,
            Xp: complex) -> tuple[np.ndarray, np.ndarray]:
    """x(tau), x'(tau) of Eq. 1 without impacts (units of g, tau = omega t) from x0, v0 at tau0: the forced
    particular solution Re(Xp e^{i eta tau}) plus the damped free vibration."""
    wd = math.sqrt(1.0 - D * D)
    p0 = Xp * np.exp(1j * eta * tau0)
    c1 = x0 - p0.real
    c2 = (v0 - (1j * eta * p0).real + D * c1) / wd
    s = np.asarray(tau) - tau0
    e = np.exp(-D * s)
    xh = e * (c1 * np.cos(wd * s) + c2 * np.sin(wd * s))
    vh = e * ((c2 * wd - D * c1) * np.cos(wd * s) - (c1 * wd + D * c2) * np.sin(wd * s))
    p = Xp * np.exp(1j * eta * np.asarray(tau))
    return xh + p.real, vh + (1j * eta * p).real


@dataclass(frozen=True)
class ExactOrbit:
    """The exact symmetric two-impact orbit of the one-mode model with Newton's law (Eq. 1, restitution r,
    recoil of the host mass M = 1/phi_c^2 included), found by shooting from a slow-flow orbit.
    multipliers: eigenvalues of the half-period map (left impact -> right impact, mirrored) in (x, x', V, tau).

    tip_amplitude: |c_1| of the tip relative to the base (m); normalised (/ a_noabs*); impact_phase: Omega t of
    the left-wall impact (rad, [0, 2 pi)); sphere_speed (m/s) after it; admissible: the sphere meets no wall in
    between (checked on 4000 points of the flight); residual: of the shooting equations (-).
    """

    level: float
    eta: float
    tip_amplitude: float
    normalised: float
    impact_phase: float
    sphere_speed: float
    admissible: bool
    residual: float
    multipliers: tuple[complex, ...] = ()

    @property
    def stable(self) -> bool:
        """All multipliers of the half-period map (impact, mirror) inside the unit circle; one leaving through -1
        breaks the orbit's symmetry (an asymmetric two-impact orbit takes over)."""
        return bool(self.multipliers) and max(abs(m) for m in self.multipliers) < 1.0


def exact_orbit(model: SlowFlowModel, level: float, eta: float, guess: TwoImpactOrbit) -> ExactOrbit:
    """Shoot the exact symmetric orbit at (level, eta) from the slow-flow orbit `guess` (Eq. 1 between impacts,
    Newton's law at them, the mirror symmetry x(tau + T/2) = -x(tau) of the base-excited system)."""
    from scipy.optimize import fsolve

    h, g, r, eps = model.host, model.g, model.r, model.eps
    b = level * model.a_base_star / g
    T = 2.0 * math.pi / eta
    Xp = h.coupling * eta**2 * b / (1.0 - eta**2 + 2j * h.D * eta)
    wall = lambda x, tau: x + b * np.cos(eta * tau)
    wall_v = lambda v, tau: v - b * eta * np.sin(eta * tau)

    def residual(z: np.ndarray) -> np.ndarray:
        x0, v0, V, tau0 = z
        x1, v1 = _flight(x0, v0, tau0, np.array([tau0 + T / 2.0]), h.D, eta, Xp)
        u1 = wall(x0, tau0) - 1.0 + V * T / 2.0
        P = -(1.0 + r) * (V - wall_v(v1[0], tau0 + T / 2.0)) / (1.0 + eps)  # impulse on the sphere (< 0)
        return np.array([x1[0] + x0, (v1[0] - eps * P) + v0, (V + P) + V, u1 - wall(x1[0], tau0 + T / 2.0) - 1.0])

    tau0 = guess.impact_phase / eta
    a_w = (guess.A_wall / g) * np.exp(1j * (guess.theta - guess.impact_phase))
    a = a_w - b
    x0 = float((a * np.exp(1j * eta * tau0)).real)
    v0 = float((1j * eta * a * np.exp(1j * eta * tau0)).real)
    z, _info, _ok, _ = fsolve(residual, [x0, v0, guess.sphere_speed / (h.omega * g), tau0], full_output=True,
                            xtol=1e-13)
    x0, v0, V, tau0 = z
    tau = tau0 + np.linspace(0.0, T / 2.0, 4001)
    x, _ = _flight(x0, v0, tau0, tau, h.D, eta, Xp)
    u = wall(x0, tau0) - 1.0 + V * (tau - tau0)
    inside = (wall(x, tau)[1:-1] - u[1:-1] < 1.0) & (u[1:-1] - wall(x, tau)[1:-1] < 1.0)
    weights = np.full(tau.size, 2.0)
    weights[1:-1:2], weights[0], weights[-1] = 4.0, 1.0, 1.0  # Simpson (x(tau + T/2) = -x(tau): half a period)
    c1 = 4.0 / T * (T / 2.0 / (tau.size - 1) / 3.0) * np.sum(weights * x * np.exp(-1j * eta * tau))
    tip = abs(h.phi_tip / h.phi_c) * abs(c1) * g
    a_noabs = h.phi_tip * h.participation * level * model.a_base_star / (2.0 * model.nominal.D1)
    def half_map(state: np.ndarray) -> np.ndarray:
        # from just after a left impact to just after the next (right) impact, mirrored: x -> -x, V -> -V
        x_0, v_0, V_0, t_0 = state
        t = t_0 + np.linspace(0.0, T, 2001)[1:]
        xs, _ = _flight(x_0, v_0, t_0, t, h.D, eta, Xp)
        gap = V_0 * (t - t_0) + wall(x_0, t_0) - 1.0 - wall(xs, t) - 1.0
        j = int(np.argmax(gap >= 0.0))

        def gap_at(tt: float) -> float:
            return float(V_0 * (tt - t_0) + wall(x_0, t_0) - 2.0 - wall(_flight(x_0, v_0, t_0, np.array([tt]), h.D,
                                                                                  eta, Xp)[0][0], tt))
        t1 = brentq(gap_at, t[j - 1] if j else t_0 + 1e-12, t[j], xtol=1e-15, rtol=1e-15)
        x1, v1 = _flight(x_0, v_0, t_0, np.array([t1]), h.D, eta, Xp)
        P = -(1.0 + r) * (V_0 - wall_v(v1[0], t1)) / (1.0 + eps)
        return np.array([-x1[0], -(v1[0] - eps * P), -(V_0 + P), t1 - T / 2.0])

    J = np.empty((4, 4))
    for j in range(4):
        dz = np.zeros(4)
        dz[j] = 1e-6 * max(1.0, abs(z[j]))
        J[:, j] = (half_map(z + dz) - half_map(z - dz)) / (2.0 * dz[j])
    multipliers = tuple(complex(m) for m in np.linalg.eigvals(J))
    return ExactOrbit(level=level, eta=eta, tip_amplitude=tip, normalised=tip / a_noabs,
                      impact_phase=float((eta * tau0) % (2.0 * math.pi)), sphere_speed=float(V * h.omega * g),
                      admissible=bool(np.all(inside)), residual=float(np.max(np.abs(residual(z)))),
                      multipliers=multipliers)


# --- Which symmetric two-impact orbits exist and are stable against level and frequency ---------------------

#: `orbit_map` codes per (level, eta) cell, for the symmetric two-impact orbit of the one-mode Newton model.
NO_ORBIT, STABLE, SYMMETRY_BREAKING, SADDLE = "none", "stable", "symmetry-breaking", "saddle"


@dataclass(frozen=True)
class OrbitMap:
    """Existence and stability of the symmetric two-impact 1:1 orbits on a (level, eta) grid (`orbit_map`).

    levels (a_base/a_base*), etas (Omega/omega_1); n_orbits[i, j]: how many exist (Eq. 7); best[i, j]: the code of
    the most stable one (STABLE, else SYMMETRY_BREAKING: a multiplier of the half-period map below -1, an
    asymmetric orbit takes over; else SADDLE: a multiplier above +1, the slow flow leaves; NO_ORBIT); normalised
    [i, j]: the tip level a/a_noabs* of that orbit (NaN where none).
    """

    levels: np.ndarray
    etas: np.ndarray
    n_orbits: np.ndarray
    best: np.ndarray
    normalised: np.ndarray


def orbit_map(model: SlowFlowModel, levels: np.ndarray, etas: np.ndarray) -> OrbitMap:
    """Map the symmetric two-impact orbits of the one-mode Newton model over levels x etas: the slow flow finds
    them (Eq. 7), the exact shooting (`exact_orbit`) decides their stability (multipliers of the half-period map)."""
    levels, etas = np.asarray(levels, dtype=float), np.asarray(etas, dtype=float)
    shape = (levels.size, etas.size)
    n_orbits = np.zeros(shape, dtype=int)
    best = np.full(shape, NO_ORBIT, dtype=object)
    normalised = np.full(shape, np.nan)
    rank = {STABLE: 0, SYMMETRY_BREAKING: 1, SADDLE: 2}
    for i, level in enumerate(levels):
        for j, eta in enumerate(etas):
            orbits = periodic_orbits(model, float(level), float(eta))
            n_orbits[i, j] = len(orbits)
            for orbit in orbits:
                exact = exact_orbit(model, float(level), float(eta), orbit)
                if not exact.admissible:
                    continue
                worst = max(exact.multipliers, key=abs)
                code = STABLE if exact.stable else (SYMMETRY_BREAKING if worst.real < 0 else SADDLE)
                if best[i, j] == NO_ORBIT or rank[code] < rank[best[i, j]]:
                    best[i, j], normalised[i, j] = code, exact.normalised
    return OrbitMap(levels, etas, n_orbits, best, normalised)


__all__ = ["NO_ORBIT", "SADDLE", "STABLE", "SYMMETRY_BREAKING", "ExactOrbit", "FoldCurve", "HostMode", "OrbitMap", "Screening", "SlowFlowModel", "SwitchPrediction", "TwoImpactOrbit", "apr_branch", "base_ratio", "check_restitution", "effective_factor", "exact_orbit", "fast_multipliers", "fast_stability_limit", "fast_stable", "fold_curve", "host_mode", "impact_stiffness", "orbit_map", "periodic_orbits", "restitution_factor", "screen", "sim_min_amplitude", "sim_phase", "slow_flow_model", "switch_level"]
