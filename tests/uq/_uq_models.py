"""Response functions for the uq tests, used as `module:function` models (tests/uq is put on sys.path)."""
import math

import numpy as np

from sim.errors import SimulationDiverged

SIGMA = 0.2


def noisy_linear(params, level, rep, seed):
    """a + 2 b + level plus seeded Gaussian noise of standard deviation SIGMA per repetition."""
    rng = np.random.default_rng([seed, rep, int(1e6 * params["a"]), int(1e6 * params["b"])])
    return params["a"] + 2.0 * params["b"] + level + SIGMA * rng.standard_normal()


def failing(params, level, rep, seed):
    """Diverges for a > 0.9 in repetition 0 and returns NaN for b > 0.95 (every repetition)."""
    if params["a"] > 0.9 and rep == 0:
        raise SimulationDiverged("state exploded")
    if params["b"] > 0.95:
        return math.nan
    return params["a"] + params["b"]
