"""Contacts by exponential Gauss collocation (issue 5): a whole Hertz impact in two or three steps.

During a contact with wall w only the scalar contact force F(t) = k_H c_w(t)^1.5 is nonlinear; the modes
and the sphere respond to it linearly (Eqs. 3-7). Over a step of length h from t_a (state Y_a) we write
the closing function exactly as (Duhamel)

    c_w(t_a + tau) = c_hom(tau) - int_0^tau K_w(tau - sigma) F(sigma) dsigma,
    K_w(t) = sum_j phi_w,j^2 exp(-sigma_j t) sin(omega_dj t) / omega_dj + t / m_a,

c_hom being the free flight from Y_a (closed form, `sim.exact`). F is represented by its values at s Gauss
nodes of a time map t = t_a + h w(u), u in [0, 1] (`sim.flight._time_map`: u^2 at an onset,
u (2 - u) before a release, so that F ~ (time to the end)^1.5 becomes a smooth function of u), and the
s nodal equations F_i = k_H c_w(t_i)^1.5 are solved by Newton's method. Everything linear is exact:
the s x s weights of the convolution, the modal and sphere responses to each nodal force, and the
transitions are tables that depend only on the system, the time map and h. h is taken from a geometric
ladder (LADDER_PER_OCTAVE per octave) so the tables are built once per system and reused (`Tables`).

A contact is an onset step (h ~ half the Hertz contact time), regular steps if the contact lasts longer,
and a release step whose *end* is the release: its length is a ladder value and its *start* t_e - d lies
inside the previous step, where the state is the Taylor series of the previous step's solution (exact
for its force polynomial) evaluated at d. The s nodal forces and d are solved together by Newton's
method with c_w = 0 at the step's end. Contacts this cannot treat (too short, too long, crossing the end
of a period or a record instant, a failed Newton iteration) fall back to the Dormand-Prince contact.

Accuracy: the force is interpolated by a polynomial of degree s - 1 in u, so a step has the order of
its interpolation (about s + 1 for the modal response, 2 s for the force impulse, Gauss quadrature);
with s = 10 a whole impact has a rebound error near 1e-10 (tests/sim/test_collocation.py).

Development note: `sim.exact`'s compiled period loop embeds these kernels, and numba's cache only tracks
each function's own file: after editing this module, delete sim/__pycache__/*.nb* (installs are not
affected: a new version brings new files).
"""
from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
from numba import njit
from numpy.polynomial import legendre, polynomial

from sim.flight import (ONSET, REGULAR, RELEASE, _G, _IMA, _KH, _MA, _OM, _PL, _PR, _SIG, _W2, _WD, _WLI, _WLR, _WRI,
                        _WRR, _closing_at, _rotate, _time_map, _transition)

#: Gauss nodes per collocation step.
NODES = 10
#: Order of the Taylor series that carries the state back into the previous step. It goes back by at most a
#: quarter of that step, and steps are at most one period of the highest mode: truncation below 1e-11 of
#: that mode's amplitude ((pi / 2)^16 / 16!).
SERIES_ORDER = 16
#: Step lengths: h_k = (2 pi / omega_max) 2^((k - LADDER_CENTRE) / LADDER_PER_OCTAVE).
LADDER_PER_OCTAVE = 8
LADDER_SIZE = 80
LADDER_CENTRE = 48
#: Newton's method stops when the last correction was below this, relative to the indentations (the
#: iterate is then converged to ~1e-12: quadratic convergence).
_NEWTON_TOL = 1e-6
#: Gauss-Legendre points of the quadratures that build the tables.
TABLE_QUADRATURE = 32


# ----------------------------------------------------------------------------------------------------------
# tables: layout and construction
# ----------------------------------------------------------------------------------------------------------
def _offsets(s: int, n: int) -> np.ndarray:
    """Offsets of P, Q (n x (s+1), mode by mode), W (s x (s+1), column by column), BX, BV (s x n), BZ, BZD
    (s), TR (4 x n), TAU (s+1), WQ (s) in a table, and the table's size (int64 array, indexed by _P ... _SIZE).
    The layouts put the inner loops of the kernels along contiguous memory."""
    r = s + 1
    sizes = (r * n, r * n, r * s, s * n, s * n, s, s, 4 * n, r, s)
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)


