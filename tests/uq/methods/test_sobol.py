"""Sobol' layer on the Ishigami function: SALib's estimates bracket the analytic indices."""
import numpy as np
import pytest

from uq.errors import StudyError
from uq.methods.sobol import sobol_indices, sobol_sample
from uq.problem.space import Parameter, ParameterSpace

A, B = 7.0, 0.1


def ishigami(X):
    return np.sin(X[:, 0]) + A * np.sin(X[:, 1]) ** 2 + B * X[:, 2] ** 4 * np.sin(X[:, 0])


def ishigami_analytic():
    """Closed-form variances (Ishigami & Homma 1990; Sobol' & Levitan 1999)."""
    pi = np.pi
    V1 = 0.5 * (1 + B * pi**4 / 5) ** 2
    V2 = A**2 / 8
    V13 = B**2 * pi**8 * (1 / 18 - 1 / 50)
    V = V1 + V2 + V13
    return np.array([V1, V2, 0.0]) / V, np.array([V1 + V13, V2, V13]) / V


@pytest.fixture(scope="module")
def space():
    return ParameterSpace(tuple(Parameter(f"x{i + 1}", 0.0, -np.pi, np.pi, positive=False) for i in range(3)))


def test_ishigami_analytic_indices_inside_confidence_intervals(space):
    X = sobol_sample(space, 2**13, seed=7)
    res = sobol_indices(space, X, ishigami(X), num_resamples=300, seed=3)
    S1, ST = ishigami_analytic()
    assert res.analysed and res.noise_share == 0.0
    # bootstrap 95 % half-widths; allow the rare miss of a 95 % interval with a small floor
    assert np.all(np.abs(res.S1 - S1) <= np.maximum(res.S1_conf, 5e-3)), (res.S1, res.S1_conf, S1)
    assert np.all(np.abs(res.ST - ST) <= np.maximum(res.ST_conf, 5e-3)), (res.ST, res.ST_conf, ST)
    assert np.all(res.S1_conf < 0.05)


def test_repetition_noise_share_is_estimated(space):
    # additive noise of known variance: share = (sigma^2 / r) / Var(ybar)
    X = sobol_sample(space, 2**11, seed=1)
    rng = np.random.default_rng(5)
    r, sigma = 4, 1.5
    Y = ishigami(X)[:, None] + sigma * rng.standard_normal((X.shape[0], r))
    res = sobol_indices(space, X, Y, num_resamples=100)
    expected = (sigma**2 / r) / (ishigami_analytic_variance() + sigma**2 / r)
    assert res.noise_share == pytest.approx(expected, rel=0.1)
    assert not res.notes  # noise well below half the variance: no warning
    pure_noise = sobol_indices(space, X, sigma * rng.standard_normal((X.shape[0], r)), num_resamples=10)
    assert pure_noise.noise_share == pytest.approx(1.0, rel=0.1) and "repetition noise makes up" in pure_noise.notes[0]


def ishigami_analytic_variance():
    return A**2 / 8 + B * np.pi**4 / 5 + B**2 * np.pi**8 / 18 + 0.5


def test_failed_runs_are_reported_before_salib(space):
    X = sobol_sample(space, 64, seed=0)
    Y = np.repeat(ishigami(X)[:, None], 3, axis=1)
    Y[5, 1] = np.nan  # one failed repetition: averaged over the others
    res = sobol_indices(space, X, Y)
    assert res.analysed and res.failed_runs == 1 and "1 of" in res.notes[0]
    Y[7, :] = np.nan  # a point with no finite run: not analysed, said why
    res = sobol_indices(space, X, Y)
    assert not res.analysed and "no finite run" in res.message and np.all(np.isnan(res.S1))


def test_sample_size_must_be_power_of_two(space):
    with pytest.raises(StudyError, match="power of two"):
        sobol_sample(space, 100)
