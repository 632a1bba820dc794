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


def one_line(capsys, code: int, expected: int, *phrases: str) -> str:
    err = capsys.readouterr().err
    assert code == expected, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    for phrase in phrases:
        assert phrase in err, err
    return err


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


def test_a_start_that_does_not_converge_names_the_residual_and_what_to_try(tmp_path, model_file, capsys):
    """A stepped-sine start in the strongly modulated response (no periodic orbit near): exit 3, nothing written."""
    out = tmp_path / "res"
    code = main(["orbits", "--model", model_file, "--level", "7.4", "--eta", "0.99:1.0", "--start", "simulation",
                 "--at", "1.0", "--max-period", "1", "--out", str(out)])
    line = one_line(capsys, code, 3, "residual", "start closer")
    assert "numerical failure" in line
    assert not out.exists()
