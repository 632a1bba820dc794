"""The vocabulary of the paper's quantities (`sim.model.parameters`) and its seam: a new physical input of the impactor
is one row of `PARAMETERS` and one registry line.

The toy input, defined and registered inside the test only, is the sphere's undersize dR (m): a sphere ground dR below
the paper's radius R = 7.92 mm (Sect. 2) in the same cavity has the clearance g + dR, the mass m_a (1 - dR/R)^3 and,
by Eq. 8, the Hertz constant k_H sqrt(1 - dR/R). Its row says so (`Feed(derive=...)`), gives it an option with a
unit, a study key, bounds (>= 0) and a spread of 0 .. 5 um for `ies design`'s uncertainty box; it then runs end to
end through `ies sweep` (its JSON key, the impactor's values against those closed forms), an interval study that
varies it, and `ies design`, whose box gains its dimension (16 corners instead of 8).

Files a new physical input touches: the file that defines its row (here this test) and the registry line.
"""
from __future__ import annotations

import json
import math
from dataclasses import replace

import pytest

from sim.common.units import LENGTH_UNITS, Quantity
from sim.model.parameters import (CLEARANCE_NOMINAL, K_H_NOMINAL, PARAMETERS, SPHERE_MASS, SPHERE_RADIUS, CliOption,
                                  Feed, Spread, SystemSettings, UncertainParameter, register_parameter)
from tests.support import interval_runs, tiny_design
from uq.cli import main


def undersized(settings: SystemSettings, dR: float) -> SystemSettings:
    """A sphere dR (m) below the paper's radius in the same cavity: more clearance, less mass, a softer contact."""
    shrink = (SPHERE_RADIUS - dR) / SPHERE_RADIUS
    return replace(settings, clearance=settings.clearance + dR, mass=settings.mass * shrink**3,
                   k_H=settings.k_H * math.sqrt(shrink))


UNDERSIZE = UncertainParameter(
    "dR", "m", "sphere undersize dR", 0.0, (0.0, 5e-6), Feed(derive=undersized), "undersize", positive=False,
    quantity=Quantity("sphere undersize dR", "m", LENGTH_UNITS, (1e-8, 1e-3), "5um"), spread=Spread("absolute", 0.0, 5e-6),
    option=CliOption("--undersize", "DR", "how far the sphere's radius lies below the paper's 7.92 mm (m, or with a unit)"))


@pytest.fixture
def undersize():
    """The toy row, registered by its one registry line for one test and removed after it."""
    saved = dict(PARAMETERS)
    register_parameter(UNDERSIZE)
    yield UNDERSIZE
    PARAMETERS.clear()
    PARAMETERS.update(saved)


def test_table2_and_its_spreads_are_the_papers_numbers():
    """Table 2 bit for bit: D 0.075-0.090 %, g 0.580-0.612 mm, k_H 282e3-428e3 N/mm^1.5, each its spread around
    the nominal value (the design's box carries them to other spheres)."""
    n_per_mm15 = 1e3**1.5
    assert PARAMETERS["D"].interval == (0.00075, 0.00090) and PARAMETERS["D"].nominal == 0.00085
    assert PARAMETERS["g"].interval == (0.58e-3, 0.612e-3) and PARAMETERS["g"].nominal == CLEARANCE_NOMINAL
    assert PARAMETERS["k_H"].interval == (282e3 * n_per_mm15, 428e3 * n_per_mm15)
    assert PARAMETERS["k_H"].spread.centre(K_H_NOMINAL) == pytest.approx(355e3 * n_per_mm15, rel=1e-15)
    assert [row.name for row in PARAMETERS.values() if row.spread is not None] == ["D", "g", "k_H"]