class Nodes:
    """Universal data of the s-node collocation: nodes, weights, and the maps from nodal forces to the
    Taylor coefficients (in the backward time sigma / h) of the force at the end of a step."""

    def __init__(self, s: int = NODES, order: int = SERIES_ORDER):
        x, w = legendre.leggauss(s)
        self.u = 0.5 * (x + 1.0)
        self.b = 0.5 * w
        self.wb = np.array([1.0 / np.prod(self.u[k] - np.delete(self.u, k)) for k in range(s)])
        xq, wq = legendre.leggauss(TABLE_QUADRATURE)
        self.xq = 0.5 * (xq + 1.0)
        self.bq = 0.5 * wq
        # Taylor coefficients at u = 1 of the Lagrange basis, in eps = 1 - u: C[m, k]
        C = np.zeros((order, s))
        for k in range(s):
            others = np.delete(self.u, k)
            lk = polynomial.polyfromroots(others) / np.prod(self.u[k] - others)
            # l_k(1 - eps) as a polynomial in eps
            coeffs = np.zeros(s)
            one_minus = np.array([1.0, -1.0])
            power = np.array([1.0])
            for c in lk:
                coeffs[:power.size] += c * power
                power = polynomial.polymul(power, one_minus)
            C[:s, k] = coeffs[:s] if order >= s else coeffs[:order]
        self.regular = C  # sigma / h = eps
        # onset map: u = sqrt(1 - x), eps = 1 - sqrt(1 - x), x = sigma / h
        eps = np.zeros(order)
        binom = 1.0
        for q in range(1, order):
            binom *= (0.5 - (q - 1)) / q
            eps[q] = -binom * (-1.0) ** q
        onset = np.zeros((order, s))
        power = np.zeros(order)
        power[0] = 1.0
        for m in range(s):
            onset += np.outer(power, C[m])
            power = np.convolve(power, eps)[:order]
        self.onset = onset
        # the two highest Legendre coefficients of the force polynomial from its nodal values (Gauss quadrature)
        z = 2.0 * self.u - 1.0
        self.tail = np.array([(2 * m + 1) * self.b * legendre.legval(z, np.eye(s)[m]) for m in (s - 2, s - 1)])


@njit(cache=True, inline="always")
def _lagrange(u, wb, v, out):
    """out[k] = l_k(v), the Lagrange basis on the nodes u (wb: 1 / prod_m!=k (u_k - u_m)), by prefix and
    suffix products (no divisions)."""
    s = u.size
    acc = 1.0
    for k in range(s):
        out[k] = acc
        acc *= v - u[k]
    acc = 1.0
    for k in range(s - 1, -1, -1):
        out[k] *= acc * wb[k]
        acc *= v - u[k]


# table offsets: P, Q, W, BX, BV, BZ, BZD, TR, TAU, WQ, size
_P, _Q, _W, _BX, _BV, _BZ, _BZD, _TR, _TAU, _WQ, _SIZE = range(11)


@njit(cache=True)
def _build(tab, off, kind, h, wall, u, wb, b, xq, bq, n, modes, par):
    """Fill one table (layout of `_offsets`) for a step of length h with the time map `kind` at wall 0/1.

    P, Q: c_hom at node i (row s: the step's end) = sum_j P_ij x_j + Q_ij v_j + (harmonic and sphere terms).
    W: c_w at node i drops by sum_k W_ik F_k. BX, BV, BZ, BZD: end-state response to the nodal force F_k.
    TR: mode transitions over h. TAU: node times. WQ: quadrature weights of int F dt over the step.
    The impulse responses are the transitions' entries: x(t) = b(t), x'(t) = d(t) per unit velocity.
    """
    s = u.size
    sgn = 1.0 if wall == 0 else -1.0
    row = _PL if wall == 0 else _PR
    inv_ma = par[_IMA]
    lag_k = np.empty(s)
    tab[:] = 0.0
    for i in range(s + 1):
        ui = u[i] if i < s else 1.0
        wi, _ = _time_map(kind, ui)
        tau = h * wi
        tab[off[_TAU] + i] = tau
        for j in range(n):
            a, bb, c, d = _transition(tau, modes, j)
            tab[off[_P] + j * (s + 1) + i] = sgn * modes[row, j] * a
            tab[off[_Q] + j * (s + 1) + i] = sgn * modes[row, j] * bb
        # W[i, k] = int_0^ui K(tau - h w(v)) l_k(v) h w'(v) dv
        for q in range(xq.size):
            v = ui * xq[q]
            wv, dv = _time_map(kind, v)
            lag = tau - h * wv
            K = lag * inv_ma
            for j in range(n):
                K += modes[row, j] ** 2 * _transition(lag, modes, j)[1]
            weight = ui * bq[q] * K * h * dv
            _lagrange(u, wb, v, lag_k)
            for k in range(s):
                tab[off[_W] + k * (s + 1) + i] += weight * lag_k[k]
    for q in range(xq.size):
        v = xq[q]
        wv, dv = _time_map(kind, v)
        lag = h - h * wv
        _lagrange(u, wb, v, lag_k)
        for j in range(n):
            a, bb, c, d = _transition(lag, modes, j)
            for k in range(s):
                lw = bq[q] * lag_k[k] * h * dv
                tab[off[_BX] + k * n + j] -= sgn * modes[row, j] * bb * lw
                tab[off[_BV] + k * n + j] -= sgn * modes[row, j] * d * lw
        for k in range(s):
            lw = bq[q] * lag_k[k] * h * dv
            tab[off[_BZ] + k] += sgn * lag * lw * inv_ma
            tab[off[_BZD] + k] += sgn * lw * inv_ma
    for j in range(n):
        a, bb, c, d = _transition(h, modes, j)
        tab[off[_TR] + j] = a
        tab[off[_TR] + n + j] = bb
        tab[off[_TR] + 2 * n + j] = c
        tab[off[_TR] + 3 * n + j] = d
    for k in range(s):
        _, dk = _time_map(kind, u[k])
        tab[off[_WQ] + k] = b[k] * h * dk


