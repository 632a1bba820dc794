"""Independent reference for the exact integrator's tests: scipy solve_ivp (DOP853) on Eqs. 3-7 in the
original coordinates y = [s, s', u_a, u_a'], restarted at every contact onset and release (events), so the
Hertz law's non-smoothness never sits inside a step."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp


def reference_run(y0, t_end, Omega, a_base, sys, rtol=1e-12, atol_scale=1e-16, t_eval=None):
    """Integrate from t=0 (phase 0) to t_end; returns (y(t_end), onset times, release times, rebound speeds).

    rebound speeds: the relative speed phi_w^T s' - u_a' (sign of opening) at each release.
    """
    n = sys.omega.size
    w2 = sys.omega**2
    c = 2 * sys.D * sys.omega

    def rhs(t, y):
        s = y[:n]
        sd = y[n:2 * n]
        u = y[2 * n]
        dl = sys.phi_l @ s - u - sys.g
        dr = sys.phi_r @ s - u + sys.g
        fl = sys.k_H * dl**1.5 if dl > 0 else 0.0
        fr = -sys.k_H * (-dr) ** 1.5 if dr < 0 else 0.0
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
    t = 0.0
    y = np.array(y0, dtype=float)
    closed = [ev_l(t, y) > 0, ev_r(t, y) < 0]
    onsets, releases, speeds = [], [], []
    ev_l.terminal = ev_r.terminal = True
    while t < t_end:
        # closed left: look for delta_l falling through 0; open: rising. Right wall mirrored.
        ev_l.direction = -1.0 if closed[0] else 1.0
        ev_r.direction = 1.0 if closed[1] else -1.0
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=(ev_l, ev_r),
                        first_step=1e-9)
        y = sol.y[:, -1].copy()
        t_new = sol.t[-1]
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