def test_every_rule_is_the_rows_on_the_command_line_and_in_study_files():
    """One check per row (`UncertainParameter.problem`): the same sentence whichever way a value arrives."""
    assert PARAMETERS["D"].problem(1.5) == "D must lie in (0, 1): must be below 1 (a damping ratio, e.g. 0.00085 or 0.085%), got 1.5"
    assert PARAMETERS["D"].problem(0.0).startswith("D must lie in (0, 1): must be > 0")
    assert PARAMETERS["r_cont"].problem(1.0) is None and "must be at most 1" in PARAMETERS["r_cont"].problem(1.2)
    assert PARAMETERS["friction"].problem(0.0) is None
    assert PARAMETERS["friction"].problem(-0.1).startswith("the friction coefficient mu must be >= 0")
    assert PARAMETERS["g"].problem(float("nan")).startswith("clearance g must be a positive number")
    assert PARAMETERS["g"].parse("0.6mm") == pytest.approx(0.6e-3, rel=1e-15)
    assert "did you mean 0.58mm" in PARAMETERS["g"].implausible(0.58)


def test_a_new_input_reaches_the_impactor_through_ies_sweep(undersize, model_file, capsys):
    argv = ["sweep", "--level", "7.4", "--eta", "0.99", "--wait", "0.02", "--hold", "0.05", "--reps", "1",
            "--model", model_file, "--json"]
    assert main([*argv, "--undersize", "5um"]) == 0
    impactor = json.loads(capsys.readouterr().out)["impactor"]
    shrink = 1.0 - 5e-6 / 7.92e-3
    assert impactor["dR_m"] == pytest.approx(5e-6, rel=1e-15)
    assert impactor["g_m"] == pytest.approx(0.58e-3 + 5e-6, rel=1e-14)
    assert impactor["mass_kg"] == pytest.approx(0.0177 * shrink**3, rel=1e-14)
    assert impactor["k_H_N_per_m1p5"] == pytest.approx(282e3 * 1e3**1.5 * math.sqrt(shrink), rel=1e-14)
    assert main(argv) == 0  # not given: the paper's sphere, no key of its own
    nominal = json.loads(capsys.readouterr().out)["impactor"]
    assert "dR_m" not in nominal and nominal["mass_kg"] == SPHERE_MASS
    assert main([*argv, "--undersize=-1um"]) == 2
    assert "argument --undersize: dR must be >= 0, got -1e-06" in capsys.readouterr().err


def test_a_study_varies_the_new_input(undersize, model_file, tmp_path):
    out, runs = interval_runs(tmp_path, f"modal_model = '{model_file}'\n[parameters.undersize]\nmax = '5um'\n")
    assert sorted({float(r["dR_m"]) for r in runs}) == pytest.approx([0.0, 5e-6], rel=1e-15)
    meta = json.loads((out / "study.json").read_text())
    assert meta["study"]["parameters"]["dR"]["label"] == "sphere undersize dR"


def test_the_designs_box_gains_the_new_inputs_dimension(undersize, model_file, tmp_path):
    """The box is built from the rows: D, g, k_H (the options) and the toy's own spread, 2^4 corners and the centre;
    `ies design` verifies every one of them."""
    from uq.design import problem as dp

    problem = dp.DesignProblem(excitation=(3e-6,), clearances=(0.58e-3,), radii=(7.92e-3,))
    sphere = problem.grid()[0]
    points = problem.corners(sphere)
    assert len(points) == 17 and {p["dR"] for p in points[:-1]} == {0.0, 5e-6} and points[-1]["dR"] == 2.5e-6
    assert {p["g"] for p in points[:-1]} == {0.58e-3, 0.58e-3 + 0.032e-3}
    data = tiny_design(tmp_path, model_file)
    # every box point at the level and the margin level (one run each; more where uq.design.search.settle repeats the
    # cells that decide the worst case), the toy's dimension among the deciding cells' coordinates
    assert data["verified"] and all(v["runs"] >= 17 * 2 for v in data["verified"])
    assert {d["point"]["dR"] for v in data["verified"] for d in v["deciding"]} <= {0.0, 5e-6}
