"""Batch API for the uncertainty layer: many independent stepped-sine runs in one call.

A *job* is one stepped-sine run (`sim.stepped_sine.protocol.run_sweep`, Sect. 5.1) of one parameter set (D, g, k_H of
Table 2), one excitation level a_base/a_base* and one repetition index. Every job calls `run_sweep` with
the same (seed, rep), so its random frequency offsets (``np.random.default_rng([seed, rep])``) and its
numbers are exactly those of a single run, serially or in parallel (joblib processes), in any order.
Python runs once per frequency point; the time stepping is in the numba kernels of the integrator.
By default the jobs use the exact free-flight integrator (`sim.integration.exact`); ``integrator="ode3"`` keeps the
paper's scheme.

Example::

    jobs = batch_jobs([{}, {"k_H": 1.25 * K_H_NOMINAL}], levels=[6.7, 7.4], reps=8)
    runs = run_batch(model, SteppedSine(...), jobs, seed=0, n_jobs=2)
    results = aggregate_batch(jobs, runs)       # {(params, level): SweepResult}
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

from sim.common.errors import SimulationInputError
from sim.stepped_sine.protocol import SteppedSine, SweepResult, SweepRun, aggregate_runs, run_sweep
from sim.model.system import Impactor, ModalModel, Nominal

_PARAMETERS = ("D", "g", "k_H")


@dataclass(frozen=True)
class BatchJob:
    """One stepped-sine run: level = a_base/a_base* (nominal starred normalisation, Sect. 5.3), rep the
    repetition index of the random stream, and optional overrides D (damping ratio of mode 1, -),
    g (clearance, m), k_H (N/m^1.5); None keeps the model's / the nominal impactor's value."""

    level: float
    rep: int
    D: float | None = None
    g: float | None = None
    k_H: float | None = None

    @property
    def params(self) -> tuple[tuple[str, float | None], ...]:
        """The parameter set as a hashable key (D, g, k_H)."""
        return (("D", self.D), ("g", self.g), ("k_H", self.k_H))


def batch_jobs(parameter_sets: Iterable[Mapping[str, float]], levels: Sequence[float], reps: int,
               first_rep: int = 0) -> list[BatchJob]:
    """All jobs of parameter sets x levels x repetitions (rep = first_rep .. first_rep + reps - 1).

    parameter_sets: dicts with any of the keys 'D', 'g' (m), 'k_H' (N/m^1.5); {} is the nominal set.
    """
    if int(reps) != reps or reps < 1:
        raise SimulationInputError(f"reps must be a positive integer, got {reps!r}")
    sets = [dict(p) for p in parameter_sets]
    if not sets or not len(levels):
        raise SimulationInputError("batch: give at least one parameter set and one level")
    for p in sets:
        unknown = set(p) - set(_PARAMETERS)
        if unknown:
            raise SimulationInputError(f"batch: unknown parameter(s) {sorted(unknown)}; use {', '.join(_PARAMETERS)}")
    return [BatchJob(level=float(level), rep=int(first_rep) + r, **p)
            for p in sets for level in levels for r in range(int(reps))]


def _job_inputs(model: ModalModel, job: BatchJob) -> tuple[ModalModel, Impactor]:
    """The model and impactor of one job (validated by ModalModel/Impactor: one-line errors)."""
    for name, value in job.params:
        if value is not None and not (isinstance(value, (int, float)) and math.isfinite(value)):
            raise SimulationInputError(f"batch: parameter {name} must be a finite number, got {value!r}")
    job_model = model if job.D is None else model.with_damping(job.D)
    nominal = Impactor()
    impactor = Impactor(mass=nominal.mass, clearance=nominal.clearance if job.g is None else float(job.g),
                        k_H=nominal.k_H if job.k_H is None else float(job.k_H))
    return job_model, impactor


def _run_one(model: ModalModel, protocol: SteppedSine, job: BatchJob, seed: int, nominal: Nominal) -> SweepRun:
    job_model, impactor = _job_inputs(model, job)
    return run_sweep(job_model, impactor, job.level, protocol, seed=seed, rep=job.rep, nominal=nominal)


def run_batch(model: ModalModel, protocol: SteppedSine, jobs: Sequence[BatchJob], *, seed: int,
              nominal: Nominal | None = None, integrator: str | None = "exact", n_jobs: int = 1) -> list[SweepRun]:
    """Run every job (one `run_sweep` each, identical to a single run with the same seed and rep).

    integrator: overrides protocol.integrator (None keeps it). n_jobs: joblib worker processes
    (1 = in this process; -1 = all cores). Results are returned in the order of `jobs`.
    """
    if not jobs:
        raise SimulationInputError("batch: no jobs; build them with batch_jobs(...)")
    if integrator is not None and integrator != protocol.integrator:
        protocol = dataclasses.replace(protocol, integrator=integrator)
    for job in jobs:  # fail fast, before any work, on a bad job
        _job_inputs(model, job)
    if int(n_jobs) == 1:
        return [_run_one(model, protocol, job, seed, nominal) for job in jobs]
    from joblib import Parallel, delayed

    return list(Parallel(n_jobs=int(n_jobs))(delayed(_run_one)(model, protocol, job, seed, nominal) for job in jobs))


def aggregate_batch(jobs: Sequence[BatchJob], runs: Sequence[SweepRun]) -> dict[tuple, SweepResult]:
    """Group the runs by (parameter set, level) and aggregate each group over its repetitions (Fig. 5)."""
    if len(jobs) != len(runs):
        raise SimulationInputError(f"batch: {len(jobs)} jobs but {len(runs)} runs")
    groups: dict[tuple, list[SweepRun]] = {}
    for job, run in zip(jobs, runs):
        groups.setdefault((job.params, job.level), []).append(run)
    return {key: aggregate_runs(group) for key, group in groups.items()}


__all__ = ["BatchJob", "aggregate_batch", "batch_jobs", "run_batch"]
