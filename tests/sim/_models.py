"""Small hand-made modal models for the exact integrator's tests (independent of the rig model)."""
from __future__ import annotations

import numpy as np

from sim.system import ModalModel

# A uniform cantilever of 1.8 kg (free length of the seed's beam): mass-normalised tip value 2/sqrt(m) for
# every mode (alternating sign), participation sqrt(effective-mass fraction * m) (Euler-Bernoulli values).
_EFFECTIVE_MASS_FRACTION = (0.6131, 0.1883, 0.0647, 0.0331, 0.0200, 0.0134, 0.0096, 0.0072, 0.0056)
_FREQUENCIES_HZ = (117.4, 886.0, 2494.0, 4712.0, 7540.0, 10300.0, 13300.0, 16500.0, 19800.0)
_DAMPING = (0.00085, 0.0044, 0.0005, 0.0031, 0.001, 0.001, 0.001, 0.001, 0.001)


def cantilever_like_model(n_modes: int = 9, undamped: bool = False) -> ModalModel:
    """A 9-mode model with the seed rig's frequencies (Table A.1, f9 = 19.8 kHz) and cantilever-like shapes."""
    mass = 1.8
    j = np.arange(n_modes)
    sign = np.where(j % 2 == 0, 1.0, -1.0)
    phi_c = sign * 2.0 / np.sqrt(mass)
    damping = np.full(n_modes, 1e-12) if undamped else np.array(_DAMPING[:n_modes])
    return ModalModel(
        frequencies_hz=np.array(_FREQUENCIES_HZ[:n_modes]), damping_ratios=damping,
        phi_wall_left=phi_c, phi_wall_right=phi_c, phi_tip=0.96 * phi_c,
        participation=np.sqrt(np.array(_EFFECTIVE_MASS_FRACTION[:n_modes]) * mass),
        source="tests: cantilever-like")
