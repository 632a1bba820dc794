"""The seed paper's integrator (Sect. 3.2): fixed-step third-order Bogacki-Shampine (MATLAB ``ode3``).

Eqs. 3-7 in the relative coordinates of `sim.model.system` (y = [s, s', u_a, u_a'], u_a = q_a - q_base):

    s_j''  = -2 D_j w_j s_j' - w_j^2 s_j - phi_l,j f_l - phi_r,j f_r + gamma_j a_base Omega^2 cos(Omega t)
    u_a''  = (f_l + f_r) / m_a + a_base Omega^2 cos(Omega t)

with the wall forces of the contact law sys.law (`sim.model.contact_law`: Eq. 4, or the damped law of Eq. 10, whose
force gains c_damp delta^0.25 delta' while its wall approaches), compiled per law. The scheme is the explicit 3-stage
Bogacki-Shampine tableau without error control, exactly MATLAB's fixed-step ``ode3``:

    k1 = f(t, y),  k2 = f(t + h/2, y + h/2 k1),  k3 = f(t + 3h/4, y + 3h/4 k2),
    y+ = y + h (2/9 k1 + 1/3 k2 + 4/9 k3).

Time step (Sect. 3.2): dt = 2 pi / (15 omega_max) (omega_max = omega_9 for the paper's 9 modes), times
``dt_scale``. So that every excitation period ends on a step (the protocol's whole periods, continuous
phase), the step actually used is the largest h <= dt with T = N h, N an integer (for the rig at
eta ~ 1: N ~ 2600, h shorter than dt by < 0.04 %).

Per period the kernel returns |c_1| of q_tip = phi_tip^T s, c_1 = (2/T) int_T q_tip exp(-i Omega t) dt by the
trapezoidal rule on the step points, and the number of contact onsets (open -> closed at either wall,
checked at the step points).

Dry friction (Appendix C, `sim.model.friction`): the Jenkins element between the sphere and the cavity floor, with the
sphere's displacement relative to the floor u = u_a - phi_f^T s and the slider at z: in stick the force on the
sphere is -k_t (u - z), in slip of sense sigma it is -sigma mu N (z follows u at u - sigma mu N / k_t). Stick and
slip are separate phases; a step whose end lies beyond its phase's boundary (|k_t (u - z)| > mu N in stick, a
reversal of u' in slip) is cut at the transition, located by Illinois false position on the length of a
Bogacki-Shampine step from the step's start (to 1e-13 of the step), and continued in the new phase: the force is
continuous there and the scheme keeps its order. The slider state is `SystemArrays.slider`, carried from call to
call like y.

Energy bookkeeping (Sect. 5.5, `sim.integration.energy.Ledger`) by the scheme's own quadrature: the work of the base
excitation a_base Omega^2 cos(Omega t) (gamma^T s' + m_a u_a') and each mode's dissipation 2 D_j omega_j s_j'^2
are integrated like extra components of the state (the Bogacki-Shampine weights on the stage values), as is
the contact law's dissipation (Eq. 10: c_damp delta^0.25 delta'^2 in approach), the slider's mu N |u'| of
dry friction, and
the Fourier coefficients of tip and walls by the trapezoidal rule. Its energy balance closes only to the
scheme's truncation error (third order in h). ode3 keeps no impact records.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.integration.energy import Ledger, integrator_output, stored_energy
from sim.integration.flight import LEDGER, state_layout
from sim.integration.jit import kernel
from sim.model.contact_law import Law, uses_rate, wall_dissipation, wall_force
from sim.model.system import SystemArrays, check_run_step

#: Sect. 3.2: the highest retained mode's period is sampled with 15 time levels.
STEPS_PER_HIGHEST_PERIOD = 15
#: Indentation (as a fraction of the clearance) at which the stability check linearises the Hertz contact.
#: The paper's simulations stay below 40 um = 0.07 g* (seed-rig.toml); 0.1 g leaves a margin.
STABILITY_INDENTATION_FRACTION = 0.1

# Status codes of the kernel
_OK, _NONFINITE, _OVERLAP = 0, 1, 2
# Fast-math flags that keep NaN/inf semantics (the divergence check relies on them).
_FAST = {"nsz", "arcp", "contract", "afn", "reassoc"}


def paper_time_step(omega_max: float, dt_scale: float = 1.0) -> float:
    """dt = dt_scale * 2 pi / (15 omega_max) in s (Sect. 3.2); omega_max in rad/s."""
    return dt_scale * 2.0 * math.pi / (STEPS_PER_HIGHEST_PERIOD * omega_max)


def steps_per_period(Omega: float, dt_max: float, samples_per_period: int = 1) -> int:
    """Smallest N with T/N <= dt_max (T = 2 pi/Omega) that is a multiple of `samples_per_period`."""
    period = 2.0 * math.pi / Omega
    blocks = math.ceil(period / (samples_per_period * dt_max) * (1.0 - 1e-12))
    return max(1, blocks) * samples_per_period


def stability_factor(z: complex) -> float:
    """|R(z)| of the Bogacki-Shampine 3-stage scheme, R(z) = 1 + z + z^2/2 + z^3/6."""
    return abs(1.0 + z + z * z / 2.0 + z**3 / 6.0)


def check_stability(sys: SystemArrays, h: float) -> None:
    """Refuse a step that makes ode3 unstable on a mode or on the linearised contact (SimulationInputError).

    Each mode's eigenvalue lambda = omega (-D + i sqrt(1 - D^2)) must satisfy |R(h lambda)| <= 1; the
    contact is checked as the sphere on a rigid wall linearised at delta = 0.1 g:
    k = the law's stiffness there (Eq. 4: 1.5 k_H delta^0.5), lambda = i sqrt(k / m_a). On the imaginary axis the
    limit is h omega <= sqrt(3).
    """
    candidates = [(float(w), float(d), f"mode {j + 1} ({w / (2 * math.pi):.6g} Hz)")
                  for j, (w, d) in enumerate(zip(sys.omega, sys.D))]
    if sys.k_H > 0:
        delta = STABILITY_INDENTATION_FRACTION * sys.g
        w_contact = math.sqrt(sys.law.stiffness.py_func(delta, sys.k_H) / sys.m_a)
        candidates.append((w_contact, 0.0, f"the {sys.law.name} contact ({w_contact / (2 * math.pi):.6g} Hz at "
                                           f"delta = {delta:.3g} m)"))
    if sys.slip_force > 0:  # the sphere stuck to the floor by the Jenkins spring (Appendix C)
        w_stick = math.sqrt(sys.k_t / sys.m_a)
        candidates.append((w_stick, 0.0, f"the friction spring k_t ({w_stick / (2 * math.pi):.6g} Hz)"))
    for w, d, label in candidates:
        z = h * w * complex(-d, math.sqrt(max(0.0, 1.0 - d * d)))
        if stability_factor(z) > 1.0 + 1e-12:
            limit = math.sqrt(3.0) / w
            raise SimulationInputError(
                f"time step {h:.4g} s is too large for ode3 stability on {label}: h*omega = {h * w:.3g} > "
                f"sqrt(3); use a step below {limit:.3g} s (smaller dt_scale)")


class Steps(NamedTuple):
    """The fixed steps of one run: N steps of h (s) per excitation period, the state recorded every `stride`
    steps, Omega (rad/s), a_base (m), and cos(Omega t) at the three stages of each step (`cos_stage`, 3 x N)
    and cos, sin(Omega t_k) at the steps."""

    N: int
    h: float
    stride: int
    Omega: float
    a_base: float
    cos_stage: np.ndarray
    cos0: np.ndarray
    sin0: np.ndarray


class Coefficients(NamedTuple):
    """Eqs. 3-7 as the kernel evaluates them: w2 = omega^2, c = 2 D omega (1/s), gamma = phi^T M b, the wall values phi_l, phi_r,
    the base forcing amplitudes f_modal = gamma a_base Omega^2 and f_sphere = a_base Omega^2, m_a, k_H, g, and
    c_damp of Eq. 10 (0: elastic), the friction's phi_f, k_t and slip force (Appendix C), the contact law (its
    kernels inlined per law) and Omega (rad/s)."""

    w2: np.ndarray
    c: np.ndarray
    gamma: np.ndarray
    phi_l: np.ndarray
    phi_r: np.ndarray
    f_modal: np.ndarray
    f_sphere: float
    m_a: float
    k_H: float
    g: float
    c_damp: float
    phi_f: np.ndarray
    k_t: float
    slip_force: float
    law: Law
    Omega: float


class Model(NamedTuple):
    """What a step's kernels read: the `Coefficients` and the state layout (`sim.integration.flight.state_layout`)."""

    co: Coefficients
    lay: tuple


