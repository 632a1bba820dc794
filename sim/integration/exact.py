"""Exact free-flight integrator with located contacts, for Eqs. 3-7 of the seed paper.

Between contacts the system is linear (Sect. 5.5, Eq. 9): each mode is a damped oscillator under the
harmonic base excitation and the sphere flies at constant absolute velocity. We split every quantity into
the particular harmonic solution and a homogeneous deviation, in the coordinates of `sim.model.system`
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

Contact: from the located onset, exponential Gauss collocation (`sim.integration.collocation`: the modes and the
sphere exact, the Hertz force at 10 nodes per step, two to four steps per impact, the last one ending
exactly at the release; rebound errors ~1e-10). Where that cannot go on (a contact crossing the end of a
period, a force it does not resolve, about 2 % of the contacts in the rig's sweeps)
an embedded Dormand-Prince 5(4) step with error control on all modal states (`sim.integration.dopri5`, scaled to m
of wall/tip displacement, tolerance rtol) takes over; its release is located by Newton iteration on the
length of the last step (|c| < GAP_TOLERANCE * g). Chattering is handled because every release is followed by the same
certified free-flight search.

Recorded states (the `record` of the integrator contract) are observers: in free flight the closed-form
state at the record instant, inside a contact a copy of the contact's starting state advanced by
Dormand-Prince steps to each record instant; the trajectory is the same, bit for bit, with or without them.

Measure (Sect. 5): c_1 = (2/T) int_T q_tip e^{-i Omega t} dt is exact. The particular part contributes
phi_tip^T S per whole period; for the deviation x_j, multiplying its equation by e^{-i Omega t} and
integrating by parts over the period (e^{-i Omega T} = 1) gives, with Delta_j = omega_j^2 - Omega^2 + 2 i sigma_j Omega,

    Delta_j int_T x_j e^{-i Omega t} dt = -[x_j'] - (i Omega + 2 sigma_j) [x_j] - phi_l,j F_l - phi_r,j F_r,

[.] the change over the period and F_w = int_T f_w e^{-i Omega t} dt the Fourier integral of the contact force,
two further components of the Dormand-Prince state during contacts (5th order). Free flight needs no
quadrature at all.

Energy bookkeeping (Sect. 5.5, `sim.integration.energy`), per period and in closed form from the same integrals. With
Sigma_j = int_T s_j e^{-i Omega t} dt = X_j + S_j T / 2 (X_j the integral above) and E_j = (s_j'^2 + omega_j^2 s_j^2)/2:

    input to mode j    W_j = gamma_j a_base Omega^2 int_T cos(Omega t) s_j' dt = gamma_j a_base Omega^2 ([s_j] - Omega Im Sigma_j)
    input to the sphere W_a = a_base Omega^2 m_a int_T cos(Omega t) u_a' dt = a_base Omega Im(F_l + F_r)
    contact work of j  C_j = int (phi_l,j f_l + phi_r,j f_r) s_j' dt = G_j + Omega Re(i S_j conj(phi_l,j F_l + phi_r,j F_r))
    dissipation of j   D_j = int 2 D_j omega_j s_j'^2 dt = W_j - C_j - [E_j]      (mode j's energy equation, Eq. 7)

G_j = int (phi_l,j f_l + phi_r,j f_r) x_j' dt is accumulated during contacts only, and only when a ledger is
asked for (Gauss quadrature of the exact modal velocities at the collocation nodes, `sim.integration.collocation`; a
component of the Dormand-Prince state); the harmonic part of s_j' enters through F_l, F_r. The contact forces are internal: the balance
sum_j W_j + W_a - sum_j D_j - [E] (E the stored energy, `sim.integration.energy.stored_energy`) vanishes up to the
contact integration's error.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from sim.integration import collocation, dopri5, flight
from sim.integration.energy import Ledger, integrator_output, stored_energy
from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.integration.flight import (COUNT, IMPACT, LEDGER, NONFINITE, OK, OVERLAP, STALLED, STALLED_SEARCH, Constants, Output,
                        mode_records, run_record, state_layout)
from sim.integration.jit import kernel
from sim.model.contact_law import duration_factor, onset_exponent
from sim.model.system import SystemArrays, check_run_step

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

_MAX_SEARCH = 200_000
_MAX_ONSETS_PER_PERIOD = 100_000


class Grid(NamedTuple):
    """The free-flight grid of one run: N steps of h = T / N per excitation period T (s), the state recorded
    at M instants i T / M per period (every dt = T / M s; independent of the grid), and cos, sin(Omega k h) of
    the grid points k = 0..N (`rot`, 2 x (N + 1)). The per-mode constants of a grid step are in the MODE
    records (grid_a ... grid_d, grid_decay, grid_kappa)."""

    N: int
    T: float
    h: float
    M: int
    dt: float
    rot: np.ndarray


class Work(NamedTuple):
    """Scratch of the period loop: the deviation state Y and a flight's end state Ynew (`sim.integration.flight.StateLayout`),
    the state at a located onset (`scratch`), the mode envelopes A_j (`A`), the modal deviations at the
    period's start (`X0`) and the counters (int64, `sim.integration.flight.COUNT`)."""

    Y: np.ndarray
    Ynew: np.ndarray
    scratch: np.ndarray
    A: np.ndarray
    X0: np.ndarray
    counters: np.ndarray


