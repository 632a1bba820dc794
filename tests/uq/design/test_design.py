"""`ies design` (uq.design): end to end on a tiny stepped sine, resumable, identical serially and in parallel; the
search on analytic stand-ins (same recommendation whatever the first batch, neighbours on every axis, the margin);
each bad input refused with one line, exit 2, nothing written; and a new objective added inside a test (one row)
running `ies design` end to end."""
import csv
import json
import math
import time

import numpy as np
import pytest

from uq.cli import main
from uq.design import objectives as do, prediction as dq, problem as dp, results as dr, search as ds
from uq.errors import StudyError

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


#: one sphere, two clearances: the smallest design a search walks (the objective's extension test)
SMALL = TINY.replace('clearance = "0.4mm:0.7mm:4"', 'clearance = "0.4mm:0.5mm:2"').replace(
    'radius = "6mm:7.92mm:2"', 'radius = "7.92mm"').replace('material = "brass,tungsten"', 'material = "tungsten"').replace(
    'baseline = "0.58mm,7.92mm,brass"\n', "")


def exit_code(argv):
    """main's exit code, whether it returns it or argparse raises SystemExit."""
    try:
        return main(argv)
    except SystemExit as stop:
        return stop.code


def tiny_study(tmp_path, name="tiny.toml", text=TINY):
    path = tmp_path / name
    path.write_text(text.format(out=tmp_path / "out"))
    return path


