"""Mechanical energy of the coupled system (Sect. 5.5): the stored energy, and the `Ledger` in which the
integrators book the work of the base excitation, the dissipation and the impacts of a run_step call.

Without base excitation the relative coordinates of `sim.model.system` are absolute, and with no damping the
total energy

    E = sum_j (s_j'^2 + w_j^2 s_j^2) / 2  +  m_a u_a'^2 / 2  +  (2/5) k_H (<delta_l>^2.5 + <-delta_r>^2.5)

(modes with mass-normalised shapes, sphere, Hertz potential of Eq. 4; for another law its `potential`,
`sim.model.contact_law`) is conserved through impacts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sim.integration.flight import IMPACT, LEDGER, Output
from sim.model.system import SystemArrays


def energy_parts(states: np.ndarray, sys: SystemArrays) -> dict[str, np.ndarray]:
    """Energies in J of each state row y = [s, s', u_a, u_a']: 'modes', 'sphere', 'contact' (the potential of
    the contact law sys.law) and 'total'."""
    y = np.atleast_2d(np.asarray(states, dtype=float))
    n = sys.omega.size
    s, v, u, w = y[:, :n], y[:, n:2 * n], y[:, 2 * n], y[:, 2 * n + 1]
    modes = 0.5 * np.sum(v**2 + (sys.omega * s) ** 2, axis=1)
    sphere = 0.5 * sys.m_a * w**2
    delta_l = s @ sys.phi_l - u - sys.g
    delta_r = s @ sys.phi_r - u + sys.g
    contact = sys.law.potential(delta_l, sys.k_H) + sys.law.potential(-delta_r, sys.k_H)
    return {"modes": modes, "sphere": sphere, "contact": contact, "total": modes + sphere + contact}


def stored_energy(y: np.ndarray, sys: SystemArrays) -> float:
    """The stored mechanical energy E (J) of the state y = [s, s', u_a, u_a'] in the frame moving with the base
    (Eq. 2): modes, sphere and Hertz potential (`energy_parts`); its rate is the base excitation's power minus
    the modal damping (and contact damping) dissipation (Sect. 5.5); with friction the Jenkins spring's energy
    (Appendix C) is included."""
    total = float(energy_parts(y, sys)["total"][0])
    if sys.slip_force > 0:  # the friction spring's k_t w^2 / 2 (Appendix C), w = u_a - phi_f^T s - z
        n = sys.omega.size
        w = float(y[2 * n] - sys.phi_f @ y[:n] - sys.slider[0])
        total += 0.5 * sys.k_t * w * w
    return total


#: One impact (onset to release) of a run_step call (Appendix D, Sect. 5.5): the fields of
#: `sim.integration.flight.ImpactColumns` with their units there (wall 0 = left, 1 = right; period counted from 0 in the call).
IMPACT_DTYPE = np.dtype([(name, np.float64) for name in IMPACT._fields])
#: Impact log rows per excitation period reserved by `Ledger` unless given (the rig: 1-5 impacts per period in
#: sweeps); more impacts are counted in `Ledger.dropped`, not recorded.
IMPACTS_PER_PERIOD_RESERVED = 16


@dataclass
class Ledger:
    """Energy bookkeeping and impacts of one run_step call (Sect. 5.5, Appendix D), filled by the integrator:
    pass ``ledger=Ledger()`` to `sim.integration.exact.run_step` or `sim.integration.ode3.run_step`.

    Energies are in the frame moving with the base (Eq. 2), where the base's inertia load -q_base'' drives the
    modes and the sphere; over a steady state its average equals the work done in the absolute frame.

    capacity: impact rows reserved (None: IMPACTS_PER_PERIOD_RESERVED per period + that number).
    After the call: `periods` (n_periods, LEDGER.modes + n_modes): the per-period columns of
    `sim.integration.flight.LEDGER` (input work, contact dissipation, c_1 of tip and walls, dissipation per mode, J and m);
    `impacts`: structured array (IMPACT_DTYPE) of the impacts in onset order; `dropped`: impacts beyond the
    capacity (counted, not recorded; 0 unless the capacity was too small); `stored_start`, `stored_end`: the
    stored energy (J) at the call's start and end; Omega (rad/s); `damping`: 2 D_j omega_j of each mode (1/s).
    """

    capacity: int | None = None
    periods: np.ndarray = field(default_factory=lambda: np.zeros((0, LEDGER.modes)))
    impacts: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=IMPACT_DTYPE))
    dropped: int = 0
    stored_start: float = math.nan
    stored_end: float = math.nan
    Omega: float = math.nan
    damping: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def log_rows(self, n_periods: int) -> int:
        """Rows of the impact log for a call of n_periods."""
        if self.capacity is None:
            return IMPACTS_PER_PERIOD_RESERVED * (n_periods + 1)
        return max(0, int(self.capacity))

    def fill(self, periods: np.ndarray, log: np.ndarray, count: int, stored_start: float, stored_end: float,
             Omega: float, sys: SystemArrays) -> None:
        """Store what the integrator wrote (its `Output.ledger`, `Output.log` and the impact count)."""
        self.damping = 2.0 * np.asarray(sys.D) * np.asarray(sys.omega)
        self.periods = periods
        kept = min(count, log.shape[0])
        self.impacts = np.ascontiguousarray(log[:kept]).view(IMPACT_DTYPE).reshape(-1)
        self.dropped = count - kept
        self.stored_start, self.stored_end, self.Omega = stored_start, stored_end, Omega

    @property
    def input(self) -> np.ndarray:
        """Work done by the base excitation per period (J)."""
        return self.periods[:, LEDGER.input]

    @property
    def contact(self) -> np.ndarray:
        """Energy dissipated in the contacts per period (J; zero for the elastic law of Eq. 4)."""
        return self.periods[:, LEDGER.contact]

    @property
    def friction(self) -> np.ndarray:
        """Energy dissipated by dry friction at the cavity floor per period (J; Appendix C, zero without)."""
        return self.periods[:, LEDGER.friction]

    @property
    def dissipation(self) -> np.ndarray:
        """Energy dissipated by each mode's modal damping per period, (n_periods, n_modes) (J)."""
        return self.periods[:, LEDGER.modes:]

    def fundamental(self, where: str = "tip") -> np.ndarray:
        """Complex c_1 (m) per period of the tip ("tip") or of a wall ("left", "right"), relative to the base:
        the fundamental harmonic is Re(c_1 e^{i Omega t}) (Sect. 5)."""
        if where not in ("tip", "left", "right"):
            raise ValueError(f"where must be 'tip', 'left' or 'right', got {where!r}")
        re = getattr(LEDGER, f"{where}_re")
        return self.periods[:, re] + 1j * self.periods[:, re + 1]

    @property
    def period(self) -> float:
        """The excitation period T = 2 pi / Omega (s)."""
        return 2.0 * math.pi / self.Omega

    @property
    def mean_kinetic(self) -> np.ndarray:
        """Time average of each mode's kinetic energy s_j'^2 / 2 over the call (J): its dissipation over
        2 D_j omega_j (exact with the bookkeeping, no sampling)."""
        seconds = self.periods.shape[0] * self.period
        return self.dissipation.sum(axis=0) / self.damping / (2.0 * seconds)

    @property
    def balance_error(self) -> float:
        """(input - dissipated - (E_end - E_start)) / input over the call (-)."""
        total_in = float(self.input.sum())
        residual = total_in - float(self.dissipation.sum()) - float(self.contact.sum()) - float(self.friction.sum()) - (
            self.stored_end - self.stored_start)
        return residual / total_in if total_in != 0.0 else math.nan


def integrator_output(n_periods: int, n_modes: int, record: np.ndarray, ledger: Ledger | None) -> Output:
    """The `sim.integration.flight.Output` of a run_step call of n_periods: the impact log sized by the ledger (none without)."""
    rows = ledger.log_rows(n_periods) if ledger is not None else 0
    return Output(amplitudes=np.empty(n_periods), impacts=np.zeros(n_periods, dtype=np.int64), record=record,
                  ledger=np.zeros((n_periods, LEDGER.modes + n_modes)), log=np.empty((rows, len(IMPACT))),
                  log_count=np.zeros(1, dtype=np.int64))