@kernel(inline="always", fastmath=_FAST)
def _indentations(y, co, lay):
    """(delta_l, delta_r) of Eqs. 4-6: contact at the left wall when delta_l > 0, at the right when delta_r < 0."""
    u = y[lay.z]
    dl = -u - co.g
    dr = -u + co.g
    for j in range(lay.n):
        dl += co.phi_l[j] * y[lay.x + j]
        dr += co.phi_r[j] * y[lay.x + j]
    return dl, dr


@kernel(inline="always", fastmath=_FAST)
def _approach_rate(y, phi, co, lay):
    """d/dt of phi^T s - u_a: the rate of delta_l (phi = phi_l) or of delta_r (phi = phi_r) in m/s."""
    rate = -y[lay.zd]
    for j in range(lay.n):
        rate += phi[j] * y[lay.v + j]
    return rate


@kernel(inline="always", fastmath=_FAST)
def _floor_relative(y, co, lay):
    """(u, u') of the sphere relative to the cavity floor, u = u_a - phi_f^T s (m, m/s; Appendix C)."""
    u = y[lay.z]
    ud = y[lay.zd]
    for j in range(lay.n):
        u -= co.phi_f[j] * y[lay.x + j]
        ud -= co.phi_f[j] * y[lay.v + j]
    return u, ud