class Recorder(NamedTuple):
    """Scratch of the recorded states (`_record_flight`, `_record_contact`): a copy Y of the state at a
    contact's start that is advanced from record instant to record instant, Ynew for free flights, and a
    Dormand-Prince scratch of its own (its counters are not the run's)."""

    Y: np.ndarray
    Ynew: np.ndarray
    dp: dopri5.Work


class Run(NamedTuple):
    """Everything `_advance` works with: the constants, the grid, the output, the scratch of the period loop,
    of the Dormand-Prince contact (counting into the same counters), the collocation context, whether
    contacts start by collocation (else all by Dormand-Prince) and the scratch of the recorded states."""

    cst: Constants
    grid: Grid
    out: Output
    work: Work
    dp: dopri5.Work
    colloc: collocation.Context
    use_collocation: bool
    recorder: Recorder


# ----------------------------------------------------------------------------------------------------------
# free flight: certification and the search for onsets
# ----------------------------------------------------------------------------------------------------------
@kernel(inline="always")
def _majorant_step(c, cd, M):
    """Smallest positive root h of c + cd h + M h^2 / 2 = 0 for c < 0 (inf if there is none)."""
    if M <= 0.0:
        return -c / cd if cd > 0.0 else np.inf
    root = math.sqrt(cd * cd - 2.0 * M * c)
    if cd > 0.0:
        return -2.0 * c / (cd + root)
    return (root - cd) / M


@kernel(inline="always")
def _envelope(Y, j, cst):
    """A_j, the modulus of mode j's complex amplitude (m sqrt(kg)); it only decays in free flight (Eq. 9)."""
    md = cst.modes
    lay = state_layout(md.size)
    x = Y[lay.x + j]
    q = (Y[lay.v + j] + md[j].sig * x) * md[j].inv_wd
    return math.sqrt(x * x + q * q)


@kernel
def _curvature_bounds(Y, cst):
    """M_l, M_r: bounds of |c''| (m/s^2) valid from now on in free flight (mode envelopes only decay)."""
    md, par = cst.modes, cst.par
    Ml = par.M_l0
    Mr = par.M_r0
    for j in range(md.size):
        A = _envelope(Y, j, cst) * md[j].w2
        Ml += md[j].abs_phi_l * A
        Mr += md[j].abs_phi_r * A
    return Ml, Mr


@kernel
def _search(Y, t0, tau_end, cst, scratch, counters):
    """First contact onset in (t0, t0 + tau_end] of the free flight from Y (Eqs. 4-6, 9), by conservative
    Newton steps on the quadratic majorants of the closing functions.

    Returns (tau, wall): wall 0 (left) or 1 (right) with the onset at t0 + tau and the state there in
    scratch[:acc], -1 if the interval is certified contact-free, -2 if the search stalled.
    """
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    Ml, Mr = _curvature_bounds(Y, cst)
    tol = par.gap_tol
    vmin = par.v_min
    tau = 0.0
    for _ in range(_MAX_SEARCH):
        if tau == 0.0:
            flight.copy_into(scratch, Y, 0, lay.acc)
            cl, cld, cr, crd = flight.closing(Y, t0, cst)
        else:
            for j in range(lay.n):
                a, b, c, d = flight.transition(tau, md, j)
                x = Y[lay.x + j]
                v = Y[lay.v + j]
                scratch[lay.x + j] = a * x + b * v
                scratch[lay.v + j] = c * x + d * v
            scratch[lay.z] = Y[lay.z] + tau * Y[lay.zd]
            scratch[lay.zd] = Y[lay.zd]
            cl, cld, cr, crd = flight.closing(scratch, t0 + tau, cst)
        counters[COUNT.search_evaluations] += 1
        if cl > -tol and (cld > vmin or cl > tol):
            return tau, 0
        if cr > -tol and (crd > vmin or cr > tol):
            return tau, 1
        h = min(_majorant_step(min(cl, -tol), cld, Ml), _majorant_step(min(cr, -tol), crd, Mr))
        tau += h
        if tau >= tau_end:
            return tau_end, -1
    return tau, -2


@kernel(inline="always")
def _grid_bounds(A, h, cst):
    """(B_l, B_r, M_l, M_r) of a grid step of h s for the mode envelopes A: the chord bounds' curvature terms
    and the bounds of |c''| (module docstring)."""
    md, par = cst.modes, cst.par
    Bl = par.M_l0 * h * h * 0.125
    Br = par.M_r0 * h * h * 0.125
    Ml = par.M_l0
    Mr = par.M_r0
    for j in range(md.size):
        Bl += md[j].abs_phi_l * md[j].grid_kappa * A[j]
        Br += md[j].abs_phi_r * md[j].grid_kappa * A[j]
        Ml += md[j].abs_phi_l * md[j].w2 * A[j]
        Mr += md[j].abs_phi_r * md[j].w2 * A[j]
    return Bl, Br, Ml, Mr