# ----------------------------------------------------------------------------------------------------------
# one step: the free closing function at the nodes, Newton on the nodal indentations, the end state
# ----------------------------------------------------------------------------------------------------------
@njit(cache=True)
def _solve_in_place(AT, x, m):
    """x <- A^-1 x for the leading m x m block of A, given by columns (AT[k, i] = A[i, k]; destroyed):
    Gaussian elimination with partial pivoting, column-oriented so that the inner loops run along
    contiguous memory."""
    for c in range(m):
        p = c
        best = abs(AT[c, c])
        for r in range(c + 1, m):
            if abs(AT[c, r]) > best:
                best = abs(AT[c, r])
                p = r
        if best == 0.0:
            return False
        if p != c:
            for k in range(m):
                tmp = AT[k, c]
                AT[k, c] = AT[k, p]
                AT[k, p] = tmp
            tmp = x[c]
            x[c] = x[p]
            x[p] = tmp
        inv = 1.0 / AT[c, c]
        for r in range(c + 1, m):
            AT[c, r] *= inv  # the multipliers
        xc = x[c]
        for r in range(c + 1, m):
            x[r] -= AT[c, r] * xc
        for k in range(c + 1, m):
            a = AT[k, c]
            for r in range(c + 1, m):
                AT[k, r] -= AT[c, r] * a
    for c in range(m - 1, -1, -1):
        x[c] /= AT[c, c]
        xc = x[c]
        for r in range(c):
            x[r] -= AT[c, r] * xc
    return True


@njit(cache=True)
def _free_closing(tab, off, ph, Y, ct, st, wall, n, s, par, out, Yd=None, out_d=None):
    """out[i] = c_w at node i (i = s: the step's end) of the free flight from Y at phase (ct, st) (ph: the
    node phases of `_phases`); with Yd = dY/dt at the start, out_d[i] = d out[i] / d(start time)."""
    sgn = 1.0 if wall == 0 else -1.0
    Wr = par[_WLR] if wall == 0 else par[_WRR]
    Wi = par[_WLI] if wall == 0 else par[_WRI]
    Om = par[_OM]
    oP = off[_P]
    oQ = off[_Q]
    r = s + 1
    for i in range(r):
        tau = tab[off[_TAU] + i]
        c = ct * ph[0, i] - st * ph[1, i]
        si = st * ph[0, i] + ct * ph[1, i]
        out[i] = sgn * (Wr * c - Wi * si - Y[2 * n] - tau * Y[2 * n + 1]) - par[_G]
        if Yd is not None:
            out_d[i] = -sgn * (Om * (Wr * si + Wi * c) + Yd[2 * n] + tau * Yd[2 * n + 1])
    # the modes, all nodes at once: P, Q are stored mode by mode
    for j in range(n):
        x = Y[j]
        v = Y[n + j]
        for i in range(r):
            out[i] += tab[oP + j * r + i] * x + tab[oQ + j * r + i] * v
        if Yd is not None:
            x = Yd[j]
            v = Yd[n + j]
            for i in range(r):
                out_d[i] += tab[oP + j * r + i] * x + tab[oQ + j * r + i] * v


@njit(cache=True, inline="always")
def _forces(delta, F, D, kH, s):
    """Hertz law at the nodes: F = k_H delta^1.5, D = dF/d delta."""
    for k in range(s):
        d = delta[k]
        if d > 0.0:
            r = math.sqrt(d)
            F[k] = kH * d * r
            D[k] = 1.5 * kH * r
        else:
            F[k] = 0.0
            D[k] = 0.0


@njit(cache=True, inline="always")
def _collocation_equations(tab, off, chom, delta, F, D, A, rhs, s):
    """The s collocation equations and their Jacobian: rhs[i] = delta_i - chom_i + sum_k W_ik F_k and
    A[k, i] = delta_ik + W_ik D_k (by columns, as W is stored). Returns max |chom_i| (the indentation scale)."""
    oW = off[_W]
    r = s + 1
    scale = 0.0
    for i in range(s):
        rhs[i] = delta[i] - chom[i]
        scale = max(scale, abs(chom[i]))
    for k in range(s):
        f = F[k]
        dk = D[k]
        for i in range(s):
            rhs[i] += tab[oW + k * r + i] * f
            A[k, i] = tab[oW + k * r + i] * dk
        A[k, k] += 1.0
    return scale