@kernel(inline="always", fastmath=_FAST)
def _deriv(y, cos_t, co, lay, out):
    """Right-hand side of Eqs. 3-7 in relative coordinates with the contact law co.law (module docstring) into out;
    returns the power (W) the contacts dissipate (0 for a conservative law, whose approach rates are not computed)."""
    dl, dr = _indentations(y, co, lay)
    rate_l = rate_r = 0.0
    if uses_rate(co.law):  # a compile-time constant: the elastic law's kernels have no trace of this
        if dl > 0.0:
            rate_l = _approach_rate(y, co.phi_l, co, lay)
        if dr < 0.0:
            rate_r = -_approach_rate(y, co.phi_r, co, lay)
    fl = wall_force(co.law, dl, rate_l, co.k_H, co.c_damp)
    fr = -wall_force(co.law, -dr, rate_r, co.k_H, co.c_damp)
    p_contact = 0.0
    if uses_rate(co.law):
        p_contact = (wall_dissipation(co.law, dl, rate_l, co.k_H, co.c_damp)
                     + wall_dissipation(co.law, -dr, rate_r, co.k_H, co.c_damp))
    for j in range(lay.n):
        out[lay.x + j] = y[lay.v + j]
        out[lay.v + j] = (-co.c[j] * y[lay.v + j] - co.w2[j] * y[lay.x + j] - co.phi_l[j] * fl - co.phi_r[j] * fr
                          + co.f_modal[j] * cos_t)
    out[lay.z] = y[lay.zd]
    out[lay.zd] = (fl + fr) / co.m_a + co.f_sphere * cos_t
    return p_contact


