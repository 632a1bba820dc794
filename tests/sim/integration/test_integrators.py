"""The integrators as records (sim.integration.integrators.INTEGRATORS): each says what it can do (dry friction, a step
scale, the contact laws it runs, its compile time), and the commands and studies ask the record instead of the name.

The toy record, registered inside the test only, runs ode3's kernels under another name but declares neither
friction nor a step scale and only the elastic law: `ies sweep` lists it, runs it, and refuses what it cannot do
with one line each, before any work."""
from __future__ import annotations

import json

import pytest

from sim.common.errors import SimulationInputError
from sim.integration.integrators import INTEGRATORS, Integrator, get_integrator, integrator_named
from sim.model.contact_law import ContactLaw
from sim.model.system import Impactor
from tests.support import FAST
from uq.cli import main

TOY = Integrator("toy", "sim.integration.ode3", "ode3's kernels, elastic only (test entry)", laws=("hertz",))


@pytest.fixture
def toy():
    """The toy record, registered by its one registry line for one test and removed after it."""
    INTEGRATORS[TOY.name] = TOY
    yield TOY
    del INTEGRATORS[TOY.name]


def test_the_shipped_records_state_their_capabilities():
    ode3, exact = integrator_named("ode3"), integrator_named("exact")
    assert ode3.friction and ode3.dt_scale and not exact.friction and not exact.dt_scale
    assert ode3.supports("hertz-damped") and exact.supports("hertz-damped")
    with pytest.raises(SimulationInputError, match="dt_scale applies only to ode3, not to 'exact'"):
        get_integrator("exact", dt_scale=0.5)
    with pytest.raises(SimulationInputError, match="dry friction .* is in the ode3 integrator only"):
        exact.check(Impactor(friction=0.07))
    ode3.check(Impactor(friction=0.07, contact_law=ContactLaw("hertz-damped", 0.9)))  # no complaint


def test_a_registered_integrator_reaches_ies_sweep_with_its_capabilities(toy, model_file, capsys):
    argv = ["sweep", "--level", "6", *FAST, "--model", model_file, "--integrator", "toy"]
    assert main([*argv, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["protocol"]["integrator"] == "toy"
    assert main(["sweep", "--level", "6", *FAST, "--model", model_file, "--integrator", "ode3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mean"] == data["mean"]  # ode3's kernels under another name
    for extra, phrase in ((["--r-cont", "0.9"], "the contact law 'hertz-damped' is not in the toy integrator; choose "
                                                "ode3 or exact"),
                          (["--friction", "0.07"], "dry friction (mu = 0.07, Appendix C) is in the ode3 integrator only"),
                          (["--dt-scale", "0.5"], "dt_scale applies only to ode3, not to 'toy'")):
        assert main([*argv, *extra]) == 2
        err = capsys.readouterr().err
        assert phrase in err and len(err.strip().splitlines()) == 1, err
    import argparse

    from sim.cli import add_sweep_arguments

    parser = argparse.ArgumentParser()
    add_sweep_arguments(parser)
    assert "toy (ode3's kernels, elastic only (test entry))" in " ".join(parser.format_help().split())