@njit(cache=True)
def _newton(tab, off, chom, delta, F, D, A, rhs, s, kH):
    """Solve delta_i = chom_i - sum_k W_ik F(delta_k) for the nodal indentations (delta holds the guess).

    Returns the number of iterations, or -1 if Newton's method did not converge."""
    for it in range(40):
        _forces(delta, F, D, kH, s)
        scale = _collocation_equations(tab, off, chom, delta, F, D, A, rhs, s)
        if not _solve_in_place(A, rhs, s):
            return -1
        change = 0.0
        for i in range(s):
            delta[i] -= rhs[i]
            change = max(change, abs(rhs[i]))
        if not change <= 1e3 * scale:
            return -1
        if change <= _NEWTON_TOL * scale:
            _forces(delta, F, D, kH, s)
            return it + 1
    return -1


@njit(cache=True)
def _end_state(tab, off, ph, Y, Yout, F, ct, st, wall, n, s, par):
    """Yout = the state at the step's end: transitions, responses to the nodal forces, and the Fourier
    integral of the contact force over the step (Gauss quadrature; ph: the node phases of `_phases`)."""
    oTR = off[_TR]
    for j in range(n):
        x = Y[j]
        v = Y[n + j]
        Yout[j] = tab[oTR + j] * x + tab[oTR + n + j] * v
        Yout[n + j] = tab[oTR + 2 * n + j] * x + tab[oTR + 3 * n + j] * v
    for k in range(s):
        f = F[k]
        for j in range(n):
            Yout[j] += tab[off[_BX] + k * n + j] * f
            Yout[n + j] += tab[off[_BV] + k * n + j] * f
    h = tab[off[_TAU] + s]
    ze = Y[2 * n] + h * Y[2 * n + 1]
    zde = Y[2 * n + 1]
    re = 0.0
    im = 0.0
    for k in range(s):
        ze += tab[off[_BZ] + k] * F[k]
        zde += tab[off[_BZD] + k] * F[k]
        c = ct * ph[0, k] - st * ph[1, k]
        si = st * ph[0, k] + ct * ph[1, k]
        wf = tab[off[_WQ] + k] * F[k]
        re += wf * c
        im -= wf * si
    Yout[2 * n] = ze
    Yout[2 * n + 1] = zde
    for i in range(2 * n + 2, Yout.size):
        Yout[i] = Y[i]
    sgn = 1.0 if wall == 0 else -1.0
    row = 2 * n + 2 if wall == 0 else 2 * n + 4
    Yout[row] += sgn * re
    Yout[row + 1] += sgn * im


# ----------------------------------------------------------------------------------------------------------
# the state inside the previous step: Taylor series in the backward time sigma
# ----------------------------------------------------------------------------------------------------------
@njit(cache=True)
def _series(Yend, F, M, h, wall, n, modes, par, S, Fs):
    """S[q]: Taylor coefficients of the state [x, v, z, z'] at t_e - sigma, Fs[q] those of the force, for
    the solution of the step that ended at t_e (length h, force polynomial with nodal values F; M maps
    them to the force's coefficients in sigma / h, `Nodes.regular` or `Nodes.onset`)."""
    p = S.shape[0]
    s = F.size
    sgn = 1.0 if wall == 0 else -1.0
    row = _PL if wall == 0 else _PR
    scale = 1.0
    inv_h = 1.0 / h
    for q in range(p):
        acc = 0.0
        for k in range(s):
            acc += M[q, k] * F[k]
        Fs[q] = acc * scale
        scale *= inv_h
    for i in range(2 * n + 2):
        S[0, i] = Yend[i]
    for q in range(p - 1):
        inv = 1.0 / (q + 1)
        for j in range(n):
            S[q + 1, j] = -S[q, n + j] * inv
            S[q + 1, n + j] = (2.0 * modes[_SIG, j] * S[q, n + j] + modes[_W2, j] * S[q, j]
                               + sgn * modes[row, j] * Fs[q]) * inv
        S[q + 1, 2 * n] = -S[q, 2 * n + 1] * inv
        S[q + 1, 2 * n + 1] = -sgn * Fs[q] * par[_IMA] * inv


@njit(cache=True)
def _series_at(S, sigma, Y, m):
    """Y[:m] = the state at t_e - sigma from the series S of `_series` (Horner, all components at once)."""
    p = S.shape[0]
    for i in range(m):
        Y[i] = S[p - 1, i]
    for q in range(p - 2, -1, -1):
        for i in range(m):
            Y[i] = Y[i] * sigma + S[q, i]


#: 1 / k for k = 1, 2, ... (the integrals of the powers in `_overlap_fourier`)
_INV = 1.0 / np.arange(1.0, 40.0)
#: Terms of the exponential's series in `_overlap_fourier` ((Omega sigma)^5 / 5! < 1e-12 for Omega sigma < 0.01).
_OVERLAP_TERMS = 5


