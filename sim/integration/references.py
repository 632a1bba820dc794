"""Independent references for the simulator's tests and benchmarks (seed paper Eqs. 3-7): not our own
integrators, so our integrators can be checked against them.

* `reference_run`: scipy's `solve_ivp` (DOP853) on Eqs. 3-7 in the original coordinates
  y = [s, s', u_a, u_a'], restarted at every contact onset and release (events), so the Hertz law's
  non-smoothness never sits inside a step.
* `cantilever_like_model`: a 9-mode model with the rig's frequencies (Table A.1, f9 = 19.8 kHz) and the mode
  values of a uniform Euler-Bernoulli cantilever (closed-form effective masses), independent of `sim.hosts.rig`.
* `ringing_energy_drift`: energy conservation (a conservation law) of `sim.integration.exact` over 1000 impacts.

Imported by tests/ and tests/benchmarks/ as ordinary modules; scipy and sim.integration.exact are imported on use.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from sim.integration.energy import energy_parts
from sim.model.system import Impactor, ModalModel, SystemArrays, system_arrays


def reference_run(y0: np.ndarray, t_end: float, Omega: float, a_base: float, sys: SystemArrays, *, rtol: float = 1e-12,
                  atol_scale: float = 1e-16, pieces: list | None = None,
                  t0: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Eqs. 3-7 with the contact law sys.law at both walls (Eq. 4 by default; its force as written in
    `sim.model.contact_law`, evaluated in Python) under q_base = a_base cos(Omega t) (SI units), by DOP853 from
    y0 at t0 (s; phase Omega t0) to t_end (s), restarted at every contact event; returns (y(t_end), onset
    times (s), release times (s), rebound speeds (m/s)).

    rebound speeds: the relative speed phi_w^T s' - u_a' (sign of opening) at each release.
    pieces: a list that receives (t_start, t_stop, dense solution) of every piece between events.
    """
    from scipy.integrate import solve_ivp

    n = sys.omega.size
    w2 = sys.omega**2
    c = 2 * sys.D * sys.omega
    force = sys.law.force.py_func

    def rhs(t, y):
        s = y[:n]
        sd = y[n:2 * n]
        u = y[2 * n]
        dl = sys.phi_l @ s - u - sys.g
        dr = sys.phi_r @ s - u + sys.g
        fl = force(dl, sys.phi_l @ sd - y[2 * n + 1], sys.k_H, sys.c_damp) if dl > 0 else 0.0
        fr = -force(-dr, y[2 * n + 1] - sys.phi_r @ sd, sys.k_H, sys.c_damp) if dr < 0 else 0.0
        acc = a_base * Omega**2 * math.cos(Omega * t)
        out = np.empty_like(y)
        out[:n] = sd
        out[n:2 * n] = -c * sd - w2 * s - sys.phi_l * fl - sys.phi_r * fr + sys.gamma * acc
        out[2 * n] = y[2 * n + 1]
        out[2 * n + 1] = (fl + fr) / sys.m_a + acc
        return out

    def ev_l(t, y):
        return sys.phi_l @ y[:n] - y[2 * n] - sys.g

    def ev_r(t, y):
        return sys.phi_r @ y[:n] - y[2 * n] + sys.g

    atol = np.concatenate([np.full(n, sys.g * atol_scale), np.full(n, sys.g * atol_scale * sys.omega.max()),
                           [sys.g * atol_scale, sys.g * atol_scale * sys.omega.max()]])
    t = float(t0)
    y = np.array(y0, dtype=float)
    closed = [ev_l(t, y) > 0, ev_r(t, y) < 0]
    onsets, releases, speeds = [], [], []
    ev_l.terminal = ev_r.terminal = True
    while t < t_end:
        # closed left: look for delta_l falling through 0; open: rising. Right wall mirrored.
        ev_l.direction = -1.0 if closed[0] else 1.0
        ev_r.direction = 1.0 if closed[1] else -1.0
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=(ev_l, ev_r),
                        first_step=1e-9, dense_output=pieces is not None)
        y = sol.y[:, -1].copy()
        t_new = sol.t[-1]
        if pieces is not None:
            pieces.append((t, t_new, sol.sol))
        if sol.status == 1:
            for w in range(2):
                if sol.t_events[w].size:
                    if closed[w]:
                        releases.append(t_new)
                        phi = sys.phi_l if w == 0 else sys.phi_r
                        speeds.append(abs(phi @ y[n:2 * n] - y[2 * n + 1]))
                    else:
                        onsets.append(t_new)
                    closed[w] = not closed[w]
        if t_new <= t:
            raise RuntimeError("reference integration did not progress")
        t = t_new
    return y, np.array(onsets), np.array(releases), np.array(speeds)


