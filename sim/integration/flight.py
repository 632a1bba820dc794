"""What the integrators' kernels share (`sim.integration.exact`, `sim.integration.dopri5`, `sim.integration.collocation`; the layout and the
output also `sim.integration.ode3`): the named layout of the state, the constants of one run as numba records, the
output of a period loop, the kernels' counters and status codes, and the closed-form pieces of free flight
(the homogeneous part of Eq. 9; symbols in `sim.integration.exact`'s docstring).

Conventions of the kernels (each measured against the positional code they replace, same machine code speed):
* Constants are numba records read by name (``md[j].sig``, ``par.Omega``): a structured array with a record
  per mode and one record of scalars. A record costs no reference counting, whereas every array a counting
  kernel keeps from its arguments across a call is counted up and down (two atomic operations) on every call.
  The exact integrator's kernels do not count (`sim.integration.jit`, `kernel(refcounts=False)`); ode3's do.
* Hence tuples of arrays (workspaces, contexts) are unpacked at a kernel's entry, and a kernel called per
  contact step or per grid step is handed few arrays.
* A kernel takes the state layout from `state_layout(n)`, not from an argument: inlined, its offsets are
  arithmetic on n that the compiler sees (offsets handed over as numbers made the contact steps 15 % slower).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from sim.integration.jit import kernel
from sim.model.contact_law import Law


# ----------------------------------------------------------------------------------------------------------
# the deviation state Y and the constants of a run
# ----------------------------------------------------------------------------------------------------------
class StateLayout(NamedTuple):
    """Offsets of the components of the deviation state Y (length `size`) of `sim.integration.exact` for n modes.

    Y[x + j], Y[v + j]: homogeneous deviation x_j of mode j and its rate (m sqrt(kg), m sqrt(kg) / s);
    Y[z], Y[zd]: sphere coordinate z = u_a + a_base cos(Omega t) and its rate (m, m/s); these 2 n + 2
    components (up to `acc`) are the mechanical state. From `acc` on, integrals carried through the period:
    Y[F_l], Y[F_l + 1] = Re, Im of F_l = int f_l e^{-i Omega t} dt (N s), the same for F_r;
    Y[G + j] = int (phi_l,j f_l + phi_r,j f_r) x_j' dt, the work of mode j's deviation on the contacts (J),
    the one integral of the energy bookkeeping (`sim.integration.energy`) that free flight does not give in closed form;
    Y[Dc] = the energy the damped contact law of Eq. 10 dissipates (J; stays 0 for the elastic law).
    """

    n: int
    x: int
    v: int
    z: int
    zd: int
    acc: int
    F_l: int
    F_r: int
    G: int
    Dc: int
    size: int


@kernel(inline="always")
def state_layout(n: int) -> StateLayout:
    """The `StateLayout` for n modes. A new component is one line here and one field in `StateLayout`."""
    x = 0
    v = x + n
    z = v + n
    zd = z + 1
    acc = zd + 1
    F_l = acc
    F_r = F_l + 2
    G = F_r + 2
    Dc = G + n
    size = Dc + 1
    return StateLayout(n=n, x=x, v=v, z=z, zd=zd, acc=acc, F_l=F_l, F_r=F_r, G=G, Dc=Dc, size=size)


#: The constants of mode j in one run (a record per mode; Eqs. 7, 9 and the scales of the contact steps).
MODE = np.dtype([
    ("sig", np.float64),  # decay rate sigma_j = D_j omega_j (1/s)
    ("wd", np.float64),  # damped frequency omega_dj = omega_j sqrt(1 - D_j^2) (rad/s)
    ("w2", np.float64),  # omega_j^2 (1/s^2)
    ("phi_l", np.float64),  # mode value at the left wall (1/sqrt(kg))
    ("phi_r", np.float64),  # ... at the right wall
    ("abs_phi_l", np.float64),  # |phi_l,j|, |phi_r,j| (curvature bounds)
    ("abs_phi_r", np.float64),
    ("sig_wd", np.float64),  # sigma_j / omega_dj, 1 / omega_dj, omega_j^2 / omega_dj: the transition
    ("inv_wd", np.float64),  # without divisions
    ("w2_wd", np.float64),
    ("S_re", np.float64),  # particular harmonic solution S_j (m sqrt(kg)), Re and Im
    ("S_im", np.float64),
    ("rho_re", np.float64),  # phi_tip,j / Delta_j (the Fourier coefficient from the deviations)
    ("rho_im", np.float64),
    ("idelta_re", np.float64),  # 1 / Delta_j (s^2): the Fourier integral of x_j over a period (`sim.integration.exact`)
    ("idelta_im", np.float64),
    ("gamma", np.float64),  # participation phi_j^T M b (sqrt(kg))
    ("phi_tip", np.float64),  # mode value at the tip (1/sqrt(kg))
    ("err_x", np.float64),  # inverse error scales of a Dormand-Prince step: of x_j (1/(m sqrt(kg)))
    ("err_v", np.float64),  # ... and of x_j' (s/(m sqrt(kg)))
    ("grid_a", np.float64),  # the transition (`transition`) over a free-flight grid step h (`sim.integration.exact`)
    ("grid_b", np.float64),
    ("grid_c", np.float64),
    ("grid_d", np.float64),
    ("grid_decay", np.float64),  # exp(-sigma_j h): the envelope's decay over a grid step
    ("grid_kappa", np.float64),  # min(omega_j^2 h^2 / 8, 2): the chord bound's factor of a grid step
], align=True)

#: The scalar constants of one run (one record).
RUN = np.dtype([
    ("Omega", np.float64),  # excitation frequency (rad/s)
    ("a_base", np.float64),  # base amplitude (m)
    ("m_a", np.float64),  # sphere mass (kg) and its inverse
    ("inv_m_a", np.float64),
    ("k_H", np.float64),  # Hertz constant (N/m^1.5)
    ("c_damp", np.float64),  # damping factor of Eq. 10, d_H = c_damp delta^0.25 (N s / m^1.25; 0: elastic)
    ("g", np.float64),  # clearance (m)
    ("W_l_re", np.float64),  # W_w = phi_w^T S + a_base: harmonic wall motion relative to the base (m)
    ("W_l_im", np.float64),
    ("W_r_re", np.float64),
    ("W_r_im", np.float64),
    ("P_re", np.float64),  # phi_tip^T S: harmonic tip displacement (m)
    ("P_im", np.float64),
    ("gap_tol", np.float64),  # onset/release tolerance on the closing functions (m)
    ("v_min", np.float64),  # least approach speed of an onset (m/s)
    ("M_l0", np.float64),  # |W_w| Omega^2: the harmonic part of the curvature bounds (m/s^2)
    ("M_r0", np.float64),
    ("err_z", np.float64),  # inverse error scales of a Dormand-Prince step: of z (1/m) and z' (s/m)
    ("err_zd", np.float64),
    ("h_max", np.float64),  # longest Dormand-Prince contact step (s)
    ("h_fixed", np.float64),  # > 0: fixed Dormand-Prince contact step instead of error control (s)
    ("book", np.float64),  # 1: keep the energy bookkeeping's contact work and the impact log, 0: not (`sim.integration.energy`)
], align=True)


def mode_records(**columns: np.ndarray) -> np.ndarray:
    """The `MODE` records of n modes from a float array of n values per field (every field by name, SI units)."""
    missing = set(MODE.names) - set(columns)
    if missing or len(columns) != len(MODE.names):
        raise ValueError(f"mode_records needs exactly the fields of MODE; missing {sorted(missing)}")
    table = np.empty((np.size(columns["sig"]), len(MODE.names)))
    for i, name in enumerate(MODE.names):
        table[:, i] = columns[name]
    return table.view(MODE).reshape(-1)  # MODE has float64 fields only: a row of the table is a record


def run_record(**values: float) -> np.void:
    """The `RUN` record with these values (every field by name, in SI units)."""
    missing = set(RUN.names) - set(values)
    if missing or len(values) != len(RUN.names):
        raise ValueError(f"run_record needs exactly the fields of RUN; missing {sorted(missing)}")
    return np.array([values[name] for name in RUN.names], dtype=np.float64).view(RUN)[0]


class Constants(NamedTuple):
    """The constants of one run of the exact integrator: a `MODE` record per mode, the `RUN` record (the
    state layout is `state_layout(modes.size)`) and the contact law (`sim.model.contact_law.Law`: the kernels are
    compiled per law; its constants k, c are par.k_H, par.c_damp)."""

    modes: np.ndarray
    par: np.void
    law: Law


class Output(NamedTuple):
    """What the period loop of an integrator writes (contract of `sim.model.system`): per period |c_1| of q_tip (m)
    and the number of contact onsets, and the state [s, s', u_a, u_a'] at the record instants into the rows
    of `record` (none: 0 rows); the energy bookkeeping per period into the rows of `ledger` (columns `LEDGER`
    then the dissipation of each mode; none: 0 rows) and the impacts into the rows of `log` (columns `IMPACT`;
    `log_count[0]` counts every impact, also those beyond the log's rows)."""

    amplitudes: np.ndarray
    impacts: np.ndarray
    record: np.ndarray
    ledger: np.ndarray
    log: np.ndarray
    log_count: np.ndarray


class LedgerColumns(NamedTuple):
    """Columns of a period's row of `Output.ledger` (Sect. 5.5; `sim.integration.energy`): the work of the base excitation
    `input` (J), the dissipation in the contacts `contact` and by dry friction `friction` (J, Appendix C; ode3
    only), the complex fundamental Fourier coefficients
    c_1 = (2/T) int_T q e^{-i Omega t} dt (m) of the tip and of both walls (relative to the base), and from
    column `modes` on the dissipation of each mode's modal damping int 2 D_j omega_j s_j'^2 dt (J)."""

    input: int
    contact: int
    friction: int
    tip_re: int
    tip_im: int
    left_re: int
    left_im: int
    right_re: int
    right_im: int
    modes: int


LEDGER = LedgerColumns(*range(len(LedgerColumns._fields)))


class ImpactColumns(NamedTuple):
    """Columns of an impact's row of `Output.log` (one contact, onset to release; Appendix D): the wall (0 left,
    1 right), the period of the onset (from 0 in the run_step call) and its phase time in that period (s), the
    duration (s), the impulse int |f| dt (N s), the approach speed (closing rate at the onset, m/s), the sphere's
    velocity relative to the base u_a' before and after (m/s), and the modal energies (s_j'^2 + omega_j^2 s_j^2)/2
    of mode 1 and of modes 2..N at the onset and at the release (J). A contact still open at the call's end
    has NaN release fields."""

    wall: int
    period: int
    t_onset: int
    duration: int
    impulse: int
    approach_speed: int
    sphere_before: int
    sphere_after: int
    fundamental_onset: int
    higher_onset: int
    fundamental_release: int
    higher_release: int


IMPACT = ImpactColumns(*range(len(ImpactColumns._fields)))


class Phase(NamedTuple):
    """A phase time t (s) of the excitation period with cos(Omega t) and sin(Omega t)."""

    t: float
    cos: float
    sin: float


class Counters(NamedTuple):
    """Index of each counter of the exact integrator's kernels (`run_step(..., stats=...)` uses the names)."""

    grid_steps: int
    searches: int
    search_evaluations: int
    contact_steps: int
    rejected_steps: int
    release_iterations: int
    contacts: int
    collocation_steps: int
    collocation_fallbacks: int


COUNT = Counters(*range(len(Counters._fields)))
# status of a kernel
OK, NONFINITE, OVERLAP, STALLED, STALLED_SEARCH = range(5)


# ----------------------------------------------------------------------------------------------------------
# free flight in closed form
# ----------------------------------------------------------------------------------------------------------
@kernel(inline="always")
def transition(tau, md, j):
    """Transition of the damped oscillator j over tau s (Eq. 9, homogeneous):
    (x, v)(tau) = [[a, b], [c, d]] (x0, v0)."""
    e = math.exp(-md[j].sig * tau)
    co = math.cos(md[j].wd * tau)
    si = math.sin(md[j].wd * tau)
    q = md[j].sig_wd * si  # the records hold the ratios (no divisions here)
    return e * (co + q), e * si * md[j].inv_wd, -e * md[j].w2_wd * si, e * (co - q)


@kernel
def flight_transitions(tau, md, tr):
    """tr[:, j] = transition (a, b, c, d) of mode j over a free flight of tau s (Eq. 9)."""
    for j in range(md.size):
        tr[0, j], tr[1, j], tr[2, j], tr[3, j] = transition(tau, md, j)


@kernel(inline="always")
def _fly_mode(Y, Ynew, j, tr, lay):
    """Mode j of a free flight with the transition tr = (a, b, c, d) of `transition` (Eq. 9)."""
    a, b, c, d = tr
    x = Y[lay.x + j]
    v = Y[lay.v + j]
    Ynew[lay.x + j] = a * x + b * v
    Ynew[lay.v + j] = c * x + d * v


@kernel(inline="always")
def _fly_sphere(Y, Ynew, tau, lay):
    """The sphere of a free flight over tau s (constant velocity). The carried integrals do not change in free
    flight: they are not written (the callers copy the mechanical state, `lay.acc` components, back)."""
    Ynew[lay.z] = Y[lay.z] + tau * Y[lay.zd]
    Ynew[lay.zd] = Y[lay.zd]


@kernel(inline="always")
def copy_into(dst, src, start, stop):
    """dst[start:stop] = src[start:stop], element by element (a slice copy needs the reference counts that the
    exact integrator's kernels run without: `sim.integration.jit.kernel`)."""
    for i in range(start, stop):
        dst[i] = src[i]


@kernel(inline="always")  # called per grid step: a call costs more than its body
def grid_flight(Y, Ynew, h, md):
    """Ynew[:acc] = free flight of Y over one grid step h (s) with the transitions of the records (grid_a ... grid_d)."""
    lay = state_layout(md.size)
    for j in range(lay.n):
        _fly_mode(Y, Ynew, j, (md[j].grid_a, md[j].grid_b, md[j].grid_c, md[j].grid_d), lay)
    _fly_sphere(Y, Ynew, h, lay)


@kernel(inline="always")  # called after every release and per recorded sample: like grid_flight, cheaper inline
def free_flight(Y, Ynew, tau, md):
    """Ynew[:acc] = free flight of Y over tau s (Eq. 9)."""
    lay = state_layout(md.size)
    for j in range(lay.n):
        _fly_mode(Y, Ynew, j, transition(tau, md, j), lay)
    _fly_sphere(Y, Ynew, tau, lay)


# time maps of a contact step, t = t_a + h w(u) with u in [0, 1] (`time_map`). numpy integers, not Python ones: a
# kernel called with a Python constant is compiled once more for that literal value (numba's Literal[int]), which
# doubled the exact integrator's compile time for no measurable speed.
ONSET, REGULAR, RELEASE, GRAZE = (np.int64(kind) for kind in range(4))


@kernel(inline="always")
def time_map(kind, u):
    """(w(u), w'(u)) of a contact step's time map t = t_a + h w(u), w(1) = 1 (contacts of Eq. 4).

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


@kernel(inline="always")
def closing(Y, t, cst):
    """(c_l, c_l', c_r, c_r') at phase time t s: contact at a wall when its c > 0 (Eqs. 4-6)."""
    Om = cst.par.Omega
    return closing_at(Y, math.cos(Om * t), math.sin(Om * t), cst)


@kernel(inline="always")
def closing_at(Y, ct, st, cst):
    """`closing` with cos, sin(Omega t) given."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    Om = par.Omega
    sl = par.W_l_re * ct - par.W_l_im * st
    sld = -Om * (par.W_l_re * st + par.W_l_im * ct)
    sr = par.W_r_re * ct - par.W_r_im * st
    srd = -Om * (par.W_r_re * st + par.W_r_im * ct)
    for j in range(lay.n):
        x = Y[lay.x + j]
        v = Y[lay.v + j]
        sl += md[j].phi_l * x
        sld += md[j].phi_l * v
        sr += md[j].phi_r * x
        srd += md[j].phi_r * v
    z = Y[lay.z]
    zd = Y[lay.zd]
    g = par.g
    return sl - z - g, sld - zd, -(sr - z) - g, -(srd - zd)


# 1 / (k (k + 1)) for the nested Taylor series of `rotate` (multiplications: a chain of divisions is slow)
_C12, _C34, _C56, _C78, _C910, _C1112 = 1 / 2, 1 / 12, 1 / 30, 1 / 56, 1 / 90, 1 / 132
_S23, _S45, _S67, _S89, _S1011, _S1213 = 1 / 6, 1 / 20, 1 / 42, 1 / 72, 1 / 110, 1 / 156


@kernel(inline="always")
def rotate(ct, st, angle):
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
