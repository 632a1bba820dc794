r"""The nature of a stepped-sine point's response (seed paper Sect. 5.1: "confirmed via Poincaré mappings, not shown"):
its largest Lyapunov exponent, periodic / quasi-periodic / chaotic, and its Poincaré section.

Largest Lyapunov exponent (`largest_lyapunov`), by two nearby trajectories with renormalisation (Benettin et al.,
Meccanica 15, 1980) on the setting's integrator (the exact one by default: no truncation error in free flight, so
the separation is the model's, not the scheme's): from the reference state y_0, once per excitation period a copy
displaced by LYAPUNOV_STEP along the unit direction d_i (scaled units, `state_scales`: g at the walls) is run
alongside the reference over one period, and

    g_i = ln( |P(y_i + e d_i) - P(y_i)| / e ),   d_{i+1} = (P(y_i + e d_i) - P(y_i)) / |...|,   y_{i+1} = P(y_i),

with P one period of the integrator; the exponent per period is the slope of the running sum of g_i after a
transient (`slope`; the first TRANSIENT_SHARE of the record, at least TRANSIENT_MIN periods: the separation turning
onto the leading direction from the seeded random d_0), its standard error that of the mean of g_i by batch means
(BATCHES batches, which also holds for the correlated g_i of a chaotic attractor), and the running mean over the
record its convergence. The slope rather than the mean: where the leading multipliers are a complex pair (a stable
focus) the separation's norm in the scaled units swings with their rotation, and the mean keeps that swing divided
by the record's length (on the rig's stable orbit with its higher modes damped 100-fold, |mu| = 0.9765: the mean
is off by 8-14 % over 400-800 periods, the slope by less than 1 %). Both copies restart every period
alike, so the reference is the integrator's one-period map iterated. The separation e = 1e-8 g grows by e^8 per
period at most on the rig (its exponent is 5-8 per period at 7.4): 3e-5 g, far inside the linear range of the map
(its second derivatives ~4e3 scaled, `sim.orbits.shooting`), and far above its noise (~1e-12 g).

Checks (tests/sim/stepped_sine/test_dynamics.py): the host alone is linear and its largest exponent that of mode 1's
damping, -D_1 omega_1 T = -2 pi D_1 / eta per period (the sphere, which then never touches, is left out of the
separation: its free flight has a multiplier 1 that is no dynamics of the host); on a stable periodic orbit it is
ln |mu|max per period of the orbit's largest Floquet multiplier; on the rig at 7.4 / eta 0.978 it is positive and
stays so with the record doubled and the contacts' tolerance tightened.

Dynamics (`classify`): "chaotic" when the exponent exceeds both CHAOS_FLOOR and three standard errors; else
"periodic" when the states once per period repeat with a period k <= MAX_PERIOD within PERIODIC_TOLERANCE (scaled,
over the record's last quarter) or the exponent is below minus three standard errors (the response converges onto
a stable orbit); else "quasi-periodic" (a largest exponent of zero within its error, the states not repeating: a
torus). A point without contact is periodic (the host's linear response).

Poincaré section (`poincare`): the states once per period (the integrator's own states at phase 0, not interpolated)
as the tip's displacement and velocity relative to the base, over a_noabs* (the velocity divided by Omega), and the
power spectrum of the per-period amplitudes a_i (mean removed) against the frequency in cycles per excitation period
(0..0.5): a periodic response is a few points and no line but at multiples of 1/k, a quasi-periodic one a closed
curve and discrete lines, a chaotic one a cloud and a broad spectrum.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from sim.common.errors import SimulationInputError
from sim.model.system import ModalModel, SystemArrays

#: Separation of the two trajectories at each renormalisation (scaled units: g at the walls).
LYAPUNOV_STEP = 1e-8
#: The transient left out: this share of the record, at least TRANSIENT_MIN periods.
TRANSIENT_SHARE = 0.25
TRANSIENT_MIN = 10
#: Batches of the standard error (batch means).
BATCHES = 10
#: The shortest record an exponent is computed from (periods): the transient and ten batches of six periods.
MIN_PERIODS = 80
#: The exponent has converged when its standard error is below this share of its value, or below ABSOLUTE_ERROR
#: per period (an exponent near zero: a torus or a weakly stable orbit).
RELATIVE_ERROR = 0.05
ABSOLUTE_ERROR = 2e-3
#: Chaotic: an exponent above this (per period) and above three standard errors.
CHAOS_FLOOR = 0.01
#: Periodic: the states once per period repeat after k <= MAX_PERIOD periods within this (scaled units).
PERIODIC_TOLERANCE = 1e-6
MAX_PERIOD = 8
PERIODIC, QUASI_PERIODIC, CHAOTIC = "periodic", "quasi-periodic", "chaotic"
#: The dynamics' words, in the outputs.
DYNAMICS = (PERIODIC, QUASI_PERIODIC, CHAOTIC)


def state_scales(model: ModalModel, clearance: float) -> np.ndarray:
    """The unit of each state component (the integrators' layout [s, s', u_a, u_a']) in which a change of 1 moves the
    walls, tip or sphere by about `clearance` g: mode j's displacement g / max(|phi_l,j|, |phi_r,j|, |phi_tip,j|) (m
    sqrt(kg)), its velocity that times omega_j, the sphere's g (m) and g omega_1 (m/s)."""
    phi = np.maximum(np.maximum(np.abs(model.phi_wall_left), np.abs(model.phi_wall_right)), np.abs(model.phi_tip))
    phi = np.where(phi > 0, phi, 1.0)
    s = clearance / phi
    return np.concatenate([s, s * model.omega, [clearance, clearance * float(model.omega[0])]])