# A uniform cantilever of 1.8 kg (free length of the seed's beam): mass-normalised tip value 2/sqrt(m) for
# every mode (alternating sign), participation sqrt(effective-mass fraction * m) (Euler-Bernoulli values).
_EFFECTIVE_MASS_FRACTION = (0.6131, 0.1883, 0.0647, 0.0331, 0.0200, 0.0134, 0.0096, 0.0072, 0.0056)
_FREQUENCIES_HZ = (117.4, 886.0, 2494.0, 4712.0, 7540.0, 10300.0, 13300.0, 16500.0, 19800.0)
_DAMPING = (0.00085, 0.0044, 0.0005, 0.0031, 0.001, 0.001, 0.001, 0.001, 0.001)


def cantilever_like_model(n_modes: int = 9, undamped: bool = False) -> ModalModel:
    """The first `n_modes` modes of a uniform 1.8 kg cantilever (mode values and participations above) at the
    seed rig's frequencies (Table A.1, f9 = 19.8 kHz) and damping (Table 2, Table A.1); `undamped`: D = 1e-12."""
    mass = 1.8
    j = np.arange(n_modes)
    sign = np.where(j % 2 == 0, 1.0, -1.0)
    phi_c = sign * 2.0 / np.sqrt(mass)
    damping = np.full(n_modes, 1e-12) if undamped else np.array(_DAMPING[:n_modes])
    return ModalModel(
        frequencies_hz=np.array(_FREQUENCIES_HZ[:n_modes]), damping_ratios=damping,
        phi_wall_left=phi_c, phi_wall_right=phi_c, phi_tip=0.96 * phi_c,
        participation=np.sqrt(np.array(_EFFECTIVE_MASS_FRACTION[:n_modes]) * mass),
        source="tests: cantilever-like")


def ringing_energy_drift(**run_step_options: Any) -> tuple[float, int, dict]:
    """Relative change of the total energy (`sim.integration.energy`) over >= 1000 impacts of the sphere launched at
    0.5 m/s in the undamped (D = 1e-15), unforced cantilever-like beam, by `sim.integration.exact.run_step` in calls of
    20 periods at 100 Hz with these options; with the number of impacts and the kernel's counters."""
    from sim.integration import exact

    base = cantilever_like_model(undamped=True)
    model = ModalModel(frequencies_hz=base.frequencies_hz, damping_ratios=np.full(base.n_modes, 1e-15),
                       phi_wall_left=base.phi_wall_left, phi_wall_right=base.phi_wall_right,
                       phi_tip=base.phi_tip, participation=base.participation)
    sys = system_arrays(model, Impactor())
    y = np.zeros(2 * base.n_modes + 2)
    y[-1] = 0.5
    e0 = energy_parts(y, sys)["total"][0]
    impacts = 0
    stats: dict = {}
    while impacts < 1000:
        _, imp = exact.run_step(y, 20, 2 * math.pi * 100.0, 0.0, sys, stats=stats, **run_step_options)
        impacts += int(imp.sum())
    return abs(energy_parts(y, sys)["total"][0] - e0) / e0, impacts, stats


