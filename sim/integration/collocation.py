"""Contacts by exponential Gauss collocation: a whole Hertz impact (Eq. 4) in two or three steps.

During a contact with wall w only the scalar contact force F(t) = k_H c_w(t)^1.5 is nonlinear; the modes
and the sphere respond to it linearly (Eqs. 3-7). Over a step of length h from t_a (state Y_a) we write
the closing function exactly as (Duhamel)

    c_w(t_a + tau) = c_hom(tau) - int_0^tau K_w(tau - sigma) F(sigma) dsigma,
    K_w(t) = sum_j phi_w,j^2 exp(-sigma_j t) sin(omega_dj t) / omega_dj + t / m_a,

c_hom being the free flight from Y_a (closed form, `sim.integration.flight`). F is represented by its values at s Gauss
nodes of a time map t = t_a + h w(u), u in [0, 1] (`sim.integration.flight.time_map`: u^2 at an onset,
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

The force and its derivative at the nodes are the contact law's (`sim.model.contact_law`, inlined per law); the
first guesses of the step lengths are those of a Hertz impact, so only laws that say `collocation=True` (Eq. 4)
come here; the exact integrator takes the contacts of the others by Dormand-Prince.

Accuracy: the force is interpolated by a polynomial of degree s - 1 in u, so a step has the order of
its interpolation (about s + 1 for the modal response, 2 s for the force impulse, Gauss quadrature);
with s = 10 a whole impact has a rebound error near 1e-10 (tests/sim/integration/test_collocation.py).
"""
from __future__ import annotations

import math
from collections import OrderedDict
from typing import NamedTuple

import numpy as np
from numpy.polynomial import legendre, polynomial

from sim.integration.flight import (ONSET, REGULAR, RELEASE, Constants, closing_at, copy_into, rotate, state_layout, time_map,
                        transition)
from sim.integration.jit import kernel
from sim.model.contact_law import wall_force, wall_stiffness

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
# node data and tables
# ----------------------------------------------------------------------------------------------------------
class Nodes(NamedTuple):
    """Universal data of the s-node collocation: nodes u and weights b on [0, 1], barycentric weights wb,
    the quadrature (xq, bq) that builds the tables, the maps from nodal forces to the Taylor coefficients
    (in the backward time sigma / h) of the force at the end of a regular / onset step, and the rows of
    the two highest Legendre coefficients of the force polynomial (`tail`)."""

    u: np.ndarray
    b: np.ndarray
    wb: np.ndarray
    xq: np.ndarray
    bq: np.ndarray
    regular: np.ndarray
    onset: np.ndarray
    tail: np.ndarray


def gauss_nodes(s: int = NODES, order: int = SERIES_ORDER, quadrature: int = TABLE_QUADRATURE) -> Nodes:
    """The `Nodes` of s Gauss-Legendre nodes, Taylor series of `order` terms, tables by `quadrature` points."""
    x, w = legendre.leggauss(s)
    u = 0.5 * (x + 1.0)
    b = 0.5 * w
    wb = np.array([1.0 / np.prod(u[k] - np.delete(u, k)) for k in range(s)])
    xq, wq = legendre.leggauss(quadrature)
    # Taylor coefficients at u = 1 of the Lagrange basis, in eps = 1 - u: C[m, k]
    C = np.zeros((order, s))
    for k in range(s):
        others = np.delete(u, k)
        lk = polynomial.polyfromroots(others) / np.prod(u[k] - others)
        # l_k(1 - eps) as a polynomial in eps
        coeffs = np.zeros(s)
        one_minus = np.array([1.0, -1.0])
        power = np.array([1.0])
        for c in lk:
            coeffs[:power.size] += c * power
            power = polynomial.polymul(power, one_minus)
        C[:s, k] = coeffs[:s] if order >= s else coeffs[:order]
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
    # the two highest Legendre coefficients of the force polynomial from its nodal values (Gauss quadrature)
    z = 2.0 * u - 1.0
    tail = np.array([(2 * m + 1) * b * legendre.legval(z, np.eye(s)[m]) for m in (s - 2, s - 1)])
    return Nodes(u=u, b=b, wb=wb, xq=0.5 * (xq + 1.0), bq=0.5 * wq, regular=C, onset=onset, tail=tail)


#: The node data of `contact` (NODES nodes), frozen into the kernels as constants.
NODE_DATA = gauss_nodes()


#: The blocks of a table, in their order: P, Q (n x (s+1), mode by mode), W (s x (s+1), column by column), BX,
#: BV (s x n), BZ, BZD (s), TR (4 x n), TAU (s+1), WQ (s), and the contact work's VC, VD (s x n, node by node)
#: and VS (s (s + 1) / 2 x n, the node pairs k <= i, pair by pair). The layouts put the inner loops of the kernels
#: along contiguous memory (for the contact work: along the modes, so that all modes advance together).
TABLE_BLOCKS = ("P", "Q", "W", "BX", "BV", "BZ", "BZD", "TR", "TAU", "WQ", "VC", "VD", "VS")