@kernel(inline="always")
def _max_bound(c0, c0d, c1, c1d, B, M, h):
    """Smallest of the chord and the two Taylor upper bounds of max c over a step of length h."""
    chord = max(c0, c1) + B
    left = max(c0, c0 + c0d * h + 0.5 * M * h * h)
    right = max(c1, c1 - c1d * h + 0.5 * M * h * h)
    return min(chord, min(left, right))


# ----------------------------------------------------------------------------------------------------------
# the state of the integrator contract
# ----------------------------------------------------------------------------------------------------------
@kernel
def _from_state(y, Y, cst):
    """Y = the deviation state of y = [s, s', u_a, u_a'] at phase 0: s = x + Re(S), s' = v - Omega Im(S),
    u_a = z - a_base (the split of the module docstring)."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    for j in range(lay.n):
        Y[lay.x + j] = y[lay.x + j] - md[j].S_re
        Y[lay.v + j] = y[lay.v + j] + par.Omega * md[j].S_im
    Y[lay.z] = y[lay.z] + par.a_base
    Y[lay.zd] = y[lay.zd]


@kernel
def _to_state(Y, t, y_out, cst):
    """Write [s, s', u_a, u_a'] at phase time t from the deviation state Y (inverse of `_from_state` at t)."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    Om = par.Omega
    ct = math.cos(Om * t)
    st = math.sin(Om * t)
    for j in range(lay.n):
        sr = md[j].S_re
        si = md[j].S_im
        y_out[lay.x + j] = Y[lay.x + j] + sr * ct - si * st
        y_out[lay.v + j] = Y[lay.v + j] - Om * (sr * st + si * ct)
    y_out[lay.z] = Y[lay.z] - par.a_base * ct
    y_out[lay.zd] = Y[lay.zd] + par.a_base * Om * st


# ----------------------------------------------------------------------------------------------------------
# the phases of a period: free flight (grid steps, searches, the flight from a release), contact (in
# `sim.integration.collocation`, `sim.integration.dopri5`), the period's Fourier coefficient; and the period loop
# ----------------------------------------------------------------------------------------------------------
@kernel
def _fly(p, t, released, onsets, cst, grid, work, recording_to):
    """Free flight of period p from t (Eq. 9) until a contact onset or the period's end. From a release at t
    the flight to the next grid point is searched; from there the flight goes on one grid step at a time in
    closed form, each step accepted if certified contact-free, else searched. The state is recorded at the
    record instants passed into recording_to = (record, recorder) (`_record_flight`). More than
    _MAX_ONSETS_PER_PERIOD onsets so far (onsets) stop
    the run at the first grid point reached.

    Returns (status, t, wall, tau): an onset at wall 0/1 at t + tau (its state in work.scratch), t the release
    or the grid point the searched step starts from, or wall -1 at the period's end. t is a grid point unless
    released.
    """
    record, recorder = recording_to
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    Y, Ynew, A, scratch, counters = work.Y, work.Ynew, work.A, work.scratch, work.counters
    N, hg, rot = grid.N, grid.h, grid.rot
    recording = record.shape[0] > 0
    k = int(t / hg)
    if released:
        # from the release to the next grid point
        if k >= N:
            k = N - 1
        tau, wall = _search(Y, t, (k + 1) * hg - t, cst, scratch, counters)
        if recording:
            _record_flight(p, Y, t, t + tau if wall != -1 else (k + 1) * hg, record, grid, recorder, cst)
        if wall != -1:
            return (STALLED_SEARCH if wall == -2 else OK), t, wall, tau
        flight.free_flight(Y, Ynew, tau, md)
        for i in range(lay.acc):
            Y[i] = Ynew[i]
        k += 1
        t = k * hg
        if onsets > _MAX_ONSETS_PER_PERIOD:
            return STALLED, t, -1, 0.0
        if k >= N:
            if recording:
                _to_state(Y, t, record[(p + 1) * grid.M], cst)
            return OK, t, -1, 0.0
    no_contact = par.k_H == 0.0  # host structure alone (k_H = 0): linear, exact everywhere
    for j in range(lay.n):
        A[j] = _envelope(Y, j, cst)
    c_valid = False  # c_l, c_r and their rates at the current grid point known from the last grid step
    c1l = c1ld = c1r = c1rd = 0.0
    while True:
        counters[COUNT.grid_steps] += 1
        flight.grid_flight(Y, Ynew, hg, md)
        if c_valid:  # the end of the last accepted grid step
            c0l, c0ld, c0r, c0rd = c1l, c1ld, c1r, c1rd
        else:
            c0l, c0ld, c0r, c0rd = flight.closing_at(Y, rot[0, k], rot[1, k], cst)
        c1l, c1ld, c1r, c1rd = flight.closing_at(Ynew, rot[0, k + 1], rot[1, k + 1], cst)
        Bl, Br, Ml, Mr = _grid_bounds(A, hg, cst)
        ok = no_contact or (_max_bound(c0l, c0ld, c1l, c1ld, Bl, Ml, hg) < 0.0
                            and _max_bound(c0r, c0rd, c1r, c1rd, Br, Mr, hg) < 0.0)
        if not ok:
            counters[COUNT.searches] += 1
            tau, wall = _search(Y, t, hg, cst, scratch, counters)
            if wall != -1:
                if recording:
                    _record_flight(p, Y, t, t + tau, record, grid, recorder, cst)
                return (STALLED_SEARCH if wall == -2 else OK), t, wall, tau
        if recording:
            _record_flight(p, Y, t, (k + 1) * hg, record, grid, recorder, cst)
        c_valid = True
        for i in range(lay.acc):
            Y[i] = Ynew[i]
        for j in range(lay.n):
            A[j] *= md[j].grid_decay
        k += 1
        t = k * hg
        if k >= N:
            if recording:
                _to_state(Y, t, record[(p + 1) * grid.M], cst)
            return OK, t, -1, 0.0