def rebound_error(v0: float, runner, a_base: float = 0.0) -> float:
    """Relative error of the sphere's velocity after one impact against DOP853 (`reference_run`, rtol 1e-12,
    events): the sphere 20 um from the left wall closing at v0 (m/s), the cantilever-like beam at rest, one
    period of 1 ms (one impact). runner(y, sys, Omega, a_base) advances y in place over that period."""
    sys = system_arrays(cantilever_like_model(), Impactor())
    n = sys.omega.size
    y0 = np.zeros(2 * n + 2)
    y0[2 * n] = -sys.g + 2e-5
    y0[2 * n + 1] = -v0
    Omega = 2 * math.pi * 1000.0
    y_ref, onsets, releases, _ = reference_run(y0, 2 * math.pi / Omega, Omega, a_base, sys)
    if onsets.size != 1 or releases.size != 1:
        raise AssertionError(f"the reference run has {onsets.size} onsets and {releases.size} releases, not one impact")
    y = y0.copy()
    runner(y, sys, Omega, a_base)
    return abs(y[2 * n + 1] - y_ref[2 * n + 1]) / v0


def two_body_impact(r_cont: float, v0: float, m_a: float, m_beam: float, k_H: float,
                    rtol: float = 1e-12) -> dict[str, float]:
    """One impact of the sphere (m_a, kg) on a free rigid wall of mass m_beam (kg) under Eq. 10 (the paper's
    xi(r_cont) and d_H, written out here from the paper, not taken from `sim.model.contact_law`), by scipy DOP853 in
    the bodies' own coordinates x_a, x_w with events at delta = 0 (onset, release) and delta' = 0 (turning
    point: approach -> restitution). The sphere closes at v0 (m/s), the wall at rest; delta = x_a - x_w.

    Returns the coefficient of restitution r = -(relative velocity after) / (relative velocity before), the
    kinetic energies before and after (J), the dissipated energy (J, the integral of d_H delta'^2 as a state),
    the largest indentation (m) and the times of the turning point and the release (s).
    """
    from scipy.integrate import solve_ivp

    xi = 4.5 * math.sqrt(5.0) * (1.0 - r_cont**2) / (r_cont * (r_cont * (9.0 * math.pi - 16.0) + 16.0))
    m_red = m_beam * m_a / (m_beam + m_a)

    def force(delta: float, rate: float, approach: bool) -> float:
        if delta <= 0:
            return 0.0
        f = k_H * delta**1.5
        return f + 2.0 * xi * math.sqrt(k_H * math.sqrt(delta) * m_red) * rate if approach else f

    def rhs_of(approach: bool):
        def rhs(_t, y):
            delta, rate = y[0] - y[2], y[1] - y[3]
            f = force(delta, rate, approach)
            dissipation = f * rate - (k_H * max(delta, 0.0) ** 1.5 * rate)  # the damper's power
            return [y[1], -f / m_a, y[3], f / m_beam, dissipation]
        return rhs

    def turning(_t, y):
        return y[1] - y[3]

    def release(_t, y):
        return y[0] - y[2]

    turning.terminal, turning.direction = True, -1.0
    release.terminal, release.direction = True, -1.0
    # contact duration scale: (m_red^2 / (k_H^2 v0))^(1/5)
    tau = (m_red**2 / (k_H**2 * v0)) ** 0.2
    atol = np.array([1e-18, 1e-16 * v0, 1e-18, 1e-16 * v0, 1e-30])
    y0 = [0.0, v0, 0.0, 0.0, 0.0]  # onset: delta = 0 at t = 0
    approach = solve_ivp(rhs_of(True), (0.0, 20 * tau), y0, method="DOP853", rtol=rtol, atol=atol, events=turning)
    if approach.status != 1:
        raise RuntimeError("the reference impact found no turning point")
    y1, t1 = approach.y[:, -1], approach.t[-1]
    restitution = solve_ivp(rhs_of(False), (t1, t1 + 20 * tau), y1, method="DOP853", rtol=rtol, atol=atol,
                            events=release)
    if restitution.status != 1:
        raise RuntimeError("the reference impact found no release")
    y2 = restitution.y[:, -1]
    kinetic = lambda y: 0.5 * m_a * y[1] ** 2 + 0.5 * m_beam * y[3] ** 2  # noqa: E731
    return {"r": -(y2[1] - y2[3]) / v0, "kinetic_before": 0.5 * m_a * v0**2, "kinetic_after": kinetic(y2),
            "dissipated": float(y2[4]), "max_indentation": float(y1[0] - y1[2]), "t_turning": float(t1),
            "t_release": float(restitution.t[-1])}


