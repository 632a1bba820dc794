"""`ies design` (uq.design): end to end on a tiny stepped sine, resumable, identical serially and in parallel, and
each bad input refused with one line, exit 2, nothing written (issue 28)."""
import csv
import json

import numpy as np
import pytest

from uq.design import problem as dp, results as dr, search as ds
from uq.cli import main

TINY = """[study]
kind = "design"
output = "{out}"
[design]
excitation = "3um:6um:2"
clearance = "0.4mm:0.7mm:4"
radius = "6mm:7.92mm:2"
material = "brass,tungsten"
candidates = 1
reps = 1
baseline = "0.58mm,7.92mm,brass"
[excitation]
eta = {{ start = 0.97, stop = 1.0, n = 3 }}
wait = 0.2
hold = 0.2
"""


def exit_code(argv):
    """main's exit code, whether it returns it or argparse raises SystemExit."""
    try:
        return main(argv)
    except SystemExit as stop:
        return stop.code


def tiny_study(tmp_path, name="tiny.toml"):
    path = tmp_path / name
    path.write_text(TINY.format(out=tmp_path / "out"))
    return path


@pytest.mark.slow
def test_a_tiny_design_end_to_end_resumes_and_is_the_same_in_parallel(tmp_path, capsys):
    study = tiny_study(tmp_path)
    assert main(["design", str(study), "--jobs", "1", "--quiet"]) == 0
    printed = capsys.readouterr().out
    out = tmp_path / "out"
    assert {p.name for p in out.iterdir()} >= {"design.csv", "design.json", "design-levels.csv", "design-map.png",
                                               "design-map.pdf", "design-curves.png", "design-curves.pdf", "tasks",
                                               "results.nc"}
    data = json.loads((out / "design.json").read_text())
    assert set(data) == set(dr.DESIGN_KEYS)
    best = data["recommendation"]
    assert printed.strip().splitlines()[-2].startswith("recommendation: clearance ")
    assert best["sentence"] in printed
    # the recommendation is verified and the best verified design; the baseline is verified too
    worst = [v["worst_m"] for v in data["verified"]]
    assert best["worst_m"] == min(worst) and data["baseline"]["worst_m"] >= best["worst_m"]
    assert data["baseline"]["clearance_m"] == pytest.approx(0.58e-3)
    with open(out / "design.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == list(dr.DESIGN_CSV.names)
    assert sum(r["status"] != "screened" for r in rows) == len(data["verified"])
    assert all(float(r["cavity_m"]) == pytest.approx(2 * (float(r["radius_m"]) + float(r["clearance_m"])))
               for r in rows)
    # results.nc holds the same numbers as design-levels.csv
    from uq.outputs.results import open_study

    ds = open_study(out)
    with open(out / "design-levels.csv") as f:
        levels = list(csv.DictReader(f))
    assert ds["high"].values.ravel().tolist() == pytest.approx([float(r["high_m"]) for r in levels], rel=1e-12)
    assert ds["high"].attrs["units"] == "m" and ds.attrs["recommendation"] == best["sentence"]
    # every verified design: 8 corners + the centre, at 2 levels, 1 repetition
    assert all(v["runs"] == 9 * 2 for v in data["verified"])
    # the worst case is in metres: below the structure without IES at the top of the range
    assert best["worst_m"] < max(data["no_absorber"]["tip_m"])
    # --resume runs nothing again and gives the same numbers; in parallel too
    assert main(["design", str(study), "--jobs", "1", "--quiet", "--resume", "--no-figures"]) == 0
    again = json.loads((out / "design.json").read_text())
    assert again["verified"] == data["verified"]
    assert main(["design", str(study), "--jobs", "2", "--quiet", "--out", str(tmp_path / "par"), "--no-figures"]) == 0
    parallel = json.loads((tmp_path / "par" / "design.json").read_text())
    assert parallel["verified"] == data["verified"]


def test_ranges_read_units_counts_and_accelerations():
    assert dp.parse_range("0.2mm:1.2mm:6", "clearance", count=10) == pytest.approx((2e-4, 4e-4, 6e-4, 8e-4, 1e-3,
                                                                                    1.2e-3))
    assert dp.parse_range("7.92mm", "radius", count=4) == (pytest.approx(7.92e-3),)
    assert len(dp.parse_range("2um:8um", "excitation", count=10)) == 10
    omega = 2 * np.pi * 10.0
    assert dp.parse_range("1m/s2:4m/s2:2", "excitation", count=10, omega=omega) == pytest.approx(
        (1 / omega**2, 4 / omega**2))


@pytest.mark.parametrize("args, phrase", [
    (["--excitation", "8um:2um"], "the range is reversed"),
    (["--excitation", "2um:8um:0"], "COUNT must be >= 1"),
    (["--excitation", "2:8"], "has no unit"),
    (["--excitation", "2m:8m"], "implausible"),
    (["--excitation", "2parsec:8um"], "unknown unit"),
    (["--excitation", "2um:8um", "--clearance=-0.5mm:1mm"], "must be > 0"),
    (["--excitation", "2um:8um", "--material", "gold"], "unknown sphere material 'gold'"),
    (["--excitation", "2um:8um", "--radius", "9mm:12mm"], "no design fits"),
    (["--excitation", "2um:8um", "--baseline", "0.58mm,9mm,brass"], "--baseline"),
    (["--excitation", "2um:8um", "--damping", "0.0009:0.0007"], "LOW <= HIGH"),
    (["--excitation", "0.01um:0.02um"], "never reaches the clearance"),
    (["--excitation", "2um:8um", "--model", "nothere.toml"], "--model"),
    (["--clearance", "0.5mm"], "--excitation is required"),
])
def test_each_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, args, phrase):
    out = tmp_path / "out"
    assert exit_code(["design", *args, "--out", str(out), "--jobs", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert phrase in err and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()


def test_a_study_file_with_an_unknown_key_or_kind_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\nkind = "design"\n[design]\nexcitation = "2um:8um"\nclearence = "1mm"\n')
    assert exit_code(["design", str(bad)]) == 2
    assert "unknown key(s) in [design]: clearence" in capsys.readouterr().err
    bad.write_text('[study]\nkind = "interval"\n')
    assert exit_code(["design", str(bad)]) == 2
    assert 'kind must be "design"' in capsys.readouterr().err


def test_the_screening_is_worst_over_the_damping_interval_and_ranks_designs():
    problem = dp.DesignProblem(excitation=(2e-6, 6e-6), clearances=(0.3e-3, 0.58e-3), radii=(6e-3, 7.92e-3))
    mode = dp.host_mode(dp.host_model(problem))
    screened = ds.screen_designs(problem, mode)
    low_damping = ds.screen_designs(dp.DesignProblem(excitation=problem.excitation, clearances=problem.clearances,
                                                   radii=problem.radii, D=(0.0009, 0.0009),
                                                   clearance_tolerance=(0.0, 0.0)), mode)
    assert np.all(screened.tip >= low_damping.tip - 1e-15)
    chosen = ds.candidates(problem, screened)
    assert chosen[0] == screened.designs[int(np.argmin(screened.worst))]


def test_a_host_whose_first_mode_does_not_move_the_walls_is_refused(tmp_path, capsys):
    from sim.hosts.modal_file import save_modal_model
    from sim.model.system import ModalModel

    still = ModalModel(frequencies_hz=np.array([117.4, 2494.0]), damping_ratios=np.array([0.00085, 0.0005]),
                       phi_wall_left=np.array([0.0, 0.95]), phi_wall_right=np.array([0.0, 0.95]),
                       phi_tip=np.array([1.0, 0.8]), participation=np.array([0.95, 0.35]), source="walls at a node")
    path = save_modal_model(still, tmp_path / "node.toml")
    out = tmp_path / "out"
    assert exit_code(["design", "--excitation", "2um:8um", "--model", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "the host model cannot be designed for" in err and len(err.splitlines()) == 1 and not out.exists()


def test_a_calibration_sets_the_upper_end_of_the_k_H_factor(tmp_path, capsys):
    import argparse

    from uq.commands.design import add_design_arguments, design_problem
    from uq.problem.space import K_H_STAR

    parser = argparse.ArgumentParser()
    add_design_arguments(parser)
    calibration = tmp_path / "cal.json"
    calibration.write_text(json.dumps({"k_H": 1.4 * K_H_STAR}))
    problem, _, _ = design_problem(parser.parse_args(["--excitation", "2um:8um", "--calibration", str(calibration)]))
    assert problem.k_H_factor == pytest.approx((1.0, 1.4))
    soft = tmp_path / "soft.json"
    soft.write_text(json.dumps({"k_H": 0.9 * K_H_STAR}))
    assert exit_code(["design", "--excitation", "2um:8um", "--calibration", str(soft), "--out", str(tmp_path / "o")]) == 2
    assert "a crater should stiffen the contact" in capsys.readouterr().err
