"""The stepped-sine protocol of the seed paper (Sects. 5.1-5.3) and its aggregation over repetitions.

One *run* (`run_sweep`) starts from homogeneous initial conditions and steps through the frequency grid
leg by leg (e.g. up, down, up), carrying the state over from point to
point with a continuous excitation phase. At each point it waits `wait` seconds and then holds `hold`
seconds, both rounded to whole excitation periods (at least one hold period), and records the measures of
`sim.stepped_sine.measures` over the hold.

Frequencies: eta = Omega / omega_1 (omega_1 of the model = the nominal natural frequency omega*, Sect. 5.2).
Random perturbation (Sect. 5.1: the simulations were repeated "starting at slightly different, randomly
perturbed excitation frequencies in each stepped sine run"), `SteppedSine.perturb`:
* ``"start"`` (default, the paper's): each run draws one relative offset e ~ Uniform(-perturbation,
  +perturbation) and starts with a lead-in of one wait time at eta_0 (1 + e), eta_0 its first grid
  frequency; then every point waits and holds at its nominal grid frequency. The runs differ by their start
  only, every point is measured at the frequency it is reported at, and averaging runs does not blur a sharp
  peak (without the IES the average is the analytic frequency response). The lead-in is a separate phase,
  not the first point's wait: a hold right after the switch from eta_0 (1 + e) to eta_0 would still carry
  the switch's transient (up to 8 % of the linear resonant amplitude after a 15 s wait at e = 5e-4).
* ``"each-point"``: every visited point k gets its own offset, ``eta_k' = eta_k (1 + e_k)``, wait and hold at
  eta_k'. Each repetition sample is then interpolated linearly in its simulated frequencies (`eta_actual`)
  onto the nominal grid before the samples are averaged (at the grid's ends the nearest simulated point
  is taken), so that the average is again reported at the frequency it belongs to.
The offsets are drawn from ``np.random.default_rng([seed, rep])`` (one per run, or one per visited point in
execution order); nothing else is random. A run is therefore reproducible from (seed, rep) alone, in any
order and in any process. The default half-width 5e-4 is a quarter of the default grid spacing (0.002).

Initial conditions (`SteppedSine.start`; the paper says only "homogeneous initial conditions", Sect. 5.1):
* ``"base-velocity"`` (default): zero *relative* displacements and velocities of the host structure and
  the sphere under q_base = a_base sin(Omega t), i.e. the sphere starts with the absolute velocity
  a_base Omega of the base. It keeps rattling at every excitation level > 1, so an up-sweep meets the
  resonance with an active IES, as the paper's simulations do (Appendix C: the simulated IES "remains
  active" far from resonance; Figs. 5, 6 show impacting responses down to a_base/a_base* = 1.26).
* ``"rest"``: y = 0, the sphere centred at rest. Far below resonance the walls never reach it; an up-sweep
  then stays on the linear branch up to eta ~ 1 - D_1 level and its largest "mean" is the last linear
  point before the first impact (~1/level), not a resonant level of the IES (uq/studies/fidelity/README.md).
Evidence for the default (updated rig model, exact integrator, 0.96:1.02:31, 3 s / 5 s, 3 runs):
``ies overview --sequence up --start base-velocity`` gives the paper's Fig. 6 shape (a flat SMR plateau,
mean 0.04-0.06 and max 0.12-0.2 of a_noabs*, then a sharp switch to APR with mean rising with the level);
with ``--start rest`` every level from 3 to 9 stays linear (resonant mean 0.08-0.19 = the linear branch).

Legs and repetitions (`SteppedSine.repetition`):
* ``"leg"`` (default, the experiment's counting, Sect. 5.1): every leg of every run is one repetition of
  the frequency response; up-down-up from rest gives three samples per frequency, the later legs starting
  from the state the previous leg left.
* ``"run"``: one run is one repetition (the paper's simulations start every run from rest); the visits of
  a frequency in its legs are pooled as one longer hold (mean over all hold periods, max of the maxima).
With the single-leg sequences "up" and "down" both choices coincide. The turning point of a multi-leg
sequence is visited once in each leg.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Callable, Iterator

import numpy as np

from sim.common.errors import SimulationInputError
from sim.integration.energy import Ledger
from sim.integration.integrators import DEFAULT_INTEGRATOR
from sim.stepped_sine.measures import APR, LINEAR, REGIME_CV_THRESHOLD, SCATTERING_MEASURES, classify_regime, point_measures
from sim.model.system import (CLEARANCE_NOMINAL, SPHERE_MASS, Impactor, ModalModel, Nominal, SystemArrays,
                        a_base_star, a_noabs_star, system_arrays)

#: The sweep sequences: each a tuple of legs ("up": increasing eta, "down": decreasing).
SEQUENCES: dict[str, tuple[str, ...]] = {
    "up": ("up",),
    "down": ("down",),
    "up-down-up": ("up", "down", "up"),
    "up-down-up-down-up": ("up", "down", "up", "down", "up"),
}
REPETITION_UNITS = ("leg", "run")
#: How the frequencies of a run are perturbed (module docstring): its start only, or every visited point.
PERTURB_MODES = ("start", "each-point")
#: Initial conditions of a run: "rest" = y = 0 at excitation phase 0 (sphere centred, at rest relative to the
#: base and, as the base velocity is zero there, in the inertial frame); "base-velocity" = homogeneous
#: initial conditions in relative coordinates under q_base = a_base sin(Omega t), i.e. at the instant of peak
#: base velocity: the sphere starts with the absolute velocity a_base Omega and (frictionless) drifts into a
#: wall. We start it at phase 0 with u_a' = a_base Omega (the host's start-up transient differs slightly;
#: it has decayed after the wait).
STARTS = ("rest", "base-velocity")


@dataclass(frozen=True)
class SteppedSine:
    """A stepped-sine protocol (Sect. 5.1).

    eta_start, eta_stop, n_eta: the grid of eta = Omega/omega_1 (linspace, start < stop, or n_eta = 1);
    sequence: one of SEQUENCES; wait, hold: s per frequency point (paper: 3 s and 5 s with the IES; 15 s
    wait without); perturbation: half-width of the uniform relative frequency offset; perturb: what it
    perturbs (PERTURB_MODES: the start of each run, default, or each visited point; module docstring);
    repetition: "leg" or "run" (module docstring); integrator: a name of `sim.integration.integrators`;
    dt_scale: multiple of the paper's ode3 step (ode3 only); start: initial conditions of each run
    (STARTS; default "base-velocity", the reading of the paper's homogeneous initial conditions that
    reproduces Figs. 5, 6; "rest" keeps the sphere idle until the response exceeds the clearance; module
    docstring).
    """

    eta_start: float = 0.96
    eta_stop: float = 1.02
    n_eta: int = 31
    sequence: str = "up"
    wait: float = 3.0
    hold: float = 5.0
    perturbation: float = 5e-4
    repetition: str = "leg"
    integrator: str = DEFAULT_INTEGRATOR  # a name of `sim.integration.integrators.INTEGRATORS` (exact free flight)
    dt_scale: float = 1.0
    start: str = "base-velocity"
    perturb: str = "start"

    def __post_init__(self) -> None:
        for name in ("eta_start", "eta_stop", "wait", "hold", "perturbation", "dt_scale"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SimulationInputError(f"stepped sine: {name} must be a finite number, got {value!r}")
        if int(self.n_eta) != self.n_eta or self.n_eta < 1:
            raise SimulationInputError(f"stepped sine: the eta grid is empty (n = {self.n_eta}); give n >= 1, e.g. 0.96:1.02:31")
        if self.eta_start <= 0:
            raise SimulationInputError(f"stepped sine: eta must be positive, got start {self.eta_start}")
        if self.n_eta > 1 and not self.eta_stop > self.eta_start:
            raise SimulationInputError(
                f"stepped sine: eta range {self.eta_start}:{self.eta_stop} is empty or reversed; give START < STOP "
                "(the direction comes from --sequence)")
        if self.n_eta == 1 and self.eta_stop != self.eta_start:
            raise SimulationInputError("stepped sine: a single frequency needs START == STOP, e.g. 0.976:0.976:1")
        if self.sequence not in SEQUENCES:
            raise SimulationInputError(f"stepped sine: unknown sequence {self.sequence!r}; choose one of {', '.join(SEQUENCES)}")
        if self.repetition not in REPETITION_UNITS:
            raise SimulationInputError(f"stepped sine: repetition must be 'leg' or 'run', got {self.repetition!r}")
        if self.perturb not in PERTURB_MODES:
            raise SimulationInputError(f"stepped sine: perturb must be one of {', '.join(PERTURB_MODES)}, got {self.perturb!r}")
        if self.start not in STARTS:
            raise SimulationInputError(f"stepped sine: start must be one of {', '.join(STARTS)}, got {self.start!r}")
        if self.wait < 0:
            raise SimulationInputError(f"stepped sine: wait must be >= 0 s, got {self.wait}")
        if self.hold <= 0:
            raise SimulationInputError(f"stepped sine: hold must be positive (s), got {self.hold}")
        if not 0 <= self.perturbation < 0.05:
            raise SimulationInputError(f"stepped sine: perturbation must lie in [0, 0.05) (relative), got {self.perturbation}")
        if self.dt_scale <= 0:
            raise SimulationInputError(f"stepped sine: dt_scale must be positive, got {self.dt_scale}")

    @property
    def eta(self) -> np.ndarray:
        """The nominal eta grid, ascending."""
        return np.linspace(self.eta_start, self.eta_stop, int(self.n_eta))

    @property
    def legs(self) -> tuple[str, ...]:
        return SEQUENCES[self.sequence]

    def periods(self, Omega: float) -> tuple[int, int]:
        """(wait, hold) in whole excitation periods at Omega (rad/s); refuses a hold shorter than one period."""
        period = 2.0 * math.pi / Omega
        if self.hold < period * (1.0 - 1e-9):
            raise SimulationInputError(
                f"stepped sine: hold {self.hold:g} s is shorter than one excitation period ({period:.4g} s); "
                "give a longer --hold")
        return int(round(self.wait / period)), max(1, int(round(self.hold / period)))


@dataclass
class SweepRun:
    """One stepped-sine run (`run_sweep`): per visited point, in execution order.

    eta: nominal grid value; eta_actual: the perturbed value simulated; leg: leg index (0, 1, ...);
    mean, max, min, std: per-period amplitudes over the hold / a_noabs*; impacts_per_period: contact
    onsets per period over the hold; hold_periods: hold length in periods; scattering: per point the
    energy scattering and impact measures (`sim.stepped_sine.measures.SCATTERING_MEASURES` -> array; NaN where not available).
    level = a_base/a_base*; a_base, a_noabs (m); wall_time_s of the run; lyapunov, dynamics: per point the largest
    Lyapunov exponent over the hold (per period) and periodic / quasi-periodic / chaotic (`sim.stepped_sine.dynamics`),
    None when not measured.
    """

    eta: np.ndarray
    eta_actual: np.ndarray
    leg: np.ndarray
    mean: np.ndarray
    max: np.ndarray
    min: np.ndarray
    std: np.ndarray
    impacts_per_period: np.ndarray
    hold_periods: np.ndarray
    level: float
    a_base: float
    a_noabs: float
    seed: int
    rep: int
    protocol: SteppedSine
    impactor: Impactor | None
    wall_time_s: float = 0.0
    scattering: dict[str, np.ndarray] = field(default_factory=dict)
    lyapunov: np.ndarray | None = None
    dynamics: list[str] | None = None

    @property
    def cv(self) -> np.ndarray:
        return np.divide(self.std, self.mean, out=np.zeros_like(self.std), where=self.mean > 0)


@dataclass
class SweepResult:
    """A frequency response aggregated over repetitions (Fig. 5) and its resonant levels (Fig. 6).

    Arrays over the eta grid (ascending): mean, max = averages over the repetition samples of the
    per-point mean and max amplitude (/ a_noabs*); *_lo, *_hi = their smallest and largest sample (the
    spread of Fig. 5); *_std = their standard deviation; cv = average amplitude spread std/mean;
    impacts_per_period = average contact onsets per period; regime per point ('APR', 'SMR', 'linear').
    resonant_mean, resonant_max: largest mean / max over eta (Sect. 5.2, 5.3); eta_resonant_mean/max where
    they occur; regime: the regime at eta_resonant_mean; resonant_*_samples: the repetition samples at
    eta_resonant_mean / eta_resonant_max, whose average the resonant level is (their range and standard error
    are its spread: `resonant_spread`); mean/max/cv/impacts_samples: the (n_samples, n_eta) data behind the
    averages, samples ordered run by run, leg by leg. scattering: per name of `sim.stepped_sine.measures.SCATTERING_MEASURES`
    the average over the samples per eta (NaN-aware; balance_error: the largest magnitude), scattering_samples:
    their (n_samples, n_eta) data.
    """

    eta: np.ndarray
    mean: np.ndarray
    mean_lo: np.ndarray
    mean_hi: np.ndarray
    mean_std: np.ndarray
    max: np.ndarray
    max_lo: np.ndarray
    max_hi: np.ndarray
    max_std: np.ndarray
    cv: np.ndarray
    impacts_per_period: np.ndarray
    regime_per_eta: list[str]
    resonant_mean: float
    resonant_max: float
    eta_resonant_mean: float
    eta_resonant_max: float
    regime: str
    resonant_mean_samples: np.ndarray
    resonant_max_samples: np.ndarray
    mean_samples: np.ndarray
    max_samples: np.ndarray
    cv_samples: np.ndarray
    impacts_samples: np.ndarray
    n_samples: int
    n_runs: int
    level: float
    a_base: float
    a_noabs: float
    protocol: SteppedSine
    wall_time_s: float
    extra: dict = field(default_factory=dict)
    scattering: dict[str, np.ndarray] = field(default_factory=dict)
    scattering_samples: dict[str, np.ndarray] = field(default_factory=dict)
    lyapunov_per_period: np.ndarray | None = None
    dynamics: list[str] | None = None
    lyapunov_samples: np.ndarray | None = None

    def resonant_spread(self, output: str) -> tuple[float, float, float]:
        """(lo, hi, standard error) of the resonant level `output` ("mean" or "max"): the range of its repetition
        samples (all taken at its eta, so lo <= level <= hi) and the standard error of their average (NaN for a
        single sample: no noise estimate). Each sample's own maximum over eta would not do: when the samples
        peak at different eta it can lie above the maximum of the average (at level 4 a "lower" bound 0.0457
        above the value 0.0452)."""
        samples = self.resonant_mean_samples if output == "mean" else self.resonant_max_samples
        level = self.resonant_mean if output == "mean" else self.resonant_max
        se = float(np.std(samples, ddof=1) / np.sqrt(samples.size)) if samples.size >= 2 else math.nan
        return min(float(samples.min()), level), max(float(samples.max()), level), se  # rounding of the average

    def to_dict(self) -> dict:
        """Plain data for JSON (see `sim.common.files.dumps`)."""
        out = {k: getattr(self, k) for k in (
            "level", "a_base", "a_noabs", "eta", "mean", "max", "mean_lo", "mean_hi", "mean_std", "max_lo",
            "max_hi", "max_std", "cv", "impacts_per_period", "regime_per_eta", "resonant_mean", "resonant_max",
            "eta_resonant_mean", "eta_resonant_max", "regime", "resonant_mean_samples", "resonant_max_samples",
            "mean_samples", "max_samples", "cv_samples", "impacts_samples", "n_samples", "n_runs", "wall_time_s")}
        out["protocol"] = asdict(self.protocol)
        out["regime_cv_threshold"] = REGIME_CV_THRESHOLD
        out.update(scattering_keys(self.scattering))
        if self.lyapunov_per_period is not None:
            out.update(lyapunov_per_period=self.lyapunov_per_period, dynamics=self.dynamics,
                       lyapunov_samples=self.lyapunov_samples)
        out.update(self.extra)
        return out


def scattering_keys(measures: dict) -> dict:
    """The JSON keys of the scattering measures (Sect. 5.5, Appendix D) of `ies sweep` / `ies overview`: each
    measure by its name, and "dissipation" {fundamental, higher_modes, contact (shares of the input work),
    input (mean input power, W), balance_error, friction (share)} (values or arrays over eta as given)."""
    out = {name: measures[name] for name in SCATTERING_MEASURES if not name.startswith("dissipation_")
           and name not in ("input_power", "balance_error")}
    out["dissipation"] = {"fundamental": measures["dissipation_fundamental"],
                          "higher_modes": measures["dissipation_higher_modes"],
                          "contact": measures["dissipation_contact"], "input": measures["input_power"],
                          "balance_error": measures["balance_error"], "friction": measures["dissipation_friction"]}
    return out


def simulated_system(model: ModalModel, impactor: Impactor | None) -> SystemArrays:
    """System arrays; without impactor k_H = 0 (the sphere never touches: the linear host structure)."""
    if impactor is not None:
        return system_arrays(model, impactor)
    return system_arrays(model, Impactor(SPHERE_MASS, CLEARANCE_NOMINAL))._replace(k_H=0.0)


def check_level(level: float) -> float:
    """Validate the excitation level a_base/a_base* (> 0)."""
    level = float(level)
    if not math.isfinite(level) or level <= 0:
        raise SimulationInputError(f"excitation level a_base/a_base* must be positive, got {level!r}")
    return level


def _check_seed(value: int, name: str) -> int:
    if int(value) != value or value < 0:
        raise SimulationInputError(f"{name} must be a non-negative integer, got {value!r}")
    return int(value)


def visit_points(model: ModalModel, sys: SystemArrays, a_base: float, protocol: SteppedSine, y: np.ndarray, *,
                 seed: int, rep: int) -> Iterator[tuple[int, float, float, float]]:
    """Walk ONE stepped-sine run (Sect. 5.1) from the initial conditions of protocol.start, advancing y in place:
    for each visited point in execution order the lead-in (before the first point) and the wait are run, and
    (leg index, eta, eta_actual, Omega in rad/s) is yielded with y at the start of the point's hold. The caller
    runs the hold on y before asking for the next point.

    The random frequency offsets come only from ``np.random.default_rng([seed, rep])`` (module docstring).
    """
    from sim.integration.integrators import get_integrator

    run_step = get_integrator(protocol.integrator, dt_scale=protocol.dt_scale)
    omega_1 = float(model.omega[0])
    grid = protocol.eta
    protocol.periods(omega_1 * grid[0] * (1.0 - protocol.perturbation))  # refuse a too short hold up front
    rng = np.random.default_rng([seed, rep])
    each_point = protocol.perturb == "each-point"
    start_offset = 0.0 if each_point else float(rng.uniform(-protocol.perturbation, protocol.perturbation))
    first = True
    for leg_index, direction in enumerate(protocol.legs):
        order = grid if direction == "up" else grid[::-1]
        offsets = (rng.uniform(-protocol.perturbation, protocol.perturbation, size=order.size) if each_point
                   else np.zeros(order.size))
        for eta, offset in zip(order, offsets):
            eta_actual = float(eta) * (1.0 + float(offset))
            Omega = eta_actual * omega_1
            if first:
                first = False
                Omega_start = Omega * (1.0 + start_offset)
                if protocol.start == "base-velocity":
                    y[2 * model.n_modes + 1] = a_base * Omega_start
                n_lead_in = protocol.periods(Omega_start)[0] if not each_point else 0
                if n_lead_in:
                    run_step(y, n_lead_in, Omega_start, a_base, sys, None)
            n_wait = protocol.periods(Omega)[0]
            if n_wait:
                run_step(y, n_wait, Omega, a_base, sys, None)
            yield leg_index, float(eta), eta_actual, Omega


def run_sweep(model: ModalModel, impactor: Impactor | None, level: float, protocol: SteppedSine, *,
              seed: int, rep: int, nominal: Nominal | None = None,
              progress: Callable[[], None] | None = None, lyapunov: bool = False) -> SweepRun:
    """ONE stepped-sine run from homogeneous initial conditions (Sect. 5.1; protocol.start) at
    a_base = level * a_base* (nominal D*, g*): the points of `visit_points`, each with its hold.

    impactor None simulates the host structure alone. The random frequency offsets come only from
    ``np.random.default_rng([seed, rep])`` (module docstring). `progress` is called after every point. lyapunov:
    also each hold's largest Lyapunov exponent and dynamics (`hold_dynamics`).
    """
    from sim.integration.integrators import get_integrator

    level = check_level(level)
    seed = _check_seed(seed, "seed")
    rep = _check_seed(rep, "rep")
    run_step = get_integrator(protocol.integrator, dt_scale=protocol.dt_scale)
    sys = simulated_system(model, impactor)
    a_base = level * a_base_star(model, nominal)
    a_noabs = a_noabs_star(model, a_base, nominal)
    started = time.perf_counter()
    y = np.zeros(2 * model.n_modes + 2)
    rows: list[tuple] = []
    natures: list[tuple[float, str]] = []
    for leg_index, eta, eta_actual, Omega in visit_points(model, sys, a_base, protocol, y, seed=seed, rep=rep):
        n_hold = protocol.periods(Omega)[1]
        ledger = Ledger()
        start = y.copy()
        amplitudes, impacts = run_step(y, n_hold, Omega, a_base, sys, None, ledger=ledger)
        m = point_measures(amplitudes, impacts, a_noabs, ledger)
        rows.append((eta, eta_actual, leg_index, m.mean, m.max, m.min, m.std, m.impacts_per_period, n_hold,
                     *(getattr(m.scattering, name) for name in SCATTERING_MEASURES)))
        if lyapunov:
            natures.append(hold_dynamics(model, impactor, sys, protocol, start, n_hold, Omega, a_base, seed=seed))
        if progress is not None:
            progress()
    cols = list(zip(*rows))
    as_f = lambda i: np.array(cols[i], dtype=float)  # noqa: E731
    return SweepRun(
        eta=as_f(0), eta_actual=as_f(1), leg=np.array(cols[2], dtype=int), mean=as_f(3), max=as_f(4),
        min=as_f(5), std=as_f(6), impacts_per_period=as_f(7), hold_periods=np.array(cols[8], dtype=int),
        level=level, a_base=a_base, a_noabs=a_noabs, seed=seed, rep=rep, protocol=protocol, impactor=impactor,
        wall_time_s=time.perf_counter() - started,
        scattering={name: as_f(9 + i) for i, name in enumerate(SCATTERING_MEASURES)},
        lyapunov=np.array([n[0] for n in natures]) if lyapunov else None,
        dynamics=[n[1] for n in natures] if lyapunov else None)


def hold_dynamics(model: ModalModel, impactor: Impactor | None, sys: SystemArrays, protocol: SteppedSine,
                  start: np.ndarray, n_hold: int, Omega: float, a_base: float, *, seed: int = 0) -> tuple[float, str]:
    """(largest Lyapunov exponent per period, dynamics) of one hold of n_hold periods from its start state
    (`sim.stepped_sine.dynamics`: the exponent over the hold, the states once per period for its periodicity)."""
    from sim.integration.integrators import get_integrator
    from sim.stepped_sine.dynamics import classify, largest_lyapunov, one_period, periodicity, state_scales

    scale = state_scales(model, sys.g)
    run = one_period(get_integrator(protocol.integrator, dt_scale=protocol.dt_scale), Omega, a_base, sys,
                     protocol.integrator)
    states, onsets = [], []
    result = largest_lyapunov(run, start, n_hold, scale, host_only=impactor is None, seed=seed,
                              on_period=lambda i, y, a, n: (states.append(y), onsets.append(n)))
    impacts = float(np.mean(onsets)) if impactor is not None else 0.0
    return result.per_period, classify(result, periodicity(np.array(states), scale), impacts)


def check_lyapunov_holds(model: ModalModel, protocol: SteppedSine) -> None:
    """One line (SimulationInputError) when a hold of the protocol is too short for a Lyapunov exponent
    (`sim.stepped_sine.dynamics.MIN_PERIODS`), before anything is simulated."""
    from sim.stepped_sine.dynamics import MIN_PERIODS

    shortest = protocol.periods(float(model.omega[0]) * protocol.eta[0] * (1.0 - protocol.perturbation))[1]
    if shortest < MIN_PERIODS:
        need = MIN_PERIODS * 2.0 * math.pi / (float(model.omega[0]) * protocol.eta[0])
        raise SimulationInputError(f"--lyapunov takes each hold's exponent: a hold of {shortest} periods is too short "
                                   f"(at least {MIN_PERIODS}); give --hold {math.ceil(need * 10) / 10:g} s or more")


_SAMPLED = ("mean", "max", "std", "impacts_per_period", "hold_periods")


def _samples(run: SweepRun, grid: np.ndarray) -> list[dict[str, np.ndarray]]:
    """The repetition samples of one run on the ascending grid (per leg, or pooled per run)."""
    n = grid.size
    per_leg = []
    columns = {key: getattr(run, key) for key in _SAMPLED}
    columns.update({name: run.scattering.get(name, np.full(run.eta.size, np.nan)) for name in SCATTERING_MEASURES})
    for leg in np.unique(run.leg):
        sel = run.leg == leg
        sample = {}
        if run.protocol.perturb == "each-point":  # back onto the grid from the frequencies simulated
            order = np.argsort(run.eta_actual[sel])
            for key, values in columns.items():
                sample[key] = np.interp(grid, run.eta_actual[sel][order], values[sel][order])
        else:
            idx = np.searchsorted(grid, run.eta[sel])
            for key, values in columns.items():
                sample[key] = np.empty(n)
                sample[key][idx] = values[sel]
        per_leg.append(sample)
    if run.protocol.repetition == "leg" or len(per_leg) == 1:
        return per_leg
    # pool the legs as one longer hold: weighted mean, max of maxima, pooled std (law of total variance)
    w = np.array([s["hold_periods"] for s in per_leg])
    mean = np.array([s["mean"] for s in per_leg])
    pooled_mean = np.sum(w * mean, axis=0) / w.sum(axis=0)
    second = np.sum(w * (np.array([s["std"] for s in per_leg]) ** 2 + mean**2), axis=0) / w.sum(axis=0)
    weighted = lambda key: np.sum(w * np.array([s[key] for s in per_leg]), axis=0) / w.sum(axis=0)  # noqa: E731
    return [{
        "mean": pooled_mean,
        "max": np.max([s["max"] for s in per_leg], axis=0),
        "std": np.sqrt(np.clip(second - pooled_mean**2, 0.0, None)),
        "impacts_per_period": weighted("impacts_per_period"),
        "hold_periods": w.sum(axis=0),
        **{name: weighted(name) for name in SCATTERING_MEASURES if name != "balance_error"},
        "balance_error": _largest_magnitude(np.array([s["balance_error"] for s in per_leg])),
    }]


def _largest_magnitude(samples: np.ndarray) -> np.ndarray:
    """Per column the sample of largest magnitude (NaN where all are NaN): the worst balance error."""
    magnitude = np.where(np.isnan(samples), -1.0, np.abs(samples))
    picked = np.take_along_axis(samples, np.argmax(magnitude, axis=0)[None], axis=0)[0]
    return picked


def _scattering_average(stack: np.ndarray, name: str) -> np.ndarray:
    """The repetition average of a scattering measure per eta (NaN-aware; the worst for balance_error)."""
    if name == "balance_error":
        return _largest_magnitude(stack)
    counts = np.sum(np.isfinite(stack), axis=0)
    return np.divide(np.nansum(stack, axis=0), counts, out=np.full(stack.shape[1], np.nan), where=counts > 0)


def aggregate_runs(runs: list[SweepRun]) -> SweepResult:
    """Aggregate runs of the same protocol and level into a frequency response with its spread (Fig. 5)."""
    if not runs:
        raise SimulationInputError("no runs to aggregate; give at least one repetition")
    first = runs[0]
    for run in runs[1:]:
        if run.protocol != first.protocol or run.level != first.level or run.a_base != first.a_base:
            raise SimulationInputError("runs to aggregate must share the protocol and the excitation level")
    grid = first.protocol.eta
    samples = [s for run in runs for s in _samples(run, grid)]
    stack = {key: np.array([s[key] for s in samples]) for key in ("mean", "max", "std", "impacts_per_period")}
    scattering = {name: np.array([s[name] for s in samples]) for name in SCATTERING_MEASURES}
    cv_samples = np.divide(stack["std"], stack["mean"], out=np.zeros_like(stack["std"]), where=stack["mean"] > 0)
    mean, mx = stack["mean"].mean(axis=0), stack["max"].mean(axis=0)
    cv = cv_samples.mean(axis=0)
    impacts = stack["impacts_per_period"].mean(axis=0)
    regimes = [str(r) for r in classify_regime(cv, impacts)]
    i_mean, i_max = int(np.argmax(mean)), int(np.argmax(mx))
    natures = _dynamics_average(runs, grid)
    return SweepResult(
        eta=grid, mean=mean, mean_lo=stack["mean"].min(axis=0), mean_hi=stack["mean"].max(axis=0),
        mean_std=stack["mean"].std(axis=0), max=mx, max_lo=stack["max"].min(axis=0), max_hi=stack["max"].max(axis=0),
        max_std=stack["max"].std(axis=0), cv=cv, impacts_per_period=impacts, regime_per_eta=regimes,
        resonant_mean=float(mean[i_mean]), resonant_max=float(mx[i_max]),
        eta_resonant_mean=float(grid[i_mean]), eta_resonant_max=float(grid[i_max]), regime=regimes[i_mean],
        resonant_mean_samples=stack["mean"][:, i_mean], resonant_max_samples=stack["max"][:, i_max],
        mean_samples=stack["mean"], max_samples=stack["max"], cv_samples=cv_samples,
        impacts_samples=stack["impacts_per_period"], n_samples=len(samples), n_runs=len(runs), level=first.level, a_base=first.a_base, a_noabs=first.a_noabs,
        protocol=first.protocol, wall_time_s=float(sum(r.wall_time_s for r in runs)),
        scattering={name: _scattering_average(scattering[name], name) for name in SCATTERING_MEASURES},
        scattering_samples=scattering, **natures)


def _dynamics_average(runs: list[SweepRun], grid: np.ndarray) -> dict:
    """The SweepResult fields of the runs' Lyapunov exponents (none when they were not measured): per eta the mean
    exponent over every visit of it (legs and runs: `lyapunov_samples` one row per visit) and the dynamics most of
    them had (a tie goes to the less regular: chaotic, then quasi-periodic)."""
    if any(run.lyapunov is None for run in runs):
        return {}
    from sim.stepped_sine.dynamics import DYNAMICS

    exponents: dict[float, list[float]] = {float(e): [] for e in grid}
    kinds: dict[float, list[str]] = {float(e): [] for e in grid}
    for run in runs:
        for eta, value, kind in zip(run.eta, run.lyapunov, run.dynamics):
            nearest = float(grid[int(np.argmin(np.abs(grid - eta)))])
            exponents[nearest].append(float(value))
            kinds[nearest].append(kind)
    visits = max(len(v) for v in exponents.values())
    samples = np.full((visits, grid.size), np.nan)
    for j, eta in enumerate(grid):
        values = exponents[float(eta)]
        samples[:len(values), j] = values
    order = {kind: -i for i, kind in enumerate(DYNAMICS)}  # ties: the later in DYNAMICS wins
    dynamics = [max(set(k), key=lambda kind: (k.count(kind), -order.get(kind, 0))) if k else ""
                for k in (kinds[float(e)] for e in grid)]
    return {"lyapunov_per_period": np.nanmean(samples, axis=0), "dynamics": dynamics, "lyapunov_samples": samples}


def sweep(model: ModalModel, impactor: Impactor | None, level: float, protocol: SteppedSine, *, reps: int,
          seed: int, nominal: Nominal | None = None, progress: bool | None | Callable[[], None] = None,
          lyapunov: bool = False) -> SweepResult:
    """`reps` runs (rep = 0 .. reps-1) of `run_sweep`, aggregated (Sects. 5.1, 5.2); lyapunov: with each hold's
    largest Lyapunov exponent and dynamics.

    progress: report the progress on stderr (`sim.common.progress`: a bar on a terminal, plain lines in a log; None:
    only if the sweep is long), or a callable called after every point (the caller's own report).
    """
    from sim.common.progress import progress as report

    if int(reps) != reps or reps < 1:
        raise SimulationInputError(f"reps must be a positive integer, got {reps!r}")
    total = int(reps) * len(protocol.legs) * int(protocol.n_eta)
    if progress is None:
        progress = total * (protocol.wait + protocol.hold) > 60.0
    started = time.perf_counter()
    with report(total, f"sweep {level:g}", "pt", enabled=not callable(progress) and bool(progress), leave=False) as bar:
        runs = [run_sweep(model, impactor, level, protocol, seed=seed, rep=rep, nominal=nominal,
                          progress=progress if callable(progress) else bar.update, lyapunov=lyapunov)
                for rep in range(int(reps))]
    result = aggregate_runs(runs)
    result.wall_time_s = time.perf_counter() - started
    return result


__all__ = ["SEQUENCES", "SteppedSine", "SweepResult", "SweepRun", "aggregate_runs", "check_level", "run_sweep",
           "sweep", "visit_points", "APR", "LINEAR"]