@dataclass(frozen=True)
class Lyapunov:
    """The largest Lyapunov exponent of a record (module docstring).

    per_period: the exponent per excitation period (natural log); standard_error: its batch-means error; periods:
    the record's length; transient: the periods left out at its start; growth: g_i of every period of the record
    (ln of the separation's growth); running: the running mean of g_i from the transient's end (the convergence);
    converged: standard error below RELATIVE_ERROR of the exponent or ABSOLUTE_ERROR; periods_needed: the record
    that would bring the error there (periods); host_only: the sphere left out (no impactor).
    """

    per_period: float
    standard_error: float
    periods: int
    transient: int
    growth: np.ndarray
    running: np.ndarray
    converged: bool
    periods_needed: int
    host_only: bool = False


def check_record(periods: int, option: str = "--periods") -> int:
    """The record's length in periods, or one line (SimulationInputError) naming the length needed."""
    if int(periods) != periods or periods < MIN_PERIODS:
        raise SimulationInputError(f"a largest Lyapunov exponent needs a record of at least {MIN_PERIODS} excitation "
                                   f"periods (a transient and {BATCHES} batches for its error), got {option} "
                                   f"{periods}; give {option} {MIN_PERIODS} or more (400 converge on the rig)")
    return int(periods)


def largest_lyapunov(run_period: Callable[[np.ndarray], tuple[float, int]], y0: np.ndarray, periods: int,
                     scale: np.ndarray, *, host_only: bool = False, seed: int = 0,
                     on_period: Callable[[int, np.ndarray, float, int], None] | None = None) -> Lyapunov:
    """The largest Lyapunov exponent per period from the state y0 (SI, phase 0) over `periods` periods (module
    docstring). run_period(y) advances y in place over one period and returns (|c_1| of the tip that period (m),
    contact onsets); scale: `state_scales`; host_only: leave the sphere's two components out (no impactor); seed:
    of the first direction; on_period(i, y_i, amplitude, onsets): called with the reference before each period is
    run (the Poincaré section, the periodicity)."""
    periods = check_record(periods)
    n = y0.size
    mask = np.ones(n)
    if host_only:
        mask[-2:] = 0.0
    d = np.random.default_rng([seed, 0x1a9]).standard_normal(n) * mask
    d /= np.linalg.norm(d)
    y = np.array(y0, dtype=np.float64)
    growth = np.empty(periods)
    for i in range(periods):
        other = y + LYAPUNOV_STEP * d * scale
        before = y.copy()
        amplitude, onsets = run_period(y)
        run_period(other)
        if on_period is not None:
            on_period(i, before, amplitude, onsets)
        separation = (other - y) / scale * mask
        size = float(np.linalg.norm(separation))
        if not (size > 0 and math.isfinite(size)):  # the copies met exactly (or failed): no growth this period
            growth[i] = math.log(1e-300) if size == 0 else math.nan
            continue
        growth[i] = math.log(size / LYAPUNOV_STEP)
        d = separation / size
    transient = max(TRANSIENT_MIN, int(TRANSIENT_SHARE * periods))
    tail = growth[transient:]
    exponent = slope(tail)
    batches = np.array_split(tail, BATCHES)
    se = float(np.std([b.mean() for b in batches], ddof=1) / math.sqrt(BATCHES))
    target = max(RELATIVE_ERROR * abs(exponent), ABSOLUTE_ERROR)
    needed = transient + int(math.ceil(tail.size * (se / target) ** 2)) if se > target else periods
    running = np.cumsum(tail) / np.arange(1, tail.size + 1)
    return Lyapunov(per_period=exponent, standard_error=se, periods=periods, transient=transient, growth=growth,
                    running=running, converged=se <= target, periods_needed=int(needed), host_only=host_only)


