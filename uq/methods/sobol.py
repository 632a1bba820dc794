"""Variance-based (Sobol') sensitivity of the resonant response levels, through SALib.

Sampling: SALib's Sobol' sequence with Saltelli's cross-sampling (first and total order only,
N (k + 2) points for k varied parameters). Analysis: SALib's estimators of S1 and ST with bootstrap
confidence intervals (Saltelli et al. 2010, Jansen 1999).

The simulated IES response is chaotic (Sect. 5.1 of the seed paper): repeated stepped-sine runs with
slightly perturbed frequencies scatter. Each sample point is therefore run `r` times; the analysis
uses the mean over repetitions, and the repetition noise is estimated from the within-point
variance: the variance of a mean of r runs is s^2 / r, so the share of the variance of the analysed
output that is noise rather than parameters is  mean_i(s_i^2 / r_i) / Var_i(ybar_i).
Failed runs (NaN/inf) are caught and reported before SALib sees them: a point with at least one
finite repetition uses the finite ones; an output with a point that has none is not analysed.

Two definitions of the indices, both written (`noise_free`, `with_noise`):
* S1, ST: indices of the analysed output, the repetition mean, whose variance V + sigma^2 includes the noise
  sigma^2 = s (V + sigma^2) of the mean of r runs. They are what Saltelli's estimators return on a noisy model:
  every model evaluation draws its own noise, so the first-order estimator (Saltelli 2010) sees V_i / (V + sigma^2)
  and Jansen's total-order estimator sees (V_Ti + sigma^2) / (V + sigma^2): the noise acts as an input of its own
  that counts into every ST. They depend on the repetitions r through s.
* S1_noise_free, ST_noise_free: V_i / V and V_Ti / V, the indices of the expected response (r -> infinity), what a
  regression surrogate fits (`uq.methods.surrogate`): S1 / (1 - s) and (ST - s) / (1 - s).

The methods of Sobol' studies (``[study] kind = "sobol"``) share their analysis (`SobolMethod`: per output and level
the indices, sobol.csv and variance.csv) and differ in their sampling and estimator: Saltelli's (`Saltelli`, here,
the reference) and the polynomial-chaos surrogate's (`uq.methods.surrogate.PCE`).
"""
from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from sim.common.options import positive_int
from sim.common.outputs import Column, OutputFile
from uq.errors import StudyError
from uq.problem.method import Analysis, Method, Plan, Runs, Table
from uq.problem.space import ParameterSpace
from uq.problem.study import Context, Setting, Study, check_number, numeric


def sobol_sample(space: ParameterSpace, n: int, *, seed: int = 0) -> np.ndarray:
    """Saltelli/Sobol' sample of the varied parameters (values in SI), shape (n (k + 2), k).

    `n` must be a power of two (SALib's Sobol' sequence keeps its balance properties only then).
    """
    from SALib.sample import sobol as sobol_sampler

    if n < 2 or n & (n - 1):
        raise StudyError(f"Sobol' base sample size n = {n} must be a power of two >= 2, e.g. 64")
    return sobol_sampler.sample(space.salib_problem(), n, calc_second_order=False, seed=seed)


