r"""Starting points of the shooting (`sim.orbits.shooting`): the linear solution, the slow flow's symmetric
two-impact orbit carried to the full model by continuation, and a simulated state.

* `linear_state` (Eq. 7 without contacts): every mode on its particular harmonic solution S_j (the module
  docstring of `sim.integration.exact`), s_j = Re S_j, s_j' = -Omega Im S_j at phase 0, the sphere at rest in the
  inertial frame at the cavity's centre (u_a = -a_base, u_a' = 0). It is a periodic orbit exactly when the walls'
  motion relative to the base, |W_w| = |phi_w^T S + a_base|, stays below the clearance (`linear_wall_amplitude`):
  the linear frequency response, with the sphere neutral (it may rest anywhere it is not reached).
* `slow_flow_state` (`sim.reduced.slow_flow`, Eqs. 4-7 there): mode 1 on the slow flow's fundamental a (relative
  wall motion a g / phi_c at the walls), the higher modes on their particular solutions, the sphere on its flight
  between the impacts at the orbit's impact phase with its speed V: after the left impact at Omega t_L it leaves
  the left wall (absolute position w(t_L) - g) at +V, after the right one at t_L + T/2 the right wall (w + g) at -V.
* `slow_flow_orbit`: the full model's symmetric two-impact orbit. Newton's method does not reach it from the slow
  flow on the nominal host (the ringing higher modes make the half map's multipliers ~ 10-50 and its basin
  ~1e-3 g, `sim.orbits.shooting`), but it does with the higher modes' damping raised a hundredfold or more
  (HOMOTOPY_DAMPING: they ring out between impacts and the map is close to the one-mode map the slow flow
  averages); from there the orbit is continued in that factor (`higher_damping`, log) down to the setting's value. If that continuation turns back (a
  fold) before reaching it, there is no such orbit connected to the slow flow's, and the function says where.
* `stepped_sine_state`: the state a stepped sine reaches at a point, stepping from another eta as the protocol does
  (`simulated_state`: the state after a number of periods from a given state): a start near a stable orbit.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from sim.common.errors import SimulationInputError
from sim.integration.integrators import get_integrator
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import OrbitNotConverged, PeriodicOrbit, ShootingMap, solve_orbit

#: The higher modes' damping factors from which `slow_flow_orbit` starts, tried in turn (modes 2..N ring out within
#: a period; the damping ratios are capped at 0.5): on the rig Newton's method reaches the two-impact orbit from the
#: slow flow at 100x at 7.4, but only at 300x at level 5.
HOMOTOPY_DAMPING = (100.0, 300.0)
#: The stepped-sine start's grid step in eta and wait per point (s): the fidelity studies' protocol (0.002, 3 s).
STEP = 0.002
WAIT = 3.0
#: The slow flow's modal restitution r (Eq. D.1) of the start: the simulator's value on the rig near resonance
#: (`sim.reduced.slow_flow`'s validity table: 0.857); only the start depends on it, not the orbit found.
DEFAULT_RESTITUTION = 0.86


def particular_solution(setting: OrbitSetting) -> np.ndarray:
    """S_j = gamma_j a_base Omega^2 / (omega_j^2 - Omega^2 + 2 i D_j omega_j Omega) (complex, m sqrt(kg)): the forced
    harmonic response of each mode to the base motion a_base cos(Omega t) (Eq. 7 without contacts)."""
    host, Om = setting.host, setting.Omega
    w = host.omega
    return host.participation * setting.a_base * Om**2 / (w**2 - Om**2 + 2j * host.damping_ratios * w * Om)


def linear_wall_amplitude(setting: OrbitSetting) -> float:
    """max over both walls of |phi_w^T S + a_base| (m): the amplitude of the linear response's wall motion relative
    to the base and hence to a sphere at rest in the inertial frame. Below the clearance g the linear solution is a
    periodic orbit without impacts."""
    S = particular_solution(setting)
    m = setting.model
    return max(abs(complex(m.phi_wall_left @ S) + setting.a_base), abs(complex(m.phi_wall_right @ S) + setting.a_base))


def linear_state(setting: OrbitSetting) -> np.ndarray:
    """The linear solution's state at phase 0 (module docstring), SI."""
    S = particular_solution(setting)
    n = S.size
    y = np.zeros(2 * n + 2)
    y[:n] = S.real
    y[n:2 * n] = -setting.Omega * S.imag
    y[2 * n] = -setting.a_base
    return y


def linear_orbit(setting: OrbitSetting) -> PeriodicOrbit:
    """The linear solution as a `PeriodicOrbit` (no impacts); one line if the walls reach the sphere at this level
    (then there is no linear orbit: start from the slow flow)."""
    reach = linear_wall_amplitude(setting)
    if reach >= setting.impactor.clearance:
        raise SimulationInputError(f"orbits: at eta {setting.eta:g}, level {setting.level:g} the linear response moves "
                                   f"the walls by {reach / setting.impactor.clearance:.3g} g: the sphere is hit, there "
                                   "is no linear orbit (start from the slow flow)")
    return solve_orbit(setting, linear_state(setting), symmetric=False)