@kernel(inline="always", fastmath=_FAST)
def _friction(y, co, lay, out, slider):
    """Add to `out` (the derivative of `_deriv`) the friction force f_t of the slider slider = (z, sense) (sense 0
    stick, +-1 slip; + f_t on the sphere, - phi_f,j f_t on the modes, Appendix C). Returns the power (W) the slider
    dissipates. (A separate function: inside `_deriv`, even untaken, such branches made the elastic steps 2.4x
    slower.)"""
    slider_z, sense = slider
    u, ud = _floor_relative(y, co, lay)
    p_friction = 0.0
    if sense == 0.0:
        ft = -co.k_t * (u - slider_z)
    else:
        ft = -sense * co.slip_force
        p_friction = -ft * ud
    for j in range(lay.n):
        out[lay.v + j] -= co.phi_f[j] * ft
    out[lay.zd] += ft / co.m_a
    return p_friction


@kernel(inline="always", fastmath=_FAST)
def _tip(y, phi_tip, lay):
    """q_tip = phi_tip^T s (m)."""
    q = 0.0
    for j in range(lay.n):
        q += phi_tip[j] * y[lay.x + j]
    return q


@kernel(inline="always", fastmath=_FAST)
def _book(y, cos_t, weight, co, lay, ledger_row):
    """Add weight times the integrands of the energy bookkeeping at a stage (state y, cos(Omega t)) to the
    period's ledger row: the base excitation's power and each mode's damping power (W)."""
    p_in = co.m_a * y[lay.zd]
    for j in range(lay.n):
        v = y[lay.v + j]
        p_in += co.gamma[j] * v
        ledger_row[LEDGER.modes + j] += weight * co.c[j] * v * v
    ledger_row[LEDGER.input] += weight * co.f_sphere * cos_t * p_in


@kernel(inline="always", fastmath=_FAST)
def _stage(y, cos_t, weight, model, out, slider, row, book):
    """A stage of the friction step: the derivative with the slider's force (slider = (z, sense)) into `out`, and
    with `book` its integrands (weight: the stage's quadrature weight, s) into the ledger row."""
    co, lay = model
    p_contact = _deriv(y, cos_t, co, lay, out)
    p_friction = _friction(y, co, lay, out, slider)
    if book:
        _book(y, cos_t, weight, co, lay, row)
        row[LEDGER.contact] += weight * p_contact
        row[LEDGER.friction] += weight * p_friction


@kernel(inline="always", fastmath=_FAST)
def _bs_step(y, t, L, model, slider, stages, row, book):
    """One Bogacki-Shampine step of length L (s) from (t, y) with the slider (z, sense) in its phase: the state at
    t + L in stages[3] (y unchanged); with `book` the bookkeeping's integrands into `row` (weights scaled to L)."""
    k1, k2, k3, yt = stages[0], stages[1], stages[2], stages[4]
    Omega = model.co.Omega
    ny = model.lay.acc
    c0 = math.cos(Omega * t)
    c1 = math.cos(Omega * (t + 0.5 * L))
    c2 = math.cos(Omega * (t + 0.75 * L))
    _stage(y, c0, L * 2.0 / 9.0, model, k1, slider, row, book)
    for i in range(ny):
        yt[i] = y[i] + 0.5 * L * k1[i]
    _stage(yt, c1, L / 3.0, model, k2, slider, row, book)
    for i in range(ny):
        yt[i] = y[i] + 0.75 * L * k2[i]
    _stage(yt, c2, L * 4.0 / 9.0, model, k3, slider, row, book)
    end = stages[3]
    for i in range(ny):
        end[i] = y[i] + L * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i])


@kernel(inline="always", fastmath=_FAST)
def _phase_event(y, co, lay, slider_z, sense):
    """The phase's boundary function, < 0 inside (Appendix C): in stick |k_t (u - z)| - mu N (N), in slip of sense
    sigma -sigma u' (m/s)."""
    u, ud = _floor_relative(y, co, lay)
    if sense == 0.0:
        return abs(co.k_t * (u - slider_z)) - co.slip_force
    return -sense * ud


