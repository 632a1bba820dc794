"""sim.integration.integrators.warm_up: the kernels are compiled before a progress bar starts, and a slow (first) compilation
says so while it happens."""
import io
import time

import numpy as np
import pytest

from sim.integration import integrators


@pytest.fixture(autouse=True)
def fresh(monkeypatch):
    monkeypatch.setattr(integrators, "_WARM", set())


def test_a_slow_warm_up_says_that_it_compiles_while_it_happens(monkeypatch):
    said_during = []
    stream = io.StringIO()

    def slow_compile(run_step):
        time.sleep(0.5)
        said_during.append(stream.getvalue())

    monkeypatch.setattr(integrators, "NOTICE_AFTER_S", 0.1)
    monkeypatch.setattr(integrators, "_run_tiny_system", slow_compile)
    assert integrators.warm_up("exact", stream=stream) >= 0.5
    assert said_during == ["compiling the exact integrator's kernels (first run only, about "
                           f"{integrators.COMPILE_MINUTES['exact']} min) ...\n"]
    assert stream.getvalue().splitlines()[-1].startswith("kernels compiled in ")
    assert integrators.warm_up("exact", stream=stream) == 0.0  # once per process


def test_a_quick_warm_up_is_silent(monkeypatch):
    stream = io.StringIO()
    calls = []
    monkeypatch.setattr(integrators, "_run_tiny_system", calls.append)
    integrators.warm_up("ode3", stream=stream)
    assert stream.getvalue() == "" and len(calls) == 1


@pytest.mark.parametrize("name", integrators.available())
def test_the_tiny_system_impacts(name):
    """The warm-up run reaches a contact, so the contact kernels are compiled too."""
    record = {}
    run_step = integrators.get_integrator(name)

    def counting(y, n, Omega, a_base, sys, rec):
        record["out"] = run_step(y, n, Omega, a_base, sys, rec)
        return record["out"]

    integrators._run_tiny_system(counting)
    amplitudes, impacts = record["out"]
    assert np.sum(impacts) > 0 and np.all(np.isfinite(amplitudes))


def test_an_unknown_integrator_is_refused_before_anything_runs():
    from sim.common.errors import SimulationInputError

    with pytest.raises(SimulationInputError, match="unknown integrator 'rk4'"):
        integrators.warm_up("rk4")
