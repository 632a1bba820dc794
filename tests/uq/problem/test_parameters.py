"""The parameter seam (issue 27): one row of `sim.model.parameters.PARAMETERS` is all a new parameter needs.

The toy row, added inside the test only, scales the sphere's mass; a tiny interval study lists it under its study
key [parameters.mass_scale] and runs through `ies interval` end to end (study file, parameter space, response
model, impactor builder, runner, bands), and `ies sweep` gains its option. References that are not our code: the
mass the impactor is built with is m_a = 0.0177 kg (Table 1) times the row's value.
"""
from __future__ import annotations

import csv
import json

import pytest

from sim.model.parameters import PARAMETERS, SPHERE_MASS, CliOption, Feed, UncertainParameter
from uq.cli import main

TOY = UncertainParameter("sphere_mass_scale", "-", "sphere mass / m_a", 1.0, (1.0, 1.5), Feed("mass", scale=True),
                         "mass_scale", option=CliOption("--sphere-mass-scale", "X", "sphere mass over m_a"))


@pytest.fixture
def toy_row(monkeypatch: pytest.MonkeyPatch) -> UncertainParameter:
    monkeypatch.setitem(PARAMETERS, TOY.name, TOY)
    return TOY


def test_the_toy_row_feeds_the_impactor_builder(toy_row: UncertainParameter) -> None:
    from uq.problem.models import ResponseModel, make_model

    model = make_model("ies", variant={"sphere_mass_factor": 1.2})
    assert isinstance(model, ResponseModel)
    assert toy_row.name in model.optional_parameters
    point = {"D": 0.00085, "g": 0.58e-3, "k_H": 8.9e9}
    assert model.simulated_system(point)[1].mass == pytest.approx(1.2 * SPHERE_MASS)
    assert model.simulated_system({**point, toy_row.name: 1.5})[1].mass == pytest.approx(1.5 * 1.2 * SPHERE_MASS)


def test_a_tiny_interval_study_varies_the_toy_row(toy_row: UncertainParameter, tmp_path) -> None:
    study = tmp_path / "toy.toml"
    study.write_text("[study]\nkind = 'interval'\nrepetitions = 1\n[parameters.mass_scale]\nmin = 1.0\n"
                     "max = 1.5\n[excitation]\nlevels = [7.4]\neta = { start = 0.975, stop = 0.98, n = 2 }\n"
                     "wait = 0.1\nhold = 0.1\n[interval]\ninterior = 0\n")
    out = tmp_path / "o"
    assert main(["interval", str(study), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    meta = json.loads((out / "study.json").read_text())
    assert meta["study"]["parameters"]["sphere_mass_scale"] == {"nominal": 1.0, "min": 1.0, "max": 1.5, "unit": "-",
                                                               "label": "sphere mass / m_a"}
    with open(out / "runs.csv", newline="") as fh:
        runs = list(csv.DictReader(fh))
    scales = {float(r["sphere_mass_scale"]) for r in runs}
    assert scales == {1.0, 1.5}
    by_scale = {float(r["sphere_mass_scale"]): float(r["mean"]) for r in runs}
    assert by_scale[1.0] != by_scale[1.5]  # a heavier sphere changes the resonant level
    with open(out / "bands.csv", newline="") as fh:
        bands = [r for r in csv.DictReader(fh) if r["design"] == "individual:sphere_mass_scale" and r["output"] == "mean"]
    assert len(bands) == 1 and float(bands[0]["lower"]) <= float(bands[0]["upper"])


def test_the_toy_row_is_an_option_of_ies_sweep(toy_row: UncertainParameter) -> None:
    import argparse

    from sim.cli import add_sweep_arguments, build_system

    parser = argparse.ArgumentParser()
    add_sweep_arguments(parser)
    args = parser.parse_args(["--level", "5", "--sphere-mass-scale", "2"])
    assert build_system(args)[1].mass == pytest.approx(2 * SPHERE_MASS)
