"""Test-wide settings: in CI (CI=true) hypothesis runs derandomized, so a green run is reproducible."""
import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


def pytest_sessionstart(session) -> None:
    """Compile (or load) the integrators' kernels once, quietly, before the tests: a cold numba cache would otherwise
    put the first run's "compiling ..." notice on the stderr of whichever command test comes first, and the tests
    that check a command's one-line messages would depend on their order. The notice itself is tested in
    tests/sim/test_warm_up.py."""
    import io

    from sim.integration.integrators import available, warm_up_all
    from sim.model.contact_law import LAWS

    warm_up_all([(name, law) for name in available() for law in LAWS], stream=io.StringIO())
