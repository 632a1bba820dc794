"""Contacts by exponential Gauss collocation (sim.integration.collocation): the tables against a finer quadrature,
the backward series against an independent forward step, the observed order of a step, and whole impacts
against scipy's DOP853 (rtol 1e-12, restarted at the contact events)."""
import math

import numpy as np
import pytest

from sim.integration import collocation as C
from sim.integration import exact
from sim.integration.flight import state_layout
from sim.common.errors import SimulationInputError
from sim.model.system import Impactor, system_arrays

from sim.integration.references import cantilever_like_model, reference_run

N9 = 9
OMEGA = 2 * math.pi * 1000.0


@pytest.fixture(scope="module")
def beam():
    """The 9-mode cantilever-like system and its kernel constants (sim.integration.flight.Constants) at 1 kHz excitation."""
    sys = system_arrays(cantilever_like_model(), Impactor())
    cst, _ = exact._prepare(OMEGA, 2e-5, sys, 48, exact.CONTACT_RTOL, 0.5 / sys.omega.max())
    return sys, cst


def _table(cst, kind, h, wall=0, nodes=None, quadrature=C.TABLE_QUADRATURE):
    nodes = nodes or C.gauss_nodes()
    if quadrature != C.TABLE_QUADRATURE:
        nodes = C.gauss_nodes(nodes.u.size, nodes.onset.shape[0], quadrature)
    off = C.table_layout(nodes.u.size, N9)
    tab = np.zeros(off.size)
    C._build(tab, nodes, off, kind, h, wall, cst)
    return tab, off


def _phases(tab, off, s, Omega=OMEGA):
    """cos, sin(Omega tau) at the nodes and the end of a table (what `C._step_table` caches per run)."""
    tau = tab[off.TAU:off.TAU + s + 1]
    return np.vstack([np.cos(Omega * tau), np.sin(Omega * tau)])


@pytest.mark.parametrize("kind", [C.ONSET, C.REGULAR, C.RELEASE])
def test_tables_are_converged_in_their_quadrature(beam, kind):
    """Every block of a table (a 40 us step, the highest mode turning by 5 rad) agrees with the same table
    built with twice the quadrature points to 1e-13 of the block's largest entry."""
    _, cst = beam
    coarse, off = _table(cst, kind, 40e-6)
    fine, _ = _table(cst, kind, 40e-6, quadrature=2 * C.TABLE_QUADRATURE)
    for block in range(len(C.TABLE_BLOCKS)):
        a, b = coarse[off[block]:off[block + 1]], fine[off[block]:off[block + 1]]
        assert np.max(np.abs(a - b)) <= 1e-13 * np.max(np.abs(b))


def _state_in_contact(sys):
    """A deviation state with the modes ringing and the sphere moving (the steps below do not solve for F)."""
    rng = np.random.default_rng(3)
    Y = np.zeros(state_layout(N9).size)
    Y[:N9] = 1e-7 * rng.standard_normal(N9) / np.arange(1, N9 + 1)
    Y[N9:2 * N9] = 1e-7 * rng.standard_normal(N9) * sys.omega / np.arange(1, N9 + 1)
    Y[2 * N9] = sys.phi_l @ Y[:N9] - sys.g
    Y[2 * N9 + 1] = sys.phi_l @ Y[N9:2 * N9] - 0.3
    return Y


@pytest.mark.parametrize("kind, M", [(C.REGULAR, "regular"), (C.ONSET, "onset")])
def test_backward_series_is_the_step_solution(beam, kind, M):
    """The Taylor series that carries the state back from a step's end (into which the release step starts)
    equals an independent forward step over the first 75 % (or 85 %) with the same force polynomial."""
    sys, cst = beam
    nodes = C.gauss_nodes()
    h = 30e-6
    tab, off = _table(cst, kind, h)
    Y = _state_in_contact(sys)
    F = 40.0 + 30.0 * np.sin(3.0 * nodes.u)  # nodal forces (N): any smooth pulse piece
    Yend = np.empty_like(Y)
    C._end_state(C.Step(tab, _phases(tab, off, nodes.u.size), off), Y, Yend, F, 1.0, 0.0, 0)
    S = np.zeros((C.SERIES_ORDER, 2 * N9 + 2))
    Fs = np.zeros(C.SERIES_ORDER)
    C._series(Yend, F, getattr(nodes, M), h, 0, cst, S, Fs)
    for fraction in (0.75, 0.85):
        # the same force polynomial on the part [0, fraction h] of the step: the map w(u) = u or u^2 of the
        # shorter step reaches w = fraction at u' = fraction (regular) or sqrt(fraction) (onset)
        scale = fraction if kind == C.REGULAR else math.sqrt(fraction)
        part, _ = _table(cst, kind, fraction * h)
        lag = np.empty((nodes.u.size, nodes.u.size))
        for row, v in zip(lag, nodes.u):
            C._lagrange(nodes.u, nodes.wb, scale * v, row)
        Ypart = np.empty_like(Y)
        C._end_state(C.Step(part, _phases(part, off, nodes.u.size), off), Y, Ypart, lag @ F, 1.0, 0.0, 0)
        Yb = np.empty(2 * N9 + 2)
        C._series_at(S, (1.0 - fraction) * h, Yb, 2 * N9 + 2)
        scale_state = np.concatenate([np.full(N9, np.abs(Y[:N9]).max()), np.full(N9, np.abs(Y[N9:2 * N9]).max()),
                                      [abs(Y[2 * N9]), abs(Y[2 * N9 + 1])]])
        assert np.max(np.abs(Yb - Ypart[:2 * N9 + 2]) / scale_state) < 1e-10