class TableLayout(NamedTuple):
    """Offsets of the blocks of a table (`TABLE_BLOCKS`), its size, and the nodes s and modes n it is for."""

    P: int
    Q: int
    W: int
    BX: int
    BV: int
    BZ: int
    BZD: int
    TR: int
    TAU: int
    WQ: int
    VC: int
    VD: int
    VS: int
    size: int
    s: int
    n: int


def table_layout(s: int, n: int) -> TableLayout:
    """The `TableLayout` of s nodes and n modes."""
    r = s + 1
    sizes = {"P": r * n, "Q": r * n, "W": r * s, "BX": s * n, "BV": s * n, "BZ": s, "BZD": s, "TR": 4 * n,
             "TAU": r, "WQ": s, "VC": s * n, "VD": s * n, "VS": s * (s + 1) // 2 * n}
    ends = np.cumsum([sizes[name] for name in TABLE_BLOCKS])
    starts = [0, *ends[:-1].tolist()]
    return TableLayout(**dict(zip(TABLE_BLOCKS, starts)), size=int(ends[-1]), s=s, n=n)


class Step(NamedTuple):
    """One step's table (layout `off`), with cos, sin(Omega tau_i) at its nodes and end (2 x (s + 1))."""

    tab: np.ndarray
    ph: np.ndarray
    off: TableLayout


@kernel(inline="always")
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


@kernel(inline="always")
def _phi(md, j, wall):
    """phi_w,j: mode j at wall 0 (left) or 1 (right)."""
    return md[j].phi_l if wall == 0 else md[j].phi_r


@kernel(refcounts=True)  # allocates its scratch; called from the integrator's kernels, which run without
def _build(tab, nodes, off, kind, h, wall, cst):
    """Fill one table (layout `off`) for a step of length h with the time map `kind` at wall 0/1 (Eqs. 3-7).

    P, Q: c_hom at node i (row s: the step's end) = sum_j P_ij x_j + Q_ij v_j + (harmonic and sphere terms).
    W: c_w at node i drops by sum_k W_ik F_k. BX, BV, BZ, BZD: end-state response to the nodal force F_k.
    TR: mode transitions over h. TAU: node times. WQ: quadrature weights of int F dt over the step.
    VC, VD, VS: the contact work of mode j over the step, G_j = int sgn phi_w,j F x_j' dt (Gauss quadrature at
    the nodes), = sum_i F_i (VC_ij x_j + VD_ij v_j) + sum_{k <= i} VS_ikj F_i F_k (`_contact_work`).
    The impulse responses are the transitions' entries: x(t) = b(t), x'(t) = d(t) per unit velocity.
    """
    md = cst.modes
    u, wb, b, xq, bq = nodes.u, nodes.wb, nodes.b, nodes.xq, nodes.bq
    s = u.size
    n = off.n
    sgn = 1.0 if wall == 0 else -1.0
    inv_ma = cst.par.inv_m_a
    lag_k = np.empty(s)
    vel = np.zeros((s, s, n))  # vel[i, k, j]: x_j' at node i per unit nodal force F_k
    tab[:] = 0.0
    for i in range(s + 1):
        ui = u[i] if i < s else 1.0
        wi, _ = time_map(kind, ui)
        tau = h * wi
        tab[off.TAU + i] = tau
        for j in range(n):
            a, bb, c, d = transition(tau, md, j)
            tab[off.P + j * (s + 1) + i] = sgn * _phi(md, j, wall) * a
            tab[off.Q + j * (s + 1) + i] = sgn * _phi(md, j, wall) * bb
        # W[i, k] = int_0^ui K(tau - h w(v)) l_k(v) h w'(v) dv
        for q in range(xq.size):
            v = ui * xq[q]
            wv, dv = time_map(kind, v)
            lag = tau - h * wv
            K = lag * inv_ma
            for j in range(n):
                K += _phi(md, j, wall) ** 2 * transition(lag, md, j)[1]
            weight = ui * bq[q] * K * h * dv
            _lagrange(u, wb, v, lag_k)
            for k in range(s):
                tab[off.W + k * (s + 1) + i] += weight * lag_k[k]
            if i < s:
                for j in range(n):
                    dj = -sgn * _phi(md, j, wall) * transition(lag, md, j)[3] * ui * bq[q] * h * dv
                    for k in range(s):
                        vel[i, k, j] += dj * lag_k[k]
    for q in range(xq.size):
        v = xq[q]
        wv, dv = time_map(kind, v)
        lag = h - h * wv
        _lagrange(u, wb, v, lag_k)
        for j in range(n):
            a, bb, c, d = transition(lag, md, j)
            for k in range(s):
                lw = bq[q] * lag_k[k] * h * dv
                tab[off.BX + k * n + j] -= sgn * _phi(md, j, wall) * bb * lw
                tab[off.BV + k * n + j] -= sgn * _phi(md, j, wall) * d * lw
        for k in range(s):
            lw = bq[q] * lag_k[k] * h * dv
            tab[off.BZ + k] += sgn * lag * lw * inv_ma
            tab[off.BZD + k] += sgn * lw * inv_ma
    for j in range(n):
        a, bb, c, d = transition(h, md, j)
        tab[off.TR + j] = a
        tab[off.TR + n + j] = bb
        tab[off.TR + 2 * n + j] = c
        tab[off.TR + 3 * n + j] = d
    for k in range(s):
        _, dk = time_map(kind, u[k])
        tab[off.WQ + k] = b[k] * h * dk
    # the contact work: quadrature weight, sign and wall value folded in; the pairs (i, k) and (k, i) summed
    for i in range(s):
        for j in range(n):
            wphi = tab[off.WQ + i] * sgn * _phi(md, j, wall)
            _, _, c, d = transition(tab[off.TAU + i], md, j)
            tab[off.VC + i * n + j] = wphi * c
            tab[off.VD + i * n + j] = wphi * d
    for i in range(s):
        for k in range(i + 1):
            for j in range(n):
                pair = tab[off.WQ + i] * sgn * _phi(md, j, wall) * vel[i, k, j]
                if k < i:
                    pair += tab[off.WQ + k] * sgn * _phi(md, j, wall) * vel[k, i, j]
                tab[off.VS + ((i * (i + 1)) // 2 + k) * n + j] = pair


# ----------------------------------------------------------------------------------------------------------
# one step: the free closing function at the nodes, Newton on the nodal indentations, the end state
# ----------------------------------------------------------------------------------------------------------
class WorkRows(NamedTuple):
    """Rows of the workspace (`Workspace.rows`) of `contact`: at the nodes and the end (s + 1 entries) the free
    closing function `chom`, its rate `dchom` and the right-hand side `rhs`; at the nodes the indentations
    `delta`, forces `F` and dF/d delta `D`; the states `Ynew` (a step's end) and `Ys` (a release step's
    start); the backward series `Fs` of the force; the products F_i F_k (k <= i) of the nodal forces `pairs`;
    the modes' contact work of a step `work`."""

    chom: int
    dchom: int
    rhs: int
    delta: int
    F: int
    D: int
    Ynew: int
    Ys: int
    Fs: int
    pairs: int
    work: int


ROW = WorkRows(*range(len(WorkRows._fields)))


class Workspace(NamedTuple):
    """Scratch of `contact`: the vectors named by `ROW` (rows of one array, as long as the longest), the Newton
    matrix A ((s + 1) x (s + 1), by columns) and the backward series S of the mechanical state (order x acc).
    One array for the vectors, handed around as a whole (from before the kernels ran without reference counts,
    `sim.integration.jit`; still fewer arguments per call)."""

    rows: np.ndarray
    A: np.ndarray
    S: np.ndarray


def workspace(nodes: Nodes, n: int) -> Workspace:
    """The `Workspace` of `contact` for n modes."""
    s = nodes.u.size
    order = nodes.onset.shape[0]
    lay = state_layout(n)
    return Workspace(rows=np.zeros((len(ROW), max(s + 1, lay.size, order, s * (s + 1) // 2))), A=np.zeros((s + 1, s + 1)),
                     S=np.zeros((order, lay.acc)))


def first_guesses(nodes: Nodes) -> np.ndarray:
    """Indentations over their first guess for an onset / regular / release step (rows 0 / 1 / 2), at the nodes."""
    guesses = np.empty((3, nodes.u.size))
    guesses[0] = 0.85  # onset: indentation / free indentation (Hertz: ~0.7 at the half contact)
    guesses[1] = 0.9
    guesses[2] = (1.0 - nodes.u) ** 2  # release: indentation / indentation at the start, linear in time to the end
    return guesses


@kernel
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


@kernel(inline="always")
def _add_modes(step, Y, lay, out):
    """out[i] += sum_j P_ij x_j + Q_ij v_j over the nodes and the end (P, Q are stored mode by mode)."""
    tab, off = step.tab, step.off
    r = off.s + 1
    for j in range(lay.n):
        x = Y[lay.x + j]
        v = Y[lay.v + j]
        for i in range(r):
            out[i] += tab[off.P + j * r + i] * x + tab[off.Q + j * r + i] * v


@kernel(inline="always")
def _node_phase(ph, i, ct, st):
    """cos, sin(Omega t) at node i of a step (node phases ph) that starts at cos, sin(Omega t_a) = ct, st."""
    return ct * ph[0, i] - st * ph[1, i], st * ph[0, i] + ct * ph[1, i]


@kernel(inline="always")
def _wall(par, wall):
    """(sign, Re W_w, Im W_w) of wall 0 (left, c = delta) or 1 (right, c = -delta) (Eqs. 4-6)."""
    if wall == 0:
        return 1.0, par.W_l_re, par.W_l_im
    return -1.0, par.W_r_re, par.W_r_im


@kernel
def _free_closing(step, Y, ct, st, wall, cst, out, rate):
    """out[i] = c_w at node i (i = s: the step's end) of the free flight from Y at phase (ct, st) (Eqs. 4-6, 9).

    rate: Y is instead dY/dt at the start, and out[i] the derivative of c_w(node i) by the start time (the
    modes enter both alike)."""
    tab, ph, off = step.tab, step.ph, step.off
    par = cst.par
    lay = state_layout(cst.modes.size)
    sgn, Wr, Wi = _wall(par, wall)
    for i in range(off.s + 1):
        c, si = _node_phase(ph, i, ct, st)
        if rate:
            out[i] = -sgn * (par.Omega * (Wr * si + Wi * c) + Y[lay.z] + tab[off.TAU + i] * Y[lay.zd])
        else:
            out[i] = sgn * (Wr * c - Wi * si - Y[lay.z] - tab[off.TAU + i] * Y[lay.zd]) - par.g
    _add_modes(step, Y, lay, out)


@kernel(inline="always")
def _forces(delta, F, D, spring, s):
    """The contact law at the nodes: F = its force (Eq. 4: k_H delta^1.5), D = dF/d delta; spring = (law, k, c)
    of `_spring` (a law that collocation takes: its force does not depend on the rate, `Law.collocation`)."""
    law, k_law, c_law = spring
    for k in range(s):
        d = delta[k]
        if d > 0.0:
            F[k] = wall_force(law, d, 0.0, k_law, c_law)
            D[k] = wall_stiffness(law, d, k_law)
        else:
            F[k] = 0.0
            D[k] = 0.0


@kernel(inline="always")
def _spring(cst):
    """(law, k, c): the contact law of `cst` and its constants (`sim.model.contact_law.Law`)."""
    return cst.law, cst.par.k_H, cst.par.c_damp


@kernel(inline="always")
def _collocation_equations(step, chom, delta, F, D, A, rhs):
    """The s collocation equations and their Jacobian: rhs[i] = delta_i - chom_i + sum_k W_ik F_k and
    A[k, i] = delta_ik + W_ik D_k (by columns, as W is stored). Returns max |chom_i| (the indentation scale)."""
    tab, off = step.tab, step.off
    s = off.s
    oW = off.W
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


@kernel
def _newton(step, ws, spring):
    """Solve delta_i = chom_i - sum_k W_ik F(delta_k) for the nodal indentations (row delta of ws holds the guess).

    Returns the number of iterations, or -1 if Newton's method did not converge."""
    s = step.off.s
    rows, A = ws.rows, ws.A
    chom, delta, F, D, rhs = rows[ROW.chom], rows[ROW.delta], rows[ROW.F], rows[ROW.D], rows[ROW.rhs]
    for it in range(40):
        _forces(delta, F, D, spring, s)
        scale = _collocation_equations(step, chom, delta, F, D, A, rhs)
        if not _solve_in_place(A, rhs, s):
            return -1
        change = 0.0
        for i in range(s):
            delta[i] -= rhs[i]
            change = max(change, abs(rhs[i]))
        if not change <= 1e3 * scale:
            return -1
        if change <= _NEWTON_TOL * scale:
            _forces(delta, F, D, spring, s)
            return it + 1
    return -1


@kernel(fastmath=True)
def _contact_work(tab, off, Y, Yout, F, FF, G):
    """Yout[G + j] += the contact work of mode j's deviation over the step of the table `tab` (layout `off`),
    int sgn phi_w,j F x_j' dt (Gauss quadrature at the nodes of the exact modal velocities there: blocks VC, VD,
    VS), with FF the scratch for the s (s + 1) / 2 products F_i F_k and G for the n sums. The modes are the inner
    loops (contiguous in the table): they advance together in vector registers. Bookkeeping only, so the sums
    may be reordered (fastmath)."""
    lay = state_layout(off.n)
    n = lay.n
    s = off.s
    m = 0
    for i in range(s):
        for k in range(i + 1):
            FF[m] = F[i] * F[k]
            m += 1
    for j in range(n):
        G[j] = 0.0
    for i in range(s):
        f = F[i]
        vc = off.VC + i * n
        vd = off.VD + i * n
        for j in range(n):
            G[j] += f * (tab[vc + j] * Y[lay.x + j] + tab[vd + j] * Y[lay.v + j])
    for q in range(m):
        ff = FF[q]
        row = off.VS + q * n
        for j in range(n):
            G[j] += tab[row + j] * ff
    for j in range(n):
        Yout[lay.G + j] += G[j]


@kernel
def _end_state(step, Y, Yout, F, ct, st, wall):
    """Yout = the state at the step's end (Eqs. 3-7): transitions, responses to the nodal forces F, and the
    Fourier integral of the contact force over the step (Gauss quadrature at the node phases). The modes'
    contact work is `_contact_work`'s."""
    tab, ph, off = step.tab, step.ph, step.off
    lay = state_layout(off.n)
    n = lay.n
    s = off.s
    oTR = off.TR
    for j in range(n):
        x = Y[lay.x + j]
        v = Y[lay.v + j]
        Yout[lay.x + j] = tab[oTR + j] * x + tab[oTR + n + j] * v
        Yout[lay.v + j] = tab[oTR + 2 * n + j] * x + tab[oTR + 3 * n + j] * v
    for k in range(s):
        f = F[k]
        for j in range(n):
            Yout[lay.x + j] += tab[off.BX + k * n + j] * f
            Yout[lay.v + j] += tab[off.BV + k * n + j] * f
    h = tab[off.TAU + s]
    ze = Y[lay.z] + h * Y[lay.zd]
    zde = Y[lay.zd]
    re = 0.0
    im = 0.0
    for k in range(s):
        ze += tab[off.BZ + k] * F[k]
        zde += tab[off.BZD + k] * F[k]
        c, si = _node_phase(ph, k, ct, st)
        wf = tab[off.WQ + k] * F[k]
        re += wf * c
        im -= wf * si
    Yout[lay.z] = ze
    Yout[lay.zd] = zde
    for i in range(lay.acc, Yout.size):
        Yout[i] = Y[i]
    sgn = 1.0 if wall == 0 else -1.0
    row = lay.F_l if wall == 0 else lay.F_r
    Yout[row] += sgn * re
    Yout[row + 1] += sgn * im


# ----------------------------------------------------------------------------------------------------------
# the state inside the previous step: Taylor series in the backward time sigma
# ----------------------------------------------------------------------------------------------------------
@kernel
def _series(Yend, F, M, h, wall, cst, S, Fs):
    """S[q]: Taylor coefficients of the mechanical state [x, v, z, z'] at t_e - sigma (Eqs. 3-7), Fs[q] those
    of the force, for the solution of the step that ended at t_e (length h, force polynomial with nodal
    values F; M maps them to the force's coefficients in sigma / h, `Nodes.regular` or `Nodes.onset`)."""
    md = cst.modes
    lay = state_layout(md.size)
    p = S.shape[0]
    s = F.size
    sgn = 1.0 if wall == 0 else -1.0
    scale = 1.0
    inv_h = 1.0 / h
    for q in range(p):
        acc = 0.0
        for k in range(s):
            acc += M[q, k] * F[k]
        Fs[q] = acc * scale
        scale *= inv_h
    for i in range(lay.acc):
        S[0, i] = Yend[i]
    for q in range(p - 1):
        inv = 1.0 / (q + 1)
        for j in range(lay.n):
            S[q + 1, lay.x + j] = -S[q, lay.v + j] * inv
            S[q + 1, lay.v + j] = (2.0 * md[j].sig * S[q, lay.v + j] + md[j].w2 * S[q, lay.x + j]
                                   + sgn * _phi(md, j, wall) * Fs[q]) * inv
        S[q + 1, lay.z] = -S[q, lay.zd] * inv
        S[q + 1, lay.zd] = -sgn * Fs[q] * cst.par.inv_m_a * inv


@kernel
def _series_at(S, sigma, Y, m):
    """Y[:m] = the state at t_e - sigma from the series S of `_series` (Horner, all components at once)."""
    p = S.shape[0]
    for i in range(m):
        Y[i] = S[p - 1, i]
    for q in range(p - 2, -1, -1):
        for i in range(m):
            Y[i] = Y[i] * sigma + S[q, i]


#: 1 / k for k = 1, 2, ... (the integrals of the powers in `_overlap_fourier` and `_overlap_work`: k <= 2 SERIES_ORDER)
_INV = 1.0 / np.arange(1.0, 40.0)
#: Terms of the exponential's series in `_overlap_fourier` ((Omega sigma)^5 / 5! < 1e-12 for Omega sigma < 0.01).
_OVERLAP_TERMS = 5


@kernel
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


@kernel
def _overlap_work(S, Fs, sigma, wall, cst, Y):
    """Y[G + j] -= int over [t_e - sigma, t_e] of sgn phi_w,j F x_j' dt: the contact work of the overlap, the
    exact integral of the product of the series of the force (Fs) and of the modal velocities (S), both in the
    backward time (`_series`): sum_b S_b,j K_b with K_b = sum_a Fs_a sigma^(a + b + 1) / (a + b + 1), one K_b
    for all modes."""
    md = cst.modes
    lay = state_layout(md.size)
    sgn = 1.0 if wall == 0 else -1.0
    p = S.shape[0]
    lead = sgn * sigma  # sgn sigma^(b + 1)
    for b in range(p):
        K = 0.0
        term = lead  # sgn Fs_a sigma^(a + b + 1) / Fs_a
        for a in range(Fs.size):
            K += Fs[a] * term * _INV[a + b]
            term *= sigma
        for j in range(lay.n):
            Y[lay.G + j] -= K * _phi(md, j, wall) * S[b, lay.v + j]
        lead *= sigma


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
# 6-point Gauss-Legendre on [0, 1] for `_time_to_release`
_GL6_X = np.array([0.033765242898423975, 0.16939530676686776, 0.3806904069584015, 0.6193095930415985,
                   0.8306046932331322, 0.966234757101576])
_GL6_W = np.array([0.08566224618958517, 0.1803807865240693, 0.23395696728634552, 0.23395696728634552,
                   0.1803807865240693, 0.08566224618958517])


@kernel
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


@kernel
def _ladder(h, h_ref, up):
    """Index of the ladder step just below (up=False) or above (up=True) h; -1 if outside the ladder."""
    x = LADDER_PER_OCTAVE * math.log2(h / h_ref) + LADDER_CENTRE
    k = int(math.ceil(x - 1e-12)) if up else int(math.floor(x + 1e-12))
    return k if 0 <= k < LADDER_SIZE else -1


@kernel
def _ladder_h(k, h_ref):
    """Length (s) of ladder step k."""
    return h_ref * 2.0 ** ((k - LADDER_CENTRE) / LADDER_PER_OCTAVE)


class Tables(NamedTuple):
    """The ladder of tables of one system, `tabs[wall, kind, k]` (built on first use, then `built` is set),
    their layout, and h_ref (the period of the highest mode, s) that scales the ladder."""

    tabs: np.ndarray
    built: np.ndarray
    off: TableLayout
    h_ref: float


class Context(NamedTuple):
    """What `contact` works with in one run_step call (the nodes are `NODE_DATA`): the system's `Tables`, the
    first `guesses` (rows of `first_guesses`, updated from contact to contact), cos, sin(Omega tau_i) of each
    table's nodes (`phases`, filled on first use, then `phased` is set) and the `Workspace`."""

    tables: Tables
    guesses: np.ndarray
    phases: np.ndarray
    phased: np.ndarray
    work: Workspace


class StepEnd(NamedTuple):
    """The end of the last accepted step: cos, sin(Omega t) there, the step's length h (s), and c, c' of the
    active wall there (m, m/s)."""

    cos: float
    sin: float
    h: float
    c: float
    cd: float


@kernel
def _step_table(tables, phases, phased, wall, kind, k, cst):
    """The `Step` of (wall, kind, ladder index k): its table built (`NODE_DATA`) and its node phases computed
    (in phases, phased of the `Context`) on first use."""
    off = tables.off
    if not tables.built[wall, kind, k]:
        _build(tables.tabs[wall, kind, k], NODE_DATA, off, kind, _ladder_h(k, tables.h_ref), wall, cst)
        tables.built[wall, kind, k] = True
    tab = tables.tabs[wall, kind, k]
    if not phased[kind, k]:
        Om = cst.par.Omega
        for i in range(off.s + 1):
            phases[kind, k, 0, i], phases[kind, k, 1, i] = rotate(1.0, 0.0, Om * tab[off.TAU + i])
        phased[kind, k] = True
    return Step(tab, phases[kind, k], off)


@kernel
def _active(Y, ct, st, wall, cst):
    """(c, c') of `wall` (Eqs. 4-6)."""
    cl, cld, cr, crd = closing_at(Y, ct, st, cst)
    return (cl, cld) if wall == 0 else (cr, crd)


@kernel
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


@kernel
def _forward_step(step, Y, ct, st, wall, ratio, ws, cst):
    """Solve a step from Y that has no release inside: nodal forces in row F of ws, first guess ratio times
    the free indentation (ratio is updated). False if Newton's method failed or an indentation is not positive."""
    s = step.off.s
    chom = ws.rows[ROW.chom]
    delta = ws.rows[ROW.delta]
    _free_closing(step, Y, ct, st, wall, cst, chom, False)
    for i in range(s):
        delta[i] = ratio[i] * chom[i]
    if _newton(step, ws, _spring(cst)) < 0:
        return False
    for i in range(s):
        if not delta[i] > 0.0:
            return False
    for i in range(s):
        ratio[i] = delta[i] / chom[i]
    return True


@kernel
def _release_step(step, end, d, wall, ratio, ws, cst):
    """Newton's method for the release step `step` that starts d before the last step's `end` (a `StepEnd`;
    the series of that step's state and force in ws.S and row Fs of ws): unknowns the nodal indentations and d,
    equations the collocation and c_w = 0 at the step's end. d is kept in [-0.3 h, 0.6 h] of the last step
    (the series' range). Returns (status, d): 0 converged, 1 failed, 2 d left its range (the release is
    elsewhere: another ladder length); the nodal forces are left in row F of ws."""
    md, par = cst.modes, cst.par
    lay = state_layout(md.size)
    tab, off = step.tab, step.off
    s = off.s
    rows, A, S = ws.rows, ws.A, ws.S
    chom, dchom, delta, F, D, rhs = (rows[ROW.chom], rows[ROW.dchom], rows[ROW.delta], rows[ROW.F], rows[ROW.D],
                                     rows[ROW.rhs])
    Fs = rows[ROW.Fs, :S.shape[0]]
    Ys = rows[ROW.Ys]
    Yd = rows[ROW.Ynew]  # dY/dt at the start (free while the release step runs)
    Om = par.Omega
    sgn = 1.0 if wall == 0 else -1.0
    oW = off.W
    d_lo = -0.3 * end.h
    d_hi = 0.6 * end.h
    c_e = end.c
    for i in range(s):
        delta[i] = ratio[i] * c_e
    for _ in range(30):
        # the start state (series at d), its rate dY/dt (Eqs. 3-7 with the force's series) and c_hom at the nodes
        _series_at(S, d, Ys, lay.acc)
        f = Fs[Fs.size - 1]
        for q in range(Fs.size - 2, -1, -1):
            f = f * d + Fs[q]
        for j in range(lay.n):
            Yd[lay.x + j] = Ys[lay.v + j]
            Yd[lay.v + j] = (-2.0 * md[j].sig * Ys[lay.v + j] - md[j].w2 * Ys[lay.x + j]
                             - sgn * _phi(md, j, wall) * f)
        Yd[lay.z] = Ys[lay.zd]
        Yd[lay.zd] = sgn * f * par.inv_m_a
        cb, sb = rotate(end.cos, end.sin, -Om * d)
        _free_closing(step, Ys, cb, sb, wall, cst, chom, False)
        _free_closing(step, Yd, cb, sb, wall, cst, dchom, True)
        _forces(delta, F, D, _spring(cst), s)
        # the collocation equations at the nodes, then c_w = 0 at the end, and the column of d (d/dd = -d/dt_start)
        scale = max(_collocation_equations(step, chom, delta, F, D, A, rhs), abs(chom[s]))
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
        change = abs(rhs[s] * end.cd)
        for i in range(s):
            delta[i] -= rhs[i]
            change = max(change, abs(rhs[i]))
        d -= rhs[s]
        if not (change <= 1e3 * scale and math.isfinite(d)):
            return 1, d
        if not d_lo <= d <= d_hi:
            return 2, d
        if change <= _NEWTON_TOL * scale:
            _forces(delta, F, D, _spring(cst), s)
            for i in range(s):
                if not delta[i] > 0.0:
                    return 1, d
            for i in range(s):
                ratio[i] = delta[i] / c_e
            return 0, d
    return 1, d


@kernel
def contact(Y, t, t_stop, wall, ctx, cst):
    """Integrate the contact with `wall` (0 left, 1 right) from its located onset (t, Y) to its release (Eqs. 3-7).

    Returns (outcome, t, steps): RELEASED with Y the state at the release time t, or FALLBACK with Y the
    valid state at t (the onset itself if steps == 0) from where the Dormand-Prince contact goes on.
    ctx: the `Context` of the run; ctx.guesses[0 / 1 / 2] holds the indentations of the last onset / regular /
    release step over their first guess.
    """
    tables, phases, phased, guesses, ws = ctx.tables, ctx.phases, ctx.phased, ctx.guesses, ctx.work
    h_ref = tables.h_ref
    nodes = NODE_DATA
    rows, S = ws.rows, ws.S
    F = rows[ROW.F, :NODES]
    Fs = rows[ROW.Fs, :S.shape[0]]
    par = cst.par
    lay = state_layout(cst.modes.size)
    s = NODES
    m = lay.acc
    Om = par.Omega
    kH = par.k_H
    sgn = 1.0 if wall == 0 else -1.0
    book = par.book > 0.0  # the energy bookkeeping's contact work (`sim.integration.exact`)
    ct = math.cos(Om * t)
    st = math.sin(Om * t)
    _, v = _active(Y, ct, st, wall, cst)
    if not v > 0.0:
        return FALLBACK, t, 0
    t_hertz = _HERTZ_TIME * (5.0 * par.m_a * v * v / (4.0 * kH)) ** 0.4 / v
    k = _ladder(min(_ONSET_FRACTION * t_hertz, _MAX_STEP_PERIODS * h_ref), h_ref, False)
    if k < 0 or t + 1.5 * t_hertz >= t_stop:
        return FALLBACK, t, 0
    kind = ONSET
    Ynew = rows[ROW.Ynew, :Y.size]
    steps = 0
    halvings = 0
    for _ in range(100):
        # a step (onset or regular) from the last accepted state; it is repeated at half the length if it
        # failed (Newton, a release inside, unresolved force) or ended too close to the release (its force
        # is then not smooth in the step's time), at most _MAX_HALVINGS times in a contact
        step = _step_table(tables, phases, phased, wall, kind, k, cst)
        h = _ladder_h(k, h_ref)
        R = 0.0
        ok = (_forward_step(step, Y, ct, st, wall, guesses[kind], ws, cst)
              and _resolution(nodes.tail, F, s) <= _RESOLUTION_TOL)
        if ok:
            _end_state(step, Y, Ynew, F, ct, st, wall)
            c1, s1 = _node_phase(step.ph, s, ct, st)
            c_e, cd_e = _active(Ynew, c1, s1, wall, cst)
            if c_e > 0.0:
                R = _time_to_release(c_e, cd_e, par.m_a, kH)
        if R < _CLEARANCE * h:
            k -= LADDER_PER_OCTAVE
            halvings += 1
            if k < 0 or halvings > _MAX_HALVINGS:
                return FALLBACK, t, steps
            continue
        if book:  # the accepted step's contact work (F still holds its nodal forces)
            _contact_work(step.tab, step.off, Y, Ynew, F, rows[ROW.pairs], rows[ROW.work])
        copy_into(Y, Ynew, 0, Y.size)
        t += h
        norm = 1.5 - 0.5 * (c1 * c1 + s1 * s1)  # keeps cos^2 + sin^2 = 1 to rounding
        ct = c1 * norm
        st = s1 * norm
        steps += 1
        if R <= _RELEASE_REACH * h:
            # the release step: its end is the release, its start t - d lies in the last step (series there)
            _series(Y, F, nodes.onset if kind == ONSET else nodes.regular, h, wall, cst, S, Fs)
            end = StepEnd(ct, st, h, c_e, cd_e)
            for _attempt in range(3):
                k = _ladder(R + 0.1 * h, h_ref, True)
                if k < 0:
                    return FALLBACK, t, steps
                step = _step_table(tables, phases, phased, wall, RELEASE, k, cst)
                h_k = _ladder_h(k, h_ref)
                status, d = _release_step(step, end, h_k - R, wall, guesses[2], ws, cst)
                if status == 1:
                    return FALLBACK, t, steps
                R = h_k - min(max(d, -0.3 * h), 0.6 * h)  # the release as found (or as far as the series reaches)
                if (status == 0 and 0.0 <= d <= 0.25 * h) or R > _RELEASE_REACH * h:
                    break
            if status == 0 and 0.0 <= d <= 0.25 * h and _resolution(nodes.tail, F, s) <= _RESOLUTION_TOL:
                if t - d + h_k >= t_stop:
                    return FALLBACK, t, steps
                # the state at the release step's start: the series, without the overlap's share of F_w
                Ys = rows[ROW.Ys]
                _series_at(S, d, Ys, m)
                cs, ss = rotate(ct, st, -Om * d)
                ore, oim = _overlap_fourier(Fs, d, ct, st, Om)
                copy_into(Ynew, Ys, 0, m)
                copy_into(Ynew, Y, m, Y.size)
                frow = lay.F_l if wall == 0 else lay.F_r
                Ynew[frow] -= sgn * ore
                Ynew[frow + 1] -= sgn * oim
                if book:
                    _overlap_work(S, Fs, d, wall, cst, Ynew)
                _end_state(step, Ynew, Y, F, cs, ss, wall)
                if book:
                    _contact_work(step.tab, step.off, Ynew, Y, F, rows[ROW.pairs], rows[ROW.work])
                return RELEASED, t - d + h_k, steps + 1
            # the contact lasts longer than predicted, or its end is not resolved: a regular step first
        k = _ladder(min(R / 1.6, _MAX_STEP_PERIODS * h_ref), h_ref, False)
        if k < 0 or t + 1.5 * R >= t_stop:
            return FALLBACK, t, steps
        kind = REGULAR
    return FALLBACK, t, steps


# ----------------------------------------------------------------------------------------------------------
# tables per system
# ----------------------------------------------------------------------------------------------------------
#: Tables of the most recently used systems (a few MB each). They depend on the modes, the wall values and
#: the sphere's mass only, so a whole sweep (and every point of a study with the same D) shares them.
_CACHE: OrderedDict[bytes, Tables] = OrderedDict()
_CACHE_SIZE = 4
#: The fields of the `sim.integration.flight.MODE` records the tables depend on.
_SYSTEM_FIELDS = ("sig", "wd", "w2", "phi_l", "phi_r")


def tables_for(modes: np.ndarray, m_a: float) -> Tables:
    """The `Tables` of the system with these mode records (`sim.integration.flight.MODE`) and sphere mass m_a (kg)."""
    key = np.stack([modes[name] for name in _SYSTEM_FIELDS]).tobytes() + np.float64(m_a).tobytes()
    tables = _CACHE.pop(key, None)
    if tables is None:
        off = table_layout(NODES, modes.size)
        h_ref = 2.0 * math.pi / math.sqrt(float(np.max(modes["w2"])))  # the period of the highest mode
        tables = Tables(tabs=np.zeros((2, 3, LADDER_SIZE, off.size)),
                        built=np.zeros((2, 3, LADDER_SIZE), dtype=np.bool_), off=off, h_ref=h_ref)
    _CACHE[key] = tables
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return tables


def context(cst: Constants) -> Context:
    """The `Context` for one run_step call of the system in `cst`: its tables, fresh first guesses, and room
    for the node phases of its Omega."""
    return Context(tables=tables_for(cst.modes, float(cst.par["m_a"])), guesses=first_guesses(NODE_DATA),
                   phases=np.zeros((3, LADDER_SIZE, 2, NODES + 1)), phased=np.zeros((3, LADDER_SIZE), dtype=np.bool_),
                   work=workspace(NODE_DATA, cst.modes.size))