#: at most this many stick/slip transitions are located within one ode3 step
_MAX_TRANSITIONS_PER_STEP = 8


@kernel(fastmath=_FAST)
def _friction_step(y, t, h, model, slider, stages, rows):
    """Advance y in place over one ode3 step (t, t + h) with dry friction (`_friction`; slider = (z, sense)), in
    sub-steps that end on each located stick/slip transition (module docstring), booked into rows[0] (rows[1]:
    scratch of the same length). Returns the slider's new (z, sense)."""
    co, lay = model
    row, trial_row = rows
    slider_z, sense = slider
    ny = lay.acc
    end = stages[3]
    left = h
    located = 0
    while True:
        trial_row[:] = 0.0
        _bs_step(y, t, left, model, (slider_z, sense), stages, trial_row, True)
        if located == _MAX_TRANSITIONS_PER_STEP or _phase_event(end, co, lay, slider_z, sense) <= 0.0:
            break  # the rest of the step in this phase
        located += 1
        # Illinois false position on the sub-step's length L: the event crosses 0 in (lo, hi]
        lo, hi = 0.0, left
        g_lo = min(_phase_event(y, co, lay, slider_z, sense), 0.0)
        g_hi = _phase_event(end, co, lay, slider_z, sense)
        side = 0
        for _it in range(60):
            if hi - lo <= 1e-13 * h:
                break
            L = (lo * g_hi - hi * g_lo) / (g_hi - g_lo)
            if not lo < L < hi:
                L = 0.5 * (lo + hi)
            _bs_step(y, t, L, model, (slider_z, sense), stages, trial_row, False)
            g = _phase_event(end, co, lay, slider_z, sense)
            if g > 0.0:
                hi, g_hi = L, g
                if side == 1:
                    g_lo *= 0.5
                side = 1
            else:
                lo, g_lo = L, g
                if side == -1:
                    g_hi *= 0.5
                side = -1
        # the sub-step to the transition (its far side), booked; then the new phase from there
        _bs_step(y, t, hi, model, (slider_z, sense), stages, row, True)
        for i in range(ny):
            y[i] = end[i]
        u, _ = _floor_relative(y, co, lay)
        w_s = co.slip_force / co.k_t
        if sense == 0.0:  # stick -> slip in the sense of the spring's elongation, on the limit exactly
            sense = 1.0 if u - slider_z > 0.0 else -1.0
            slider_z = u - sense * w_s
        else:  # slip -> stick: the slider stays where the spring is at the limit (continuous force)
            slider_z = u - sense * w_s
            sense = 0.0
        t += hi
        left -= hi
        if left <= 1e-13 * h:
            return slider_z, sense
    for i in range(row.size):
        row[i] += trial_row[i]
    for i in range(ny):
        y[i] = end[i]
    if sense != 0.0:  # in slip the slider follows the sphere at the limit
        u, _ = _floor_relative(y, co, lay)
        slider_z = u - sense * co.slip_force / co.k_t
    return slider_z, sense


