"""Sobol' indices from a polynomial-chaos surrogate (`[sobol] method = "pce"`), through OpenTURNS.

Saltelli's estimators (`uq.methods.sobol`) need n (k + 2) model points; a polynomial chaos expansion (PCE) fitted by
regression to a space-filling design of far fewer points gives the same indices analytically from its
coefficients (Sudret 2008, Reliab. Eng. Syst. Saf. 93: S_i = sum of the squared coefficients of the terms in
x_i alone over the sum of all but the constant's; S_Ti of all terms containing x_i), provided the response is
smooth over the parameter box.

Design: a scrambled Sobol' sequence of `points` points over the same box as Saltelli's sample (scipy.stats.qmc,
seeded, Owen scrambling), balanced when `points` is a power of two. On the shipped Sobol' study (32 points x 3
repetitions, eight seeds) it gave the small index of g with a third of a plain Latin hypercube's scatter (standard
deviation 0.035 against 0.065; the hypercube's random column correlations move variance between parameters) and
without the bias of a discrepancy-optimised one (+0.04). Fit: Legendre polynomials of the uniform inputs up to a
total degree, the terms chosen by least-angle regression (LARS) with a corrected leave-one-out selection (Blatman &
Sudret 2011, J. Comput. Phys. 230), OpenTURNS' `FunctionalChaosAlgorithm`.

What is reported beside the indices:
* the cross-validated error: K-fold (10 folds, or one per point below 10), the whole fit (LARS included)
  repeated on each training part, as a share of the output variance (1 - Q^2);
* the repetition noise: the mean squared standard error of the repetition means, as a share of the variance
  (`uq.methods.sobol`); even a perfect surrogate's cross-validated error is about this noise share times
  (1 + terms / training points), the part no regression can explain;
* bootstrap confidence half-widths of S1 and ST: the design points resampled with replacement, the fit
  repeated, z * standard deviation of the indices (SALib's convention, so the tables compare);
* the indices in both definitions of `uq.methods.sobol`: the fit's own are those of the expected response (regression
  averages the repetition noise out); S1 and ST count the noise in as Saltelli's estimators do, so that the two
  methods' tables mean the same;
* smoothness: a regime switch inside the box (almost periodic / strongly modulated, Sect. 5.3 of the seed paper)
  makes the response jump, and a polynomial then spreads the jump over every term. The response is flagged
  not smooth when the cross-validated error exceeds the noise's expected part by more than `max_misfit`, or when
  the points of one level fall into different regimes.

The method (`PCE`, ``[sobol] method = "pce"``) shares the Sobol' analysis of `uq.methods.sobol.SobolMethod` and adds
its fit per output and level (surrogate.csv).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sim.common.options import positive_int
from sim.common.outputs import Column, OutputFile
from uq.errors import StudyError
from uq.methods.sobol import SHARED_SETTINGS, SobolMethod, SobolResult, with_noise
from uq.problem.method import Table
from uq.problem.space import ParameterSpace
from uq.problem.study import Context, Study, numeric
#: cross-validation folds (fewer when the design has fewer points)
FOLDS = 10
#: the default of `[sobol] max_misfit`: cross-validated error beyond the noise's part, share of the variance
MAX_MISFIT = 0.1


def basis_size(k: int, degree: int) -> int:
    """Number of terms of a full polynomial basis of total degree `degree` in `k` variables: C(k + p, p)."""
    return math.comb(k + degree, degree)


def check_design(k: int, points: int, degree: int) -> None:
    """One-line StudyError when `points` design points cannot fit a degree-`degree` basis in `k` parameters."""
    if degree < 1:
        raise StudyError(f"[sobol] degree must be >= 1, got {degree}")
    terms = basis_size(k, degree)
    if points < terms:
        raise StudyError(f"[sobol] points = {points} is too few for degree {degree} in {k} parameters ({terms} "
                         f"polynomial terms): give points >= {terms} (the default, {default_points(k, degree)}, "
                         "recommended) or lower the degree")


def default_points(k: int, degree: int) -> int:
    """Three design points per term of the full basis (the usual rule for regression-based PCE), rounded up to a
    power of two (the balance of the Sobol' design)."""
    return 1 << (3 * basis_size(k, degree) - 1).bit_length()


def openturns():
    """The openturns module, or a one-line StudyError naming the extra to install."""
    try:
        import openturns as ot
    except ImportError:
        raise StudyError("[sobol] method = \"pce\" needs OpenTURNS: pip install 'ies-workbench[surrogate]'") from None
    ot.Log.Show(ot.Log.NONE)
    return ot


def pce_sample(space: ParameterSpace, points: int, *, seed: int = 0) -> np.ndarray:
    """Scrambled Sobol' design of the varied parameters (values in SI), shape (points, k), over the box [min, max]."""
    import warnings

    from scipy.stats import qmc

    lo, hi = np.array(space.salib_problem()["bounds"], dtype=float).T
    with warnings.catch_warnings():  # a count that is not a power of two is allowed: less balanced, still low-discrepancy
        warnings.filterwarnings("ignore", message="The balance properties of Sobol' points")
        unit = qmc.Sobol(d=lo.size, scramble=True, seed=seed).random(points)
    return lo + unit * (hi - lo)


@dataclass
class PCEResult(SobolResult):
    """`SobolResult` of a PCE surrogate, with its fit's quality.

    degree, terms: the basis' total degree and the terms LARS kept; points: design points used;
    cv_error: K-fold cross-validated mean squared error over the output variance (1 - Q^2);
    noise_floor: the part of cv_error the repetition noise explains (noise share x (1 + terms / training points));
    regimes: the distinct regimes of the design points (empty for models without regimes);
    smooth: False where the fit says the response jumps (see the module docstring), with the reason in `rough`.
    """

    degree: int = 0
    terms: int = 0
    points: int = 0
    cv_error: float = math.nan
    noise_floor: float = math.nan
    regimes: tuple[str, ...] = ()
    smooth: bool = True
    rough: str = ""


def _unit(space: ParameterSpace, X: np.ndarray) -> np.ndarray:
    lo, hi = np.array(space.salib_problem()["bounds"], dtype=float).T
    return (np.asarray(X, dtype=float) - lo) / (hi - lo)


def fit_pce(U: np.ndarray, y: np.ndarray, degree: int):
    """OpenTURNS FunctionalChaosResult of y over unit-cube points U (n, k): Legendre basis of total degree
    `degree`, terms selected by LARS with corrected leave-one-out."""
    ot = openturns()
    k = U.shape[1]
    distribution = ot.JointDistribution([ot.Uniform(0.0, 1.0)] * k)
    enumerate_ = ot.LinearEnumerateFunction(k)
    basis = ot.OrthogonalProductPolynomialFactory([ot.LegendreFactory()] * k, enumerate_)
    selection = ot.LeastSquaresMetaModelSelectionFactory(ot.LARS(), ot.CorrectedLeaveOneOut())
    algo = ot.FunctionalChaosAlgorithm(ot.Sample(np.asarray(U, dtype=float)), ot.Sample(np.asarray(y, float)[:, None]),
                                       distribution, ot.FixedStrategy(basis, basis_size(k, degree)),
                                       ot.LeastSquaresStrategy(selection))
    algo.run()
    return algo.getResult()


def pce_sobol(U: np.ndarray, y: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(S1, ST, number of terms kept) of the PCE of y over U (Sudret 2008, from the coefficients)."""
    ot = openturns()
    result = fit_pce(U, y, degree)
    indices = ot.FunctionalChaosSobolIndices(result)
    k = U.shape[1]
    return (np.array([indices.getSobolIndex(i) for i in range(k)]),
            np.array([indices.getSobolTotalIndex(i) for i in range(k)]), len(result.getIndices()))


def cross_validated_error(U: np.ndarray, y: np.ndarray, degree: int, *, seed: int = 0) -> float:
    """K-fold cross-validated mean squared error of the PCE fit over Var(y) (ddof 1): the fit, term selection
    included, repeated on each training part and evaluated on the held-out points."""
    n = y.size
    folds = min(FOLDS, n)
    order = np.random.default_rng(seed).permutation(n)
    residual = np.empty(n)
    for part in np.array_split(order, folds):
        train = np.setdiff1d(order, part)
        model = fit_pce(U[train], y[train], degree).getMetaModel()
        residual[part] = y[part] - np.asarray(model(U[part]), dtype=float)[:, 0]
    return float(np.mean(residual**2) / np.var(y, ddof=1))


def pce_indices(space: ParameterSpace, X: np.ndarray, y: np.ndarray, *, degree: int, noise: np.ndarray | None = None,
                regimes: Sequence[str] = (), num_resamples: int = 200, confidence: float = 0.95, seed: int = 0,
                max_misfit: float = MAX_MISFIT) -> PCEResult:
    """S1 and ST of y (one value per design point, e.g. a repetition mean) at the design X of `pce_sample`, from a
    PCE surrogate, with bootstrap confidence half-widths, the cross-validated error and a smoothness verdict.

    noise: variance of each y due to the repetition scatter (squared standard error; NaN where unknown; None for a
    deterministic function); regimes: the regime of each point ("" or none for models without regimes).
    """
    from scipy.stats import norm

    names = space.salib_problem()["names"]
    k = len(names)
    y = np.asarray(y, dtype=float)
    check_design(k, y.size, degree)
    nan = np.full(k, np.nan)
    bad = ~np.isfinite(y)

    def failed(message: str, variance: float = np.nan, noise_variance: float = np.nan) -> PCEResult:
        return PCEResult(names, nan, nan, nan, nan, variance, noise_variance, np.nan, failed_runs=int(bad.sum()),
                         confidence=confidence, message=message, notes=[], degree=degree, points=y.size)

    if bad.any():
        return failed(f"{int(bad.sum())} design point(s) have no finite run; the surrogate needs every point "
                      "(fix the failing runs or narrow the parameter box)")
    variance = float(np.var(y, ddof=1))
    noise_variance = 0.0 if noise is None else (float(np.nanmean(noise)) if np.isfinite(noise).any() else np.nan)
    if variance <= 0:
        return failed("the output does not vary over the design", variance, noise_variance)
    notes = []
    if np.isnan(noise_variance):
        notes.append("no noise estimate (one repetition per point): the cross-validated error cannot be split into "
                     "noise and misfit; run repetitions >= 2")
    U = _unit(space, X)
    S1, ST, terms = pce_sobol(U, y, degree)
    cv_error = cross_validated_error(U, y, degree, seed=seed)
    train = y.size * (1 - 1 / min(FOLDS, y.size))
    share = noise_variance / variance
    floor = (share if np.isfinite(share) else 0.0) * (1 + terms / train)
    rng = np.random.default_rng(seed)
    boot = np.empty((num_resamples, 2, k))
    for b in range(num_resamples):
        pick = rng.integers(0, y.size, y.size)
        boot[b, 0], boot[b, 1], _ = pce_sobol(U[pick], y[pick], degree)
    z = norm.ppf(0.5 + confidence / 2)
    S1_conf, ST_conf = z * boot.std(axis=0, ddof=1)
    # the fit filters the noise out: its indices are the noise-free ones; S1 and ST are defined as Saltelli's
    S1, S1_conf, ST, ST_conf = with_noise(S1, S1_conf, ST, ST_conf, share)
    distinct = tuple(sorted({r for r in regimes if r}))
    rough = []
    if cv_error > floor + max_misfit:
        rough.append(f"cross-validated error {cv_error:.0%} of the variance against {floor:.0%} the repetition noise "
                     f"explains (allowed misfit {max_misfit:.0%})")
    if len(distinct) > 1:
        counts = ", ".join(f"{r} {sum(1 for x in regimes if x == r)}" for r in distinct)
        rough.append(f"the design points fall into different regimes ({counts} points)")
    if share >= 0.5:
        notes.append(f"repetition noise makes up {share:.0%} of the variance: the indices mostly describe noise; "
                     "raise the repetitions or the hold time")
    return PCEResult(names, S1, S1_conf, ST, ST_conf, variance, noise_variance, share, failed_runs=0,
                     confidence=confidence, message="", notes=notes,
                     degree=degree, terms=terms, points=y.size, cv_error=cv_error, noise_floor=floor,
                     regimes=distinct, smooth=not rough, rough="; ".join(rough))


# ---- the method --------------------------------------------------------------------------------------------------

SURROGATE_CSV = OutputFile("surrogate.csv", "ies sobol, method pce", "The polynomial-chaos surrogate's fit per "
                           "output and level (`uq.methods.surrogate`).", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("points", "-", "the design's points (scrambled Sobol')"),
    Column("degree", "-", "the basis' total degree"),
    Column("terms", "-", "the polynomial terms LARS kept"),
    Column("cv_error", "-", "10-fold cross-validated error, a share of the output variance"),
    Column("noise_floor", "-", "the part of cv_error the repetition noise explains"),
    Column("smooth", "-", "1 where the response is smooth, 0 not (NOT SMOOTH: indices unreliable), empty: not analysed"),
    Column("regimes", "", "the regimes the design points fall into"),
    Column("rough", "", "why it is not smooth"),
))


class PCE(SobolMethod):
    """Sobol' indices from a polynomial-chaos surrogate of a scrambled Sobol' design (module docstring)."""

    name = "pce"
    help = ("a polynomial-chaos surrogate (OpenTURNS) of a scrambled Sobol' design: a tenth of the runs where the response "
            "is smooth")
    settings = (*SHARED_SETTINGS,
                numeric("points", 0, "design points of the surrogate (default: 3 per polynomial term, rounded up to a "
                        "power of 2)", integer=True, option="--points", metavar="N", parse=positive_int, identity=False),
                numeric("degree", 2, "total polynomial degree (points >= C(k + degree, degree))", integer=True,
                        option="--degree", metavar="P", parse=positive_int, identity=False),
                numeric("max_misfit", MAX_MISFIT, "cross-validated error beyond the noise (share of the variance) above "
                        "which the response is flagged not smooth", identity=False))
    tables = (*SobolMethod.tables, Table(SURROGATE_CSV, dims={"level": "level"}, split="output"))
    #: Saltelli's base sample n, which files of the release before the method registry gave any Sobol' study
    superseded = {"n": "points"}

    def finish(self, values: dict[str, Any], context: Context) -> dict[str, Any]:
        values = super().finish(values, context)
        k = len(context.space.varied)
        values["points"] = values["points"] or default_points(k, values["degree"])
        check_design(k, values["points"], values["degree"])
        openturns()
        return values

    def sample(self, study: Study) -> np.ndarray:
        return pce_sample(study.space, study.settings["points"], seed=study.seed)

    def indices(self, study: Study, X: np.ndarray, value: np.ndarray, se: np.ndarray,
                regimes: list[str]) -> PCEResult:
        s = study.settings
        return pce_indices(study.space, X, value, degree=s["degree"], noise=se**2, regimes=regimes,
                           num_resamples=s["bootstrap"], confidence=s["confidence"], seed=study.seed,
                           max_misfit=s["max_misfit"])

    def level_notes(self, study: Study, result: PCEResult) -> list[str]:
        if result.message or result.smooth:
            return []
        return [f"NOT SMOOTH: {result.rough}; the surrogate's indices are not reliable there: use method = "
                "\"saltelli\""]

    def level_rows(self, output: str, level: float, result: PCEResult) -> dict[str, list[Any]]:
        return {"surrogate.csv": [output, level, result.points, result.degree, result.terms, result.cv_error,
                                  result.noise_floor, int(result.smooth) if not result.message else "",
                                  " ".join(result.regimes), result.rough]}

    def level_summary(self, result: PCEResult) -> dict[str, Any]:
        return {"cv_error": result.cv_error, "noise_floor": result.noise_floor,
                "smooth": bool(result.smooth and not result.message)}

    def summary(self, study: Study, results: list[PCEResult]) -> dict[str, Any]:
        return {"method": "pce", "design_points": study.settings["points"], "degree": study.settings["degree"],
                "smooth": all(r.smooth and not r.message for r in results)}