@kernel(inline="always")
def _first_instant(t, grid):
    """Index i of the first record instant i dt after t (the instants of a period are i = 1 .. M - 1 past its
    start; the one at its end is the next period's row 0)."""
    i = int(t / grid.dt)
    while i > 0 and i * grid.dt > t:
        i -= 1
    while i * grid.dt <= t:
        i += 1
    return i


@kernel
def _record_flight(p, Y, ta, tb, record, grid, recorder, cst):
    """Record the states of period p at the record instants in (ta, tb] of the free flight of Y from ta, in
    closed form (Eq. 9); Y is left as it is. The segments (ta, tb] of flights and contacts tile the period,
    so every instant is recorded once."""
    i = _first_instant(ta, grid)
    while i < grid.M and i * grid.dt <= tb:
        flight.free_flight(Y, recorder.Ynew, i * grid.dt - ta, cst.modes)
        _to_state(recorder.Ynew, i * grid.dt, record[p * grid.M + i], cst)
        i += 1


@kernel
def _record_contact(p, t0, t1, at_onset, h, record, run):
    """Record the states of period p at the record instants in (t0, t1] of the contact phase from t0 (an
    onset if at_onset) to t1 (its release or the period's end).

    An observer: the contact itself runs to its release whether or not states are recorded. The copy
    run.recorder.Y of the state at t0 is advanced by Dormand-Prince contact steps (first step h) to each
    record instant in turn, and in closed-form flight past the copy's own release (it may lie a rounding
    before t1). Returns a status (`sim.integration.flight`): STALLED if a step did not reach its record instant.
    """
    cst, grid, rec = run.cst, run.grid, run.recorder
    Y = rec.Y
    i = _first_instant(t0, grid)
    t = t0
    in_contact = True
    while i < grid.M and i * grid.dt <= t1:
        t_rec = i * grid.dt
        if in_contact:
            t, h, in_flight, status, _ = dopri5.contact(Y, t, t_rec, h, at_onset, rec.dp, cst)
            if status != OK:
                return status
            if not (in_flight or t == t_rec):
                return STALLED
            at_onset = False
            in_contact = not in_flight
        if t_rec > t:
            flight.free_flight(Y, rec.Ynew, t_rec - t, cst.modes)
            flight.copy_into(Y, rec.Ynew, 0, Y.size)
            t = t_rec
        _to_state(Y, t_rec, record[p * grid.M + i], cst)
        i += 1
    return OK


@kernel
def _initial_contact_step(Y, t, cst):
    """First Dormand-Prince step of a contact, tied to the contact time of one impact on a rigid wall under the law
    k delta^p (`sim.model.contact_law.Law`: exponent p, duration factor c_t): delta_max = ((p + 1) m v0^2 / (2 k))^(1/(p+1))
    from the energy, t_c = c_t delta_max / v0 (Hertz, Eq. 4: p = 1.5, c_t = 2.9432)."""
    cl, cld, cr, crd = flight.closing(Y, t, cst)
    v = max(cld, crd, 1e-6)
    p1 = onset_exponent(cst.law) + 1.0  # compile-time constants per law
    delta_max = (p1 * cst.par.m_a * v * v / (2.0 * cst.par.k_H)) ** (1.0 / p1)
    return min(0.02 * duration_factor(cst.law) * delta_max / v, cst.par.h_max)