@pytest.mark.slow
def test_a_tiny_design_end_to_end_resumes_and_is_the_same_in_parallel(tmp_path, capsys):
    study = tiny_study(tmp_path)
    assert main(["design", str(study), "--jobs", "1", "--quiet"]) == 0
    printed = capsys.readouterr().out
    out = tmp_path / "out"
    written = {p.name for p in out.iterdir()}
    assert written >= {"design.csv", "design.json", "design-levels.csv", "design-map.png", "design-map.pdf",
                       "design-curves.png", "design-curves.pdf", "tasks", "results.nc"}
    # every file written is named, as every other command does
    assert f"results in {out}/" in printed and all(f"  {name}\n" in printed for name in written - {"tasks"})
    data = json.loads((out / "design.json").read_text())
    assert set(data) == set(dr.DESIGN_KEYS)
    best = data["recommendation"]
    assert next(line for line in printed.splitlines() if line.startswith("recommendation: clearance "))
    assert best["sentence"] in printed and "margin" in best["sentence"]
    # the recommendation is verified, admissible, and the best admissible verified design; the baseline is verified too
    admissible = [v for v in data["verified"] if v["admissible"]]
    assert best["admissible"] and best["worst_m"] == min(v["worst_m"] for v in admissible)
    assert best["margin_worst"] >= data["settings"]["margin"]
    assert data["baseline"]["clearance_m"] == pytest.approx(0.58e-3)
    # every verified design has its prediction beside its verification, and its round
    assert all(v["predicted_worst_m"] > 0 and v["switch_worst_m"] > 0 and v["round"] >= 0 for v in data["verified"])
    assert data["search"]["rounds"][0] and data["search"]["stop"] and data["similarity"]
    # one name per quantity: no key both with and without _m, the slow flow's as screened_*
    for v in data["verified"]:
        assert not {k for k in v if k + "_m" in v}, v.keys()
    # the worst case with its interval, the cells deciding it (with extra repetitions for the recommendation)
    low, high = best["worst_interval_m"]
    assert low < high and low <= best["worst_m"] * 1.5 and high >= best["worst_m"] * 0.5
    assert best["deciding"] and max(c["runs"] for c in best["deciding"]) >= 2 * data["settings"]["repetitions"]
    assert data["search"]["settling"]["text"] and data["settings"]["apr_rule"] == "any run"
    # the check: an ies sweep line with the sphere, the clearance and the level as a base amplitude
    check = best["check_command"]
    assert check.startswith("ies sweep --level ") and "um --radius " in check and f"--material {best['material']}" in check
    assert "--g " in check and "--wall-material steel" in check and f"check it: {check}" in printed
    import shlex

    assert main([*shlex.split(check)[1:], "--out", str(tmp_path / "check")]) == 0  # it runs as printed
    # normalised by the host's own D_1* (the rig: Table 2's 0.085 %), the box's D interval from the host, both stated
    assert data["host"]["D_star"] == pytest.approx(0.00085) and data["no_absorber"]["D_1"] == pytest.approx(0.00085)
    assert data["host"]["normalisation"]["D_star"] == pytest.approx(0.00085) and "box: D_1 0.075-0.09 %" in printed
    with open(out / "design.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == list(dr.DESIGN_CSV.names)
    assert sum(r["status"] != "screened" for r in rows) == len(data["verified"])
    assert all(float(r["cavity_m"]) == pytest.approx(2 * (float(r["radius_m"]) + float(r["clearance_m"])))
               for r in rows)
    assert all(r["margin_worst"] and r["switch_worst_m"] and r["worst_interval_low_m"] for r in rows
               if r["status"] != "screened")
    assert not any(cell == "None" for r in rows for cell in r.values())  # empty cells, not None
    with open(out / "design-levels.csv") as f:
        assert "None" not in f.read()
    # results.nc holds the same numbers as design-levels.csv
    from uq.outputs.results import open_study

    nc = open_study(out)
    with open(out / "design-levels.csv") as f:
        levels = [r for r in csv.DictReader(f) if r["role"] == "operating"]
    assert nc["high"].values.ravel().tolist() == pytest.approx([float(r["high_m"]) for r in levels], rel=1e-12)
    assert nc["high"].attrs["units"] == "m" and nc.attrs["recommendation"] == best["sentence"]
    # every verified design: 8 corners + the centre, at 2 operating levels and the margin level, 1 repetition
    assert all(v["runs"] >= 9 * 3 for v in data["verified"]) and any(v["runs"] == 9 * 3 for v in data["verified"])
    # the worst case is in metres: below the structure without IES at the top of the range
    assert best["worst_m"] < max(data["no_absorber"]["tip_m"])
    # --resume runs nothing again and gives the same numbers; in parallel too
    assert main(["design", str(study), "--jobs", "1", "--quiet", "--resume", "--no-figures"]) == 0
    again = json.loads((out / "design.json").read_text())
    assert again["verified"] == data["verified"]
    assert main(["design", str(study), "--jobs", "2", "--quiet", "--out", str(tmp_path / "par"), "--no-figures"]) == 0
    parallel = json.loads((tmp_path / "par" / "design.json").read_text())
    assert parallel["verified"] == data["verified"]


def rms_acceleration(record, omega_1):
    """The toy objective's value of one run: the RMS of the tip's fundamental acceleration at the resonant frequency,
    (eta omega_1)^2 |c_1| / sqrt(2), from the run's per-frequency trace (m/s^2)."""
    if record.get("error") or "trace" not in record:
        return math.nan
    trace = record["trace"]
    k = int(np.argmax(trace["mean"]))
    return (trace["eta"][k] * omega_1) ** 2 * trace["mean"][k] * trace["a_noabs"] / math.sqrt(2.0)


@pytest.mark.slow
def test_a_new_objective_is_one_row_and_runs_ies_design_end_to_end(tmp_path, capsys, monkeypatch):
    """The extension of the objective table: worst-case RMS tip acceleration, added here as one row (quantity,
    statistic, unit, screening predictor), chosen by --objective; its values are the amplitude objective's own runs
    times (eta omega_1)^2 / sqrt(2), so each design's worst case lies within the eta range's bounds of that."""
    row = do.Objective("rms-acceleration", "RMS tip acceleration", "RMS of the fundamental at the resonant frequency",
                       "m/s^2", "m/s^2", 1.0, rms_acceleration,
                       lambda tip, omega_1: omega_1**2 * np.asarray(tip) / math.sqrt(2.0))
    monkeypatch.setitem(do.OBJECTIVES, row.name, row)
    study = tiny_study(tmp_path, text=SMALL)
    assert main(["design", str(study), "--jobs", "1", "--quiet", "--no-figures", "--objective", "rms-acceleration",
                 "--out", str(tmp_path / "acc")]) == 0
    printed = capsys.readouterr().out
    data = json.loads((tmp_path / "acc" / "design.json").read_text())
    assert data["objective"]["unit"] == "m/s^2" and "m/s^2" in printed
    assert "worst_m" not in data["recommendation"] and data["recommendation"]["worst_m_per_s2"] > 0
    assert main(["design", str(study), "--jobs", "1", "--quiet", "--no-figures", "--out", str(tmp_path / "amp")]) == 0
    amplitude = {(v["clearance_m"], v["radius_m"], v["material"]): v["worst_m"]
                 for v in json.loads((tmp_path / "amp" / "design.json").read_text())["verified"]}
    omega_1 = data["host"]["omega_1_rad_per_s"]
    both = [(v["worst_m_per_s2"], amplitude[key]) for v in data["verified"]
            if (key := (v["clearance_m"], v["radius_m"], v["material"])) in amplitude]
    assert both
    for acceleration, tip in both:
        assert 0.97**2 * omega_1**2 / math.sqrt(2) * tip * (1 - 1e-9) <= acceleration
        assert acceleration <= 1.0**2 * omega_1**2 / math.sqrt(2) * tip * (1 + 1e-9)


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
    (["--excitation", "2um:8um", "--clearance", "1e-3m:2e-3:3"], "'2e-3' has no unit"),
    (["--excitation", "2m:8m"], "implausible"),
    (["--excitation", "2parsec:8um"], "unknown unit"),
    (["--excitation", "2um:8um", "--clearance=-0.5mm:1mm"], "must be > 0"),
    (["--excitation", "2um:8um", "--material", "gold"], "unknown sphere material 'gold'"),
    (["--excitation", "2um:8um", "--radius", "9mm:12mm"], "no design fits"),
    (["--excitation", "2um:8um", "--baseline", "0.58mm,9mm,brass"], "--baseline"),
    (["--excitation", "2um:8um", "--damping", "0.0009:0.0007"], "LOW <= HIGH"),
    (["--excitation", "2um:8um", "--damping", "0.5:1.5"], "high end must lie in (0, 1)"),
    (["--excitation", "2um:8um", "--damping", "0.0009:0.001"], "does not contain the host's nominal D_1 = 0.085 %"),
    (["--excitation", "2um:8um", "--wall-material", "wood"],
     "unknown wall material 'wood'; choose one of steel, aluminium, titanium, brass, cast-iron"),
    (["--excitation", "2um:8um", "--material", "brass,gold"], "unknown sphere material 'gold'; choose one of brass, "
                                                              "steel, tungsten"),
    (["--excitation", "2um:8um", "--wall-material", "E=70GPa"], "missing nu"),
    (["--excitation", "0.01um:0.02um"], "never reaches the clearance"),
    (["--excitation", "2um:8um", "--model", "nothere.toml"], "--model"),
    (["--clearance", "0.5mm"], "--excitation is required"),
    (["--excitation", "2um:8um", "--margin", "0"], "--margin 0: give the margin"),
    (["--excitation", "2um:8um", "--margin", "20"], "fraction in (0, 1]"),
    (["--excitation", "2um:8um", "--margin", "much"], "--margin 'much'"),
    (["--excitation", "2um:8um", "--min-wall", "20mm"], "two walls of 20 mm leave no room in the 28 mm block"),
    (["--excitation", "2um:8um", "--objective", "loudness"], "--objective must be one of mean, max"),
    (["--excitation", "0.66um:6.6um:100000000"], "COUNT 100000000 is more than 1000 values"),
    (["--excitation", "1um:6um:1000", "--clearance", "0.1mm:0.5mm:1000", "--radius", "5mm:7mm:10"],
     "more than the 2,000,000 the screening holds"),
    (["--excitation", "0.66um:6.6um:1000", "--reps", "20"], "at most 20,000 without --allow-large: give fewer levels"),
])
def test_each_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, args, phrase):
    out = tmp_path / "out"
    started = time.perf_counter()
    assert exit_code(["design", *args, "--out", str(out), "--jobs", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert phrase in err and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert not out.exists()
    assert time.perf_counter() - started < 30  # refused before any work


def test_an_absurd_count_is_refused_at_once_with_its_cost():
    started = time.perf_counter()
    with pytest.raises(StudyError, match=r"2\.7e\+09 runs .* about .* years on one core"):
        dp.parse_range("0.66um:6.6um:100000000", "excitation", count=10)
    assert time.perf_counter() - started < 1.0


def test_a_unitless_stop_is_refused_the_same_in_a_study_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\nkind = "design"\n[design]\nexcitation = "2um:8um"\nclearance = "1e-3m:2e-3:3"\n')
    assert exit_code(["design", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert "--clearance '1e-3m:2e-3:3': '2e-3' has no unit" in capsys.readouterr().err


def test_a_study_file_with_an_unknown_key_or_kind_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\nkind = "design"\n[design]\nexcitation = "2um:8um"\nclearence = "1mm"\n')
    assert exit_code(["design", str(bad)]) == 2
    assert "unknown key(s) in [design]: clearence" in capsys.readouterr().err
    bad.write_text('[study]\nkind = "interval"\n')
    assert exit_code(["design", str(bad)]) == 2
    assert 'kind must be "design"' in capsys.readouterr().err


def test_the_screening_is_worst_over_the_damping_interval():
    problem = dp.DesignProblem(excitation=(2e-6, 6e-6), clearances=(0.3e-3, 0.58e-3), radii=(6e-3, 7.92e-3))
    mode = dp.host_mode(dp.host_model(problem))
    screened = ds.screen_designs(problem, mode)
    low_damping = ds.screen_designs(dp.DesignProblem(excitation=problem.excitation, clearances=problem.clearances,
                                                   radii=problem.radii, D=(0.0009, 0.0009),
                                                   clearance_tolerance=(0.0, 0.0)), mode)
    assert np.all(screened.tip >= low_damping.tip - 1e-15)


# --- the search on analytic stand-ins ---------------------------------------------------------------------------

TOP = 6.6e-6


def true_switch(s):
    """The stand-in's switch (m) at the box's worst corner: proportional to g (the similarity law), earlier for a
    lighter sphere."""
    return 11e-6 * (s.clearance / 1e-3) * (s.mass / 0.0177) ** 0.3


def true_worst(s):
    """The stand-in's verified worst case (m): below the switch it grows with g (the onset of impacts) and falls with
    the sphere's mass; on the almost periodic side it is 5x higher."""
    value = 0.2e-3 * (s.clearance / 0.7e-3) * (0.0177 / s.mass) ** 0.2
    return value if true_switch(s) > TOP else 5.0 * value


class StandInPredictor:
    """A predictor whose switch is the true one within 3 % and whose worst case ranks the designs badly."""

    def __init__(self):
        self.built = []

    def ensure(self, spheres):
        self.built += [s for s in spheres if (s.radius, s.material) not in self.built]

    def predict(self, s):
        corner = dq.Corner(0.00075, 0.0, 1.0)
        wrong = 0.3e-3 * (1.0 + 40.0 * (s.clearance - 1.0e-3) ** 2 / 1e-6)  # best predicted at 1 mm
        return dq.DesignPrediction(s, np.full(3, wrong), true_switch(s) * 1.03, "found", corner,
                                   true_switch(s) * 1.1, "found", (0.1e-3, 0.5e-3))


def stand_in_verify(problem, calls):
    def verify_batch(spheres, round_, reps_at=None):
        calls.append(list(spheres))
        out = []
        for s in spheres:
            w = true_worst(s)
            apr = np.zeros((9, len(problem.excitation) + 1))
            if true_switch(s) <= TOP * (1 + problem.margin):
                apr[0, -1] = 1.0  # a corner almost periodic at the margin level
            out.append(dr.Verified(s, np.full(3, 0.5 * w), np.full(3, w), np.full(3, 0.8 * w), np.zeros(3),
                                   np.zeros(3, bool), 81, point_apr=apr, margin_high=w,
                                   excitation=(*problem.excitation, TOP * (1 + problem.margin)),
                                   prediction=StandInPredictor().predict(s), round=round_))
        return out
    return verify_batch


def stand_in_problem(**kw):
    settings = dict(excitation=(2.2e-6, 4.4e-6, TOP), clearances=tuple(np.round(np.linspace(0.2e-3, 1.6e-3, 8), 9)),
                    radii=(7.92e-3,), block_width=60e-3)
    return dp.DesignProblem(**{**settings, **kw})


def screened_of(problem):
    """A screening that ranks the grid in reverse (the slow flow's weakness on an unseen host)."""
    designs = problem.grid()
    worst = np.array([-d.clearance - d.radius for d in designs])
    return dr.Screened(designs, np.zeros((len(designs), 3)), np.zeros((len(designs), 3), object), np.zeros(len(designs)),
                       worst, 0.0)


@pytest.mark.parametrize("candidates", [1, 2, 3, 5, 8])
def test_the_search_recommends_the_same_design_whatever_the_first_batch(candidates):
    problem = stand_in_problem(candidates=candidates)
    calls = []
    verified, trail = ds.search(problem, StandInPredictor(), stand_in_verify(problem, calls), screened_of(problem))
    best = verified[0]
    admissible = [s for s in problem.grid() if true_switch(s) > TOP * (1 + problem.margin)]
    assert best.design == min(admissible, key=true_worst)  # the brute-force optimum of the stand-in
    assert best.admissible(TOP, problem.margin)
    g = list(problem.clearances)
    k = g.index(best.design.clearance)
    verified_g = {v.design.clearance for v in verified}
    assert g[k - 1] in verified_g and g[k + 1] in verified_g  # verified neighbours on both sides
    assert len(calls[0]) == candidates and trail.stop


def test_the_search_walks_every_axis_radius_and_material_included():
    problem = stand_in_problem(radii=(6e-3, 7e-3, 7.92e-3), materials=("brass", "steel", "tungsten"), candidates=1)
    calls = []
    verified, _ = ds.search(problem, StandInPredictor(), stand_in_verify(problem, calls), screened_of(problem))
    admissible = [s for s in problem.grid() if problem.fits(s) and true_switch(s) > TOP * (1 + problem.margin)]
    assert verified[0].design == min(admissible, key=true_worst)
    best = verified[0].design
    seen = {v.design for v in verified}
    assert all(n in seen for n in ds.neighbours(problem, best))
    assert ds.material_axis(problem) == ["steel", "brass", "tungsten"]  # by density


def test_neighbours_stay_on_the_grid_and_in_the_cavity():
    problem = stand_in_problem(radii=(6e-3, 7.92e-3), materials=("brass", "tungsten"), block_width=28e-3)
    s = dp.Design(problem.clearances[0], 6e-3, "brass")
    around = ds.neighbours(problem, s)
    assert dp.Design(problem.clearances[1], 6e-3, "brass") in around
    assert dp.Design(problem.clearances[0], 7.92e-3, "brass") in around
    assert dp.Design(problem.clearances[0], 6e-3, "tungsten") in around
    assert all(problem.fits(n) for n in around) and len(around) == 3
    assert ds.neighbours(problem, dp.Design(0.58e-3, 7.92e-3, "brass")) == []  # off the grid


def test_admissible_needs_the_margin_and_no_almost_periodic_run_anywhere_in_the_box():
    problem = stand_in_problem()
    s = dp.Design(1.2e-3, 7.92e-3, "brass")
    v = stand_in_verify(problem, [])([s], 0)[0]
    assert v.admissible(TOP, 0.2) and v.margin(TOP) == pytest.approx(true_switch(s) * 1.03 / TOP - 1)
    seen = dataclass_replace(v, point_apr=np.where(np.arange(4) == 1, 1.0, 0.0)[None, :].repeat(9, 0))
    assert not seen.admissible(TOP, 0.2) and seen.switch_worst() == pytest.approx(problem.excitation[1])
    assert seen.switch_kind() == "verified"
    assert not v.admissible(TOP, v.margin(TOP) + 0.01)
    # an almost periodic label below a point's first impacts (a rattle, no resonance of the IES) does not count
    rattle = dataclass_replace(seen, point_onset=np.full(9, problem.excitation[1] * 1.01))
    assert rattle.admissible(TOP, 0.2) and rattle.apr_seen_at() == math.inf


def dataclass_replace(obj, **changes):
    import dataclasses

    return dataclasses.replace(obj, **changes)


def test_no_admissible_design_after_verification_exits_3_and_writes_every_verified_design(tmp_path, monkeypatch,
                                                                                         capsys):
    """A range in which every verified design has one almost periodic run (1 of 3) at the margin level: the conservative
    rule makes none admissible; one line with the best margin, how many designs fit the block and where to widen it,
    exit 3; design.csv and design.json hold every verified design, marked not admissible, and no recommendation."""
    def every_design_switches(problem, predictor, verify_batch, screened, log=None):
        n = len(problem.excitation)
        out = []
        for s in problem.grid():
            apr = np.zeros((9, n + 1))
            apr[0, -1] = 1.0 / 3.0
            out.append(dr.Verified(s, np.full(n, 0.5e-4), np.full(n, 1e-4), np.full(n, 0.8e-4), np.zeros(n),
                                   np.zeros(n, bool), 9 * (n + 1) * 3, point_apr=apr, margin_high=1e-4,
                                   excitation=(*problem.excitation, problem.margin_level()),
                                   prediction=dataclass_replace(StandInPredictor().predict(s), per_level=np.full(n, 1e-4)),
                                   worst_interval=(0.9e-4, 1.1e-4)))
        return out, ds.Search([problem.grid()], "stand-in")

    monkeypatch.setattr(ds, "search", every_design_switches)
    monkeypatch.setattr(dq.Predictor, "describe", lambda self: [])
    out = tmp_path / "out"
    code = exit_code(["design", "--excitation", "2um:8um:2", "--clearance", "0.3mm:3mm:4", "--out", str(out),
                      "--quiet", "--jobs", "1", "--reps", "1"])
    err = capsys.readouterr().err.strip()
    assert code == 3 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert "no verified design keeps a margin of 20% to the switch: the best, g 0.300 mm" in err
    assert "1 of 4 designs fit the 28 mm block" in err and "--block-width 32.9mm takes them all" in err
    assert "--resume" in err
    data = json.loads((out / "design.json").read_text())
    assert data["recommendation"] is None and data["refusal"] in err
    assert len(data["verified"]) == 4 and not any(v["admissible"] for v in data["verified"])
    with open(out / "design.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["status"] != "screened"]
    assert len(rows) == 4 and {r["admissible"] for r in rows} == {"0"}
    assert not any(cell == "None" for r in rows for cell in r.values())


def test_a_design_the_similarity_law_sees_no_room_for_is_refused_before_verification(tmp_path, monkeypatch, capsys):
    """Where every prediction switches inside the range + margin, one line with the predicted margins, exit 2, and
    not one verification run."""
    verified = []
    monkeypatch.setattr(dq.Predictor, "ensure", lambda self, spheres: None)
    monkeypatch.setattr(dq.Predictor, "predict", lambda self, s: dq.DesignPrediction(
        s, np.full(2, 1e-4), 9e-6 * s.clearance / 1e-3, "found", dq.Corner(0.00075, 0.0, 1.0), 1e-5, "found",
        (1e-4, 4e-4)))
    monkeypatch.setattr(ds, "verify", lambda *a, **k: verified.append(a) or [])
    out = tmp_path / "out"
    code = exit_code(["design", "--excitation", "2um:8um:2", "--clearance", "0.3mm:1mm:3", "--out", str(out),
                      "--quiet", "--jobs", "1", "--reps", "1", "--block-width", "32mm"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "the similarity law predicts no design keeping a margin of 20%" in err
    assert "g 1.000 mm, brass R 7.92 mm: 12% (switch at 9 um)" in err and "3 of 3 designs fit" in err
    assert not verified and not (out / "design.json").exists()


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


def test_the_box_is_its_distinct_corners_and_its_centre():
    problem = dp.DesignProblem(excitation=(2e-6,), clearances=(0.5e-3,), radii=(7.92e-3,))
    sphere = dp.Design(0.5e-3, 7.92e-3, "brass")
    points = problem.corners(sphere)
    corners = {dq.corner_of(p, sphere) for p in points[:-1]}
    assert len(points) == 9 and len(corners) == 8
    ends = [(D, t, f) for D in problem.D for t in problem.clearance_tolerance for f in problem.k_H_factor]
    assert all(min(abs(c.D - D) + abs(c.tolerance - t) + abs(c.k_H_factor - f) for D, t, f in ends) < 1e-12
               for c in corners)
    centre = dq.corner_of(points[-1], sphere)
    assert centre.D == pytest.approx(0.5 * sum(problem.D)) and centre.k_H_factor == pytest.approx(
        0.5 * sum(problem.k_H_factor)) and points[-1]["g"] == pytest.approx(0.5e-3 + 0.016e-3)


def test_a_steel_sphere_on_aluminium_walls_has_eq_8s_ratio_of_contact_moduli(tmp_path):
    """Eq. 8 with both bodies: k_H on an aluminium wall over k_H on steel is E*_Al / E*_steel, 1/E* = (1 - nu_s^2)/E_s
    + (1 - nu_w^2)/E_w with the handbook values (steel 207 GPa, 0.30; 6061-T6 68.9 GPa, 0.33): about 0.51 (issue 40,
    item 3). The design takes the wall from the host's [host] table, or --wall-material, without --k-H-factor; the box's
    k_H corners are Table 2's factors on that value."""
    from sim.hosts.modal_file import load_modal_model, save_modal_model
    from sim.hosts.rig import seed_rig_model
    from sim.model.materials import WALL_MATERIALS

    def e_star(E1, nu1, E2, nu2):
        return 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)

    expected = e_star(207e9, 0.30, 68.9e9, 0.33) / e_star(207e9, 0.30, 207e9, 0.30)
    steel = dp.Design(1e-3, 5e-3, "steel")
    aluminium = dp.Design(1e-3, 5e-3, "steel", WALL_MATERIALS["aluminium"])
    assert aluminium.k_H / steel.k_H == pytest.approx(expected, rel=1e-12) and 0.50 < expected < 0.52
    # the host's [host] wall_material reaches every design, and --wall-material wins over it
    path = save_modal_model(dataclass_replace(seed_rig_model(), wall=WALL_MATERIALS["aluminium"]), tmp_path / "host.toml")
    assert 'wall_material = "aluminium"' in path.read_text() and load_modal_model(path).wall_material.name == "aluminium"
    settings = {**dp.DESIGN_SETTINGS, "excitation": "2um:6um:2", "radius": "5mm", "material": "steel",
                "clearance": "1mm", "model": str(path)}
    on_host = dp.problem_of(settings)
    assert on_host.wall.name == "aluminium" and on_host.grid()[0].k_H == pytest.approx(aluminium.k_H, rel=1e-12)
    k_H = sorted({p["k_H"] for p in on_host.corners(on_host.grid()[0])[:-1]})
    assert k_H == pytest.approx([aluminium.k_H * f for f in on_host.k_H_factor], rel=1e-12)
    assert dp.problem_of({**settings, "wall_material": "steel"}).grid()[0].k_H == pytest.approx(steel.k_H, rel=1e-12)


def test_the_box_takes_the_hosts_damping_interval_else_table_2s_relative_one_around_its_D_1(tmp_path):
    """Issue 40, item 2: a host with D_1 = 0.1 % and no interval gets Table 2's relative interval around its own D_1*
    (0.0882-0.1059 %), said so; one with a [host] damping_interval gets that; the structure without IES is at its
    nominal D_1* (a_noabs* = phi_tip (phi^T M b) a_base / (2 D_1*), Sect. 5)."""
    from sim.hosts.modal_file import save_modal_model
    from sim.hosts.rig import seed_rig_model

    model = seed_rig_model()
    damping = model.damping_ratios.copy()
    damping[0] = 0.001
    path = save_modal_model(dataclass_replace(model, damping_ratios=damping, damping_interval=None), tmp_path / "h.toml")
    settings = {**dp.DESIGN_SETTINGS, "excitation": "2um:6um:2", "model": str(path)}
    problem = dp.problem_of(settings)
    assert problem.D == pytest.approx((0.001 * 0.00075 / 0.00085, 0.001 * 0.0009 / 0.00085))
    assert "Table 2's relative interval" in problem.damping_source and "D_1 0.08824-0.1059 %" in problem.box_text()
    host = dp.host_model(problem)
    a = np.array([3.0e-6])
    assert dp.no_absorber(host, a)[0] == pytest.approx(abs(host.phi_tip[0] * host.participation[0]) * 3.0e-6 / 0.002)
    save_modal_model(dataclass_replace(model, damping_ratios=damping, damping_interval=(0.0009, 0.0012)), path)
    own = dp.problem_of(settings)
    assert own.D == (0.0009, 0.0012) and own.damping_source == "the host's damping interval"


def test_an_almost_periodic_label_below_a_references_first_impacts_is_no_switch():
    """A linear response is periodic (cv below 0.1): below a reference's first impacts, own level D_1 / D_1*, its
    label does not count for the similarity law's switch (it put the rig's switch at own level 0.5 once)."""
    problem = dp.DesignProblem(excitation=(2e-6,), clearances=(1e-3,), radii=(7.92e-3,))

    def every_run_almost_periodic(tasks):
        return {t: {"outputs": {"apr": 1.0, "mean": 0.1}, "trace": {"a_noabs": 1e-3}} for t in tasks}

    rig = dp.host_model(problem)
    predictor = dq.Predictor(problem, do.objective_named("mean"), rig, every_run_almost_periodic)
    evaluate = predictor._evaluator([(1e-3, 8.9e9, 0.00075)], 0.0177, [0])
    below, above = evaluate([(0, 0.5), (0, 0.9)])  # onset at 0.00075 / 0.00085 = 0.88
    assert below.apr == 0.0 and above.apr == 1.0


def test_the_readmes_modal_file_loads_and_its_host_reaches_the_design(tmp_path):
    """The format in README.md ("Your own structure") is a modal file as written: it loads, its D_1 is the nominal
    D_1*, its [host] interval and aluminium walls reach the design's box and Eq. 8."""
    import re
    from pathlib import Path

    from sim.hosts.modal_file import load_modal_model

    readme = (Path(__file__).resolve().parents[3] / "README.md").read_text()
    section = readme[readme.index("## Your own structure"):]
    (block,) = re.findall(r"```toml\n(.*?)```", section, flags=re.S)[:1]
    path = tmp_path / "beam.toml"
    path.write_text(block)
    model = load_modal_model(path)
    assert model.D_star == 0.001 and model.damping_interval == (0.0009, 0.0012)
    assert model.wall_material.name == "aluminium" and model.n_modes == 3
    problem = dp.problem_of({**dp.DESIGN_SETTINGS, "excitation": "1.2um:6um:6", "model": str(path), "radius": "5mm",
                             "material": "steel", "clearance": "0.4mm:1.8mm:8"})
    assert problem.D == (0.0009, 0.0012) and problem.wall.name == "aluminium"


@pytest.mark.parametrize("gap, settled, most", [(0.20, True, 9), (0.01, False, 15)])
def test_overlapping_intervals_get_more_repetitions_until_they_part_or_the_budget_is_spent(gap, settled, most):
    """Two admissible designs whose worst cases' intervals shrink as 1/sqrt(runs) at their deciding cell: 0.20 apart
    they part after 9 runs a cell (3 rounds of the design's 3); 0.01 apart they overlap still at the budget, 15 runs
    (5x), and the ranking is said to be within the noise. The winner's deciding cell always gets at least 2x."""
    problem = stand_in_problem(repetitions=3)
    a, b = problem.grid()[5], problem.grid()[6]
    worst = {a: 1.0, b: 1.0 + gap}

    def verify_batch(designs, round_, reps_at):
        out = []
        for s in designs:
            n = reps_at.get(s, {}).get((0, 2), problem.repetitions)
            half = 0.25 / math.sqrt(n)
            runs = np.full((9, 4), problem.repetitions)
            runs[0, 2] = n
            out.append(dr.Verified(s, np.full(3, 0.5), np.full(3, worst[s]), np.full(3, 0.5), np.zeros(3),
                                   np.zeros(3, bool), int(runs.sum()), point_apr=np.zeros((9, 4)),
                                   excitation=(*problem.excitation, problem.margin_level()),
                                   prediction=StandInPredictor().predict(s), worst_interval=(worst[s] - half,
                                                                                            worst[s] + half),
                                   deciding=((0, 2),), point_runs=runs))
        return out

    reps_at = {}
    verified = {v.design: v for v in verify_batch([a, b], 0, reps_at)}
    settling = ds.settle(problem, verified, reps_at, lambda designs: verify_batch(designs, 0, reps_at))
    assert settling.winner == a and settling.runner_up == b
    assert settling.overlap == (not settled) and settling.most_runs == most and settling.budget == 15
    assert reps_at[a][(0, 2)] == most and reps_at[b][(0, 2)] == most
    text = settling.text(verified, lambda x: f"{x:.3g}", "mm")
    assert ("ranking settled" in text) == settled and ("within the noise" in text) == (not settled)


def test_a_design_on_the_edge_of_the_grid_says_what_was_not_tried():
    """The search sees only the grid: the largest clearance (of the range, or that fits the block), the smallest, the
    largest or smallest radius are said with the option that looks beyond; a design inside says nothing."""
    wide = dp.DesignProblem(excitation=(2e-6,), clearances=(0.6e-3, 1.0e-3, 1.4e-3), radii=(6e-3, 7e-3, 7.92e-3),
                            block_width=60e-3)
    assert wide.edge_text(dp.Design(1.0e-3, 7e-3, "brass")) == ""
    top = wide.edge_text(dp.Design(1.4e-3, 7e-3, "brass"))
    assert "largest clearance of --clearance (1.4 mm)" in top and "widen --clearance" in top and "radius" not in top
    bottom = wide.edge_text(dp.Design(0.6e-3, 7.92e-3, "brass"))
    assert "smallest clearance" in bottom and "the largest radius of --radius (7.92 mm)" in bottom
    # 2R + 2g <= 28 mm - 2 walls of 5.5 mm: R 7.92 mm holds g 0.3 and 0.5 mm, not 0.8 mm
    tight = dp.DesignProblem(excitation=(2e-6,), clearances=(0.3e-3, 0.5e-3, 0.8e-3), radii=(7.92e-3,),
                             block_width=28e-3)
    assert not tight.fits(dp.Design(0.8e-3, 7.92e-3, "brass"))
    cut = tight.edge_text(dp.Design(0.5e-3, 7.92e-3, "brass"))
    assert "the largest clearance that fits the block (0.5 mm)" in cut and "--block-width" in cut