def slow_flow_state(setting: OrbitSetting, orbit: object) -> np.ndarray:
    """The full model's state at phase 0 built from a slow-flow orbit (`sim.reduced.slow_flow.TwoImpactOrbit`;
    module docstring), SI."""
    g = setting.impactor.clearance
    Om, T = setting.Omega, setting.period
    b = setting.a_base / g
    a_w = (orbit.A_wall / g) * np.exp(1j * (orbit.theta - orbit.impact_phase))  # absolute wall motion / g
    a = a_w - b  # relative to the base
    phi_c = setting.model.phi_contact
    y = linear_state(setting)
    n = setting.model.n_modes
    y[0] = a.real * g / phi_c
    y[n] = -Om * a.imag * g / phi_c

    def wall(t: float) -> float:
        return float((a_w * np.exp(1j * Om * t)).real) * g

    t_left = orbit.impact_phase / Om
    V = orbit.sphere_speed
    if t_left <= T / 2.0:  # phase 0 lies in the flight from the right impact at t_left - T/2
        position, velocity = wall(t_left - T / 2.0) + g - V * (T / 2.0 - t_left), -V
    else:  # in the flight from the left impact at t_left - T
        position, velocity = wall(t_left - T) - g + V * (T - t_left), V
    y[2 * n] = position - setting.a_base
    y[2 * n + 1] = velocity
    return y


def slow_flow_candidates(setting: OrbitSetting, restitution: float = DEFAULT_RESTITUTION) -> list:
    """The slow flow's symmetric two-impact orbits at the setting's level and eta (`sim.reduced.slow_flow.
    periodic_orbits`), by decreasing amplitude (the upper one first: the branch the response sits on)."""
    from sim.reduced.slow_flow import periodic_orbits, slow_flow_model

    model = slow_flow_model(setting.model, setting.impactor, restitution, setting.nominal)
    return sorted(periodic_orbits(model, setting.level, setting.eta), key=lambda o: -o.A_wall)


def slow_flow_orbit(setting: OrbitSetting, *, restitution: float = DEFAULT_RESTITUTION, which: int = 0,
                    damping: tuple[float, ...] = HOMOTOPY_DAMPING, progress: object = None) -> PeriodicOrbit:
    """The full model's symmetric two-impact orbit at the setting from the slow flow's (the `which`-th by
    decreasing amplitude), by Newton's method at the higher modes' damping times the first factor of `damping` that
    converges and continuation in that factor down to the setting's (module docstring). OrbitNotConverged with what
    to try when it fails."""
    from sim.orbits.continuation import continue_branch

    candidates = slow_flow_candidates(setting, restitution)
    if len(candidates) <= which:
        raise OrbitNotConverged(f"orbits: the slow flow has no two-impact orbit at eta {setting.eta:g}, level "
                                f"{setting.level:g} (r = {restitution:g}); try another eta (below the resonance) "
                                "or a higher level")
    symmetric = setting.symmetric_walls
    failure: Exception | None = None
    for factor in damping:
        damped = replace(setting, higher_damping=setting.higher_damping * factor)
        try:
            start = solve_orbit(damped, slow_flow_state(damped, candidates[which]), symmetric=symmetric)
            break
        except OrbitNotConverged as exc:
            failure = exc
    else:
        raise failure
    if factor == 1.0:
        return start
    target = setting.higher_damping
    branch = continue_branch(start, "higher_damping", (target, damped.higher_damping), direction=-1.0,
                             origin="slow flow", progress=progress)
    last = branch.points[-1].orbit
    if not math.isclose(last.setting.higher_damping, target, rel_tol=1e-9):
        lowest = min(p.orbit.setting.higher_damping for p in branch.points)
        raise OrbitNotConverged(f"orbits: the slow flow's two-impact orbit at eta {setting.eta:g}, level "
                                f"{setting.level:g} does not reach the setting's higher-mode damping: followed from "
                                f"{factor:g} x it turns back at {lowest:.3g} x ({branch.stop}); try another eta")
    return last


def stepped_sine_state(setting: OrbitSetting, eta_from: float, *, step: float = STEP, wait: float = WAIT) -> np.ndarray:
    """The state a stepped sine reaches at the setting's eta (Sect. 5.1, `sim.stepped_sine.protocol`): from the
    base-velocity start at eta_from, `wait` seconds at every eta of the grid eta_from, eta_from +- step, ... up to
    (or down to) the setting's eta, SI."""
    if not (math.isfinite(eta_from) and eta_from > 0 and step > 0 and wait > 0):
        raise SimulationInputError("orbits: a stepped-sine start needs a positive eta_from, step and wait")
    n = max(1, int(round(abs(setting.eta - eta_from) / step)))
    y = None
    for eta in np.linspace(eta_from, setting.eta, n + 1):
        at = replace(setting, eta=float(eta))
        y = simulated_state(at, max(1, int(round(wait / at.period))), y)
    return y


def simulated_state(setting: OrbitSetting, periods: int, y0: np.ndarray | None = None) -> np.ndarray:
    """The state after `periods` excitation periods of the setting's integrator from y0 (default: the stepped
    sine's base-velocity start, `sim.stepped_sine.protocol`), SI."""
    if int(periods) < 1:
        raise SimulationInputError(f"orbits: periods must be >= 1, got {periods!r}")
    n = setting.model.n_modes
    y = np.zeros(2 * n + 2) if y0 is None else np.array(y0, dtype=np.float64)
    if y0 is None:
        y[-1] = setting.a_base * setting.Omega
    shooting = ShootingMap(setting, 1)
    run_step = get_integrator(setting.integrator, dt_scale=setting.dt_scale if setting.integrator == "ode3" else None)
    run_step(y, int(periods), setting.Omega, setting.a_base, shooting.sys, None)
    return y
