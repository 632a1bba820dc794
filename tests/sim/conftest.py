"""Small hand-made modal models for the simulator's physics tests (shared by tests/sim).

They are not the rig: they have the rig's scales (f1 = 117.4 Hz, highest mode ~20 kHz, beam-like mode
values) so that step sizes, damping and contact time scales are realistic, but few modes so tests are fast.
"""
import numpy as np
import pytest

from sim.model.system import ModalModel


@pytest.fixture
def three_mode_model() -> ModalModel:
    """Three beam-like modes: 117.4 Hz (D = 0.085 %), 2494 Hz, 19.8 kHz; walls at the tip."""
    return ModalModel(
        frequencies_hz=np.array([117.4, 2494.0, 19800.0]),
        damping_ratios=np.array([0.00085, 0.0005, 0.001]),
        phi_wall_left=np.array([1.05, 0.95, 0.6]),
        phi_wall_right=np.array([1.05, 0.95, 0.6]),
        phi_tip=np.array([1.0, 0.8, 0.3]),
        participation=np.array([0.95, 0.35, 0.1]),
        source="three-mode test model",
    )


@pytest.fixture
def rigid_wall_model() -> ModalModel:
    """One mode that the walls do not see (phi = 0 at the walls): the sphere meets rigid walls."""
    return ModalModel(
        frequencies_hz=np.array([100.0]), damping_ratios=np.array([0.01]), phi_wall_left=np.array([0.0]),
        phi_wall_right=np.array([0.0]), phi_tip=np.array([1.0]), participation=np.array([1.0]), source="rigid walls",
    )