def test_observed_order_of_a_collocation_step(beam):
    """Regular steps through a closed contact against DOP853: with s = 4 nodes the log-log fit of the
    sphere's velocity error against h has at least the order of Gauss quadrature of the impulse (2 s = 8;
    measured 9.2)."""
    sys, _ = beam
    cst, _ = exact._prepare(OMEGA, 0.0, sys, 48, exact.CONTACT_RTOL, 0.5 / sys.omega.max())
    nodes = C.gauss_nodes(4, C.SERIES_ORDER)
    y0 = np.zeros(2 * N9 + 2)
    y0[2 * N9] = -sys.g - 5e-6
    y0[2 * N9 + 1] = -0.3
    span = 32e-6
    y_ref, onsets, releases, _ = reference_run(y0, span, OMEGA, 0.0, sys)
    assert releases.size == 0
    steps, errors = [], []
    ws = C.workspace(nodes, N9)
    for n_steps in (2, 3, 4, 6):
        h = span / n_steps
        tab, off = _table(cst, C.REGULAR, h, nodes=nodes)
        Y = np.zeros(state_layout(N9).size)
        Y[:2 * N9 + 2] = y0
        ratio = np.ones(4)
        step = C.Step(tab, _phases(tab, off, 4, Omega=cst.par["Omega"]), off)
        for _ in range(n_steps):
            assert C._forward_step(step, Y, 1.0, 0.0, 0, ratio, ws, cst)
            Ynew = np.empty_like(Y)
            C._end_state(step, Y, Ynew, ws.rows[C.ROW.F, :4].copy(), 1.0, 0.0, 0)
            Y = Ynew
        steps.append(h)
        errors.append(abs(Y[2 * N9 + 1] - y_ref[2 * N9 + 1]) / 0.3)
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    print(f"\ncollocation step (s = 4): h {['%.1e' % h for h in steps]} s, errors {['%.1e' % e for e in errors]}, "
          f"order {order:.2f}")
    assert 7.5 < order < 10.5


def _impact(sys, v0, wall, a_base):
    """y at phase 0 with the sphere 1 um from `wall`, closing at v0; beam at rest."""
    sgn = 1.0 if wall == 0 else -1.0
    y0 = np.zeros(2 * N9 + 2)
    y0[2 * N9] = -sgn * (sys.g - 1e-6)
    y0[2 * N9 + 1] = -sgn * v0
    return y0


@pytest.mark.parametrize("wall", [0, 1])
@pytest.mark.parametrize("v0", [0.01, 0.1, 0.5, 1.0])
def test_whole_impacts_match_scipy_to_1e_9(beam, v0, wall):
    """One impact at either wall under base excitation, entirely by collocation (no fall-back): the rebound
    velocity and the state after a whole period agree with DOP853 to 1e-9 of v0."""
    sys, *_ = beam
    a_base = 1e-8  # base acceleration 0.4 m/s^2: the slowest sphere still meets the wall within 100 us
    y0 = _impact(sys, v0, wall, a_base)
    y_ref, onsets, releases, _ = reference_run(y0, 2 * math.pi / OMEGA, OMEGA, a_base, sys)
    assert onsets.size == 1 and releases.size == 1
    y = y0.copy()
    stats = {}
    exact.run_step(y, 1, OMEGA, a_base, sys, stats=stats)
    assert stats["contacts"] == 1 and stats["collocation_fallbacks"] == 0 and stats["collocation_steps"] >= 2
    assert abs(y[2 * N9 + 1] - y_ref[2 * N9 + 1]) < 1e-9 * v0
    assert np.max(np.abs(y[N9:2 * N9] - y_ref[N9:2 * N9])) < 1e-9 * v0


def test_dopri5_contacts_on_request_and_bad_choice(beam):
    """contacts="dopri5" integrates every contact with the Dormand-Prince pair; anything else is one line."""
    sys, *_ = beam
    y = _impact(sys, 0.5, 0, 0.0)
    stats = {}
    exact.run_step(y, 1, OMEGA, 0.0, sys, contacts="dopri5", rtol=1e-7, stats=stats)
    assert stats["contacts"] == 1 and stats["collocation_steps"] == 0 and stats["contact_steps"] > 10
    with pytest.raises(SimulationInputError, match="contacts must be"):
        exact.run_step(y, 1, OMEGA, 0.0, sys, contacts="gauss")


def test_tables_are_shared_by_systems_with_the_same_modes(beam):
    """The ladder of tables is built once per system (modes, walls, sphere mass), whatever the excitation."""
    sys, cst = beam
    other, _ = exact._prepare(2 * OMEGA, 1e-4, sys, 48, exact.CONTACT_RTOL, 0.5 / sys.omega.max())
    modes, other = cst.modes, other.modes
    assert C.tables_for(modes, sys.m_a) is C.tables_for(other, sys.m_a)
    assert C.tables_for(modes, sys.m_a) is not C.tables_for(modes, 2 * sys.m_a)
