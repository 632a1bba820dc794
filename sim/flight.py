"""The state layout shared by the contact integrators of `sim.exact` and `sim.collocation`, and the
closed-form pieces of free flight (the homogeneous part of Eq. 9; symbols in `sim.exact`'s docstring)."""
from __future__ import annotations

import math

from numba import njit

# rows of the per-mode constant table
_SIG, _WD, _W2, _PL, _PR, _RHR, _RHI, _APL, _APR, _SRE, _SIM, _SCX, _SCV = range(13)
_N_ROWS = 13
# entries of the scalar parameter vector
(_OM, _ABASE, _MA, _KH, _G, _WLR, _WLI, _WRR, _WRI, _PRE, _PIM, _TOL, _VMIN, _HG, _ML0, _MR0, _SCZ, _SCZD,
 _HMAX) = range(19)
_N_PAR = 19


# ----------------------------------------------------------------------------------------------------------
# free flight in closed form
# ----------------------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _transition(tau, sig, wd, w2):
    """Damped-oscillator transition over tau: (x, v)(tau) = [[a, b], [c, d]] (x0, v0)."""
    e = math.exp(-sig * tau)
    co = math.cos(wd * tau)
    si = math.sin(wd * tau)
    return e * (co + sig / wd * si), e * si / wd, -e * w2 / wd * si, e * (co - sig / wd * si)


@njit(cache=True)
def _flight_transitions(tau, modes, tr):
    """tr[:, j] = transition (a, b, c, d) of mode j over a free flight of length tau."""
    for j in range(modes.shape[1]):
        tr[0, j], tr[1, j], tr[2, j], tr[3, j] = _transition(tau, modes[_SIG, j], modes[_WD, j], modes[_W2, j])


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


@njit(cache=True, inline="always")
def _rotate(ct, st, angle):
    """cos, sin(theta + angle) from cos, sin(theta); Taylor series (to 1e-20) for the small angles of contacts."""
    if abs(angle) < 0.2:
        a2 = angle * angle
        ca = 1.0 - a2 / 2.0 * (1.0 - a2 / 12.0 * (1.0 - a2 / 30.0 * (1.0 - a2 / 56.0 * (1.0 - a2 / 90.0 * (1.0 - a2 / 132.0)))))
        sa = angle * (1.0 - a2 / 6.0 * (1.0 - a2 / 20.0 * (1.0 - a2 / 42.0 * (1.0 - a2 / 72.0 * (1.0 - a2 / 110.0 * (1.0 - a2 / 156.0))))))
    else:
        ca = math.cos(angle)
        sa = math.sin(angle)
    return ct * ca - st * sa, st * ca + ct * sa


