"""Analytic test functions of the study machinery (SALib's habit), usable as ``model = "module:function"`` in
a study file (`uq.problem.models.FunctionModel`): each has the model signature ``(params, level, rep, seed) -> float``
and answers known in closed form, so a study of them checks intervals, Sobol' indices, repetition noise and
failed-run reporting without the simulator.

* `noisy_linear`: a + 2 b + level plus seeded Gaussian noise (standard deviation SIGMA per repetition): over
  a, b in [0, 1] its band at a level is [level, level + 3], it is monotone in a and b, and the repetition
  noise variance of an r-repetition mean is SIGMA^2 / r against Var(a + 2 b) = 5/12 of uniform a, b.
* `pure_noise`: seeded Gaussian noise of standard deviation SIGMA whatever a and b: every index it gets
  describes noise (its noise share of the variance is about 1).
* `step`: a + 2 b + 3 H(a - 0.5) (H the unit step): a jump across the box, as a regime switch makes; a smooth
  surrogate cannot follow it and must say so.
* `failing`: a + b, except that it diverges (`sim.common.errors.SimulationDiverged`) for a > 0.9 in repetition 0 and
  returns NaN for b > 0.95: every run there is a failed run that a study must report, not hide.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from sim.common.errors import SimulationDiverged

SIGMA = 0.2


def noisy_linear(params: Mapping[str, float], level: float, rep: int, seed: int) -> float:
    """a + 2 b + level plus seeded Gaussian noise of standard deviation SIGMA per repetition."""
    rng = np.random.default_rng([seed, rep, int(1e6 * params["a"]), int(1e6 * params["b"])])
    return params["a"] + 2.0 * params["b"] + level + SIGMA * rng.standard_normal()


def pure_noise(params: Mapping[str, float], level: float, rep: int, seed: int) -> float:
    """Seeded Gaussian noise of standard deviation SIGMA, independent of the parameters."""
    rng = np.random.default_rng([seed, rep, int(1e6 * params["a"]), int(1e6 * params["b"])])
    return level + SIGMA * rng.standard_normal()


def failing(params: Mapping[str, float], level: float, rep: int, seed: int) -> float:
    """a + b; diverges for a > 0.9 in repetition 0 and returns NaN for b > 0.95 (every repetition)."""
    if params["a"] > 0.9 and rep == 0:
        raise SimulationDiverged("state exploded")
    if params["b"] > 0.95:
        return math.nan
    return params["a"] + params["b"]


def step(params: Mapping[str, float], level: float, rep: int, seed: int) -> float:
    """a + 2 b + 3 H(a - 0.5): linear with a jump of 3 at a = 0.5 (deterministic)."""
    return params["a"] + 2.0 * params["b"] + (3.0 if params["a"] > 0.5 else 0.0)