@njit(cache=True)
def _overlap_fourier(Fs, sigma, ct_e, st_e, Om):
    """int over [t_e - sigma, t_e] of F(t) exp(-i Omega t) dt from the force's series (Omega sigma << 1)."""
    jr = 0.0
    ji = 0.0
    power = sigma  # sigma^(q + 1)
    for q in range(Fs.size):
        term = Fs[q] * power
        for m in range(_OVERLAP_TERMS):
            # Fs[q] sigma^(q + m + 1) (i Omega)^m / m! / (q + m + 1)
            part = term * _INV[q + m]
            if m % 4 == 0:
                jr += part
            elif m % 4 == 1:
                ji += part
            elif m % 4 == 2:
                jr -= part
            else:
                ji -= part
            term *= Om * sigma * _INV[m]
        power *= sigma
    return ct_e * jr + st_e * ji, ct_e * ji - st_e * jr


# ----------------------------------------------------------------------------------------------------------
# a whole contact
# ----------------------------------------------------------------------------------------------------------
#: Hertz impact on a rigid wall: contact time = _HERTZ_TIME delta_max / v0 (2 sqrt(pi) Gamma(7/5) / Gamma(9/10)).
_HERTZ_TIME = 2.9432
#: The onset step covers this fraction of the predicted contact time; a release step is taken when the
#: predicted rest is at most _RELEASE_REACH times the last step, otherwise a regular step of rest / 1.6.
#: With these the first step never reaches beyond 40 % of the contact and each step stays well away from
#: the other end's singularity: three steps and rebound errors near 1e-10 (two steps: 1e-7, measured).
_ONSET_FRACTION = 0.3
_RELEASE_REACH = 1.0
#: A step is accepted only if the predicted rest of the contact after it is at least _CLEARANCE times its
#: length (closer to the release, the force is not a smooth function of the step's time: errors 1e-6).
_CLEARANCE = 0.45
#: A step whose force polynomial has its two highest Legendre coefficients above this fraction of the force
#: is not resolved (1e-5 ... 4e-4 in ordinary steps): the Dormand-Prince contact takes over.
_RESOLUTION_TOL = 1e-3
#: Halvings of rejected steps allowed in one contact before the Dormand-Prince contact takes over.
_MAX_HALVINGS = 4
#: Longest collocation step, in periods of the highest mode.
_MAX_STEP_PERIODS = 1.0
# outcome of `contact`
RELEASED, FALLBACK = 0, 1
# rows of the workspace `ws`
_CHOM, _DCHOM, _DELTA, _F, _D, _RHS, _YNEW, _YS, _FS = range(9)
_WS_ROWS = 9
# 6-point Gauss-Legendre on [0, 1] for `_time_to_release`
_GL6_X = np.array([0.033765242898423975, 0.16939530676686776, 0.3806904069584015, 0.6193095930415985,
                   0.8306046932331322, 0.966234757101576])
_GL6_W = np.array([0.08566224618958517, 0.1803807865240693, 0.23395696728634552, 0.23395696728634552,
                   0.1803807865240693, 0.08566224618958517])


@njit(cache=True)
def _time_to_release(c, cd, ma, kH):
    """Time left in a contact at indentation c > 0 and rate cd, for a Hertz impact of the sphere on a
    rigid wall with the same energy (a first guess for the release step)."""
    E = 0.5 * ma * cd * cd + 0.4 * kH * c * c * math.sqrt(c)
    dmax = (2.5 * E / kH) ** 0.4
    ve = math.sqrt(2.0 * E / ma)
    xi = min(c / dmax, 1.0)
    # J(xi) = int_0^xi (1 - eta^2.5)^-0.5 d eta = int_sqrt(1-xi)^1 2 / sqrt(q(1 - w^2)) dw, q(e) = (1 - e^2.5) / (1 - e)
    a = math.sqrt(1.0 - xi)
    J = 0.0
    for k in range(6):
        w = a + (1.0 - a) * _GL6_X[k]
        e = 1.0 - w * w
        q = (1.0 - e * e * math.sqrt(e)) / (1.0 - e) if e < 1.0 else 2.5
        J += _GL6_W[k] * (1.0 - a) * 2.0 / math.sqrt(q)
    if cd > 0.0:
        J = _HERTZ_TIME - J  # past the maximum indentation: the whole contact minus the way back
    return dmax / ve * J


@njit(cache=True)
def _ladder(h, h_ref, up):
    """Index of the ladder step just below (up=False) or above (up=True) h; -1 if outside the ladder."""
    x = LADDER_PER_OCTAVE * math.log2(h / h_ref) + LADDER_CENTRE
    k = int(math.ceil(x - 1e-12)) if up else int(math.floor(x + 1e-12))
    return k if 0 <= k < LADDER_SIZE else -1


@njit(cache=True)
def _ladder_h(k, h_ref):
    return h_ref * 2.0 ** ((k - LADDER_CENTRE) / LADDER_PER_OCTAVE)


