r"""Periodic orbits of the full model by shooting on the time integrator (seed paper Eqs. 3-7, 10; Sect. 5).

The map
-------
The state y = [s, s', u_a, u_a'] at excitation phase 0 (the integrators' contract, `sim.model.system`) is mapped
by `ShootingMap` to the state after k excitation periods, P_k(y) (the Poincare map with the phase fixed by the
excitation), and, from the same run, to the state at phase k T / 2 (`half`: a record row of the integrator, an
observer that does not change the trajectory). A kT orbit is a fixed point P_k(y) = y.

Symmetry. With phi_l = phi_r (a beam model) the system is invariant under the mirror (s, u_a) -> (-s, -u_a)
with t -> t + T/2 (the base motion changes sign, the walls exchange roles). For odd k the half map
G(y) = -F_{0 -> kT/2}(y) then satisfies P_k = G o G: a symmetric orbit (y(t + kT/2) = -y(t)) is a fixed point of
G, and its multipliers are mu = lambda^2 with lambda those of DG. A symmetric orbit is solved as G(y) = y:
that system stays regular where lambda passes -1 (symmetry breaking: mu passes +1, a pitchfork of P_k that
would make P_k(y) = y singular), and lambda tells symmetry breaking (-1) from a fold (+1)
(`sim.orbits.bifurcations`).

The Jacobian: finite differences, and why
-----------------------------------------
The exact integrator's flight is closed-form and its contacts are taken by collocation or Dormand-Prince with
error control, so there is no variational equation to integrate alongside it without writing the contacts' kernels
twice. The flow is C^1 across contact onset and release for both contact laws of the registry: Hertz's force
k delta^1.5 vanishes with zero slope at delta = 0, and the damped law of Eq. 10 adds c delta^0.25 delta', which
vanishes at onset (delta = 0) and at the turning point (delta' = 0) where it switches off; the vector field is
continuous across every switching surface, so the saltation matrix is the identity (no jump term in the
monodromy matrix), although the damped law's force is not Lipschitz at onset (delta^-0.75 in its derivative,
integrable). The monodromy matrix is therefore taken by central differences of the map on every scaled state
component (`OrbitSetting.scales`: g at the walls, times omega_j for velocities), step FD_STEP; both the end state
and the half state come from the same runs, so one Jacobian gives DP_k and DG. Accuracy against DOP853 on the
variational equations (tests/sim/orbits/test_orbit_jacobian.py), largest error over the largest entry, at 7.4 / eta
0.95: the rig with its higher modes damped 100-fold (a stable two-impact orbit) 2e-9 (half map) and 2e-8 (whole
period), multipliers 1e-8, at steps 1e-6 and 1e-7; the nominal rig (its unstable orbit, |mu| = 11.8), whose map
over a whole period has huge third derivatives: half map 7e-8 at both steps, whole period 4e-4 at 1e-6 and 4e-6 at
1e-7 (multipliers 4e-5 and 6e-7), hence FD_STEP = 1e-7; below it the map's noise (~1e-12 g) takes over. Hosts
with gentler maps want a larger step: on the rig's first mode alone the map's noise (~3e-13 g, where the contact's
number of collocation steps changes) puts 3e-6 into the Jacobian at 1e-7 and 2e-9 at 1e-4, with no truncation error
to speak of. `fd_step` therefore picks the step of each branch (`sim.orbits.continuation`) from FD_STEPS: central
differences at steps a decade apart differ by about a h^2 + 9 n / h (truncation a h^2, noise n / h), and the step
with the smallest difference to the next one is taken. That matters where the multipliers are ill-conditioned: where
a complex pair meets on the real axis near the unit circle, an error e in the Jacobian moves them by ~sqrt(e).

Newton's method (`solve_orbit`): the residual in scaled units, the step by least squares (the linear orbit's
sphere is neutral: its position is free, `sim.orbits.starts`), damped by backtracking on the residual's largest
component; a trial state that makes the integrator fail counts as a worse residual. Converged when the
residual is below TOLERANCE (in units of g: 1e-9 g ~ 6e-13 m), or when it stalls below NOISE_FLOOR.

Why the map is hard (measured on the rig at a_base/a_base* = 7.4): between impacts the higher modes ring (mode
9's decay over half a period is only exp(-0.55)), and the wall velocity a sphere meets depends on its arrival time
through that ringing, at omega_9 ~ 1.2e5 rad/s. A shift of the arrival by dt changes the rebound by
~ omega_j A_j dt, so the symmetric two-impact orbit's half map has multipliers of order -50 at the nominal damping
(it is 0.99 with the higher modes' damping raised 50-fold), and its second derivatives are large: Newton's
method converges only from within ~1e-3 g of the orbit. `sim.orbits.starts` therefore reaches the nominal host by
continuation in the higher modes' damping from a host where they ring out.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from sim.common.errors import SimulationDiverged, SimulationInputError
from sim.integration.energy import Ledger
from sim.integration.integrators import get_integrator
from sim.integration.prepared import PreparedExact
from sim.model.system import SystemArrays
from sim.orbits.setting import OrbitSetting

#: Newton's convergence tolerance on the residual's largest scaled component (units of g at the walls).
TOLERANCE = 1e-9
#: The map's own noise floor (units of g): the exact integrator's located contacts and error-controlled steps make
#: the computed map jump by ~1e-10 g where a step count changes, amplified by the orbit's multipliers; Newton's
#: method that stalls (no descent) below NOISE_FLOOR has converged as far as the map allows (measured on the rig:
#: the full map stalls at 2e-8 next to a symmetry-breaking point, the half map reaches 5e-10).
NOISE_FLOOR = 1e-7
#: Finite-difference step of the monodromy matrix in scaled units (module docstring: accuracy), and of the forward
#: differences of Newton's iterations: the maps' second derivatives reach ~4e3 (scaled) on the rig, so a forward
#: step of 1e-6 errs by ~2e-3 per entry, which next to a branch point (smallest singular value ~1e-3) misleads
#: Newton's method; 1e-8 errs by ~2e-5 (plus the map's noise, ~1e-12 / 1e-8).
FD_STEP = 1e-7
FORWARD_STEP = 1e-8
#: The steps `fd_step` chooses from (module docstring).
FD_STEPS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
#: Differences whose two runs hit the walls a different number of times straddle a grazing: the step shrinks
#: tenfold down to this, then the difference is taken one-sided, on the side of the orbit's own impacts.
SMALLEST_STEP = 1e-10
#: Most Newton iterations of `solve_orbit`.
MAX_ITERATIONS = 40
#: Largest period multiple k an orbit may have (a kT orbit's map multiplies the unstable multipliers k-fold).
MAX_PERIOD_MULTIPLE = 8
#: An impact is significant when its impulse is at least this share of the orbit's largest (as the stepped
#: sine's measure, `sim.stepped_sine.measures.SIGNIFICANT_IMPULSE_FRACTION`); lower-case in the pattern otherwise.
SIGNIFICANT_SHARE = 0.1


#: Samples per period of the highest mode with which `ShootingMap.clearance` looks for the gap's minima.
GAP_SAMPLES = 12


def flight_gaps(y: np.ndarray, t0: float, Omega: float, a_base: float, sys: SystemArrays,
                tau: float = 0.0) -> tuple[float, float]:
    """(left, right) gaps between the sphere and the walls (m; > 0 apart, the closing functions of Eqs. 4-6 with
    the sign turned) at time t0 + tau of the excitation period from the state y at phase time t0 (s), the flight
    in between free (no contact): each mode the harmonic particular solution S_j (Eq. 7) plus its damped homogeneous
    deviation, the sphere at constant absolute velocity (u_a = z - a_base cos(Omega t)). The closed form the exact
    integrator's free flight takes (`sim.integration.exact`), written here again on purpose: the grazing condition
    is then checked by code that is not the integrator's."""
    n = sys.omega.size
    w, D = sys.omega, sys.D
    S = sys.gamma * a_base * Omega**2 / (w**2 - Omega**2 + 2j * D * w * Omega)
    e0 = np.exp(1j * Omega * t0)
    x0 = y[:n] - np.real(S * e0)
    v0 = y[n:2 * n] - np.real(1j * Omega * S * e0)
    sigma = D * w
    wd = w * np.sqrt(1.0 - D**2)
    x = np.exp(-sigma * tau) * (x0 * np.cos(wd * tau) + (v0 + sigma * x0) / wd * np.sin(wd * tau))
    s = x + np.real(S * e0 * np.exp(1j * Omega * tau))
    z0 = y[2 * n] + a_base * math.cos(Omega * t0)
    zd = y[2 * n + 1] - a_base * Omega * math.sin(Omega * t0)
    u = z0 + zd * tau - a_base * math.cos(Omega * (t0 + tau))
    return float(sys.g + u - sys.phi_l @ s), float(sys.phi_r @ s - u + sys.g)


