"""The state layout shared by the contact integrators of `sim.exact` and `sim.collocation`, and the
closed-form pieces of free flight (the homogeneous part of Eq. 9; symbols in `sim.exact`'s docstring)."""
from __future__ import annotations

import math

from numba import njit

# rows of the per-mode constant table
_SIG, _WD, _W2, _PL, _PR, _RHR, _RHI, _APL, _APR, _SRE, _SIM, _SCX, _SCV, _SOW, _IWD, _W2OW = range(16)
_N_ROWS = 16
# entries of the scalar parameter vector
(_OM, _ABASE, _MA, _KH, _G, _WLR, _WLI, _WRR, _WRI, _PRE, _PIM, _TOL, _VMIN, _HG, _ML0, _MR0, _SCZ, _SCZD,
 _HMAX, _IMA) = range(20)
_N_PAR = 20


# ----------------------------------------------------------------------------------------------------------
# free flight in closed form
# ----------------------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _transition(tau, modes, j):
    """Transition of the damped oscillator j over tau: (x, v)(tau) = [[a, b], [c, d]] (x0, v0)."""
    e = math.exp(-modes[_SIG, j] * tau)
    co = math.cos(modes[_WD, j] * tau)
    si = math.sin(modes[_WD, j] * tau)
    q = modes[_SOW, j] * si  # sigma / omega_d sin: the rows hold the ratios (no divisions here)
    return e * (co + q), e * si * modes[_IWD, j], -e * modes[_W2OW, j] * si, e * (co - q)


@njit(cache=True)
def _flight_transitions(tau, modes, tr):
    """tr[:, j] = transition (a, b, c, d) of mode j over a free flight of length tau."""
    for j in range(modes.shape[1]):
        tr[0, j], tr[1, j], tr[2, j], tr[3, j] = _transition(tau, modes, j)


@njit(cache=True)
def _apply_flight(Y, Ynew, tau, tr, n):
    """Ynew = free flight of Y over tau (the force integrals F_w do not change)."""
    for j in range(n):
        x = Y[j]
        v = Y[n + j]
        Ynew[j] = tr[0, j] * x + tr[1, j] * v
        Ynew[n + j] = tr[2, j] * x + tr[3, j] * v
    Ynew[2 * n] = Y[2 * n] + tau * Y[2 * n + 1]
    for i in range(2 * n + 1, Y.size):
        Ynew[i] = Y[i]


# time maps of a contact step, t = t_a + h w(u) with u in [0, 1] (`_time_map`)
ONSET, REGULAR, RELEASE, GRAZE = 0, 1, 2, 3


@njit(cache=True, inline="always")
def _time_map(kind, u):
    """(w(u), w'(u)) of a contact step's time map t = t_a + h w(u), w(1) = 1.

    At a contact onset (release) the Hertz force behaves like (t - t_on)^1.5 ((t_rel - t)^1.5) and a step
    in t loses its order; with t - t_on = h u^2 (t_rel - t = h (1 - u)^2) the force is a smooth function of
    u. GRAZE handles both ends at once (a whole graze in one step).
    """
    if kind == ONSET:
        return u * u, 2.0 * u
    if kind == RELEASE:
        return u * (2.0 - u), 2.0 * (1.0 - u)
    if kind == GRAZE:
        return u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u)
    return u, 1.0


@njit(cache=True, inline="always")
def _closing(Y, t, n, modes, par):
    """(c_l, c_l', c_r, c_r') at phase time t: contact at a wall when its c > 0 (Eqs. 4-6)."""
    return _closing_at(Y, math.cos(par[_OM] * t), math.sin(par[_OM] * t), n, modes, par)


@njit(cache=True, inline="always")
def _closing_at(Y, ct, st, n, modes, par):
    """`_closing` with cos, sin(Omega t) given."""
    Om = par[_OM]
    sl = par[_WLR] * ct - par[_WLI] * st
    sld = -Om * (par[_WLR] * st + par[_WLI] * ct)
    sr = par[_WRR] * ct - par[_WRI] * st
    srd = -Om * (par[_WRR] * st + par[_WRI] * ct)
    for j in range(n):
        x = Y[j]
        v = Y[n + j]
        sl += modes[_PL, j] * x
        sld += modes[_PL, j] * v
        sr += modes[_PR, j] * x
        srd += modes[_PR, j] * v
    z = Y[2 * n]
    zd = Y[2 * n + 1]
    g = par[_G]
    return sl - z - g, sld - zd, -(sr - z) - g, -(srd - zd)


# 1 / (k (k + 1)) for the nested Taylor series of `_rotate` (multiplications: a chain of divisions is slow)
_C12, _C34, _C56, _C78, _C910, _C1112 = 1 / 2, 1 / 12, 1 / 30, 1 / 56, 1 / 90, 1 / 132
_S23, _S45, _S67, _S89, _S1011, _S1213 = 1 / 6, 1 / 20, 1 / 42, 1 / 72, 1 / 110, 1 / 156


@njit(cache=True, inline="always")
def _rotate(ct, st, angle):
    """cos, sin(theta + angle) from cos, sin(theta); Taylor series (to 1e-20) for the small angles of contacts."""
    if abs(angle) < 0.2:
        a2 = angle * angle
        ca = 1.0 - a2 * _C12 * (1.0 - a2 * _C34 * (1.0 - a2 * _C56 * (1.0 - a2 * _C78 * (
            1.0 - a2 * _C910 * (1.0 - a2 * _C1112)))))
        sa = angle * (1.0 - a2 * _S23 * (1.0 - a2 * _S45 * (1.0 - a2 * _S67 * (1.0 - a2 * _S89 * (
            1.0 - a2 * _S1011 * (1.0 - a2 * _S1213))))))
    else:
        ca = math.cos(angle)
        sa = math.sin(angle)
    return ct * ca - st * sa, st * ca + ct * sa
