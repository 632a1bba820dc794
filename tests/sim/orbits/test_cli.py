"""`ies orbits` end to end on a three-mode host (fast), its files against their column tables, and its bad inputs:
one line, exit 2 (a refused option) or 3 (a start that does not converge), nothing written."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from sim.orbits.tables import ORBITS_COLUMNS
from uq.cli import main

from tests.support import one_line


def test_the_frequency_response_of_a_three_mode_host(tmp_path, model_file, capsys):
    """The slow-flow start, the branch over the range with its multipliers, the files and their columns."""
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--eta", "0.95:0.955", "--switches", "0",
                 "--out", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert "branch 0 (slow-flow start; 1 T, symmetric)" in printed.out
    assert sorted(p.name for p in out.iterdir()) == ["orbits.csv", "orbits.json", "orbits.png", "results.nc"]
    with (out / "orbits.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert tuple(rows[0]) == ORBITS_COLUMNS
    impacting = [r for r in rows if r["origin"] != "linear solution"]
    etas = [float(r["eta"]) for r in impacting]
    assert min(etas) == pytest.approx(0.95) and max(etas) == pytest.approx(0.955)
    assert all(r["pattern"] == "RL" and float(r["impacts_per_period"]) == 2 for r in impacting)
    assert all(float(r["residual"]) < 1e-7 for r in rows)
    data = json.loads((out / "orbits.json").read_text())
    assert data["responses"][0]["branches"][0]["origin"] == "slow-flow start"
    import xarray as xr

    with xr.open_dataset(out / "results.nc", engine="h5netcdf") as ds:
        assert ds.sizes["orbit"] == len(rows)
        assert ds["amplitude"].attrs["units"] == "1" and ds["amplitude_m"].attrs["units"] == "m"
        mu = ds["multiplier_re"].values + 1j * ds["multiplier_im"].values
        assert np.abs(mu[:, 0]) == pytest.approx(ds["max_multiplier"].values, rel=1e-12)
        assert json.loads(ds.attrs["settings"])["command"] == "ies orbits"


def test_a_level_without_impacts_gives_the_linear_solution_and_says_so(tmp_path, model_file, capsys):
    out = tmp_path / "res"
    assert main(["orbits", "--model", model_file, "--level", "0.3", "--eta", "0.95:0.99", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "the response is the linear one" in printed and "linear solution" in printed
    with (out / "orbits.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert rows and all(float(r["impacts_per_period"]) == 0 for r in rows)


@pytest.mark.parametrize("options, phrase", [
    (["--max-period", "9"], "argument --max-period: must be an integer in 1..8"),
    (["--max-period", "0"], "argument --max-period"),
    (["--eta", "0.3:0.5"], "leaves 0.5..2"),
    (["--eta", "1.0:0.95"], "is empty or not positive"),
    (["--eta", "0.95"], "--eta must be a range LO:HI"),
    (["--contact-law", "coulomb"], "argument --contact-law: invalid choice"),
    (["--no-impactor"], "ies orbits needs the sphere"),
    (["--switches", "-1"], "argument --switches"),
    (["--level-curve", "0.976", "--level", "7.4"], "must be a range LO:HI"),
])
def test_bad_options_are_one_line_and_write_nothing(tmp_path, model_file, capsys, options, phrase):
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--out", str(out), *options])
    one_line(capsys, code, 2, phrase)
    assert not out.exists()


def test_a_sweep_folder_without_a_sweep_is_refused(tmp_path, model_file, capsys):
    (tmp_path / "empty").mkdir()
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--sweep", str(tmp_path / "empty"), "--out", str(out)])
    one_line(capsys, code, 2, "no sweep.csv there")
    assert not out.exists()


def test_a_start_that_does_not_converge_writes_what_it_tried_and_suggests_another(tmp_path, model_file, capsys):
    """A stepped-sine start in the strongly modulated response (no periodic orbit near): exit 3, one line naming the
    best residual and another start; start-attempts.json holds each k's start state, last iterate and residual."""
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--eta", "0.99:1.0", "--start", "simulation",
                 "--at", "1.0", "--max-period", "1", "--out", str(out)])
    line = one_line(capsys, code, 3, "residual", "--start slow-flow", "start-attempts.json")
    assert "numerical failure" in line
    assert sorted(p.name for p in out.iterdir()) == ["start-attempts.json"]
    data = json.loads((out / "start-attempts.json").read_text())
    (attempt,) = data["attempts"]
    assert attempt["k"] == 1 and attempt["residual"] > 1e-7 and len(attempt["start"]) == 8
    assert data["level"] == 7.4 and "--start slow-flow" in data["suggestion"]


