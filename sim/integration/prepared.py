"""The exact integrator (`sim.integration.exact`) prepared once for many runs of one excitation: the constants, the
free-flight grid, the scratch and the output buffers are built once and every run only calls the period loop.

`exact.run_step` builds all of them at every call: on the rig (9 modes) one period from phase 0 costs 0.21 ms
through `run_step`, of which the period loop is 0.06 ms and the preparation (`exact._prepare`, the `Run` tuple) the
rest. Shooting (`sim.orbits`) runs the same excitation from dozens of perturbed states per Newton step, so it
prepares once (`PreparedExact`) and pays 0.06 ms per run. The trajectory is the one of `run_step` bit for bit (same
kernel, same constants; tests/sim/orbits/test_orbit_checks.py compares them); no ledger, no impact log, no counters.
"""
from __future__ import annotations

import numpy as np

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.integration import collocation, dopri5, exact
from sim.integration.energy import integrator_output
from sim.integration.flight import NONFINITE, OK, OVERLAP, STALLED, STALLED_SEARCH
from sim.model.system import SystemArrays, check_run_step


class PreparedExact:
    """`exact.run_step` for many states at one excitation (Omega in rad/s, a_base in m, the system `sys`): each
    `advance(y)` runs y in place over `n_periods` periods from phase 0 and records the state `samples` times per
    period (Eqs. 3-9, Sect. 5; the contract of `sim.model.system`). Options as `exact.run_step` (rtol, grid,
    contacts)."""

    def __init__(self, n_periods: int, Omega: float, a_base: float, sys: SystemArrays, *, samples: int = 1,
                 rtol: float = exact.CONTACT_RTOL, grid_per_period: int = exact.GRID_PER_PERIOD,
                 contacts: str = "collocation") -> None:
        n = sys.omega.size
        self.record = np.empty((int(n_periods) * int(samples) + 1, 2 * n + 2))
        n_periods, Omega, a_base, _, samples = check_run_step(np.zeros(2 * n + 2), n_periods, Omega, a_base, sys,
                                                              self.record)
        if sys.slip_force > 0:
            raise SimulationInputError("dry friction (Appendix C) is in the ode3 integrator only; use --integrator ode3")
        if contacts not in ("collocation", "dopri5"):
            raise SimulationInputError(f"contacts must be 'collocation' or 'dopri5', got {contacts!r}")
        self._options = (int(grid_per_period), float(rtol), 0.5 / float(np.max(sys.omega)), samples)
        self._sys = sys
        cst, grid = exact._prepare(Omega, a_base, sys, *self._options[:3], 0.0, samples, book=False)
        work = exact._work(cst)
        self._out = integrator_output(n_periods, n, self.record, None)
        recorder = exact.Recorder(Y=np.zeros(work.Y.size), Ynew=np.zeros(work.Y.size),
                                  dp=dopri5.work(work.Y.size, np.zeros_like(work.counters), False))
        self._run = exact.Run(cst._replace(law=None), grid, self._out, work,
                              dopri5.work(work.Y.size, work.counters, False), collocation.context(cst),
                              contacts == "collocation" and sys.law.collocation, recorder)
        self._guesses = collocation.first_guesses(collocation.NODE_DATA)
        self._law = sys.law
        self.n_periods = n_periods
        self.size = 2 * n + 2

    def retarget(self, Omega: float, a_base: float) -> None:
        """Prepare for another excitation of the same system (Omega in rad/s, a_base in m): only the constants, the
        grid and the node phases are new (a quarter of a fresh preparation's cost)."""
        grid_per_period, rtol, h_max, samples = self._options
        cst, grid = exact._prepare(float(Omega), float(a_base), self._sys, grid_per_period, rtol, h_max, 0.0, samples,
                                   book=False)
        run = self._run
        colloc = run.colloc._replace(phased=np.zeros_like(run.colloc.phased))
        self._run = run._replace(cst=cst._replace(law=None), grid=grid, colloc=colloc)

    def advance(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance the contiguous float64 state y in place; returns copies of (amplitudes |c_1| per period (m),
        contact onsets per period, the recorded states (n_periods * samples + 1, len(y))). SimulationDiverged as
        `exact.run_step`."""
        if y.dtype != np.float64 or y.shape != (self.size,) or not y.flags.c_contiguous:
            raise SimulationInputError(f"state y must be a contiguous float64 array of length {self.size}")
        run = self._run
        # what a run carries from contact to contact starts afresh, as in `exact.run_step`: the collocation's first
        # guesses and the Dormand-Prince step-length laws (else a run would depend on the runs before it)
        run.colloc.guesses[:] = self._guesses
        run.dp.memo[:] = 0.0
        run.recorder.dp.memo[:] = 0.0
        status, period = exact._advance(y, run, self._law)
        if status != OK:
            why = {NONFINITE: "non-finite state", OVERLAP: "an indentation larger than the clearance",
                   STALLED: "a contact phase that did not progress",
                   STALLED_SEARCH: "a contact search that did not progress"}[status]
            raise SimulationDiverged(f"exact integrator failed in period {period + 1} of this step ({why}); check k_H, "
                                     "g and the level")
        return self._out.amplitudes.copy(), self._out.impacts.copy(), self.record.copy()