class OrbitNotConverged(SimulationDiverged):
    """Newton's method did not reach a periodic orbit from the start given (exit code 3 on the command line);
    `state` and `residual`: its last iterate (SI) and that iterate's residual (units of g), when it got that far."""

    def __init__(self, message: str, state: np.ndarray | None = None, residual: float = math.nan) -> None:
        super().__init__(message)
        self.state = state
        self.residual = residual


class MapValue(NamedTuple):
    """One evaluation of the k-period map from y: the state after k periods (`end`) and at k T/2 (`half`), per
    period |c_1| of the tip (m, Sect. 5) and the contact onsets."""

    end: np.ndarray
    half: np.ndarray
    amplitudes: np.ndarray
    impacts: np.ndarray


class ShootingMap:
    """The k-period map P_k and the half map of one `OrbitSetting` on its integrator (module docstring), with its
    scaled residual and finite-difference Jacobian. `evaluations` counts the integrator runs of this map, `runs`
    (of the class) those of every map in the process: the work budget of `sim.orbits.response`. system: the
    setting's `SystemArrays` when the caller has them (`OrbitSetting.system`)."""

    runs = 0

    def __init__(self, setting: OrbitSetting, k: int = 1, *, system: SystemArrays | None = None) -> None:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= MAX_PERIOD_MULTIPLE:
            raise SimulationInputError(f"orbits: the period multiple k must be an integer in 1..{MAX_PERIOD_MULTIPLE}, "
                                       f"got {k!r}")
        self.setting = setting
        self.k = int(k)
        self.sys: SystemArrays = setting.system() if system is None else system
        self.Omega = setting.Omega
        self.a_base = setting.a_base
        self.scale = setting.scales()
        self._run_step = get_integrator(setting.integrator, dt_scale=setting.dt_scale if setting.integrator == "ode3"
                                        else None)
        self._prepared = (PreparedExact(self.k, self.Omega, self.a_base, self.sys, samples=2)
                          if setting.integrator == "exact" else None)
        self.evaluations = 0
        self.fd_step = FD_STEP
        self.shrunk = False  # the last Jacobian's differences shrank at a grazing (`jacobian`)

    @property
    def size(self) -> int:
        """Length of the state (2 n_modes + 2)."""
        return self.scale.size

    def retarget(self, setting: OrbitSetting) -> None:
        """Move the map to another excitation (eta, level) of the same system: SimulationInputError if anything but
        the excitation differs. Cheaper than a new map (`sim.integration.prepared.PreparedExact.retarget`)."""
        if (setting.model is not self.setting.model or setting.impactor != self.setting.impactor
                or setting.higher_damping != self.setting.higher_damping or setting.integrator != self.setting.integrator):
            raise SimulationInputError("orbits: retarget changes the excitation only; build a new map for another system")
        self.setting = setting
        self.Omega = setting.Omega
        self.a_base = setting.a_base
        if self._prepared is not None:
            self._prepared.retarget(self.Omega, self.a_base)

    def __call__(self, y: np.ndarray) -> MapValue:
        """Run the integrator from y (phase 0) over k periods; SimulationDiverged if it fails."""
        k = self.k
        state = np.array(y, dtype=np.float64)
        self.evaluations += 1
        ShootingMap.runs += 1
        if self._prepared is not None:
            amplitudes, impacts, record = self._prepared.advance(state)
            return MapValue(state, record[k], amplitudes, impacts)
        record = np.empty((2 * k + 1, self.size))
        amplitudes, impacts = self._run_step(state, k, self.Omega, self.a_base, self.sys, record)
        return MapValue(state, record[k].copy(), amplitudes, impacts)

    def residual(self, y: np.ndarray, symmetric: bool, value: MapValue | None = None) -> tuple[np.ndarray, MapValue]:
        """(scaled residual, the map's value): G(y) - y for a symmetric orbit (G = -half), P_k(y) - y otherwise."""
        value = self(y) if value is None else value
        image = -value.half if symmetric else value.end
        return (image - y) / self.scale, value

    def jacobian(self, y: np.ndarray, step: float | None = None, base: MapValue | None = None, *,
                 one_side: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(DP_k, DF_half) in scaled variables, each (size, size): by central differences at `step` (default the
        map's `fd_step`; module docstring), or by forward differences from `base` = the map's value at y when given
        (half the runs, error O(step) instead of O(step^2): for Newton's iterations, not for multipliers). With
        `one_side` (for multipliers), a difference whose runs hit the walls a different number of times than y's
        straddles a grazing: its step shrinks tenfold at a time (to SMALLEST_STEP, then one-sided, on the side of y's
        own impacts), and `shrunk` says so afterwards: such a Jacobian is that of one side of the grazing, and less
        accurate (the map's noise over a small step). Newton's iterations far from an orbit want the plain
        differences (one_side False): there the steps would shrink to noise for nothing."""
        step = self.fd_step if step is None else step
        n = self.size
        end = np.empty((n, n))
        half = np.empty((n, n))
        at_y = (base if base is not None else self(y)) if one_side else None  # whose impacts both runs must have
        self.shrunk = False
        for i in range(n):
            h = FORWARD_STEP if base is not None else step
            while True:
                delta = np.zeros(n)
                delta[i] = h * self.scale[i]
                plus = self(y + delta)
                minus = self(y - delta) if base is None else base
                if (at_y is None or np.array_equal(plus.impacts, at_y.impacts)
                        and np.array_equal(minus.impacts, at_y.impacts) or h <= SMALLEST_STEP):
                    break
                h /= 10.0  # the differences straddle a grazing: closer to y, on one side of it
                self.shrunk = True
            if at_y is None or np.array_equal(plus.impacts, at_y.impacts) and np.array_equal(minus.impacts,
                                                                                          at_y.impacts):
                width = h if base is not None else 2.0 * h
                end[:, i] = (plus.end - minus.end) / width / self.scale
                half[:, i] = (plus.half - minus.half) / width / self.scale
                continue
            # at a grazing: one-sided, on the side of y's own impacts
            sign, same = (1.0, plus) if np.array_equal(plus.impacts, at_y.impacts) else (-1.0, minus)
            end[:, i] = sign * (same.end - at_y.end) / h / self.scale
            half[:, i] = sign * (same.half - at_y.half) / h / self.scale
        return end, half

    def pattern(self, y: np.ndarray) -> tuple[str, float]:
        """(impact pattern, significant impacts per period) of the orbit through y (`impact_pattern`)."""
        return impact_pattern(self, y)

    def clearance(self, y: np.ndarray) -> float:
        """The smallest gap between the sphere and a wall at a local minimum of the gap in free flight over the k
        periods from y, in units of g (inf when the gap has no such minimum): where it reaches 0 an impact appears,
        the grazing condition (`sim.orbits.bifurcations`). The samples of a recorded run (GAP_SAMPLES per period of
        the highest mode at least) find the minima; each is then refined on the closed-form free flight
        (`flight_gaps`: no integrator involved, to 1e-15 g), so the value is exact to rounding."""
        from scipy.optimize import minimize_scalar

        setting, sys = self.setting, self.sys
        ratio = float(np.max(sys.omega)) / self.Omega
        M = int(min(2**14, max(256, 2 ** math.ceil(math.log2(GAP_SAMPLES * ratio)))))
        record = np.empty((self.k * M + 1, self.size))
        state = np.array(y, dtype=np.float64)
        self._run_step(state, self.k, self.Omega, self.a_base, sys, record)
        self.evaluations += 1
        dt = setting.period / M
        best = math.inf
        n = sys.omega.size
        s, u = record[:, :n], record[:, 2 * n]
        for wall, gap in enumerate((sys.g + u - s @ sys.phi_l, s @ sys.phi_r - u + sys.g)):  # as `flight_gaps`
            inner = np.flatnonzero((gap[1:-1] > 0) & (gap[1:-1] <= gap[:-2]) & (gap[1:-1] <= gap[2:])
                                   & (gap[:-2] > 0) & (gap[2:] > 0)) + 1
            for i in inner[np.argsort(gap[inner])[:3]]:  # the three lowest minima: the sampled order may be off
                t0 = (i - 1) * dt

                def at(tau: float, row: np.ndarray = record[i - 1], t0: float = t0) -> float:
                    return flight_gaps(row, t0, self.Omega, self.a_base, sys, tau)[wall]

                found = minimize_scalar(at, bounds=(0.0, 2.0 * dt), method="bounded",
                                        options={"xatol": 1e-12 * dt})
                best = min(best, float(found.fun) / sys.g, float(gap[i]) / sys.g)
        return best

    def safe_residual(self, y: np.ndarray, symmetric: bool) -> tuple[float, np.ndarray | None, MapValue | None]:
        """(largest scaled residual component, residual, value); inf and None where the integrator fails."""
        try:
            r, value = self.residual(y, symmetric)
        except SimulationDiverged:
            return math.inf, None, None
        norm = float(np.max(np.abs(r)))
        return (norm if math.isfinite(norm) else math.inf), r, value


def fd_step(shooting: ShootingMap, y: np.ndarray, symmetric: bool) -> float:
    """The central differences' step for the Jacobians of the orbits near y (module docstring: of FD_STEPS the one
    whose Jacobian differs least from the next smaller step's; DF_half for a symmetric orbit, else DP_k)."""
    which = 1 if symmetric else 0
    jacobians = [shooting.jacobian(y, step)[which] for step in FD_STEPS]
    largest = max(float(np.max(np.abs(J))) for J in jacobians) or 1.0
    differences = [float(np.max(np.abs(a - b))) / largest for a, b in zip(jacobians, jacobians[1:])]
    return FD_STEPS[int(np.argmin(differences))]


def newton_matrix(end: np.ndarray, half: np.ndarray, symmetric: bool) -> np.ndarray:
    """The scaled Jacobian of the residual: -DF_half - I (symmetric) or DP_k - I."""
    J = -half if symmetric else end
    return J - np.eye(J.shape[0])


def multipliers(end: np.ndarray, half: np.ndarray, symmetric: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """(Floquet multipliers mu of P_k, multipliers lambda of the half map G or None), each sorted by decreasing
    modulus. For a symmetric orbit mu = lambda^2 (module docstring), more accurate than eig(DP_k)."""
    if symmetric:
        lam = np.linalg.eigvals(-half)
        lam = lam[np.argsort(-np.abs(lam), kind="stable")]
        mu = lam * lam
        return mu[np.argsort(-np.abs(mu), kind="stable")], lam
    mu = np.linalg.eigvals(end)
    return mu[np.argsort(-np.abs(mu), kind="stable")], None


@dataclass
class PeriodicOrbit:
    """A periodic orbit of the full model (module docstring).

    setting: system and excitation; k: period multiple (the orbit repeats after k T); symmetric: solved as a
    fixed point of the half map G (y(t + kT/2) = -y(t)); state: y at phase 0 (SI, the integrators' layout);
    amplitudes: |c_1| of the tip relative to the base in each of the k periods (m, Sect. 5); impacts: contact
    onsets in each period; pattern: the walls hit over the k periods in order of onset (L left, R right; lower
    case: an impulse below SIGNIFICANT_SHARE of the largest, e.g. a graze or a same-wall rebound), "" without an
    impact log (ode3); significant: significant impacts per period (-); multipliers: Floquet multipliers of
    P_k (sorted by decreasing modulus); half_multipliers: those of G (symmetric orbits) or None; residual: the
    final Newton residual (scaled, units of g); jacobian: (DP_k, DF_half) scaled, kept for branch switching;
    half_state: the state at k T / 2 (SI), which tells a switched branch from its parent
    (`sim.orbits.bifurcations.switch_branch`); at_grazing: the Jacobian's differences had to shrink to stay on one
    side of a grazing (`ShootingMap.jacobian`): the multipliers are those of one side and less accurate.
    """

    setting: OrbitSetting
    k: int
    symmetric: bool
    state: np.ndarray
    amplitudes: np.ndarray
    impacts: np.ndarray
    multipliers: np.ndarray
    half_multipliers: np.ndarray | None
    residual: float
    pattern: str = ""
    significant: float = math.nan
    jacobian: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    half_state: np.ndarray | None = field(default=None, repr=False)
    at_grazing: bool = False

    @property
    def amplitude(self) -> float:
        """a/a_noabs* (-): the mean over the k periods of |c_1| per period over a_noabs* (what the stepped sine's
        mean measures on this orbit, Sect. 5.1)."""
        return float(np.mean(self.amplitudes)) / self.setting.a_noabs

    @property
    def amplitude_max(self) -> float:
        """The largest per-period |c_1| over a_noabs* (-)."""
        return float(np.max(self.amplitudes)) / self.setting.a_noabs

    @property
    def amplitude_m(self) -> float:
        """The mean per-period |c_1| of the tip relative to the base (m)."""
        return float(np.mean(self.amplitudes))

    @property
    def impacts_per_period(self) -> float:
        """Contact onsets per excitation period (-)."""
        return float(np.mean(self.impacts))

    @property
    def linear(self) -> bool:
        """True when the sphere never touches a wall (the linear frequency response; the sphere is neutral)."""
        return bool(np.sum(self.impacts) == 0)

    @property
    def max_multiplier(self) -> float:
        """Largest multiplier modulus |mu| of P_k (-); 1 for a linear orbit (its free sphere)."""
        return float(np.abs(self.multipliers[0]))

    @property
    def stable(self) -> bool:
        """All multipliers inside the unit circle (asymptotically stable). A linear orbit is not: its free sphere
        has the double multiplier 1 of a Jordan block (a sphere given any speed drifts into a wall)."""
        return not self.linear and self.max_multiplier < 1.0


def impact_pattern(shooting: ShootingMap, y: np.ndarray) -> tuple[str, float]:
    """(pattern, significant impacts per period) of the orbit through y (`PeriodicOrbit`), from one run with the
    impact log (exact integrator); ("", NaN) when the integrator keeps no impact records (ode3)."""
    ledger = Ledger()
    state = np.array(y, dtype=np.float64)
    if shooting.setting.integrator != "exact":
        return "", math.nan
    shooting._run_step(state, shooting.k, shooting.Omega, shooting.a_base, shooting.sys, None, ledger=ledger)
    records = ledger.impacts
    if records.size == 0:
        return "", 0.0
    impulse = np.nan_to_num(records["impulse"], nan=0.0)
    big = impulse >= SIGNIFICANT_SHARE * impulse.max()
    letters = ["L" if wall == 0 else "R" for wall in records["wall"]]
    return "".join(c if b else c.lower() for c, b in zip(letters, big)), float(big.sum()) / shooting.k


def make_orbit(shooting: ShootingMap, y: np.ndarray, symmetric: bool, value: MapValue | None = None,
               jacobian: tuple[np.ndarray, np.ndarray] | None = None) -> PeriodicOrbit:
    """The `PeriodicOrbit` through the converged state y: its multipliers (from `jacobian` or a new one), impact
    pattern and per-period amplitudes."""
    r, value = shooting.residual(y, symmetric, value)
    if jacobian is None:
        jacobian = shooting.jacobian(y)
    end, half = jacobian
    mu, lam = multipliers(end, half, symmetric)
    pattern, significant = shooting.pattern(y)
    return PeriodicOrbit(setting=shooting.setting, k=shooting.k, symmetric=symmetric, state=np.array(y, float),
                         amplitudes=value.amplitudes.copy(), impacts=value.impacts.copy(), multipliers=mu,
                         half_multipliers=lam, residual=float(np.max(np.abs(r))), pattern=pattern,
                         significant=significant, jacobian=(end, half), half_state=np.array(value.half, float),
                         at_grazing=bool(getattr(shooting, "shrunk", False)))


def solve_orbit(setting: OrbitSetting, guess: np.ndarray, *, k: int = 1, symmetric: bool | None = None,
                tolerance: float = TOLERANCE, max_iterations: int = MAX_ITERATIONS) -> PeriodicOrbit:
    """Newton's method for a kT orbit (P_k(y) = y, or G(y) = y when symmetric) from the state `guess` (SI, phase
    0; module docstring). symmetric None: symmetric when the walls are (`OrbitSetting.symmetric_walls`) and k is
    odd. Raises OrbitNotConverged naming the residual reached and what to try."""
    shooting = ShootingMap(setting, k)
    if symmetric is None:
        symmetric = setting.symmetric_walls and k % 2 == 1
    if symmetric and not (setting.symmetric_walls and k % 2 == 1):
        raise SimulationInputError("orbits: a symmetric orbit needs mirror-symmetric walls (phi_l = phi_r) and an odd "
                                   "period multiple k")
    y = np.array(guess, dtype=np.float64)
    if y.shape != (shooting.size,) or not np.all(np.isfinite(y)):
        raise SimulationInputError(f"orbits: the start must be a finite state of length {shooting.size}")
    norm, r, value = shooting.safe_residual(y, symmetric)
    if r is None:
        raise OrbitNotConverged("orbits: the integrator fails from the start state itself; start closer to the "
                                "orbit (a simulated state, --start slow-flow) or at a lower level")
    for _ in range(max_iterations):
        if norm < tolerance:
            break
        A = newton_matrix(*shooting.jacobian(y, one_side=False), symmetric)
        step = np.linalg.lstsq(A, -r, rcond=1e-12)[0] * shooting.scale
        damping = 1.0
        while damping >= 1.0 / 1024:
            trial = y + damping * step
            t_norm, t_r, t_value = shooting.safe_residual(trial, symmetric)
            if t_norm < (1.0 - 0.25 * damping) * norm or t_norm < tolerance:
                break
            damping /= 2.0
        else:
            if norm < NOISE_FLOOR:
                break
            raise OrbitNotConverged(f"orbits: Newton's method stalled at residual {norm:.2e} g (tolerance "
                                    f"{tolerance:.0e}) at eta {setting.eta:g}, level {setting.level:g}; start closer: "
                                    "--start slow-flow (continuation from damped higher modes), a state simulated "
                                    "at this point, or a neighbouring orbit", y, norm)
        y, norm, r, value = trial, t_norm, t_r, t_value
    else:
        raise OrbitNotConverged(f"orbits: no convergence in {max_iterations} Newton steps (residual {norm:.2e} g) at "
                                f"eta {setting.eta:g}, level {setting.level:g}; start closer (--start slow-flow, a "
                                "simulated state) or lower the level", y, norm)
    return make_orbit(shooting, y, symmetric, value)  # its multipliers from differences on one side of a grazing
