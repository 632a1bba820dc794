"""Integrators of the coupled system by name (Sect. 3.2), imported lazily.

Every entry follows the contract of `sim.system`:
``run_step(y, n_periods, Omega, a_base, sys, record=None) -> (amplitudes, impacts)``.
"""
from __future__ import annotations

import functools
import importlib
from typing import Callable

import numpy as np

from sim.errors import SimulationInputError
from sim.system import SystemArrays

RunStep = Callable[[np.ndarray, int, float, float, SystemArrays, "np.ndarray | None"], tuple[np.ndarray, np.ndarray]]

#: name -> (module, function). "ode3" is the paper's reference; "exact" is the fast free-flight integrator.
REGISTRY: dict[str, tuple[str, str]] = {
    "ode3": ("sim.ode3", "run_step"),
    "exact": ("sim.exact", "run_step"),
}
#: integrators that accept ``dt_scale`` (a multiple of the paper's dt = 2 pi/(15 omega_9))
_ACCEPTS_DT_SCALE = {"ode3"}


def available() -> list[str]:
    """Names of the registered integrators."""
    return list(REGISTRY)


def get_integrator(name: str, *, dt_scale: float | None = None) -> RunStep:
    """The `run_step` function registered under `name`, with ``dt_scale`` bound if given (ode3 only)."""
    if name not in REGISTRY:
        raise SimulationInputError(f"unknown integrator {name!r}; available: {', '.join(available())}")
    module_name, attribute = REGISTRY[name]
    run_step = getattr(importlib.import_module(module_name), attribute)
    if dt_scale is None or dt_scale == 1.0:
        return run_step
    if name not in _ACCEPTS_DT_SCALE:
        raise SimulationInputError(f"dt_scale applies only to {', '.join(sorted(_ACCEPTS_DT_SCALE))}, not to {name!r}")
    return functools.partial(run_step, dt_scale=float(dt_scale))