@njit(cache=True)
def _table(tabs, built, off, wall, kind, k, h_ref, u, wb, b, xq, bq, n, modes, par):
    """The table of (wall, kind, ladder index k), built on first use."""
    if not built[wall, kind, k]:
        _build(tabs[wall, kind, k], off, kind, _ladder_h(k, h_ref), wall, u, wb, b, xq, bq, n, modes, par)
        built[wall, kind, k] = True
    return tabs[wall, kind, k]


@njit(cache=True)
def _phases(phases, phased, tab, off, kind, k, Om, s):
    """cos, sin(Omega tau_i) at the nodes and the end (i = s) of table (kind, k), on first use in a run."""
    if not phased[kind, k]:
        for i in range(s + 1):
            phases[kind, k, 0, i], phases[kind, k, 1, i] = _rotate(1.0, 0.0, Om * tab[off[_TAU] + i])
        phased[kind, k] = True
    return phases[kind, k]


@njit(cache=True)
def _active(Y, ct, st, wall, n, modes, par):
    """(c, c') of `wall`."""
    cl, cld, cr, crd = _closing_at(Y, ct, st, n, modes, par)
    return (cl, cld) if wall == 0 else (cr, crd)


@njit(cache=True)
def _resolution(tail, F, s):
    """max |c_m| / max |F| over the two highest Legendre coefficients c_m of the step's force polynomial:
    small when the force is resolved (spectral decay), O(1) when it is not (a near-release inside)."""
    top = 0.0
    fmax = 0.0
    for k in range(s):
        fmax = max(fmax, abs(F[k]))
    for r in range(2):
        acc = 0.0
        for k in range(s):
            acc += tail[r, k] * F[k]
        top = max(top, abs(acc))
    return top / fmax if fmax > 0.0 else 0.0


@njit(cache=True)
def _forward_step(tab, off, ph, Y, ct, st, wall, n, s, par, ws, A, ratio, tail):
    """Solve a step from Y that has no release inside: nodal forces in ws[_F], first guess ratio times the
    free indentation (ratio is updated). False if Newton's method failed, an indentation is not positive or
    the force is not resolved."""
    chom = ws[_CHOM]
    delta = ws[_DELTA]
    _free_closing(tab, off, ph, Y, ct, st, wall, n, s, par, chom)
    for i in range(s):
        delta[i] = ratio[i] * chom[i]
    if _newton(tab, off, chom, delta, ws[_F], ws[_D], A, ws[_RHS], s, par[_KH]) < 0:
        return False
    for i in range(s):
        if not delta[i] > 0.0:
            return False
    for i in range(s):
        ratio[i] = delta[i] / chom[i]
    return _resolution(tail, ws[_F], s) <= _RESOLUTION_TOL


@njit(cache=True)
def _release_step(tab, off, ph, S, Fs, ct, st, d, d_lo, d_hi, c_e, cd_e, wall, n, s, modes, par, ws, A, ratio):
    """Newton's method for the release step of table `tab` that starts d before the last step's end (phase
    ct, st there; series S of the state, Fs of the force): unknowns the nodal indentations and d, equations
    the collocation and c_w = 0 at the step's end. d is kept in [d_lo, d_hi] (the series' range). Returns
    (status, d): 0 converged, 1 failed, 2 d left its range (the release is elsewhere: another ladder
    length); the nodal forces are left in ws[_F]."""
    chom = ws[_CHOM]
    dchom = ws[_DCHOM]
    delta = ws[_DELTA]
    F = ws[_F]
    D = ws[_D]
    rhs = ws[_RHS]
    Ys = ws[_YS]
    Yd = ws[_YNEW]  # dY/dt at the start (the row is free while the release step runs)
    Om = par[_OM]
    kH = par[_KH]
    sgn = 1.0 if wall == 0 else -1.0
    row = _PL if wall == 0 else _PR
    oW = off[_W]
    for i in range(s):
        delta[i] = ratio[i] * c_e
    for _ in range(30):
        # the start state (series at d), its rate dY/dt (Eqs. 3-7 with the force's series) and c_hom at the nodes
        _series_at(S, d, Ys, 2 * n + 2)
        f = Fs[Fs.size - 1]
        for q in range(Fs.size - 2, -1, -1):
            f = f * d + Fs[q]
        for j in range(n):
            Yd[j] = Ys[n + j]
            Yd[n + j] = -2.0 * modes[_SIG, j] * Ys[n + j] - modes[_W2, j] * Ys[j] - sgn * modes[row, j] * f
        Yd[2 * n] = Ys[2 * n + 1]
        Yd[2 * n + 1] = sgn * f * par[_IMA]
        cb, sb = _rotate(ct, st, -Om * d)
        _free_closing(tab, off, ph, Ys, cb, sb, wall, n, s, par, chom, Yd, dchom)
        _forces(delta, F, D, kH, s)
        # the collocation equations at the nodes, then c_w = 0 at the end, and the column of d (d/dd = -d/dt_start)
        scale = max(_collocation_equations(tab, off, chom, delta, F, D, A, rhs, s), abs(chom[s]))
        rhs[s] = chom[s]
        r = s + 1
        for k in range(s):
            rhs[s] -= tab[oW + k * r + s] * F[k]
            A[k, s] = -tab[oW + k * r + s] * D[k]
        for i in range(s):
            A[s, i] = dchom[i]
        A[s, s] = -dchom[s]
        if not _solve_in_place(A, rhs, s + 1):
            return 1, d
        change = abs(rhs[s] * cd_e)
        for i in range(s):
            delta[i] -= rhs[i]
            change = max(change, abs(rhs[i]))
        d -= rhs[s]
        if not (change <= 1e3 * scale and math.isfinite(d)):
            return 1, d
        if not d_lo <= d <= d_hi:
            return 2, d
        if change <= _NEWTON_TOL * scale:
            _forces(delta, F, D, kH, s)
            for i in range(s):
                if not delta[i] > 0.0:
                    return 1, d
            for i in range(s):
                ratio[i] = delta[i] / c_e
            return 0, d
    return 1, d


