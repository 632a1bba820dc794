"""Contacts by the embedded Dormand-Prince 5(4) pair with error control, for the exact integrator (`sim.integration.exact`).

Eqs. 3-7 in the deviation coordinates of `sim.integration.exact` plus the integrands of the Fourier integrals F_l, F_r of
the contact forces and of the modes' contact work (the energy bookkeeping, `sim.integration.energy`). A step runs on the time map of `sim.integration.flight.time_map` (u^2 from an onset, so the local
error stays of 5th order although the force starts like (t - t_on)^1.5); the step length is controlled by
the embedded error estimate on all mechanical states (scaled to m of wall/tip displacement, tolerance
rtol); the release is predicted from c, c', c'' of the active wall and reached by a step with the release
time map whose length is found by Newton iteration (|c| < the gap tolerance). `sim.integration.collocation` takes most
contacts; this pair takes those it leaves, or all of them on request.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from sim.integration import flight
from sim.integration.flight import COUNT, GRAZE, NONFINITE, OK, ONSET, OVERLAP, REGULAR, RELEASE, STALLED
from sim.integration.jit import kernel
from sim.model.contact_law import onset_exponent, uses_rate, wall_dissipation, wall_force


class ButcherTableau(NamedTuple):
    """An explicit Runge-Kutta tableau: nodes c, rows a of the lower triangle, weights b of the solution and
    b_err = b - b_hat of the embedded error estimate (b_hat: the weights of the lower-order solution)."""

    c: tuple
    a: tuple
    b: tuple
    b_err: tuple


#: Dormand, J. R. and Prince, P. J. (1980), A family of embedded Runge-Kutta formulae, J. Comput. Appl. Math.
#: 6(1), 19-26, RK5(4)7M: the coefficients of scipy's RK45 and MATLAB's ode45. The 7th stage is the solution
#: (first same as last): its row of a is b.
DOPRI5 = ButcherTableau(
    c=(0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0),
    a=((),
       (1 / 5,),
       (3 / 40, 9 / 40),
       (44 / 45, -56 / 15, 32 / 9),
       (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
       (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656)),
    b=(35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0.0),
    b_err=(71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40),
)


class Work(NamedTuple):
    """Scratch of the Dormand-Prince contact: K (7 x size) the stage derivatives, `stage` the state of a
    stage, `end` the state at a step's end, `memo` the two step-length laws of `contact`, `counters` (int64,
    indexed by `sim.integration.flight.COUNT`); `book`: (True,) when the energy bookkeeping's integrals (G_j, Dc) are
    carried, () when not (no ledger).

    `book` is a type, not a value, like the contact law (`sim.integration.flight.Constants.law`): the kernels are
    compiled once per combination, and a contact carries no trace of what it does not compute (a branch on
    par.c_damp inside the stages made elastic runs 4 % slower, measured)."""

    K: np.ndarray
    stage: np.ndarray
    end: np.ndarray
    memo: np.ndarray
    counters: np.ndarray
    book: tuple


def work(size: int, counters: np.ndarray, book: bool = True) -> Work:
    """A fresh `Work` for deviation states of length `size`, counting into `counters`; book: carry the energy
    bookkeeping's integrals."""
    return Work(K=np.zeros((7, size)), stage=np.zeros(size), end=np.zeros(size), memo=np.zeros(2),
                counters=counters, book=(True,) if book else ())


# No fastmath: reassociation lets each compiled specialisation round differently, and the chaotic response
# turns one ulp into a different trajectory; serial and parallel runs must give the same numbers.
_FAST = False


@kernel(inline="always", fastmath=_FAST)
def _wall_rate(ct, st, Y, left, cst):
    """d/dt of delta_l (left) or delta_r in m/s at cos, sin(Omega t) = ct, st: the harmonic wall motion's rate
    -Omega (W_re sin + W_im cos), the deviations' phi^T x' and the sphere's -z'."""
    md, par = cst.modes, cst.par
    lay = flight.state_layout(md.size)
    W_re = par.W_l_re if left else par.W_r_re
    W_im = par.W_l_im if left else par.W_r_im
    rate = -par.Omega * (W_re * st + W_im * ct) - Y[lay.zd]
    for j in range(lay.n):
        rate += (md[j].phi_l if left else md[j].phi_r) * Y[lay.v + j]
    return rate


