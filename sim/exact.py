"""Exact free-flight integrator with located contacts (issue 5), for Eqs. 3-7 of the seed paper.

Between contacts the system is linear (Sect. 5.5, Eq. 9): each mode is a damped oscillator under the
harmonic base excitation and the sphere flies at constant absolute velocity. We split every quantity into
the particular harmonic solution and a homogeneous deviation, in the coordinates of `sim.system`
(phase time t in [0, T) of the current excitation period, T = 2 pi / Omega):

    s_j = x_j + Re(S_j e^{i Omega t}),   S_j = gamma_j a_base Omega^2 / (omega_j^2 - Omega^2 + 2 i D_j omega_j Omega)
    u_a = z - a_base cos(Omega t)        (so z'' = (f_l + f_r) / m_a, zero in free flight)

    x_j'' + 2 D_j omega_j x_j' + omega_j^2 x_j = -phi_l,j f_l - phi_r,j f_r.

Free flight: x_j advances with the closed-form damped transition (the homogeneous part of Eq. 9), z
linearly; no truncation error. Closing functions of the two contacts (contact when c > 0, Eqs. 4-6):

    c_l = delta_l = phi_l^T x + Re(W_l e^{i Omega t}) - z - g,      W_w = phi_w^T S + a_base
    c_r = -delta_r = -(phi_r^T x + Re(W_r e^{i Omega t}) - z) - g.

No contact is skipped. Free flight runs on a grid of N_grid steps per period; a grid step is accepted
only if a rigorous upper bound of max c over the step is negative. With A_j the modulus of mode j's
complex amplitude (it only decays in free flight) the bounds used are (M_w = sum_j |phi_w,j| A_j omega_j^2
+ |W_w| Omega^2 bounds |c''|):

    chord:    max(c_0, c_1) + sum_j |phi_w,j| A_j min(omega_j^2 h^2 / 8, 2) + |W_w| Omega^2 h^2 / 8,
    Taylor:   max(c_0, c_0 + c_0' h + M_w h^2 / 2)   and its mirror from the step's end.

Otherwise a conservative Newton search walks from the step's start with the largest step that the
quadratic majorant c + c' h + M_w h^2 / 2 allows: it can never pass a zero of c, and converges
quadratically onto the first onset (or certifies the step). Grazes with indentation below
`GAP_TOLERANCE * g` are ignored (force < 1e-13 N at the nominal k_H).

Contact: from the located onset, exponential Gauss collocation (`sim.collocation`: the modes and the
sphere exact, the Hertz force at 10 nodes per step, two to four steps per impact, the last one ending
exactly at the release; rebound errors ~1e-10). Where that cannot go on (a contact crossing the end of a
period or a record instant, a force it does not resolve, about 2 % of the contacts in the rig's sweeps)
an embedded Dormand-Prince 5(4) step with error control on all modal states (scaled to m of wall/tip
displacement, tolerance rtol) takes over; its release is located by Newton iteration on the length of the
last step (|c| < GAP_TOLERANCE * g). Chattering is handled because every release is followed by the same
certified free-flight search.

Measure (Sect. 5): c_1 = (2/T) int_T q_tip e^{-i Omega t} dt is exact. The particular part contributes
phi_tip^T S per whole period; for the deviation x_j, multiplying its equation by e^{-i Omega t} and
integrating by parts over the period (e^{-i Omega T} = 1) gives, with Delta_j = omega_j^2 - Omega^2 + 2 i sigma_j Omega,

    Delta_j int_T x_j e^{-i Omega t} dt = -[x_j'] - (i Omega + 2 sigma_j) [x_j] - phi_l,j F_l - phi_r,j F_r,

[.] the change over the period and F_w = int_T f_w e^{-i Omega t} dt the Fourier integral of the contact force,
two further components of the Dormand-Prince state during contacts (5th order). Free flight needs no
quadrature at all.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from sim import collocation
from sim.errors import SimulationDiverged, SimulationInputError
from sim.flight import (GRAZE, ONSET, REGULAR, RELEASE, _ABASE, _APL, _APR, _G, _HG, _HMAX, _IMA, _IWD, _KH, _MA,
                        _ML0, _MR0, _N_PAR, _N_ROWS, _OM, _PIM, _PL, _PR, _PRE, _RHI, _RHR, _SCV, _SCX, _SCZ, _SCZD,
                        _SIG, _SIM, _SOW, _SRE, _TOL, _VMIN, _W2, _W2OW, _WD, _WLI, _WLR, _WRI, _WRR, _apply_flight,
                        _closing, _closing_at, _flight_transitions, _rotate, _time_map, _transition)
from sim.system import SystemArrays, check_run_step

#: Free-flight grid steps per excitation period (certification cells; no effect on accuracy).
GRID_PER_PERIOD = 48
#: Default tolerance of the Dormand-Prince contact steps, relative to the clearance g (error per step, in m / g).
#: They only take the contacts collocation leaves (2 % in sweeps), so it is tight: the energy drift over 1000
#: impacts is theirs, 3e-7 to 9e-7 at 1e-10 depending on the trajectory, 6e-9 to 3e-7 at 1e-11, at no measurable
#: cost per point (tests/benchmarks/test_exact_energy.py).
CONTACT_RTOL = 1e-11
#: Onset/release location tolerance on the closing function, relative to g.
GAP_TOLERANCE = 1e-12
#: Contact onsets need an approach speed above this (m/s) unless the indentation already exceeds the tolerance.
MIN_APPROACH_SPEED = 1e-9

# counters
_C_GRID, _C_SEARCH, _C_EVAL, _C_ACC, _C_REJ, _C_REL, _C_CONTACT, _C_COLLOC, _C_FALLBACK = range(9)
_N_COUNT = 9
# status codes
_OK, _NONFINITE, _OVERLAP, _STALLED, _STALLED_SEARCH = 0, 1, 2, 3, 4
_MAX_SEARCH = 200_000
_MAX_ONSETS_PER_PERIOD = 100_000

# Dormand-Prince 5(4) tableau (Dormand & Prince 1980; the coefficients of scipy's RK45 / MATLAB ode45)
_C2, _C3, _C4, _C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
_A21 = 1 / 5
_A31, _A32 = 3 / 40, 9 / 40
_A41, _A42, _A43 = 44 / 45, -56 / 15, 32 / 9
_A51, _A52, _A53, _A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
_A61, _A62, _A63, _A64, _A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
_B1, _B3, _B4, _B5, _B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
_E1, _E3, _E4, _E5, _E6, _E7 = 71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40


@njit(cache=True, inline="always")
def _majorant_step(c, cd, M):
    """Smallest positive root h of c + cd h + M h^2 / 2 = 0 for c < 0 (inf if there is none)."""
    if M <= 0.0:
        return -c / cd if cd > 0.0 else np.inf
    root = math.sqrt(cd * cd - 2.0 * M * c)
    if cd > 0.0:
        return -2.0 * c / (cd + root)
    return (root - cd) / M


@njit(cache=True)
def _curvature_bounds(Y, n, modes, par):
    """M_l, M_r: bounds of |c''| valid from now on in free flight (mode envelopes only decay)."""
    Ml = par[_ML0]
    Mr = par[_MR0]
    for j in range(n):
        x = Y[j]
        q = (Y[n + j] + modes[_SIG, j] * x) * modes[_IWD, j]
        A = math.sqrt(x * x + q * q) * modes[_W2, j]
        Ml += modes[_APL, j] * A
        Mr += modes[_APR, j] * A
    return Ml, Mr


@njit(cache=True)
def _search(Y, t0, tau_end, n, modes, par, scratch, counters):
    """First contact onset in (t0, t0 + tau_end] of the free flight from Y, by conservative Newton steps.

    Returns (tau, wall): wall 0 (left) or 1 (right) with the onset at t0 + tau and the state there in
    scratch[:2 n + 2], -1 if the interval is certified contact-free, -2 if the search stalled.
    """
    Ml, Mr = _curvature_bounds(Y, n, modes, par)
    tol = par[_TOL]
    vmin = par[_VMIN]
    tau = 0.0
    for _ in range(_MAX_SEARCH):
        if tau == 0.0:
            scratch[:2 * n + 2] = Y[:2 * n + 2]
            cl, cld, cr, crd = _closing(Y, t0, n, modes, par)
        else:
            for j in range(n):
                a, b, c, d = _transition(tau, modes, j)
                x = Y[j]
                v = Y[n + j]
                scratch[j] = a * x + b * v
                scratch[n + j] = c * x + d * v
            scratch[2 * n] = Y[2 * n] + tau * Y[2 * n + 1]
            scratch[2 * n + 1] = Y[2 * n + 1]
            cl, cld, cr, crd = _closing(scratch, t0 + tau, n, modes, par)
        counters[_C_EVAL] += 1
        if cl > -tol and (cld > vmin or cl > tol):
            return tau, 0
        if cr > -tol and (crd > vmin or cr > tol):
            return tau, 1
        h = min(_majorant_step(min(cl, -tol), cld, Ml), _majorant_step(min(cr, -tol), crd, Mr))
        tau += h
        if tau >= tau_end:
            return tau_end, -1
    return tau, -2


# ----------------------------------------------------------------------------------------------------------
# contact: Dormand-Prince 5(4) with error control
# ----------------------------------------------------------------------------------------------------------
# No fastmath: reassociation lets each compiled specialisation round differently, and the chaotic response
# turns one ulp into a different trajectory; with a cold numba cache serial and parallel runs then differed
# (tests/sim/test_batch.py failed 3 times out of 3 on a fresh checkout), breaking issue 6's bit-identity.
_FAST = False


@njit(cache=True, inline="always", fastmath=_FAST)
def _rhs(ct, st, Y, out, n, modes, par):
    """Eqs. 3-7 in the deviation coordinates at cos, sin(Omega t) = ct, st, plus the integrands of F_l, F_r."""
    g = par[_G]
    z = Y[2 * n]
    dl = par[_WLR] * ct - par[_WLI] * st - z - g
    dr = par[_WRR] * ct - par[_WRI] * st - z + g
    for j in range(n):
        x = Y[j]
        dl += modes[_PL, j] * x
        dr += modes[_PR, j] * x
    kH = par[_KH]
    fl = kH * dl * math.sqrt(dl) if dl > 0.0 else 0.0
    fr = -kH * (-dr) * math.sqrt(-dr) if dr < 0.0 else 0.0
    for j in range(n):
        v = Y[n + j]
        out[j] = v
        out[n + j] = -2.0 * modes[_SIG, j] * v - modes[_W2, j] * Y[j] - modes[_PL, j] * fl - modes[_PR, j] * fr
    out[2 * n] = Y[2 * n + 1]
    out[2 * n + 1] = (fl + fr) * par[_IMA]
    out[2 * n + 2] = fl * ct
    out[2 * n + 3] = -fl * st
    out[2 * n + 4] = fr * ct
    out[2 * n + 5] = -fr * st


@njit(cache=True, inline="always")
def _warp(kind, u, s):
    """(phi(u), phi'(u)) of a step of length s with the time map `kind` of `sim.flight._time_map`: with it
    an onset or release step keeps its 5th order (in t the local error is O(h^2.5) there)."""
    w, dw = _time_map(kind, u)
    return s * w, s * dw


@njit(cache=True, fastmath=_FAST)
def _dp_step(Y, ct0, st0, s, kind, K, tmp, Ynew, n, modes, par):
    """One Dormand-Prince 5(4) step from (t, Y), cos, sin(Omega t) = ct0, st0, over the time map of `_warp`
    (kind, length s in time). The phase is carried by rotations (`_rotate`): no cos/sin per step.

    K holds the raw right-hand sides F: K[0] = F(t, Y) on entry, K[6] = F(t + s, Ynew) on exit (FSAL);
    dY/du = phi'(u) F(t_a + phi(u), Y). Returns the scaled error estimate (accept if <= 1): max over the
    mechanical states of |err_i| / scale_i, scales from `_prepare` (m of wall/tip displacement).
    """
    m = Y.size
    Om = par[_OM]
    _, d1 = _warp(kind, 0.0, s)
    p2, d2 = _warp(kind, _C2, s)
    p3, d3 = _warp(kind, _C3, s)
    p4, d4 = _warp(kind, _C4, s)
    p5, d5 = _warp(kind, _C5, s)
    _, d6 = _warp(kind, 1.0, s)
    for i in range(m):
        tmp[i] = Y[i] + _A21 * d1 * K[0, i]
    ct, st = _rotate(ct0, st0, Om * p2)
    _rhs(ct, st, tmp, K[1], n, modes, par)
    for i in range(m):
        tmp[i] = Y[i] + _A31 * d1 * K[0, i] + _A32 * d2 * K[1, i]
    ct, st = _rotate(ct0, st0, Om * p3)
    _rhs(ct, st, tmp, K[2], n, modes, par)
    for i in range(m):
        tmp[i] = Y[i] + _A41 * d1 * K[0, i] + _A42 * d2 * K[1, i] + _A43 * d3 * K[2, i]
    ct, st = _rotate(ct0, st0, Om * p4)
    _rhs(ct, st, tmp, K[3], n, modes, par)
    for i in range(m):
        tmp[i] = Y[i] + _A51 * d1 * K[0, i] + _A52 * d2 * K[1, i] + _A53 * d3 * K[2, i] + _A54 * d4 * K[3, i]
    ct, st = _rotate(ct0, st0, Om * p5)
    _rhs(ct, st, tmp, K[4], n, modes, par)
    for i in range(m):
        tmp[i] = (Y[i] + _A61 * d1 * K[0, i] + _A62 * d2 * K[1, i] + _A63 * d3 * K[2, i] + _A64 * d4 * K[3, i]
                  + _A65 * d5 * K[4, i])
    ct, st = _rotate(ct0, st0, Om * s)
    _rhs(ct, st, tmp, K[5], n, modes, par)
    for i in range(m):
        Ynew[i] = Y[i] + _B1 * d1 * K[0, i] + _B3 * d3 * K[2, i] + _B4 * d4 * K[3, i] + _B5 * d5 * K[4, i] + _B6 * d6 * K[5, i]
    _rhs(ct, st, Ynew, K[6], n, modes, par)
    err = 0.0
    for j in range(n):
        for i, inv in ((j, modes[_SCX, j]), (n + j, modes[_SCV, j])):
            e = (_E1 * d1 * K[0, i] + _E3 * d3 * K[2, i] + _E4 * d4 * K[3, i] + _E5 * d5 * K[4, i]
                 + _E6 * d6 * K[5, i] + _E7 * d6 * K[6, i])
            err = max(err, abs(e) * inv)
    for i, inv in ((2 * n, par[_SCZ]), (2 * n + 1, par[_SCZD])):
        e = (_E1 * d1 * K[0, i] + _E3 * d3 * K[2, i] + _E4 * d4 * K[3, i] + _E5 * d5 * K[4, i]
             + _E6 * d6 * K[5, i] + _E7 * d6 * K[6, i])
        err = max(err, abs(e) * inv)
    return err


@njit(cache=True)
def _locate_release(Y, t, ct0, st0, s, s_max, kind, wall_left, K, tmp, Ynew, n, modes, par, counters):
    """Length s of a step of `kind` from (t, Y) that ends at the release c = 0 of the active wall.

    Newton iteration on the step length from the guess s, bracketed as soon as a step ends open; never
    longer than s_max. On return Ynew holds the state at t + s; returns (s, err of that step, found).
    """
    tol = par[_TOL]
    lo = 0.0
    hi = np.inf
    err = 0.0
    c_s = 1.0
    for _ in range(60):
        if hi < np.inf:
            if not (lo < s < hi):
                s = 0.5 * (lo + hi)
        elif s <= lo:
            s = 2.0 * lo
        s = min(s, s_max)
        err = _dp_step(Y, ct0, st0, s, kind, K, tmp, Ynew, n, modes, par)
        counters[_C_REL] += 1
        ct1, st1 = _rotate(ct0, st0, par[_OM] * s)
        a1, a2, a3, a4 = _closing_at(Ynew, ct1, st1, n, modes, par)
        c_s = a1 if wall_left else a3
        cd_s = a2 if wall_left else a4
        if c_s > 0.0:
            if s >= s_max:
                return s, err, False
            lo = s
        else:
            hi = s
        if abs(c_s) <= tol or (hi < np.inf and hi - lo <= 4e-16 * (t + hi)):
            break
        if cd_s < 0.0:
            s = s - c_s / cd_s
        else:
            s = 0.5 * (lo + hi) if hi < np.inf else 2.0 * s
    if c_s > tol:
        if hi == np.inf:
            return s, err, False
        s = hi
        err = _dp_step(Y, ct0, st0, s, kind, K, tmp, Ynew, n, modes, par)
    return s, err, True


@njit(cache=True, inline="always")
def _first_root(c, cd, cdd):
    """Smallest tau > 0 with c + cd tau + cdd tau^2 / 2 = 0 for c > 0 (inf if none): release prediction."""
    if cdd == 0.0:
        return -c / cd if cd < 0.0 else np.inf
    disc = cd * cd - 2.0 * cdd * c
    if disc < 0.0:
        return np.inf
    sq = math.sqrt(disc)
    best = np.inf
    for r in ((-cd - sq) / cdd, (-cd + sq) / cdd):
        if 0.0 < r < best:
            best = r
    return best


@njit(cache=True)
def _contact(Y, t, t_stop, h, at_onset, K, tmp, Ynew, n, modes, par, counters, fixed_step, memo):
    """Integrate a contact phase from (t, Y) until all contacts have opened or t_stop is reached.

    at_onset: t is a located onset (the first step then uses the onset time map). The release is
    predicted from c, c', c'' of the active wall and reached by a step with the release time map whose
    length is found by Newton iteration. Returns (t, h_next, released, status, extra_onsets). With
    fixed_step > 0 the step is fixed (order studies) and only cut at t_stop and at the release.

    memo[0], memo[1]: err / (v^1.5 s^2.5) of the last onset / release step (v: contact speed, s: length).
    The embedded error estimate of these steps grows like s^2.5 (the force ~ u^3 is integrated exactly only
    by the 5th-order solution), so their length is predicted from that law instead of by trial.
    """
    Om = par[_OM]
    ct = math.cos(Om * t)  # the phase at t, carried along by rotations
    st = math.sin(Om * t)
    _rhs(ct, st, Y, K[0], n, modes, par)
    cl, cld, cr, crd = _closing_at(Y, ct, st, n, modes, par)
    wall_left = cl > cr  # the wall in contact (or about to be)
    open_l = cl <= 0.0
    open_r = cr <= 0.0
    c_act = cl if wall_left else cr
    cd_act = cld if wall_left else crd
    first = at_onset
    extra = 0
    adaptive = fixed_step <= 0.0
    if not adaptive:
        h = fixed_step
    elif first and memo[0] > 0.0:
        h = (0.5 / (memo[0] * max(cd_act, 1e-6) ** 1.5)) ** 0.4
    v_onset = max(cd_act, 1e-6)
    for _ in range(10_000_000):
        step = min(h, par[_HMAX])
        last = step >= t_stop - t
        if last:
            step = t_stop - t
        if adaptive and not first and c_act > 0.0:
            # c'' of the active wall from the accelerations in K[0] (harmonic part: -Omega^2 times its value)
            if wall_left:
                cdd = -Om * Om * (par[_WLR] * ct - par[_WLI] * st) - K[0, 2 * n + 1]
                for j in range(n):
                    cdd += modes[_PL, j] * K[0, n + j]
            else:
                cdd = Om * Om * (par[_WRR] * ct - par[_WRI] * st) + K[0, 2 * n + 1]
                for j in range(n):
                    cdd -= modes[_PR, j] * K[0, n + j]
            tau = _first_root(c_act, cd_act, cdd)
            v_rel = max(abs(cd_act + cdd * tau), 1e-6)
            s_rel = (0.5 / (memo[1] * v_rel**1.5)) ** 0.4 if memo[1] > 0.0 else step
            if tau <= 1.2 * s_rel and tau <= 1.25 * step and tau < t_stop - t:
                s, err, found = _locate_release(Y, t, ct, st, tau, min(2.0 * step, t_stop - t), RELEASE, wall_left, K,
                                                tmp, Ynew, n, modes, par, counters)
                if found:
                    memo[1] = max(err, 1e-3) / (v_rel**1.5 * s**2.5)
                    if err <= 1.0:
                        for i in range(Y.size):
                            Y[i] = Ynew[i]
                        counters[_C_ACC] += 1
                        return t + s, h, True, _OK, extra
                    # too long: a regular step that leaves a release step of acceptable length
                    counters[_C_REJ] += 1
                    h = max(s - s * 0.9 * err ** -0.4, 0.05 * s)
                    continue
            elif tau < step + s_rel and tau < t_stop - t:
                # approach so that the release step left over is s_rel (never longer than the step control allows)
                step = min(step, max(tau - 0.9 * s_rel, 0.5 * tau))
                last = False
        kind = ONSET if first else REGULAR
        err = _dp_step(Y, ct, st, step, kind, K, tmp, Ynew, n, modes, par)
        if not math.isfinite(err):
            return t, h, False, _NONFINITE, extra
        if adaptive and err > 1.0:
            counters[_C_REJ] += 1
            if first:
                memo[0] = err / (v_onset**1.5 * step**2.5)
                h = step * max(0.1, 0.9 * err ** -0.4)
            else:
                h = step * max(0.2, 0.9 * err ** -0.2)
            continue
        if adaptive and first:
            memo[0] = max(err, 1e-3) / (v_onset**1.5 * step**2.5)
        ct1, st1 = _rotate(ct, st, Om * step)
        ncl, ncld, ncr, ncrd = _closing_at(Ynew, ct1, st1, n, modes, par)
        if ncl <= 0.0 and ncr <= 0.0:
            # release inside (t, t + step]: a step with the release time map ending exactly there
            kind = GRAZE if first else RELEASE
            c_end = ncl if wall_left else ncr
            cd_end = ncld if wall_left else ncrd
            guess = step - c_end / cd_end if cd_end < 0.0 else 0.5 * step
            s, err, found = _locate_release(Y, t, ct, st, guess, min(2.0 * step, t_stop - t), kind, wall_left, K, tmp,
                                            Ynew, n, modes, par, counters)
            if adaptive and err > 1.0 and s > 1e-3 * step:
                # too long for the tolerance: first a shorter (onset or regular) step towards the release
                counters[_C_REJ] += 1
                h = s * min(0.5, max(0.2, 0.9 * err ** -0.2))
                continue
            counters[_C_ACC] += 1
            if not found:
                # the release-map step still ends (barely, |c| ~ rounding) closed while the regular step ended
                # open: c hovers at 0 (sphere riding on the wall); release at the regular step's end
                s = step
                _dp_step(Y, ct, st, s, ONSET if first else REGULAR, K, tmp, Ynew, n, modes, par)
            for i in range(Y.size):
                Y[i] = Ynew[i]
            return t + s, h, True, _OK, extra
        # accepted step inside the contact
        counters[_C_ACC] += 1
        if (ncl > 0.0 and open_l and not first and not wall_left) or (ncr > 0.0 and open_r and not first and wall_left):
            extra += 1  # the other wall closed within the contact (not located; physically excluded)
        open_l = ncl <= 0.0
        open_r = ncr <= 0.0
        c_act = ncl if wall_left else ncr
        cd_act = ncld if wall_left else ncrd
        first = False
        if ncl > par[_G] or ncr > par[_G]:
            return t + step, h, False, _OVERLAP, extra
        for i in range(Y.size):
            Y[i] = Ynew[i]
        for i in range(Y.size):
            K[0, i] = K[6, i]
        t = t + step
        norm = 1.5 - 0.5 * (ct1 * ct1 + st1 * st1)  # keeps cos^2 + sin^2 = 1 to rounding along the rotations
        ct = ct1 * norm
        st = st1 * norm
        if adaptive and not last:
            h = step * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.2))
        if last:
            return t_stop, h, False, _OK, extra
    return t, h, False, _STALLED, extra


# ----------------------------------------------------------------------------------------------------------
# the period loop
# ----------------------------------------------------------------------------------------------------------
@njit(cache=True)
def _to_state(Y, t, y_out, n, modes, par):
    """Write [s, s', u_a, u_a'] at phase time t from the deviation state Y (inverse of the split in `_advance`)."""
    Om = par[_OM]
    ct = math.cos(Om * t)
    st = math.sin(Om * t)
    for j in range(n):
        sr = modes[_SRE, j]
        si = modes[_SIM, j]
        y_out[j] = Y[j] + sr * ct - si * st
        y_out[n + j] = Y[n + j] - Om * (sr * st + si * ct)
    y_out[2 * n] = Y[2 * n] - par[_ABASE] * ct
    y_out[2 * n + 1] = Y[2 * n + 1] + par[_ABASE] * Om * st


@njit(cache=True)
def _advance(y, n_periods, N, modes, par, tr_g, dec_g, kappa_g, rot_g, record, stride, amplitudes,
             impacts, counters, fixed_step, use_collocation, colloc):
    """Advance y (phase 0) over n_periods excitation periods; returns (status, period of failure).

    Contacts start with `collocation.contact` (arguments in the tuple colloc) if use_collocation, and go on
    with the Dormand-Prince `_contact` wherever that falls back."""
    n = modes.shape[1]
    m = 2 * n + 6
    Om = par[_OM]
    T = 2.0 * math.pi / Om
    hg = par[_HG]
    Y = np.zeros(m)
    Ynew = np.zeros(m)
    tmp = np.zeros(m)
    K = np.zeros((7, m))
    tr = np.empty((4, n))
    A = np.empty(n)
    X0 = np.empty(2 * n)  # modal deviation state at the start of the period
    memo = np.zeros(2)
    # phase 0: s = x + Re(S), s' = v - Omega Im(S), u_a = z - a_base
    for j in range(n):
        Y[j] = y[j] - modes[_SRE, j]
        Y[n + j] = y[n + j] + Om * modes[_SIM, j]
    Y[2 * n] = y[2 * n] + par[_ABASE]
    Y[2 * n + 1] = y[2 * n + 1]
    recording = record.shape[0] > 0
    rows = N // stride
    if recording:
        for i in range(2 * n + 2):
            record[0, i] = y[i]
    cl, _, cr, _ = _closing(Y, 0.0, n, modes, par)
    no_contact = par[_KH] == 0.0  # host structure alone (k_H = 0): linear, exact everywhere
    in_contact = (cl > 0.0 or cr > 0.0) and not no_contact
    at_onset = False
    onset_wall = 0
    h_contact = 0.0
    c1l = c1ld = c1r = c1rd = 0.0
    t = 0.0
    for p in range(n_periods):
        Y[2 * n + 2:] = 0.0
        X0[:] = Y[:2 * n]
        onsets = 0
        k = 0  # grid index of the current point (free flight on the grid) or of the last grid point passed
        A_valid = False
        c_valid = False  # c_l, c_r and their rates at the current grid point known from the last grid step
        t = 0.0 if not in_contact else t
        while True:
            wall = -1  # set to 0/1 when a search locates an onset (state in tmp, at t + tau)
            tau = 0.0
            if in_contact:
                c_valid = False
                ks = (int(t / (stride * hg)) + 1) * stride
                t_stop = T if ks >= N else ks * hg
                released = False
                status = _OK
                extra = 0
                if at_onset and use_collocation:
                    outcome, t_new, steps = collocation.contact(Y, t, t_stop, onset_wall, n, modes, par, colloc)
                    counters[_C_COLLOC] += steps
                    released = outcome == collocation.RELEASED
                    t = t_new
                    if not released:
                        counters[_C_FALLBACK] += 1
                        at_onset = steps == 0
                if not released:
                    if h_contact <= 0.0:
                        h_contact = 0.01 / math.sqrt(modes[_W2, n - 1])
                    t, h_contact, released, status, extra = _contact(Y, t, t_stop, h_contact, at_onset, K, tmp, Ynew,
                                                                     n, modes, par, counters, fixed_step, memo)
                at_onset = False
                onsets += extra
                if status != _OK:
                    return status, p
                if not released:
                    if recording:
                        _to_state(Y, t, record[p * rows + min(ks, N) // stride], n, modes, par)
                    if t_stop == T:
                        break
                    continue
                in_contact = False
                k = int(t / hg)
                if k >= N:
                    k = N - 1
                # free flight from the release to the next grid point
                tau_end = (k + 1) * hg - t
                tau, wall = _search(Y, t, tau_end, n, modes, par, tmp, counters)
                if wall == -2:
                    return _STALLED_SEARCH, p
                if wall < 0:
                    _flight_transitions(tau, modes, tr)
                    _apply_flight(Y, Ynew, tau, tr, n)
                    Y[:] = Ynew
                    k += 1
                    t = k * hg
                    A_valid = False
            else:
                # one grid step k -> k + 1 in closed form, accepted if certified contact-free
                if not A_valid:
                    for j in range(n):
                        x = Y[j]
                        q = (Y[n + j] + modes[_SIG, j] * x) * modes[_IWD, j]
                        A[j] = math.sqrt(x * x + q * q)
                    A_valid = True
                counters[_C_GRID] += 1
                _apply_flight(Y, Ynew, hg, tr_g, n)
                if c_valid:  # the end of the last accepted grid step
                    c0l, c0ld, c0r, c0rd = c1l, c1ld, c1r, c1rd
                else:
                    c0l, c0ld, c0r, c0rd = _closing_at(Y, rot_g[0, k], rot_g[1, k], n, modes, par)
                c1l, c1ld, c1r, c1rd = _closing_at(Ynew, rot_g[0, k + 1], rot_g[1, k + 1], n, modes, par)
                Bl = par[_ML0] * hg * hg * 0.125
                Br = par[_MR0] * hg * hg * 0.125
                Ml = par[_ML0]
                Mr = par[_MR0]
                for j in range(n):
                    Bl += modes[_APL, j] * kappa_g[j] * A[j]
                    Br += modes[_APR, j] * kappa_g[j] * A[j]
                    Ml += modes[_APL, j] * modes[_W2, j] * A[j]
                    Mr += modes[_APR, j] * modes[_W2, j] * A[j]
                ok = no_contact or (_max_bound(c0l, c0ld, c1l, c1ld, Bl, Ml, hg) < 0.0
                                    and _max_bound(c0r, c0rd, c1r, c1rd, Br, Mr, hg) < 0.0)
                if not ok:
                    counters[_C_SEARCH] += 1
                    tau, wall = _search(Y, t, hg, n, modes, par, tmp, counters)
                    if wall == -2:
                        return _STALLED_SEARCH, p
                c_valid = wall < 0
                if wall < 0:
                    Y[:] = Ynew
                    for j in range(n):
                        A[j] *= dec_g[j]
                    k += 1
                    t = k * hg
            if wall >= 0:
                # a located onset (`_search` left the state there in tmp): the contact starts
                Y[:2 * n + 2] = tmp[:2 * n + 2]
                t = t + tau
                in_contact = True
                at_onset = True
                onset_wall = wall
                onsets += 1
                counters[_C_CONTACT] += 1
                h_contact = _initial_contact_step(Y, t, n, modes, par)
                A_valid = False
                continue
            if onsets > _MAX_ONSETS_PER_PERIOD:
                return _STALLED, p
            if recording and k % stride == 0:
                _to_state(Y, t, record[p * rows + k // stride], n, modes, par)
            if k >= N:
                break
        # c_1 = phi_tip^T S + (2/T) sum_j phi_tip,j int_T x_j e^{-i Omega t} dt, the integral from the module docstring
        cre = par[_PRE]
        cim = par[_PIM]
        for j in range(n):
            dx = Y[j] - X0[j]
            nre = (-(Y[n + j] - X0[n + j]) - 2.0 * modes[_SIG, j] * dx - modes[_PL, j] * Y[2 * n + 2]
                   - modes[_PR, j] * Y[2 * n + 4])
            nim = -Om * dx - modes[_PL, j] * Y[2 * n + 3] - modes[_PR, j] * Y[2 * n + 5]
            cre += 2.0 / T * (modes[_RHR, j] * nre - modes[_RHI, j] * nim)
            cim += 2.0 / T * (modes[_RHR, j] * nim + modes[_RHI, j] * nre)
        amplitudes[p] = math.sqrt(cre * cre + cim * cim)
        impacts[p] = onsets
        t = 0.0
        for i in range(m):
            if not math.isfinite(Y[i]):
                return _NONFINITE, p
    _to_state(Y, 0.0, y, n, modes, par)
    return _OK, n_periods


@njit(cache=True, inline="always")
def _max_bound(c0, c0d, c1, c1d, B, M, h):
    """Smallest of the chord and the two Taylor upper bounds of max c over a step of length h."""
    chord = max(c0, c1) + B
    left = max(c0, c0 + c0d * h + 0.5 * M * h * h)
    right = max(c1, c1 - c1d * h + 0.5 * M * h * h)
    return min(chord, min(left, right))


@njit(cache=True)
def _initial_contact_step(Y, t, n, modes, par):
    """First step of a contact, tied to the Hertz contact time t_c = 2.9432 delta_max / v0 (rigid wall)."""
    cl, cld, cr, crd = _closing(Y, t, n, modes, par)
    v = max(cld, crd, 1e-6)
    delta_max = (5.0 * par[_MA] * v * v / (4.0 * par[_KH])) ** 0.4
    return min(0.02 * 2.9432 * delta_max / v, par[_HMAX])


# ----------------------------------------------------------------------------------------------------------
# Python entry point
# ----------------------------------------------------------------------------------------------------------
def _prepare(Omega: float, a_base: float, sys: SystemArrays, N: int, rtol: float, h_max: float):
    """Constant tables of the kernel for one excitation (see the module docstring for the symbols)."""
    omega = np.asarray(sys.omega, dtype=np.float64)
    D = np.asarray(sys.D, dtype=np.float64)
    n = omega.size
    sig = D * omega
    wd = omega * np.sqrt(1.0 - D * D)
    S = sys.gamma * a_base * Omega**2 / (omega**2 - Omega**2 + 2j * sig * Omega)
    Wl = complex(np.dot(sys.phi_l, S)) + a_base
    Wr = complex(np.dot(sys.phi_r, S)) + a_base
    P = complex(np.dot(sys.phi_tip, S))
    atol = rtol * sys.g
    wpos = np.maximum(np.maximum(np.abs(sys.phi_l), np.abs(sys.phi_r)), np.abs(sys.phi_tip))
    wpos = np.where(wpos > 0, wpos, 1e-300)
    modes = np.empty((_N_ROWS, n))
    modes[_SIG], modes[_WD], modes[_W2] = sig, wd, omega**2
    modes[_PL], modes[_PR] = sys.phi_l, sys.phi_r
    rho = sys.phi_tip / (omega**2 - Omega**2 + 2j * sig * Omega)  # phi_tip,j / Delta_j
    modes[_RHR], modes[_RHI] = rho.real, rho.imag
    modes[_APL], modes[_APR] = np.abs(sys.phi_l), np.abs(sys.phi_r)
    modes[_SRE], modes[_SIM] = S.real, S.imag
    # inverse error scales: x_j error -> displacement phi_j x_j (m); velocity error e_v -> amplitude e_v / omega_j
    modes[_SCX] = wpos / atol
    modes[_SCV] = wpos / (atol * omega)
    modes[_SOW], modes[_IWD], modes[_W2OW] = sig / wd, 1.0 / wd, omega**2 / wd
    par = np.zeros(_N_PAR)
    par[_OM], par[_ABASE], par[_MA], par[_KH], par[_G] = Omega, a_base, sys.m_a, sys.k_H, sys.g
    par[_IMA] = 1.0 / sys.m_a
    par[_WLR], par[_WLI], par[_WRR], par[_WRI] = Wl.real, Wl.imag, Wr.real, Wr.imag
    par[_PRE], par[_PIM] = P.real, P.imag
    par[_TOL] = GAP_TOLERANCE * sys.g
    par[_VMIN] = MIN_APPROACH_SPEED
    hg = 2.0 * math.pi / Omega / N
    par[_HG] = hg
    par[_ML0], par[_MR0] = abs(Wl) * Omega**2, abs(Wr) * Omega**2
    par[_SCZ] = 1.0 / atol
    par[_SCZD] = 1.0 / (atol * omega[0])
    par[_HMAX] = h_max
    tr_g = np.empty((4, n))
    _flight_transitions(hg, modes, tr_g)
    dec_g = np.exp(-sig * hg)
    kappa_g = np.minimum(omega**2 * hg * hg / 8.0, 2.0)
    phase = Omega * hg * np.arange(N + 1)
    rot_g = np.vstack([np.cos(phase), np.sin(phase)])
    return modes, par, tr_g, dec_g, kappa_g, rot_g


def run_step(y: np.ndarray, n_periods: int, Omega: float, a_base: float, sys: SystemArrays,
             record: np.ndarray | None = None, *, rtol: float = CONTACT_RTOL, grid_per_period: int = GRID_PER_PERIOD,
             fixed_contact_step: float = 0.0, contacts: str = "collocation",
             stats: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Advance y in place over `n_periods` whole excitation periods, exact between contacts (issue 5).

    Integrator contract of `sim.system` (same as `sim.ode3.run_step`): y = [s, s', u_a, u_a'] at
    excitation phase 0 (float64, length 2 n_modes + 2); Omega in rad/s; a_base in m. Returns
    (amplitudes, impacts): per period |c_1| of q_tip in m (Sect. 5, exact quadrature) and the number of
    contact onsets (int64).

    record: optional float64 array (n_periods * M + 1, len(y)) receiving the state at M equally spaced
    instants per period (row 0 = initial state), exactly at those instants.
    rtol: tolerance of the Dormand-Prince contact steps relative to g (per step, in m of wall/tip displacement).
    grid_per_period: free-flight certification cells per period (rounded up to a multiple of M).
    fixed_contact_step: > 0 replaces the error control in contacts by this fixed step in s (order studies;
    Dormand-Prince only).
    contacts: "collocation" (default: `sim.collocation`, Dormand-Prince where it falls back) or "dopri5"
    (every contact by the Dormand-Prince 5(4) pair with error control at rtol).
    stats: optional dict that receives the kernel's counters (grid steps, searches, contact steps, ...).
    Raises SimulationInputError for bad arguments, SimulationDiverged for a non-finite state, an
    indentation beyond the clearance or a stalled contact search.
    """
    n_periods, Omega, a_base, record_arr, samples = check_run_step(y, n_periods, Omega, a_base, sys, record)
    rtol = float(rtol)
    if not math.isfinite(rtol) or not 0.0 < rtol < 1e-2:
        raise SimulationInputError(f"rtol must lie in (0, 0.01), got {rtol!r}")
    if contacts not in ("collocation", "dopri5"):
        raise SimulationInputError(f"contacts must be 'collocation' or 'dopri5', got {contacts!r}")
    if not (sys.m_a > 0 and sys.k_H >= 0 and sys.g > 0):
        raise SimulationInputError("sphere mass and clearance g must be positive and k_H >= 0 (0: no impactor)")
    N = max(int(grid_per_period), samples)
    N = -(-N // samples) * samples
    omega_max = float(np.max(sys.omega))
    h_max = 0.5 / omega_max  # keeps DOPRI5 far inside its stability region on the highest mode
    modes, par, tr_g, dec_g, kappa_g, rot_g = _prepare(Omega, a_base, sys, N, rtol, h_max)
    amplitudes = np.empty(n_periods)
    impacts = np.zeros(n_periods, dtype=np.int64)
    counters = np.zeros(_N_COUNT, dtype=np.int64)
    use_collocation = contacts == "collocation" and fixed_contact_step <= 0.0
    colloc = collocation.arguments(sys, modes)
    status, period = _advance(y, n_periods, N, modes, par, tr_g, dec_g, kappa_g, rot_g, record_arr,
                              N // samples, amplitudes, impacts, counters, float(fixed_contact_step), use_collocation,
                              colloc)
    if stats is not None:
        names = ("grid_steps", "searches", "search_evaluations", "contact_steps", "rejected_steps",
                 "release_iterations", "contacts", "collocation_steps", "collocation_fallbacks")
        for name, value in zip(names, counters):
            stats[name] = stats.get(name, 0) + int(value)
    if status != _OK:
        why = {_NONFINITE: "non-finite state", _OVERLAP: "an indentation larger than the clearance",
               _STALLED: "a contact phase that did not progress",
               _STALLED_SEARCH: "a contact search that did not progress"}[status]
        raise SimulationDiverged(
            f"exact integrator failed in period {period + 1} of this step ({why}); check k_H, g and the level")
    return amplitudes, impacts