@dataclass
class SobolResult:
    """Sobol' indices of one output with bootstrap confidence half-widths (at `confidence`).

    noise_variance: variance of the repetition mean due to the chaotic scatter;
    noise_share: its share of the total variance of the analysed (rep-averaged) output.
    failed_runs: count of non-finite runs that were dropped; message: why the output was not analysed.
    """

    names: list[str]
    S1: np.ndarray
    S1_conf: np.ndarray
    ST: np.ndarray
    ST_conf: np.ndarray
    variance: float
    noise_variance: float
    noise_share: float
    failed_runs: int = 0
    confidence: float = 0.95
    message: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def analysed(self) -> bool:
        return not self.message

    def noise_free(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(S1, S1_conf, ST, ST_conf) of the expected response, the repetition noise taken out (module docstring)."""
        return noise_free(self.S1, self.S1_conf, self.ST, self.ST_conf, self.noise_share)


def noise_free(S1: np.ndarray, S1_conf: np.ndarray, ST: np.ndarray, ST_conf: np.ndarray,
               noise_share: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Indices of the repetition mean (noise share s of its variance) -> of the expected response:
    S1 / (1 - s), (ST - s) / (1 - s), half-widths / (1 - s); an unknown s (one repetition) counts as 0, and s >= 1
    (no parameter effect resolved) gives NaN."""
    s = 0.0 if not np.isfinite(noise_share) else (float(noise_share) if noise_share < 1 else np.nan)
    return S1 / (1 - s), S1_conf / (1 - s), (ST - s) / (1 - s), ST_conf / (1 - s)


def with_noise(S1: np.ndarray, S1_conf: np.ndarray, ST: np.ndarray, ST_conf: np.ndarray,
               noise_share: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The inverse of `noise_free`: S1 (1 - s), ST (1 - s) + s, half-widths (1 - s); s >= 1 (all noise) gives
    S1 = 0 and ST = 1."""
    s = min(float(noise_share), 1.0) if np.isfinite(noise_share) else 0.0
    return S1 * (1 - s), S1_conf * (1 - s), ST * (1 - s) + s, ST_conf * (1 - s)


def check_runs(Y: np.ndarray, X: np.ndarray | None = None, names: list[str] | None = None) -> tuple[np.ndarray, list[str], str]:
    """Catch failed runs in Y (n_points x n_reps): returns (finite mask, notes, fatal message or "")."""
    finite = np.isfinite(Y)
    notes, fatal = [], ""
    n_bad = int((~finite).sum())
    if n_bad:
        dead = np.where(~finite.any(axis=1))[0]
        notes.append(f"{n_bad} of {Y.size} runs failed (NaN/inf) and were left out of the repetition means")
        if dead.size:
            where = ""
            if X is not None and names is not None:
                where = " first at " + ", ".join(f"{n}={v:.4g}" for n, v in zip(names, X[dead[0]]))
            fatal = (f"{dead.size} sample point(s) have no finite run{where}; Sobol' indices need every point "
                     "(fix the failing runs or narrow the parameter box)")
    return finite, notes, fatal


def sobol_indices(space: ParameterSpace, X: np.ndarray, Y: np.ndarray, *, num_resamples: int = 200,
                  confidence: float = 0.95, seed: int = 0, noise: np.ndarray | None = None) -> SobolResult:
    """S1 and ST of Y (n_points, or n_points x n_reps) at the sample X of `sobol_sample`.

    Repetitions (columns) are averaged; the noise estimate needs >= 2 finite repetitions per point.
    Alternatively Y is already a repetition statistic (1-D) and `noise` gives the variance of each
    value due to the repetition scatter (e.g. the squared standard error; NaN where unknown); 1-D Y without
    `noise` is a deterministic function's (no noise).
    """
    from SALib.analyze import sobol as sobol_analyzer

    problem = space.salib_problem()
    k = problem["num_vars"]
    Y = np.asarray(Y, dtype=float)
    Y = Y[:, None] if Y.ndim == 1 else Y
    if Y.shape[0] != X.shape[0] or Y.shape[0] % (k + 2):
        raise StudyError(f"{Y.shape[0]} outputs do not match the Sobol' sample of {X.shape[0]} points "
                         f"({k} parameters need a multiple of {k + 2})")
    if noise is not None:
        noise = np.asarray(noise, dtype=float)
        if Y.shape[1] != 1 or noise.shape != (Y.shape[0],):
            raise StudyError("noise must give one variance per point of a 1-D output")
    finite, notes, fatal = check_runs(Y, X, problem["names"])
    nan = np.full(k, np.nan)
    if fatal:
        return SobolResult(names=problem["names"], S1=nan, S1_conf=nan, ST=nan, ST_conf=nan, variance=np.nan,
                           noise_variance=np.nan, noise_share=np.nan, failed_runs=int((~finite).sum()),
                           confidence=confidence, message=fatal, notes=notes)
    counts = finite.sum(axis=1)
    clean = np.where(finite, Y, 0.0)
    ybar = clean.sum(axis=1) / counts
    variance = float(np.var(ybar, ddof=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        dev2 = np.where(finite, (Y - ybar[:, None]) ** 2, 0.0).sum(axis=1)
        s2 = dev2 / (counts - 1)
    usable = counts >= 2
    if noise is not None:
        noise_variance = float(np.mean(noise[np.isfinite(noise)])) if np.isfinite(noise).any() else np.nan
    elif Y.shape[1] == 1:
        noise_variance = 0.0  # one value per point, no noise given: a deterministic function
    else:
        noise_variance = float(np.mean(s2[usable] / counts[usable])) if usable.any() else np.nan
    if noise is None and not usable.all() and usable.any():
        notes.append(f"noise estimated from {int(usable.sum())} of {usable.size} points with >= 2 finite runs")
    if np.isnan(noise_variance):
        notes.append("no noise estimate (one repetition per point): how much of the variance is repetition noise is "
                     "unknown; run repetitions >= 2")
    if variance <= 0:
        return SobolResult(names=problem["names"], S1=nan, S1_conf=nan, ST=nan, ST_conf=nan, variance=variance,
                           noise_variance=noise_variance, noise_share=np.nan, failed_runs=int((~finite).sum()),
                           confidence=confidence, message="the output does not vary over the sample", notes=notes)
    if noise_variance >= 0.5 * variance:
        notes.append(f"repetition noise makes up {noise_variance / variance:.0%} of the variance (a share >= 100 % "
                     "means no parameter effect is resolved above the noise): the indices mostly describe noise; "
                     "raise the repetitions or the hold time")
    res = sobol_analyzer.analyze(problem, ybar, calc_second_order=False, num_resamples=num_resamples,
                                 conf_level=confidence, print_to_console=False, seed=seed)
    return SobolResult(names=problem["names"], S1=np.asarray(res["S1"]), S1_conf=np.asarray(res["S1_conf"]),
                       ST=np.asarray(res["ST"]), ST_conf=np.asarray(res["ST_conf"]), variance=variance,
                       noise_variance=noise_variance, noise_share=noise_variance / variance,
                       failed_runs=int((~finite).sum()), confidence=confidence, message="", notes=notes)


# ---- the methods of Sobol' studies -------------------------------------------------------------------------------

SOBOL_CSV = OutputFile("sobol.csv", "ies sobol", "", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("parameter", "", "the parameter's name"),
    Column("S1", "-", "first-order Sobol' index of the repetition mean, the noise counted in (`uq.methods.sobol`)"),
    Column("S1_conf", "-", "half-width of its confidence interval"),
    Column("ST", "-", "total Sobol' index, the noise counted into it as an input of its own"),
    Column("ST_conf", "-", "half-width of its confidence interval"),
    Column("S1_noise_free", "-", "first-order index of the expected response: S1 / (1 - noise_share)"),
    Column("S1_noise_free_conf", "-", "half-width of its confidence interval"),
    Column("ST_noise_free", "-", "total index of the expected response: (ST - noise_share) / (1 - noise_share)"),
    Column("ST_noise_free_conf", "-", "half-width of its confidence interval"),
))


VARIANCE_CSV = OutputFile("variance.csv", "ies sobol", "", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("variance", "(a/a_noabs*)^2", "variance of the repetition-mean output over the sample"),
    Column("noise_variance", "(a/a_noabs*)^2", "the part that is repetition noise (mean squared standard error)"),
    Column("noise_share", "-", "noise_variance / variance"),
    Column("failed_runs", "-", "runs that failed"),
    Column("message", "", "why a level was not analysed (empty otherwise)"),
))


def _confidence(value: Any, context: Context) -> float:
    value = float(check_number("[sobol] confidence", value))
    if not 0 < value < 1:
        raise StudyError(f"[sobol] confidence must lie in (0, 1), got {value}")
    return value


#: the settings every Sobol' method has (analysis settings: not part of the study's identity)
SHARED_SETTINGS = (
    numeric("bootstrap", 200, "bootstrap resamples of the confidence intervals", integer=True, identity=False),
    Setting("confidence", 0.95, _confidence, "confidence level of the intervals", identity=False),
)


class SobolMethod(Method):
    """What the Sobol' methods share: the kind, sobol.csv and variance.csv, and the analysis per output and level;
    a method gives its sample (`sample`) and its estimator of the indices (`indices`), and may add notes, a table row
    and summary values per level."""

    kind = "sobol"
    kind_help = "Sobol' sensitivity indices of the resonant response level per excitation level (SALib)"
    tables = (Table(SOBOL_CSV, dims={"parameter": "parameter", "level": "level"}, split="output"),
              Table(VARIANCE_CSV, dims={"level": "level"}, split="output"))

    def finish(self, values: dict[str, Any], context: Context) -> dict[str, Any]:
        if not context.space.varied:
            raise StudyError("no parameter is varied; give at least one [parameters.NAME] with min < max")
        return values

    @abstractmethod
    def sample(self, study: Study) -> np.ndarray:
        """The sample of the varied parameters (values in SI), shape (points, k)."""

    @abstractmethod
    def indices(self, study: Study, X: np.ndarray, value: np.ndarray, se: np.ndarray,
                regimes: list[str]) -> SobolResult:
        """S1, ST of one output at one level from the repetition means `value` (and their standard errors `se`)."""

    def level_notes(self, study: Study, result: SobolResult) -> list[str]:
        """Warnings about one level's indices beyond the estimator's own notes."""
        return []

    def level_rows(self, output: str, level: float, result: SobolResult) -> dict[str, list[Any]]:
        """A row of each of the method's own tables for one output and level (file name -> row)."""
        return {}

    def level_summary(self, result: SobolResult) -> dict[str, Any]:
        """Values of study.json's summary.per_level beyond the noise share and the failed runs."""
        return {}

    def summary(self, study: Study, results: list[SobolResult]) -> dict[str, Any]:
        """study.json's summary entries of the sample."""
        return {}

    def plan(self, study: Study) -> Plan:
        X = self.sample(study)
        return Plan([study.space.from_values(x) for x in X], {"X": X})

    def analyse(self, study: Study, model: Any, plan: Plan, runs: Runs) -> Analysis:
        """S1, ST with their confidence per output and level (sobol.csv, in both definitions of the indices), the
        variance and its noise share per level (variance.csv)."""
        out = Analysis(rows={t.file.file: [] for t in self.tables})
        per_level: dict[str, dict] = {}
        results = []
        for o in model.banded_outputs:
            value, se, _ = runs.stats[o]
            for j, level in enumerate(study.levels):
                res = self.indices(study, plan.extra["X"], value[:, j], se[:, j], list(runs.regimes[:, j]))
                results.append(res)
                where = f"{o} at level {level:g}"
                out.warnings += [f"{where}: {note}" for note in res.notes]
                if res.message:
                    out.warnings.append(f"{where}: not analysed: {res.message}")
                out.warnings += [f"{where}: {note}" for note in self.level_notes(study, res)]
                free = res.noise_free()
                for k, pname in enumerate(res.names):
                    out.rows["sobol.csv"].append([o, level, pname, res.S1[k], res.S1_conf[k], res.ST[k], res.ST_conf[k],
                                                  *(column[k] for column in free)])
                out.rows["variance.csv"].append([o, level, res.variance, res.noise_variance, res.noise_share,
                                                 res.failed_runs, res.message])
                for name, row in self.level_rows(o, level, res).items():
                    out.rows[name].append(row)
                per_level[f"{o}@{level:g}"] = {"noise_share": res.noise_share, "failed_runs": res.failed_runs,
                                               **self.level_summary(res)}
        out.summary = {**self.summary(study, results), "per_level": per_level}
        return out

    def figures(self, folder: Path, options: Any = None) -> list[Path]:
        """S1 and ST with their confidence intervals against the level (`uq.outputs.figures.sobol_figure`)."""
        from uq.outputs.figures import sobol_figure

        return sobol_figure(folder, options)

    def report(self, folder: Path, summary: Mapping[str, Any], name: str) -> None:
        """The indices with their confidence and the noise share per level (`uq.outputs.results.sobol_table`)."""
        from uq.outputs.results import sobol_table

        print(sobol_table(folder))


def _power_of_two(value: Any, context: Context) -> int:
    n = int(check_number("[sobol] n", value, integer=True))
    if n < 2 or n & (n - 1):
        raise StudyError(f"[sobol] n = {n} must be a power of two >= 2 (e.g. 64)")
    return n


class Saltelli(SobolMethod):
    """Saltelli's sampling and SALib's estimators (Saltelli 2010, Jansen 1999): n (k + 2) points, the reference."""

    name = "saltelli"
    help = "Saltelli's sampling and SALib's estimators, the reference: n (k + 2) points"
    settings = (Setting("n", 64, _power_of_two, "Saltelli's base sample size, a power of two: n (k + 2) points",
                        option="--n", metavar="N", parse=positive_int, identity=False),
                *SHARED_SETTINGS)

    def sample(self, study: Study) -> np.ndarray:
        return sobol_sample(study.space, study.settings["n"], seed=study.seed)

    def indices(self, study: Study, X: np.ndarray, value: np.ndarray, se: np.ndarray,
                regimes: list[str]) -> SobolResult:
        s = study.settings
        return sobol_indices(study.space, X, value, num_resamples=s["bootstrap"], confidence=s["confidence"],
                             seed=study.seed, noise=se**2)

    def level_notes(self, study: Study, result: SobolResult) -> list[str]:
        from uq.outputs.results import sample_size_advice

        if result.message:
            return []
        advice = sample_size_advice([*result.S1, *result.ST], [*result.S1_conf, *result.ST_conf], study.settings["n"])
        return [advice] if advice else []

    def summary(self, study: Study, results: list[SobolResult]) -> dict[str, Any]:
        return {"base_sample": study.settings["n"]}