@njit(cache=True)
def contact(Y, t, t_stop, wall, n, modes, par, colloc):
    """Integrate the contact with `wall` (0 left, 1 right) from its located onset (t, Y) to its release.

    Returns (outcome, t, steps): RELEASED with Y the state at the release time t, or FALLBACK with Y the
    valid state at t (the onset itself if steps == 0) from where the Dormand-Prince contact goes on.
    colloc: the tuple of `arguments` (tables, node data, first guesses and workspace); in it memo[0 / 1 / 2]
    holds the indentations of the last onset / regular / release step over their first guess.
    """
    tabs, built, off, u, wb, b, xq, bq, M_onset, M_regular, tail, h_ref, memo, ws, A, S, phases, phased = colloc
    s = u.size
    m = 2 * n + 2
    Om = par[_OM]
    kH = par[_KH]
    sgn = 1.0 if wall == 0 else -1.0
    ct = math.cos(Om * t)
    st = math.sin(Om * t)
    _, v = _active(Y, ct, st, wall, n, modes, par)
    if not v > 0.0:
        return FALLBACK, t, 0
    t_hertz = _HERTZ_TIME * (5.0 * par[_MA] * v * v / (4.0 * kH)) ** 0.4 / v
    k = _ladder(min(_ONSET_FRACTION * t_hertz, _MAX_STEP_PERIODS * h_ref), h_ref, False)
    if k < 0 or t + 1.5 * t_hertz >= t_stop:
        return FALLBACK, t, 0
    kind = ONSET
    Ynew = ws[_YNEW, :Y.size]
    steps = 0
    halvings = 0
    for _ in range(100):
        # a step (onset or regular) from the last accepted state; it is repeated at half the length if it
        # failed (Newton, a release inside, unresolved force) or ended too close to the release (its force
        # is then not smooth in the step's time), at most _MAX_HALVINGS times in a contact
        tab = _table(tabs, built, off, wall, kind, k, h_ref, u, wb, b, xq, bq, n, modes, par)
        ph = _phases(phases, phased, tab, off, kind, k, Om, s)
        h = _ladder_h(k, h_ref)
        R = 0.0
        ok = _forward_step(tab, off, ph, Y, ct, st, wall, n, s, par, ws, A, memo[kind], tail)
        if ok:
            _end_state(tab, off, ph, Y, Ynew, ws[_F], ct, st, wall, n, s, par)
            c1 = ct * ph[0, s] - st * ph[1, s]
            s1 = st * ph[0, s] + ct * ph[1, s]
            c_e, cd_e = _active(Ynew, c1, s1, wall, n, modes, par)
            if c_e > 0.0:
                R = _time_to_release(c_e, cd_e, par[_MA], kH)
        if R < _CLEARANCE * h:
            k -= LADDER_PER_OCTAVE
            halvings += 1
            if k < 0 or halvings > _MAX_HALVINGS:
                return FALLBACK, t, steps
            continue
        Y[:] = Ynew
        t += h
        norm = 1.5 - 0.5 * (c1 * c1 + s1 * s1)  # keeps cos^2 + sin^2 = 1 to rounding
        ct = c1 * norm
        st = s1 * norm
        steps += 1
        if R <= _RELEASE_REACH * h:
            # the release step: its end is the release, its start t - d lies in the last step (series there)
            Fs = ws[_FS, :S.shape[0]]
            _series(Y, ws[_F, :s], M_onset if kind == ONSET else M_regular, h, wall, n, modes, par, S, Fs)
            for _attempt in range(3):
                k = _ladder(R + 0.1 * h, h_ref, True)
                if k < 0:
                    return FALLBACK, t, steps
                tab = _table(tabs, built, off, wall, RELEASE, k, h_ref, u, wb, b, xq, bq, n, modes, par)
                ph = _phases(phases, phased, tab, off, RELEASE, k, Om, s)
                h_k = _ladder_h(k, h_ref)
                status, d = _release_step(tab, off, ph, S, Fs, ct, st, h_k - R, -0.3 * h, 0.6 * h, c_e, cd_e, wall, n, s,
                                          modes, par, ws, A, memo[2])
                if status == 1:
                    return FALLBACK, t, steps
                R = h_k - min(max(d, -0.3 * h), 0.6 * h)  # the release as found (or as far as the series reaches)
                if (status == 0 and 0.0 <= d <= 0.25 * h) or R > _RELEASE_REACH * h:
                    break
            if status == 0 and 0.0 <= d <= 0.25 * h and _resolution(tail, ws[_F], s) <= _RESOLUTION_TOL:
                if t - d + h_k >= t_stop:
                    return FALLBACK, t, steps
                # the state at the release step's start: the series, without the overlap's share of F_w
                Ys = ws[_YS]
                _series_at(S, d, Ys, m)
                cs, ss = _rotate(ct, st, -Om * d)
                ore, oim = _overlap_fourier(Fs, d, ct, st, Om)
                Ynew[:m] = Ys[:m]
                Ynew[m:] = Y[m:]
                frow = 2 * n + 2 if wall == 0 else 2 * n + 4
                Ynew[frow] -= sgn * ore
                Ynew[frow + 1] -= sgn * oim
                _end_state(tab, off, ph, Ynew, Y, ws[_F], cs, ss, wall, n, s, par)
                return RELEASED, t - d + h_k, steps + 1
            # the contact lasts longer than predicted, or its end is not resolved: a regular step first
        k = _ladder(min(R / 1.6, _MAX_STEP_PERIODS * h_ref), h_ref, False)
        if k < 0 or t + 1.5 * R >= t_stop:
            return FALLBACK, t, steps
        kind = REGULAR
    return FALLBACK, t, steps