def jenkins_reference(k_t: float, mu_N: float, mass: float, X: float, Omega: float, t_end: float,
                      rtol: float = 1e-12, pieces: list | None = None) -> dict[str, Any]:
    """Appendix C's elastic Coulomb element on a single DOF, by scipy DOP853 with events: a mass (kg) on a floor
    moved as X cos(Omega t) (m, rad/s), from rest (spring unloaded) at t = 0 to t_end (s). Absolute
    coordinates: the mass at x, the slider at p on the floor, spring elongation w = x - p, m x'' = -k_t w.
    Stick: p' = x_f' (|k_t w| < mu_N); slip: p' = x' (w fixed). Events: |k_t w| = mu_N (stick -> slip) and
    x' - x_f' = 0 (slip -> stick). The dissipated energy mu_N |x' - x_f'| is integrated as a state.

    Returns x, x' (m, m/s), the relative displacement u = x - x_f and slider position z = p - x_f (m) at t_end,
    the transitions [(t, "slip" | "stick", sign)], the spring force k_t w just before and after each transition
    (N), and the dissipated energy (J). pieces: receives (t0, t1, dense solution, kind, sign) per phase.
    """
    from scipy.integrate import solve_ivp

    floor = lambda t: X * math.cos(Omega * t)  # noqa: E731
    floor_v = lambda t: -X * Omega * math.sin(Omega * t)  # noqa: E731

    def rhs_of(slipping: bool):
        def rhs(t, y):
            x, xd, p = y[0], y[1], y[2]
            rel = xd - floor_v(t)
            return [xd, -k_t * (x - p) / mass, xd if slipping else floor_v(t), mu_N * abs(rel) if slipping else 0.0]
        return rhs

    def limit_plus(_t, y):
        return k_t * (y[0] - y[2]) - mu_N

    def limit_minus(_t, y):
        return k_t * (y[0] - y[2]) + mu_N

    def slip_velocity(t, y):
        return y[1] - floor_v(t)

    limit_plus.terminal = limit_minus.terminal = slip_velocity.terminal = True
    limit_plus.direction, limit_minus.direction = 1.0, -1.0
    scale = max(X, mu_N / k_t)
    atol = np.array([1e-14 * scale, 1e-14 * scale * max(Omega, math.sqrt(k_t / mass)), 1e-14 * scale, 1e-14 * mu_N * scale])
    t, y = 0.0, np.array([floor(0.0), floor_v(0.0), floor(0.0), 0.0])
    slipping, sign = False, 0.0
    transitions, forces = [], []
    while t < t_end:
        if slipping:
            slip_velocity.direction = -sign
            events = [slip_velocity]
        else:
            events = [limit_plus, limit_minus]
        sol = solve_ivp(rhs_of(slipping), (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=events,
                        dense_output=pieces is not None, first_step=1e-9)
        if pieces is not None:
            pieces.append((t, sol.t[-1], sol.sol, "slip" if slipping else "stick", sign))
        y, t_new = sol.y[:, -1].copy(), sol.t[-1]
        if sol.status == 1:
            before = k_t * (y[0] - y[2])
            if slipping:
                slipping = False
                transitions.append((t_new, "stick", sign))
            else:
                sign = 1.0 if sol.t_events[0].size else -1.0
                y[2] = y[0] - sign * mu_N / k_t  # on the limit exactly
                slipping = True
                transitions.append((t_new, "slip", sign))
            forces.append((before, k_t * (y[0] - y[2])))
        if t_new <= t and sol.status != 0:
            raise RuntimeError("the friction reference did not progress")
        t = t_new
    return {"x": y[0], "xd": y[1], "u": y[0] - floor(t), "z": y[2] - floor(t), "transitions": transitions,
            "forces": forces, "dissipated": float(y[3])}