@kernel(inline="always")
def _fundamental(Y, X0, T, cst):
    """|c_1| (m, Sect. 5) of the period that ends with Y and started with the modal deviations X0:
    c_1 = phi_tip^T S + (2/T) sum_j phi_tip,j int_T x_j e^{-i Omega t} dt, the integral of the module docstring."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    n = lay.n
    cre = par.P_re
    cim = par.P_im
    for j in range(n):
        dx = Y[lay.x + j] - X0[j]
        nre = (-(Y[lay.v + j] - X0[n + j]) - 2.0 * md[j].sig * dx - md[j].phi_l * Y[lay.F_l]
               - md[j].phi_r * Y[lay.F_r])
        nim = -par.Omega * dx - md[j].phi_l * Y[lay.F_l + 1] - md[j].phi_r * Y[lay.F_r + 1]
        cre += 2.0 / T * (md[j].rho_re * nre - md[j].rho_im * nim)
        cim += 2.0 / T * (md[j].rho_re * nim + md[j].rho_im * nre)
    return math.sqrt(cre * cre + cim * cim)


@kernel
def _close_period(Y, X0, T, cst, row):
    """The period's energy bookkeeping and Fourier coefficients into `row` (columns `sim.integration.flight.LEDGER`), from
    the period that ends with Y and started with the modal deviations X0 (closed forms of the module docstring)."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    n = lay.n
    Om = par.Omega
    half = 0.5 * T
    flr, fli = Y[lay.F_l], Y[lay.F_l + 1]
    frr, fri = Y[lay.F_r], Y[lay.F_r + 1]
    total_in = par.a_base * Om * (fli + fri)
    tr = ti = lr = li = rr = ri = 0.0
    for j in range(n):
        m = md[j]
        dx = Y[lay.x + j] - X0[j]
        dv = Y[lay.v + j] - X0[n + j]
        nre = -dv - 2.0 * m.sig * dx - m.phi_l * flr - m.phi_r * frr
        nim = -Om * dx - m.phi_l * fli - m.phi_r * fri
        sre = nre * m.idelta_re - nim * m.idelta_im + m.S_re * half  # Sigma_j
        sim = nre * m.idelta_im + nim * m.idelta_re + m.S_im * half
        tr += m.phi_tip * sre
        ti += m.phi_tip * sim
        lr += m.phi_l * sre
        li += m.phi_l * sim
        rr += m.phi_r * sre
        ri += m.phi_r * sim
        w_in = m.gamma * par.a_base * Om * Om * (dx - Om * sim)
        cre = m.phi_l * flr + m.phi_r * frr
        cim = m.phi_l * fli + m.phi_r * fri
        work = Y[lay.G + j] + Om * (m.S_re * cim - m.S_im * cre)
        s0 = X0[j] + m.S_re
        s1 = Y[lay.x + j] + m.S_re
        v0 = X0[n + j] - Om * m.S_im
        v1 = Y[lay.v + j] - Om * m.S_im
        dE = 0.5 * (dv * (v1 + v0) + m.w2 * dx * (s1 + s0))
        row[LEDGER.modes + j] = w_in - work - dE
        total_in += w_in
    row[LEDGER.input] = total_in
    row[LEDGER.contact] = Y[lay.Dc]  # the damped law's dissipation (Eq. 10); 0 for the elastic law (Eq. 4)
    scale = 2.0 / T
    row[LEDGER.tip_re] = scale * tr
    row[LEDGER.tip_im] = scale * ti
    row[LEDGER.left_re] = scale * lr
    row[LEDGER.left_im] = scale * li
    row[LEDGER.right_re] = scale * rr
    row[LEDGER.right_im] = scale * ri


