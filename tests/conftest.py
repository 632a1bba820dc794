"""Test-wide settings: in CI (CI=true) hypothesis runs derandomized, so a green run is reproducible."""
import os

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session) -> None:
    """Compile (or load) the integrators' kernels once, quietly, before the tests: a cold numba cache would otherwise
    put the first run's "compiling ..." notice on the stderr of whichever command test comes first, and the tests
    that check a command's one-line messages would depend on their order. The notice itself is tested in
    tests/sim/integration/test_warm_up.py. With pytest-xdist (`-n`) this runs first in the controller, before xdist
    starts the workers (in its own, later, session start: tryfirst here), so each worker only loads the kernels from the
    cache (seconds) instead of both compiling them at once."""
    import io

    from sim.integration.integrators import available, warm_up_all
    from sim.model.contact_law import LAWS

    warm_up_all([(name, law) for name in available() for law in LAWS], stream=io.StringIO())


def pytest_xdist_auto_num_workers(config) -> int | None:
    """`-n auto` (pyproject's addopts) means one worker per core, except for a run that selects the benchmarks
    (`-m benchmark`): those time themselves and need the cores to themselves, so they run in one process."""
    import re

    if re.search(r"(?<!not )\bbenchmark\b", config.option.markexpr or ""):
        return 0
    return None


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
