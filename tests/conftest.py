"""Test-wide settings: in CI (CI=true) hypothesis runs derandomized, so a green run is reproducible."""
import os

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


def pytest_sessionstart(session) -> None:
    """Compile (or load) the integrators' kernels once, quietly, before the tests: a cold numba cache would otherwise
    put the first run's "compiling ..." notice on the stderr of whichever command test comes first, and the tests
    that check a command's one-line messages would depend on their order. The notice itself is tested in
    tests/sim/integration/test_warm_up.py."""
    import io

    from sim.integration.integrators import available, warm_up_all
    from sim.model.contact_law import LAWS

    warm_up_all([(name, law) for name in available() for law in LAWS], stream=io.StringIO())


@pytest.fixture
def model_file(tmp_path) -> str:
    """A three-mode model with the rig's scales (as tests/sim's fixture) as a modal-model file: fast sweeps."""
    import numpy as np

    from sim.hosts.modal_file import save_modal_model
    from sim.model.system import ModalModel

    model = ModalModel(frequencies_hz=np.array([117.4, 2494.0, 19800.0]), damping_ratios=np.array([0.00085, 0.0005, 0.001]),
                       phi_wall_left=np.array([1.05, 0.95, 0.6]), phi_wall_right=np.array([1.05, 0.95, 0.6]),
                       phi_tip=np.array([1.0, 0.8, 0.3]), participation=np.array([0.95, 0.35, 0.1]), source="three modes")
    return str(save_modal_model(model, tmp_path / "three.toml"))