@kernel(inline="always", fastmath=_FAST)
def rhs(ct, st, Y, out, cst, book):
    """Eqs. 3-7 with the contact law cst.law (`sim.model.contact_law`) in the deviation coordinates at cos,
    sin(Omega t) = ct, st, plus the integrands of F_l, F_r and, when booking (`Work.book`), of each mode's contact
    work G_j and of the law's dissipation Dc (`sim.integration.flight.StateLayout`; it stays 0 for a conservative
    law, whose approach rates are not computed)."""
    md, par = cst.modes, cst.par
    lay = flight.state_layout(md.size)
    g = par.g
    z = Y[lay.z]
    dl = par.W_l_re * ct - par.W_l_im * st - z - g
    dr = par.W_r_re * ct - par.W_r_im * st - z + g
    for j in range(lay.n):
        x = Y[lay.x + j]
        dl += md[j].phi_l * x
        dr += md[j].phi_r * x
    law = cst.law
    rate_l = rate_r = 0.0
    if uses_rate(law):  # a compile-time constant per law
        if dl > 0.0:
            rate_l = _wall_rate(ct, st, Y, True, cst)
        if dr < 0.0:
            rate_r = -_wall_rate(ct, st, Y, False, cst)
        if len(book) > 0:
            out[lay.Dc] = (wall_dissipation(law, dl, rate_l, par.k_H, par.c_damp)
                           + wall_dissipation(law, -dr, rate_r, par.k_H, par.c_damp))
    fl = wall_force(law, dl, rate_l, par.k_H, par.c_damp)
    fr = -wall_force(law, -dr, rate_r, par.k_H, par.c_damp)
    for j in range(lay.n):
        v = Y[lay.v + j]
        out[lay.x + j] = v
        out[lay.v + j] = -2.0 * md[j].sig * v - md[j].w2 * Y[lay.x + j] - md[j].phi_l * fl - md[j].phi_r * fr
        if len(book) > 0:
            out[lay.G + j] = (md[j].phi_l * fl + md[j].phi_r * fr) * v
    out[lay.z] = Y[lay.zd]
    out[lay.zd] = (fl + fr) * par.inv_m_a
    out[lay.F_l] = fl * ct
    out[lay.F_l + 1] = -fl * st
    out[lay.F_r] = fr * ct
    out[lay.F_r + 1] = -fr * st


@kernel(inline="always")
def _warp(kind, u, s):
    """(phi(u), phi'(u)) of a step of length s with the time map `kind` of `sim.integration.flight.time_map`: with it
    an onset or release step keeps its 5th order (in t the local error is O(h^2.5) there)."""
    w, dw = flight.time_map(kind, u)
    return s * w, s * dw


@kernel(inline="always", fastmath=_FAST)
def _combine(Y, K, d, row, out, m):
    """out[:m] = Y + sum_j row[j] d[j] K[j], summed left to right (a stage or the solution; zero weights skipped)."""
    for i in range(m):
        acc = Y[i]
        for j in range(len(row)):
            if row[j] != 0.0:
                acc += row[j] * d[j] * K[j, i]
        out[i] = acc


@kernel(inline="always", fastmath=_FAST)
def _stage(Y, work, d, row, k, phase, cst):
    """Stage k: its state Y + sum_j row[j] d[j] K[j] in work.stage, and K[k] = F there, at cos, sin(Omega t) =
    phase. Only the mechanical state: the right-hand side does not depend on the carried integrals."""
    K, tmp = work.K, work.stage
    _combine(Y, K, d, row, tmp, flight.state_layout(cst.modes.size).acc)
    rhs(phase[0], phase[1], tmp, K[k], cst, work.book)