@kernel(fastmath=_FAST)
def _advance(y, sys, steps, out, law):
    """Advance y in place over the periods of `out`, N ode3 steps each; returns (status, step index of a failure).
    sys: the `SystemArrays` without their law (None); law: the contact law, an argument of its own (inside the
    tuple numba would type all of `sys` in Python at every call)."""
    lay = state_layout(sys.omega.size)
    N = steps.N
    Omega, a_base = steps.Omega, steps.a_base
    co = Coefficients(w2=sys.omega * sys.omega, c=2.0 * sys.D * sys.omega, gamma=sys.gamma, phi_l=sys.phi_l, phi_r=sys.phi_r,
                      f_modal=sys.gamma * (a_base * Omega * Omega), f_sphere=a_base * Omega * Omega, m_a=sys.m_a,
                      k_H=sys.k_H, g=sys.g, c_damp=sys.c_damp, phi_f=sys.phi_f, k_t=sys.k_t, slip_force=sys.slip_force,
                      law=law, Omega=Omega)
    model = Model(co, lay)
    ny = lay.acc
    friction = co.slip_force > 0.0  # the friction step (Appendix C)
    slider = sys.slider
    slider_z, sense = slider[0], slider[1]
    stages = np.empty((5, ny))  # the friction step's k1, k2, k3, end state and stage state
    trial_row = np.empty(out.ledger.shape[1])
    # arrays bound once: read from a tuple inside the step loop, numba would count references at every step
    h = steps.h
    cos_stage, cos0, sin0, phi_tip = steps.cos_stage, steps.cos0, steps.sin0, sys.phi_tip
    k1 = np.empty(ny)
    k2 = np.empty(ny)
    k3 = np.empty(ny)
    yt = np.empty(ny)
    b1, b2, b3 = h * 2.0 / 9.0, h / 3.0, h * 4.0 / 9.0
    record = out.record
    recording = record.shape[0] > 0
    stride = steps.stride
    rows_per_period = N // stride
    if recording:
        record[0, :] = y
    # contact state at the start (continuous with the end of the previous call)
    dl, dr = _indentations(y, co, lay)
    has_contact = co.k_H > 0.0  # k_H = 0: the host structure alone, no contacts to count
    closed_l = dl > 0.0 and has_contact
    closed_r = dr < 0.0 and has_contact
    for p in range(out.amplitudes.size):
        row = out.ledger[p]
        re = 0.5 * _tip(y, phi_tip, lay)  # trapezoid end weight, phase 0: cos = 1, sin = 0
        im = 0.0
        dl, dr = _indentations(y, co, lay)
        lre = 0.5 * (dl + y[lay.z] + co.g)  # phi_l^T s, phi_r^T s: the walls relative to the base
        rre = 0.5 * (dr + y[lay.z] - co.g)
        lim = rim = 0.0
        onsets = 0
        for k in range(N):
            if friction:
                slider_z, sense = _friction_step(y, k * h, h, model, (slider_z, sense), stages, (row, trial_row))
            else:
                # the Bogacki-Shampine stages of the module docstring (Sect. 3.2)
                p1 = _deriv(y, cos_stage[0, k], co, lay, k1)
                _book(y, cos_stage[0, k], b1, co, lay, row)
                for i in range(ny):
                    yt[i] = y[i] + 0.5 * h * k1[i]
                p2 = _deriv(yt, cos_stage[1, k], co, lay, k2)
                _book(yt, cos_stage[1, k], b2, co, lay, row)
                for i in range(ny):
                    yt[i] = y[i] + 0.75 * h * k2[i]
                p3 = _deriv(yt, cos_stage[2, k], co, lay, k3)
                _book(yt, cos_stage[2, k], b3, co, lay, row)
                if uses_rate(co.law):  # the contact law's dissipation (compiled only for a law that has one)
                    row[LEDGER.contact] += b1 * p1 + b2 * p2 + b3 * p3
                for i in range(ny):
                    y[i] += b1 * k1[i] + b2 * k2[i] + b3 * k3[i]
            # measures at the new step point t_{k+1}
            dl, dr = _indentations(y, co, lay)
            q = _tip(y, phi_tip, lay)
            kk = k + 1
            ql = dl + y[lay.z] + co.g
            qr = dr + y[lay.z] - co.g
            if kk < N:
                re += q * cos0[kk]
                im -= q * sin0[kk]
                lre += ql * cos0[kk]
                lim -= ql * sin0[kk]
                rre += qr * cos0[kk]
                rim -= qr * sin0[kk]
            else:
                re += 0.5 * q
                lre += 0.5 * ql
                rre += 0.5 * qr
            now_l = dl > 0.0 and has_contact
            now_r = dr < 0.0 and has_contact
            if now_l and not closed_l:
                onsets += 1
            if now_r and not closed_r:
                onsets += 1
            closed_l = now_l
            closed_r = now_r
            if has_contact and (dl > co.g or -dr > co.g):
                return _OVERLAP, p * N + k
            if recording and kk % stride == 0:
                record[p * rows_per_period + kk // stride, :] = y
        out.amplitudes[p] = 2.0 / N * math.sqrt(re * re + im * im)
        row[LEDGER.tip_re] = 2.0 / N * re
        row[LEDGER.tip_im] = 2.0 / N * im
        row[LEDGER.left_re] = 2.0 / N * lre
        row[LEDGER.left_im] = 2.0 / N * lim
        row[LEDGER.right_re] = 2.0 / N * rre
        row[LEDGER.right_im] = 2.0 / N * rim
        out.impacts[p] = onsets
        slider[0] = slider_z
        slider[1] = sense
        for i in range(ny):
            if not math.isfinite(y[i]):
                return _NONFINITE, (p + 1) * N
    return _OK, out.amplitudes.size * N


def run_step(y: np.ndarray, n_periods: int, Omega: float, a_base: float, sys: SystemArrays,
             record: np.ndarray | None = None, *, dt_scale: float = 1.0,
             ledger: Ledger | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Advance the state y in place over `n_periods` whole excitation periods with ode3 (Sect. 3.2).

    Integrator contract of `sim.model.system`: y = [s, s', u_a, u_a'] at excitation phase 0 (float64, length
    2 n_modes + 2); Omega in rad/s; a_base in m. Returns (amplitudes, impacts): per period |c_1| of q_tip
    in m, and the number of contact onsets (int64).

    record: optional float64 array of shape (n_periods * M + 1, len(y)); it receives the state at M
    equally spaced instants per period (row 0 = the initial state). The step is then chosen so that these
    instants are step points (h <= dt still holds).

    dt_scale: multiplies the paper's dt = 2 pi/(15 omega_max) (tests, order studies).
    ledger: optional `sim.integration.energy.Ledger` that receives the energy bookkeeping per period (the scheme's own
    quadrature, module docstring; no impact records).
    Raises SimulationInputError for bad arguments or an unstable step, SimulationDiverged if the state
    becomes non-finite or an indentation exceeds the clearance (the contact was stepped over).
    """
    n_periods, Omega, a_base, record_arr, samples = check_run_step(y, n_periods, Omega, a_base, sys, record)
    dt_scale = float(dt_scale)
    if not math.isfinite(dt_scale) or dt_scale <= 0:
        raise SimulationInputError(f"dt_scale must be positive, got {dt_scale!r}")

    dt_max = paper_time_step(float(np.max(sys.omega)), dt_scale)
    N = steps_per_period(Omega, dt_max, samples)
    h = 2.0 * math.pi / Omega / N
    check_stability(sys, h)

    phase = Omega * h * np.arange(N)
    cos_stage = np.empty((3, N))
    for row, c_stage in enumerate((0.0, 0.5, 0.75)):
        cos_stage[row] = np.cos(phase + c_stage * Omega * h)
    steps = Steps(N=N, h=h, stride=N // samples, Omega=Omega, a_base=a_base, cos_stage=cos_stage,
                  cos0=np.cos(phase), sin0=np.sin(phase))
    out = integrator_output(n_periods, sys.omega.size, record_arr, None)
    stored_start = stored_energy(y, sys) if ledger is not None else math.nan
    kernel_sys = sys._replace(m_a=float(sys.m_a), k_H=float(sys.k_H), g=float(sys.g), c_damp=float(sys.c_damp),
                              k_t=float(sys.k_t), slip_force=float(sys.slip_force), law=None)
    status, where = _advance(y, kernel_sys, steps, out, sys.law)
    if status != _OK:
        t = where * h
        why = "non-finite state" if status == _NONFINITE else "an indentation larger than the clearance"
        raise SimulationDiverged(
            f"ode3 diverged after {t:.4g} s of this step ({why}); reduce dt_scale or check k_H, g and the level")
    if ledger is not None:
        ledger.fill(out.ledger, out.log, 0, stored_start, stored_energy(y, sys), Omega, sys)
    return out.amplitudes, out.impacts