@kernel(inline="always")
def _modal_energies(Y, ct, st, cst):
    """(E_1, sum_{j >= 2} E_j) in J, E_j = (s_j'^2 + omega_j^2 s_j^2)/2, from the deviation state Y at the phase
    with cos, sin(Omega t) = ct, st."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    Om = par.Omega
    first = 0.0
    higher = 0.0
    for j in range(lay.n):
        sj = Y[lay.x + j] + md[j].S_re * ct - md[j].S_im * st
        vj = Y[lay.v + j] - Om * (md[j].S_re * st + md[j].S_im * ct)
        e = 0.5 * (vj * vj + md[j].w2 * sj * sj)
        if j == 0:
            first = e
        else:
            higher += e
    return first, higher


@kernel
def _log_onset(Y, t, p, wall, cst, log, count):
    """A new row of the impact log (`sim.integration.flight.IMPACT`) for the onset at wall 0/1, period p, phase time t;
    returns its index (-1 when the log is full: the impact is counted in count[0] only)."""
    i = count[0]
    count[0] += 1
    if i >= log.shape[0]:
        return -1
    par = cst.par
    ct = math.cos(par.Omega * t)
    st = math.sin(par.Omega * t)
    cl, cld, cr, crd = flight.closing_at(Y, ct, st, cst)
    lay = state_layout(cst.modes.size)
    e1, eh = _modal_energies(Y, ct, st, cst)
    row = log[i]
    row[IMPACT.wall] = wall
    row[IMPACT.period] = p
    row[IMPACT.t_onset] = t
    row[IMPACT.approach_speed] = cld if wall == 0 else crd
    row[IMPACT.sphere_before] = Y[lay.zd] + par.a_base * par.Omega * st
    row[IMPACT.fundamental_onset] = e1
    row[IMPACT.higher_onset] = eh
    row[IMPACT.duration] = math.nan
    row[IMPACT.impulse] = math.nan
    row[IMPACT.sphere_after] = math.nan
    row[IMPACT.fundamental_release] = math.nan
    row[IMPACT.higher_release] = math.nan
    return i


@kernel
def _log_release(Y, t, p, T, cst, log, i):
    """Complete row i of the impact log with the release at phase time t of period p."""
    if i < 0:
        return
    lay = state_layout(cst.modes.size)
    par = cst.par
    row = log[i]
    ct = math.cos(par.Omega * t)
    st = math.sin(par.Omega * t)
    e1, eh = _modal_energies(Y, ct, st, cst)
    after = Y[lay.zd] + par.a_base * par.Omega * st
    row[IMPACT.duration] = (p - row[IMPACT.period]) * T + t - row[IMPACT.t_onset]
    row[IMPACT.impulse] = par.m_a * abs(after - row[IMPACT.sphere_before])
    row[IMPACT.sphere_after] = after
    row[IMPACT.fundamental_release] = e1
    row[IMPACT.higher_release] = eh


@kernel(refcounts=False)
def _advance(y, given, law):
    """Advance y (phase 0) over the periods of given.out; returns (status, period of failure). given: the `Run`
    whose constants carry no law (None); law: the contact law (`sim.model.contact_law.Law`), an argument of its own
    because inside the tuple numba would type all of `given` in Python at every call (~0.5 ms, 5 % of a point);
    the kernels below get the `Run` with it.

    Each period from phase 0: free flight (`_fly`), contacts (`collocation.contact` from an onset if
    run.use_collocation, `dopri5.contact` wherever that falls back), then the period's |c_1| and onset count
    (`_fundamental`). A contact may go on into the next period. One kernel for all periods (a call from Python
    per period would unbox every array of `run` again), compiled without reference counts (`sim.integration.jit`): the
    kernels it calls inherit that, except `collocation._build`, which allocates."""
    cst = flight.Constants(given.cst.modes, given.cst.par, law)
    run = Run(cst, given.grid, given.out, given.work, given.dp, given.colloc, given.use_collocation, given.recorder)
    grid, colloc, dp, use_collocation = run.grid, run.colloc, run.dp, run.use_collocation
    work = run.work
    Y, X0, scratch, counters = work.Y, work.X0, work.scratch, work.counters
    amplitudes, impacts, record = run.out.amplitudes, run.out.impacts, run.out.record
    ledger, log, log_count = run.out.ledger, run.out.log, run.out.log_count
    open_impact = -1  # the log row of the contact in progress
    lay = state_layout(cst.modes.size)
    recording = record.shape[0] > 0
    _from_state(y, Y, cst)
    if recording:
        for i in range(lay.acc):
            record[0, i] = y[i]
    cl, _, cr, _ = flight.closing(Y, 0.0, cst)
    in_contact = (cl > 0.0 or cr > 0.0) and not cst.par.k_H == 0.0
    h_contact = 0.0  # the Dormand-Prince contact's step, carried from contact to contact
    for p in range(amplitudes.size):
        Y[lay.acc:] = 0.0
        flight.copy_into(X0, Y, 0, lay.z)
        onsets = 0
        t = 0.0
        released = False  # the free flight starts at a release (else at a grid point)
        at_onset = False
        wall = 0
        while True:
            if in_contact:
                t_start, onset_start, h_start = t, at_onset, h_contact
                if recording:
                    flight.copy_into(run.recorder.Y, Y, 0, Y.size)
                t_stop = grid.T
                released = False
                status = OK
                extra = 0
                if at_onset and use_collocation:
                    outcome, t, steps = collocation.contact(Y, t, t_stop, wall, colloc, cst)
                    counters[COUNT.collocation_steps] += steps
                    released = outcome == collocation.RELEASED
                    if not released:
                        counters[COUNT.collocation_fallbacks] += 1
                        at_onset = steps == 0
                if not released:
                    if h_contact <= 0.0:
                        h_contact = 0.01 / math.sqrt(cst.modes[lay.n - 1].w2)
                    t, h_contact, released, status, extra = dopri5.contact(Y, t, t_stop, h_contact, at_onset, dp, cst)
                at_onset = False
                onsets += extra
                if status != OK:
                    return status, p
                if recording:
                    status = _record_contact(p, t_start, t, onset_start, h_start, record, run)
                    if status != OK:
                        return status, p
                if not released:
                    if t != t_stop:  # a contact phase ends at its release or at the period's end
                        return STALLED, p
                    if recording:
                        _to_state(Y, t, record[(p + 1) * grid.M], cst)
                    break
                in_contact = False
                _log_release(Y, t, p, grid.T, cst, log, open_impact)
                open_impact = -1
            status, t, wall, tau = _fly(p, t, released, onsets, cst, grid, work, (record, run.recorder))
            if status != OK:
                return status, p
            if wall < 0:
                break
            # a located onset at t + tau (its state in work.scratch): the contact starts
            if onsets > _MAX_ONSETS_PER_PERIOD:  # onsets that do not advance in time
                return STALLED, p
            flight.copy_into(Y, scratch, 0, lay.acc)
            t = t + tau
            in_contact = True
            at_onset = True
            onsets += 1
            counters[COUNT.contacts] += 1
            open_impact = _log_onset(Y, t, p, wall, cst, log, log_count)
            h_contact = _initial_contact_step(Y, t, cst)
        amplitudes[p] = _fundamental(Y, X0, grid.T, cst)
        if cst.par.book > 0.0:  # the ledger's row (without a ledger nobody reads it)
            _close_period(Y, X0, grid.T, cst, ledger[p])
        impacts[p] = onsets
        for i in range(Y.size):
            if not math.isfinite(Y[i]):
                return NONFINITE, p
    _to_state(Y, 0.0, y, cst)
    return OK, amplitudes.size


# ----------------------------------------------------------------------------------------------------------
# Python entry point
# ----------------------------------------------------------------------------------------------------------
def _prepare(Omega: float, a_base: float, sys: SystemArrays, N: int, rtol: float, h_max: float,
             h_fixed: float = 0.0, samples: int = 1, *, book: bool = True) -> tuple[Constants, Grid]:
    """Constants and grid of the kernels for one excitation (see the module docstring for the symbols); the
    state is recorded at `samples` equally spaced instants per period; `book`: keep the contact work of the
    energy bookkeeping, the impact log and the ledger's rows (else the ledger is not written)."""
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
    idelta = 1.0 / (omega**2 - Omega**2 + 2j * sig * Omega)  # 1 / Delta_j
    rho = sys.phi_tip / (omega**2 - Omega**2 + 2j * sig * Omega)  # phi_tip,j / Delta_j
    hg = 2.0 * math.pi / Omega / N
    unset = np.zeros(n)
    md = mode_records(
        sig=sig, wd=wd, w2=omega**2, phi_l=sys.phi_l, phi_r=sys.phi_r, abs_phi_l=np.abs(sys.phi_l),
        abs_phi_r=np.abs(sys.phi_r), sig_wd=sig / wd, inv_wd=1.0 / wd, w2_wd=omega**2 / wd, S_re=S.real,
        S_im=S.imag, rho_re=rho.real, rho_im=rho.imag, idelta_re=idelta.real, idelta_im=idelta.imag,
        gamma=sys.gamma, phi_tip=sys.phi_tip,
        # inverse error scales: x_j error -> displacement phi_j x_j (m); velocity error e_v -> amplitude e_v / omega_j
        err_x=wpos / atol, err_v=wpos / (atol * omega),
        grid_a=unset, grid_b=unset, grid_c=unset, grid_d=unset,  # below, from the records' transition
        grid_decay=np.exp(-sig * hg), grid_kappa=np.minimum(omega**2 * hg * hg / 8.0, 2.0))
    par = run_record(Omega=Omega, a_base=a_base, m_a=sys.m_a, inv_m_a=1.0 / sys.m_a, k_H=sys.k_H, c_damp=sys.c_damp,
                     g=sys.g,
                     W_l_re=Wl.real, W_l_im=Wl.imag, W_r_re=Wr.real, W_r_im=Wr.imag, P_re=P.real, P_im=P.imag,
                     gap_tol=GAP_TOLERANCE * sys.g, v_min=MIN_APPROACH_SPEED, M_l0=abs(Wl) * Omega**2,
                     M_r0=abs(Wr) * Omega**2, err_z=1.0 / atol, err_zd=1.0 / (atol * omega[0]),
                     h_max=h_max, h_fixed=h_fixed, book=float(book))
    tr_g = np.empty((4, n))
    flight.flight_transitions(hg, md, tr_g)
    md["grid_a"], md["grid_b"], md["grid_c"], md["grid_d"] = tr_g
    phase = Omega * hg * np.arange(N + 1)
    T = 2.0 * math.pi / Omega
    grid = Grid(N=N, T=T, h=hg, M=samples, dt=T / samples, rot=np.vstack([np.cos(phase), np.sin(phase)]))
    return Constants(modes=md, par=par, law=sys.law), grid