@kernel(inline="always", fastmath=_FAST)
def _error(K, d, i):
    """Component i of the embedded error estimate, sum_j b_err[j] d[j] K[j, i] left to right."""
    e = DOPRI5.b_err
    acc = e[0] * d[0] * K[0, i]
    for j in range(1, len(e)):
        if e[j] != 0.0:
            acc += e[j] * d[j] * K[j, i]
    return acc


@kernel(fastmath=_FAST)
def step(Y, ct0, st0, s, kind, work, cst):
    """One Dormand-Prince 5(4) step (`DOPRI5`) from (t, Y), cos, sin(Omega t) = ct0, st0, over the time map of
    `_warp` (kind, length s in time); Eqs. 3-7. The phase is carried by rotations: no cos/sin per step.

    work.K holds the raw right-hand sides F: K[0] = F(t, Y) on entry, K[6] = F(t + s, end) on exit (first same
    as last); dY/du = phi'(u) F(t_a + phi(u), Y). The step's end state goes to work.end. Returns the scaled
    error estimate (accept if <= 1): max over the mechanical states of |err_i| / scale_i (the records' err_*).
    """
    md, par = cst.modes, cst.par
    lay = flight.state_layout(md.size)
    K, Ynew = work.K, work.end
    c, a = DOPRI5.c, DOPRI5.a
    Om = par.Omega
    _, d1 = _warp(kind, c[0], s)
    p2, d2 = _warp(kind, c[1], s)
    p3, d3 = _warp(kind, c[2], s)
    p4, d4 = _warp(kind, c[3], s)
    p5, d5 = _warp(kind, c[4], s)
    _, d6 = _warp(kind, c[5], s)
    d = (d1, d2, d3, d4, d5, d6, d6)
    _stage(Y, work, d, a[1], 1, flight.rotate(ct0, st0, Om * p2), cst)
    _stage(Y, work, d, a[2], 2, flight.rotate(ct0, st0, Om * p3), cst)
    _stage(Y, work, d, a[3], 3, flight.rotate(ct0, st0, Om * p4), cst)
    _stage(Y, work, d, a[4], 4, flight.rotate(ct0, st0, Om * p5), cst)
    ct, st = flight.rotate(ct0, st0, Om * s)
    _stage(Y, work, d, a[5], 5, (ct, st), cst)
    # the carried integrals up to G always (Fourier), G and Dc only when booking (else they stay 0)
    _combine(Y, K, d, DOPRI5.b, Ynew, Y.size if len(work.book) > 0 else lay.G)
    rhs(ct, st, Ynew, K[6], cst, work.book)
    err = 0.0
    for j in range(lay.n):
        err = max(err, abs(_error(K, d, lay.x + j)) * md[j].err_x)
        err = max(err, abs(_error(K, d, lay.v + j)) * md[j].err_v)
    err = max(err, abs(_error(K, d, lay.z)) * par.err_z)
    err = max(err, abs(_error(K, d, lay.zd)) * par.err_zd)
    return err


@kernel
def locate_release(Y, at, s, s_max, kind, wall_left, work, cst):
    """Length s of a step of `kind` from Y at `at` (a `sim.integration.flight.Phase`) that ends at the release c = 0 of
    the active wall (Eqs. 4-6).

    Newton iteration on the step length from the guess s, bracketed as soon as a step ends open; never
    longer than s_max. On return work.end holds the state at t + s; returns (s, err of that step, found).
    """
    tol = cst.par.gap_tol
    Om = cst.par.Omega
    Ynew, counters = work.end, work.counters
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
        err = step(Y, at.cos, at.sin, s, kind, work, cst)
        counters[COUNT.release_iterations] += 1
        ct1, st1 = flight.rotate(at.cos, at.sin, Om * s)
        a1, a2, a3, a4 = flight.closing_at(Ynew, ct1, st1, cst)
        c_s = a1 if wall_left else a3
        cd_s = a2 if wall_left else a4
        if c_s > 0.0:
            if s >= s_max:
                return s, err, False
            lo = s
        else:
            hi = s
        if abs(c_s) <= tol or (hi < np.inf and hi - lo <= 4e-16 * (at.t + hi)):
            break
        if cd_s < 0.0:
            s = s - c_s / cd_s
        else:
            s = 0.5 * (lo + hi) if hi < np.inf else 2.0 * s
    if c_s > tol:
        if hi == np.inf:
            return s, err, False
        s = hi
        err = step(Y, at.cos, at.sin, s, kind, work, cst)
    return s, err, True