def workspace(nodes: Nodes, n: int) -> tuple[np.ndarray, ...]:
    """Scratch arrays of `contact` (ws, A, S) for n modes, and a fresh memo of first guesses."""
    s = nodes.u.size
    order = nodes.onset.shape[0]
    memo = np.empty((3, s))
    memo[0] = 0.85  # onset: indentation / free indentation (Hertz: ~0.7 at the half contact)
    memo[1] = 0.9
    memo[2] = (1.0 - nodes.u) ** 2  # release: indentation / indentation at the start, linear in time to the end
    return np.zeros((_WS_ROWS, max(s + 1, 2 * n + 6, order))), np.zeros((s + 1, s + 1)), np.zeros((order, 2 * n + 2)), memo


# ----------------------------------------------------------------------------------------------------------
# tables per system
# ----------------------------------------------------------------------------------------------------------
class Tables:
    """The ladder of tables of one system (filled on first use by `contact`), with the universal node data."""

    def __init__(self, n: int):
        self.nodes = Nodes()
        self.off = _offsets(NODES, n)
        self.tabs = np.zeros((2, 3, LADDER_SIZE, int(self.off[_SIZE])))
        self.built = np.zeros((2, 3, LADDER_SIZE), dtype=np.bool_)


#: Tables of the most recently used systems (a few MB each). They depend on the modes, the wall values and
#: the sphere's mass only, so a whole sweep (and every point of a study with the same D) shares them.
_CACHE: OrderedDict[bytes, Tables] = OrderedDict()
_CACHE_SIZE = 4


def tables_for(modes: np.ndarray, m_a: float) -> Tables:
    """The `Tables` of the system with this modal table (rows of `sim.flight`) and sphere mass m_a (kg)."""
    key = np.ascontiguousarray(modes[[_SIG, _WD, _W2, _PL, _PR]]).tobytes() + np.float64(m_a).tobytes()
    tables = _CACHE.pop(key, None)
    if tables is None:
        tables = Tables(modes.shape[1])
    _CACHE[key] = tables
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return tables


def arguments(sys, modes: np.ndarray) -> tuple:
    """The tuple `sim.exact._advance` passes on to `contact` for one run_step call (fresh first guesses, and
    room for the node phases of its Omega)."""
    tables = tables_for(modes, sys.m_a)
    nodes = tables.nodes
    n = modes.shape[1]
    ws, A, S, memo = workspace(nodes, n)
    h_ref = 2.0 * math.pi / math.sqrt(float(np.max(modes[_W2])))  # period of the highest mode
    return (tables.tabs, tables.built, tables.off, nodes.u, nodes.wb, nodes.b, nodes.xq, nodes.bq, nodes.onset,
            nodes.regular, nodes.tail, h_ref, memo, ws, A, S, np.zeros((3, LADDER_SIZE, 2, NODES + 1)),
            np.zeros((3, LADDER_SIZE), dtype=np.bool_))
