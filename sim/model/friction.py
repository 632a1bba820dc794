"""Dry friction between the sphere and the cavity floor (seed paper, Appendix C): an elastic Coulomb (Jenkins)
element, a spring k_t in series with a Coulomb slider of limit mu N, N = m_a g (gravity along the beam axis).

Spring elongation w = u - z, u the sphere's x-displacement relative to the floor point, z the slider's
position on the floor. The element's force on the sphere is -k_t w.
* stick: z is constant, |k_t w| < mu N: the element is a linear spring;
* slip: |k_t w| = mu N, w is constant (= s mu N / k_t, s = +-1) and z' = u': a constant force -s mu N;
* stick -> slip when |k_t w| reaches mu N; slip -> stick when the slip velocity u' returns to 0.
The slider dissipates mu N |z'| (W); over a closed cycle of w this equals the area of the force-displacement
loop, the integral of k_t w du.

`floor_driven_response` solves the single-DOF case (the sphere of mass m on a floor moved by X cos(Omega t)) in
closed form phase by phase, with the transitions located by bracketing and Brent's method: stick is a
harmonically forced undamped oscillator, slip a constant force. This is the scheme the exact integrator
needs; `sim.integration.references.jenkins_reference` is its independent check (scipy DOP853 with events).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from sim.common.errors import SimulationInputError
from sim.model.parameters import GRAVITY, K_T_PAPER, MU_PAPER, SPHERE_MASS  # noqa: F401 (re-exported)


@dataclass(frozen=True)
class JenkinsElement:
    """Elastic Coulomb element of Appendix C: stiffness k_t (N/m), friction coefficient mu (-), normal force
    normal_force (N, default the sphere's weight m_a g). mu = 0 switches friction off."""

    k_t: float = K_T_PAPER
    mu: float = MU_PAPER
    normal_force: float = SPHERE_MASS * GRAVITY

    def __post_init__(self) -> None:
        for name, text, allow_zero in (("k_t", "k_t (N/m, e.g. 22e6)", False), ("mu", "friction coefficient mu", True),
                                       ("normal_force", "normal force (N)", False)):
            value = getattr(self, name)
            ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
            if not ok or value < 0 or (value == 0 and not allow_zero):
                raise SimulationInputError(f"{text} must be {'>= 0' if allow_zero else '> 0'}, got {value!r}")
            object.__setattr__(self, name, float(value))

    @property
    def slip_force(self) -> float:
        """Coulomb limit mu N (N)."""
        return self.mu * self.normal_force

    @property
    def slip_elongation(self) -> float:
        """Spring elongation at the slip limit, mu N / k_t (m)."""
        return self.slip_force / self.k_t


def floor_values(model, source: str = "the modal model") -> np.ndarray:
    """The modal x-values at the cavity floor (1/sqrt(kg)) that friction acts on (Appendix C); one line naming
    the key if the model has none."""
    if model.phi_floor is None:
        raise SimulationInputError(f"friction needs the mode values at the cavity floor: {source} has no 'phi_floor'; "
                                   "add it to the modal file (1/sqrt(kg), one per mode) or save the built-in rig with "
                                   "`ies modes --save`")
    return model.phi_floor


@dataclass
class FloorDrivenResult:
    """Closed-form response of a mass on a moved floor with a Jenkins element: state at t_end (u, u', z in m,
    m/s, m relative to the floor), the transitions [(time s, "slip" | "stick", sign)], the slider's dissipated
    energy (J) and the phases [(t0, t1, kind, sign, u0, v0, z0)] to sample with `relative_displacement`."""

    u: float
    v: float
    z: float
    transitions: list
    dissipated: float
    phases: list


def _first_root(g: Callable[[np.ndarray], np.ndarray], t0: float, t_end: float, h: float) -> float | None:
    """First time in (t0, t_end] where g rises through zero (g < 0 just after t0), or None."""
    chunk = 2048
    start = t0
    while start < t_end:
        ts = np.minimum(start + h * np.arange(1, chunk + 1), t_end)
        values = g(ts)
        above = np.flatnonzero(values >= 0)
        if above.size:
            i = int(above[0])
            left = ts[i - 1] if i else start
            if float(g(np.array([left]))[0]) >= 0:  # touching at the start: the phase begins on its boundary
                left = start + 1e-3 * h
            return brentq(lambda t: float(g(np.array([t]))[0]), left, ts[i], xtol=1e-16, rtol=4 * np.finfo(float).eps)
        if ts[-1] >= t_end:
            return None
        start = ts[-1]
    return None


def floor_driven_response(element: JenkinsElement, mass: float, X: float, Omega: float, t_end: float,
                          u0: float = 0.0, v0: float = 0.0, z0: float = 0.0) -> FloorDrivenResult:
    """A mass (kg) tied by `element` to a floor moving as X cos(Omega t) (m, rad/s), from t = 0 to t_end (s),
    starting in stick at relative displacement u0 (m), velocity v0 (m/s) and slider position z0 (m), with
    |k_t (u0 - z0)| < mu N. Closed form per phase (Appendix C's element on a single DOF), transitions located to
    machine precision."""
    if not (element.mu > 0 and mass > 0 and X >= 0 and Omega > 0 and t_end > 0):
        raise SimulationInputError("floor_driven_response needs mu > 0, mass > 0, X >= 0, Omega > 0 and t_end > 0")
    w_s = element.slip_elongation
    if abs(u0 - z0) >= w_s:
        raise SimulationInputError("the initial spring force must lie inside the slip limit (start in stick)")
    w2 = element.k_t / mass
    w = math.sqrt(w2)
    A = X * Omega**2  # floor acceleration amplitude: u'' = -w2 (u - z) + A cos(Omega t)
    h = min(2 * math.pi / w, 2 * math.pi / Omega) / 40
    t, u, v, z = 0.0, float(u0), float(v0), float(z0)
    kind, sign = "stick", 0.0
    transitions, phases, dissipated = [], [], 0.0
    while t < t_end:
        if kind == "stick":
            P = A / (w2 - Omega**2)
            C = (u - z) - P * math.cos(Omega * t)
            D = (v + P * Omega * math.sin(Omega * t)) / w
            t0 = t
            elong = lambda ts: C * np.cos(w * (ts - t0)) + D * np.sin(w * (ts - t0)) + P * np.cos(Omega * ts)  # noqa: E731
            candidates = [(r, s) for s in (1.0, -1.0)
                          if (r := _first_root(lambda ts, s=s: s * elong(ts) - w_s, t0, t_end, h)) is not None]
            t_next, s_next = min(candidates) if candidates else (t_end, 0.0)
            vel = -C * w * math.sin(w * (t_next - t0)) + D * w * math.cos(w * (t_next - t0)) - P * Omega * math.sin(Omega * t_next)
            phases.append((t0, t_next, "stick", 0.0, u, v, z))
            u, v = z + float(elong(np.array([t_next]))[0]), vel
            if s_next:
                u = z + s_next * w_s  # on the limit exactly
                kind, sign = "slip", s_next
                transitions.append((t_next, "slip", s_next))
        else:
            t0, ua, va, s = t, u, v, sign

            def vel(ts, t0=t0, va=va, s=s):
                return va - w2 * s * w_s * (ts - t0) + A / Omega * (np.sin(Omega * ts) - math.sin(Omega * t0))

            def disp(ts, t0=t0, ua=ua, va=va, s=s):
                tau = ts - t0
                return (ua + va * tau - 0.5 * w2 * s * w_s * tau**2 - A / Omega**2 * (np.cos(Omega * ts) - math.cos(Omega * t0))
                        - A / Omega * math.sin(Omega * t0) * tau)

            root = _first_root(lambda ts: -s * vel(ts), t0, t_end, h)
            t_next = t_end if root is None else root
            phases.append((t0, t_next, "slip", s, ua, va, ua - s * w_s))
            u = float(disp(np.array([t_next]))[0])
            dissipated += element.slip_force * abs(u - ua)  # u' keeps its sign s in slip
            z = u - s * w_s
            v = 0.0 if root is not None else float(vel(np.array([t_next]))[0])
            if root is not None:
                kind = "stick"
                transitions.append((t_next, "stick", s))
        t = t_next
    return FloorDrivenResult(u, v, z, transitions, dissipated, phases)