@kernel(inline="always")
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


@kernel(inline="always")
def _curvature(K, ct, st, wall_left, cst):
    """c'' of the active wall from the accelerations in K[0] (harmonic part: -Omega^2 times its value)."""
    md, par = cst.modes, cst.par
    lay = flight.state_layout(md.size)
    Om = par.Omega
    if wall_left:
        cdd = -Om * Om * (par.W_l_re * ct - par.W_l_im * st) - K[0, lay.zd]
        for j in range(lay.n):
            cdd += md[j].phi_l * K[0, lay.v + j]
    else:
        cdd = Om * Om * (par.W_r_re * ct - par.W_r_im * st) + K[0, lay.zd]
        for j in range(lay.n):
            cdd -= md[j].phi_r * K[0, lay.v + j]
    return cdd


@kernel
def contact(Y, t, t_stop, h, at_onset, work, cst):
    """Integrate a contact phase (Eqs. 3-7) from (t, Y) until all contacts have opened or t_stop is reached.

    at_onset: t is a located onset (the first step then uses the onset time map). The release is
    predicted from c, c', c'' of the active wall and reached by a step with the release time map whose
    length is found by Newton iteration. Returns (t, h_next, released, status, extra_onsets). With
    par.h_fixed > 0 the step is fixed (order studies) and only cut at t_stop and at the release.

    work.memo[0], [1]: err / (v^p s^(p+1)) of the last onset / release step (v: contact speed, s: length, p the
    law's onset exponent, `sim.model.contact_law.Law.exponent`: 1.5 for Hertz). The embedded error estimate of these
    steps grows like s^(p+1) (Hertz's force ~ u^3 on the time map is integrated exactly only by the 5th-order
    solution), so their length is predicted from that law instead of by trial.
    """
    par = cst.par
    p = onset_exponent(cst.law)  # a compile-time constant per law
    p1 = p + 1.0
    K, Ynew, memo, counters = work.K, work.end, work.memo, work.counters
    Om = par.Omega
    ct = math.cos(Om * t)  # the phase at t, carried along by rotations
    st = math.sin(Om * t)
    rhs(ct, st, Y, K[0], cst, work.book)
    cl, cld, cr, crd = flight.closing_at(Y, ct, st, cst)
    wall_left = cl > cr  # the wall in contact (or about to be)
    open_l = cl <= 0.0
    open_r = cr <= 0.0
    c_act = cl if wall_left else cr
    cd_act = cld if wall_left else crd
    first = at_onset
    extra = 0
    fixed_step = par.h_fixed
    adaptive = fixed_step <= 0.0
    if not adaptive:
        h = fixed_step
    elif first and memo[0] > 0.0:
        h = (0.5 / (memo[0] * max(cd_act, 1e-6) ** p)) ** (1.0 / p1)
    v_onset = max(cd_act, 1e-6)
    for _ in range(10_000_000):
        s_step = min(h, par.h_max)
        last = s_step >= t_stop - t
        if last:
            s_step = t_stop - t
        if adaptive and not first and c_act > 0.0:
            cdd = _curvature(K, ct, st, wall_left, cst)
            tau = _first_root(c_act, cd_act, cdd)
            v_rel = max(abs(cd_act + cdd * tau), 1e-6)
            s_rel = (0.5 / (memo[1] * v_rel**p)) ** (1.0 / p1) if memo[1] > 0.0 else s_step
            if tau <= 1.2 * s_rel and tau <= 1.25 * s_step and tau < t_stop - t:
                s, err, found = locate_release(Y, flight.Phase(t, ct, st), tau, min(2.0 * s_step, t_stop - t),
                                               RELEASE, wall_left, work, cst)
                if found:
                    memo[1] = max(err, 1e-3) / (v_rel**p * s**p1)
                    if err <= 1.0:
                        for i in range(Y.size):
                            Y[i] = Ynew[i]
                        counters[COUNT.contact_steps] += 1
                        return t + s, h, True, OK, extra
                    # too long: a regular step that leaves a release step of acceptable length
                    counters[COUNT.rejected_steps] += 1
                    h = max(s - s * 0.9 * err ** (-1.0 / p1), 0.05 * s)
                    continue
            elif tau < s_step + s_rel and tau < t_stop - t:
                # approach so that the release step left over is s_rel (never longer than the step control allows)
                s_step = min(s_step, max(tau - 0.9 * s_rel, 0.5 * tau))
                last = False
        kind = ONSET if first else REGULAR
        err = step(Y, ct, st, s_step, kind, work, cst)
        if not math.isfinite(err):
            return t, h, False, NONFINITE, extra
        if adaptive and err > 1.0:
            counters[COUNT.rejected_steps] += 1
            if first:
                memo[0] = err / (v_onset**p * s_step**p1)
                h = s_step * max(0.1, 0.9 * err ** (-1.0 / p1))
            else:
                h = s_step * max(0.2, 0.9 * err ** -0.2)
            continue
        if adaptive and first:
            memo[0] = max(err, 1e-3) / (v_onset**p * s_step**p1)
        ct1, st1 = flight.rotate(ct, st, Om * s_step)
        ncl, ncld, ncr, ncrd = flight.closing_at(Ynew, ct1, st1, cst)
        if ncl <= 0.0 and ncr <= 0.0:
            # release inside (t, t + s_step]: a step with the release time map ending exactly there
            kind = GRAZE if first else RELEASE
            c_end = ncl if wall_left else ncr
            cd_end = ncld if wall_left else ncrd
            guess = s_step - c_end / cd_end if cd_end < 0.0 else 0.5 * s_step
            s, err, found = locate_release(Y, flight.Phase(t, ct, st), guess, min(2.0 * s_step, t_stop - t), kind,
                                           wall_left, work, cst)
            if adaptive and err > 1.0 and s > 1e-3 * s_step:
                # too long for the tolerance: first a shorter (onset or regular) step towards the release
                counters[COUNT.rejected_steps] += 1
                h = s * min(0.5, max(0.2, 0.9 * err ** -0.2))
                continue
            counters[COUNT.contact_steps] += 1
            if not found:
                # the release-map step still ends (barely, |c| ~ rounding) closed while the regular step ended
                # open: c hovers at 0 (sphere riding on the wall); release at the regular step's end
                s = s_step
                step(Y, ct, st, s, ONSET if first else REGULAR, work, cst)
            for i in range(Y.size):
                Y[i] = Ynew[i]
            return t + s, h, True, OK, extra
        # accepted step inside the contact
        counters[COUNT.contact_steps] += 1
        if (ncl > 0.0 and open_l and not first and not wall_left) or (ncr > 0.0 and open_r and not first and wall_left):
            extra += 1  # the other wall closed within the contact (not located; physically excluded)
        open_l = ncl <= 0.0
        open_r = ncr <= 0.0
        c_act = ncl if wall_left else ncr
        cd_act = ncld if wall_left else ncrd
        first = False
        if ncl > par.g or ncr > par.g:
            return t + s_step, h, False, OVERLAP, extra
        for i in range(Y.size):
            Y[i] = Ynew[i]
        for i in range(Y.size):
            K[0, i] = K[6, i]
        t = t + s_step
        norm = 1.5 - 0.5 * (ct1 * ct1 + st1 * st1)  # keeps cos^2 + sin^2 = 1 to rounding along the rotations
        ct = ct1 * norm
        st = st1 * norm
        if adaptive and not last:
            h = s_step * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** -0.2))
        if last:
            return t_stop, h, False, OK, extra
    return t, h, False, STALLED, extra