def slope(growth: np.ndarray) -> float:
    """The exponent of a tail of g_i: the least-squares slope of their running sum against the period (module
    docstring: where the leading multipliers are a complex pair the separation's norm swings with their rotation,
    and the plain mean of g_i keeps that swing over the record's length; the slope integrates it out)."""
    total = np.concatenate([[0.0], np.cumsum(growth)])
    return float(np.polyfit(np.arange(total.size, dtype=float), total, 1)[0])


def periodicity(states: np.ndarray, scale: np.ndarray, max_period: int = MAX_PERIOD) -> int | None:
    """The least k <= max_period with which the states once per period (rows, SI) repeat over the record's last
    quarter within PERIODIC_TOLERANCE (scaled), or None."""
    tail = states[-max(len(states) // 4, max_period + 1):] / scale
    for k in range(1, max_period + 1):
        if len(tail) > k and float(np.max(np.abs(tail[k:] - tail[:-k]))) < PERIODIC_TOLERANCE:
            return k
    return None


def classify(lyapunov: Lyapunov | None, period: int | None, impacts: float) -> str:
    """"periodic", "quasi-periodic" or "chaotic" (module docstring) from the exponent (None: not measured, then
    by the states alone), the states' period (`periodicity`) and the contact onsets per period."""
    if impacts <= 0:
        return PERIODIC
    if lyapunov is not None:
        margin = 3.0 * lyapunov.standard_error
        if lyapunov.per_period > max(CHAOS_FLOOR, margin):
            return CHAOTIC
        if period is not None or lyapunov.per_period < -margin:
            return PERIODIC
        return QUASI_PERIODIC
    return PERIODIC if period is not None else ""


def linear_host_exponent(model: ModalModel, eta: float) -> float:
    """The host alone's largest exponent per period: mode 1's decay over one period, -D_1 omega_1 T = -2 pi D_1 / eta
    (the least damped mode when it is the first; in general the largest of -D_j omega_j T)."""
    return float(np.max(-model.damping_ratios * model.omega * 2.0 * math.pi / (eta * float(model.omega[0]))))


def one_period(run_step: Callable, Omega: float, a_base: float, sys: SystemArrays, integrator: str = "exact",
               **options: Any) -> Callable[[np.ndarray], tuple[float, int]]:
    """run_period(y) for `largest_lyapunov`: one period of the integrator (the exact one prepared once,
    `sim.integration.prepared.PreparedExact`, with its `options`: rtol, contacts; else `run_step`), returning (|c_1|
    (m), contact onsets)."""
    if integrator == "exact":
        from sim.integration.prepared import PreparedExact

        prepared = PreparedExact(1, Omega, a_base, sys, **options)

        def run_exact(y: np.ndarray) -> tuple[float, int]:
            amplitudes, impacts, _ = prepared.advance(y)
            return float(amplitudes[0]), int(impacts[0])

        return run_exact

    def run(y: np.ndarray) -> tuple[float, int]:
        amplitudes, impacts = run_step(y, 1, Omega, a_base, sys, None, **options)
        return float(amplitudes[0]), int(impacts[0])

    return run


def poincare(states: np.ndarray, amplitudes: np.ndarray, model: ModalModel, Omega: float, a_noabs: float) -> dict:
    """The Poincaré section and the per-period amplitudes' spectrum (module docstring): {"q_tip", "v_tip": the tip's
    displacement and velocity / Omega relative to the base at phase 0, over a_noabs* (-); "frequency_per_period":
    0..0.5 (cycles per excitation period); "amplitude_spectrum": |FFT|^2 / n of a_i / a_noabs* with the mean removed
    (-)}."""
    n = model.n_modes
    q = states[:, :n] @ model.phi_tip / a_noabs
    v = states[:, n:2 * n] @ model.phi_tip / (Omega * a_noabs)
    a = np.asarray(amplitudes, dtype=float) / a_noabs
    spectrum = np.abs(np.fft.rfft(a - a.mean())) ** 2 / max(a.size, 1)
    return {"q_tip": q, "v_tip": v, "frequency_per_period": np.fft.rfftfreq(a.size), "amplitude_spectrum": spectrum}


__all__ = ["CHAOTIC", "DYNAMICS", "Lyapunov", "MIN_PERIODS", "PERIODIC", "QUASI_PERIODIC", "check_record", "classify",
           "largest_lyapunov", "linear_host_exponent", "one_period", "periodicity", "poincare", "state_scales"]