def _work(cst: Constants) -> Work:
    """A fresh `Work` for the period loop."""
    lay = state_layout(cst.modes.size)
    return Work(Y=np.zeros(lay.size), Ynew=np.zeros(lay.size), scratch=np.zeros(lay.size), A=np.empty(lay.n),
                X0=np.empty(lay.z), counters=np.zeros(len(COUNT), dtype=np.int64))


def run_step(y: np.ndarray, n_periods: int, Omega: float, a_base: float, sys: SystemArrays,
             record: np.ndarray | None = None, *, rtol: float = CONTACT_RTOL, grid_per_period: int = GRID_PER_PERIOD,
             fixed_contact_step: float = 0.0, contacts: str = "collocation",
             stats: dict | None = None, ledger: Ledger | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Advance y in place over `n_periods` whole excitation periods, exact between contacts (Eqs. 3-9, Sect. 5).

    Integrator contract of `sim.model.system` (same as `sim.integration.ode3.run_step`): y = [s, s', u_a, u_a'] at
    excitation phase 0 (float64, length 2 n_modes + 2); Omega in rad/s; a_base in m. Returns
    (amplitudes, impacts): per period |c_1| of q_tip in m (Sect. 5, exact quadrature) and the number of
    contact onsets (int64).

    record: optional float64 array (n_periods * M + 1, len(y)) receiving the state at M equally spaced
    instants per period (row 0 = initial state), exactly at those instants.
    rtol: tolerance of the Dormand-Prince contact steps relative to g (per step, in m of wall/tip displacement).
    grid_per_period: free-flight certification cells per period (no effect on the trajectory beyond rounding
    and the onset tolerance; recording does not change them).
    fixed_contact_step: > 0 replaces the error control in contacts by this fixed step in s (order studies;
    Dormand-Prince only).
    contacts: "collocation" (default: `sim.integration.collocation`, Dormand-Prince where it falls back) or "dopri5"
    (every contact by the Dormand-Prince 5(4) pair with error control at rtol). With a contact law that collocation
    does not take (`sim.model.contact_law.Law.collocation`: the damped law of Eq. 10) every contact takes the
    Dormand-Prince pair.
    stats: optional dict that receives the kernel's counters (the fields of `sim.integration.flight.Counters`: grid
    steps, searches, contact steps, ...).
    ledger: optional `sim.integration.energy.Ledger` that receives the energy bookkeeping per period (exact closed forms,
    module docstring) and the impact records of the call (Sect. 5.5, Appendix D).
    Raises SimulationInputError for bad arguments, SimulationDiverged for a non-finite state, an
    indentation beyond the clearance or a stalled contact search.
    """
    n_periods, Omega, a_base, record_arr, samples = check_run_step(y, n_periods, Omega, a_base, sys, record)
    rtol = float(rtol)
    if not math.isfinite(rtol) or not 0.0 < rtol < 1e-2:
        raise SimulationInputError(f"rtol must lie in (0, 0.01), got {rtol!r}")
    if sys.slip_force > 0:
        raise SimulationInputError("dry friction (Appendix C) is in the ode3 integrator only; use --integrator ode3")
    if contacts not in ("collocation", "dopri5"):
        raise SimulationInputError(f"contacts must be 'collocation' or 'dopri5', got {contacts!r}")
    if not (sys.m_a > 0 and sys.k_H >= 0 and sys.g > 0):
        raise SimulationInputError("sphere mass and clearance g must be positive and k_H >= 0 (0: no impactor)")
    N = int(grid_per_period)
    if N < 1:
        raise SimulationInputError(f"grid_per_period must be >= 1, got {grid_per_period!r}")
    omega_max = float(np.max(sys.omega))
    h_max = 0.5 / omega_max  # keeps DOPRI5 far inside its stability region on the highest mode
    cst, grid = _prepare(Omega, a_base, sys, N, rtol, h_max, float(fixed_contact_step), samples,
                         book=ledger is not None)
    work = _work(cst)
    out = integrator_output(n_periods, sys.omega.size, record_arr, ledger)
    stored_start = stored_energy(y, sys) if ledger is not None else math.nan
    # collocation solves the laws that say so (Eq. 4); the others (Eq. 10) take the Dormand-Prince contact
    use_collocation = contacts == "collocation" and fixed_contact_step <= 0.0 and sys.law.collocation
    recorder = Recorder(Y=np.zeros(work.Y.size), Ynew=np.zeros(work.Y.size),
                        dp=dopri5.work(work.Y.size, np.zeros_like(work.counters), ledger is not None))
    run = Run(cst._replace(law=None), grid, out, work, dopri5.work(work.Y.size, work.counters, ledger is not None),
              collocation.context(cst), use_collocation, recorder)
    status, period = _advance(y, run, sys.law)
    if stats is not None:
        for name, value in zip(COUNT._fields, work.counters):
            stats[name] = stats.get(name, 0) + int(value)
    if status != OK:
        why = {NONFINITE: "non-finite state", OVERLAP: "an indentation larger than the clearance",
               STALLED: "a contact phase that did not progress",
               STALLED_SEARCH: "a contact search that did not progress"}[status]
        raise SimulationDiverged(
            f"exact integrator failed in period {period + 1} of this step ({why}); check k_H, g and the level")
    if ledger is not None:
        ledger.fill(out.ledger, out.log, int(out.log_count[0]), stored_start, stored_energy(y, sys), Omega, sys)
    return out.amplitudes, out.impacts