def test_friction_is_refused_before_any_compilation(tmp_path, capsys, monkeypatch):
    """--friction with the ode3 integrator (which takes friction) on the built-in rig (which has the floor's mode
    values): refused in one line naming --friction, before the kernels are warmed up (compiled), nothing written."""
    import sim.integration.integrators as integrators

    def no_compiling(*args, **kwargs):
        raise AssertionError("compiled before refusing")

    monkeypatch.setattr(integrators, "warm_up", no_compiling)
    out = tmp_path / "res"
    code = main(["orbits", "--level", "7.4", "--friction", "0.07", "--integrator", "ode3", "--out", str(out)])
    line = one_line(capsys, code, 2, "--friction")
    assert "--mu" not in line
    assert not out.exists()


def test_a_sweep_of_another_level_is_refused(tmp_path, model_file, capsys):
    """A sweep folder of level 6 with --level 7.4: one line naming both levels, nothing written; with
    --level-curve a sweep is refused too."""
    sweep = tmp_path / "sweep6"
    sweep.mkdir()
    (sweep / "sweep.csv").write_text("eta,mean,mean_lo,mean_hi\n0.97,0.1,0.09,0.11\n")
    (sweep / "sweep.json").write_text(json.dumps({"level": 6.0}))
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--sweep", str(sweep), "--out", str(out)])
    one_line(capsys, code, 2, "level 6", "--level 7.4")
    code = main(["orbits", "--model", model_file, "--level", "5:9", "--level-curve", "0.97", "--sweep", str(sweep),
                 "--out", str(out)])
    one_line(capsys, code, 2, "--level-curve")
    assert not out.exists()


def test_the_rigs_first_mode_alone_has_its_stable_asymmetric_orbit_on_the_diagram(tmp_path, capsys):
    """The issue's case: the rig's first mode alone (`ies modes --n-modes 1 --save`) at level 7.4. The symmetric
    two-impact orbit loses its stability at a located symmetry breaking (eta 0.9553, not a Neimark-Sacker point),
    and the stable asymmetric period-T orbit beyond it (eta 0.95707, a/a_noabs* 0.08789, |mu| 0.99966; a direct
    simulation from the perturbed symmetric orbit settles on it) is on the diagram as stable. The independent
    reference for |mu|: DOP853 on the variational equations gives 0.99965711 for this orbit."""
    one = tmp_path / "one.toml"
    assert main(["modes", "--n-modes", "1", "--save", str(one)]) == 0
    out = tmp_path / "res"
    assert main(["orbits", "--model", str(one), "--level", "7.4", "--eta", "0.953:0.958", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "symmetry-breaking at eta 0.9552" in printed and "loses stability" in printed
    with (out / "orbits.csv").open(newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["origin"] != "linear solution"]
    breaking = [r for r in rows if r["bifurcation"] == "symmetry-breaking"]
    assert breaking and float(breaking[0]["location_error"]) < 1e-4
    asymmetric = sorted((float(r["eta"]), float(r["amplitude"]), r) for r in rows
                        if r["symmetric"] == "0" and r["period_multiple"] == "1")
    below = [a for a in asymmetric if a[0] <= 0.95707]
    above = [a for a in asymmetric if a[0] > 0.95707]
    assert below and above
    (x0, y0, r0), (x1, y1, r1) = max(below, key=lambda a: a[0]), min(above, key=lambda a: a[0])
    assert x1 - x0 < 2e-3 and r0["stable"] == r1["stable"] == "1"
    assert y0 + (0.95707 - x0) / (x1 - x0) * (y1 - y0) == pytest.approx(0.08789, abs=2e-4)
    assert 0.9995 < float(r0["max_multiplier"]) < 1.0


def test_the_budget_of_switchings_and_searches_is_the_users(tmp_path, capsys):
    """`--budget 0` leaves the switching at the located symmetry breaking and the searches undone, says so and
    records the budget; the default budget finds the stable asymmetric orbit (the test above)."""
    one = tmp_path / "one.toml"
    assert main(["modes", "--n-modes", "1", "--save", str(one)]) == 0
    out = tmp_path / "res"
    assert main(["orbits", "--model", str(one), "--level", "7.4", "--eta", "0.953:0.958", "--budget", "0",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "symmetry-breaking at eta 0.9552" in printed
    assert "the response's 0 map runs for switchings and searches (--budget)" in printed
    with (out / "orbits.csv").open(newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["origin"] != "linear solution"]
    assert rows and all(r["symmetric"] == "1" for r in rows)  # the asymmetric branch was not reached
    assert json.loads((out / "orbits.json").read_text())["budget"] == 0
    one_line(capsys, main(["orbits", "--model", str(one), "--level", "7.4", "--budget", "-1", "--out",
                           str(tmp_path / "x")]), 2, "--budget")
