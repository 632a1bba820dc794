"""The second new-user pass (issue 25, item 2): every bad or odd input it met is one line on stderr, exit code 2 (a
user mistake) or 3 (the machine: a read-only or full disk, memory), no traceback, and nothing computed is lost
(checked before the work, or written to a fallback folder the line names).

A read-only or full disk is simulated by making the one file writer (`sim.common.files`) raise OSError(EROFS / ENOSPC):
the tests run as root, which ignores file permissions. Every test uses a three-mode model and runs of a few
hundredths of a simulated second, or stops before the simulation.
"""
from __future__ import annotations

import errno
import json
from pathlib import Path

import numpy as np
import pytest

import sim.common.files
from uq.cli import main

from tests.support import FAST, STUDIES, one_line


def names(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def no_simulation(monkeypatch) -> None:
    """Make any stepped-sine run fail the test: the refusal must come before the work."""
    def forbidden(*args, **kwargs):
        raise AssertionError("the simulation ran before the refusal")

    monkeypatch.setattr("sim.stepped_sine.protocol.sweep", forbidden)
    monkeypatch.setattr("sim.analysis.trace.record_trace", forbidden)


def read_only_disk(monkeypatch) -> None:
    """Every new file the writer creates fails as on a read-only file system."""
    def refuse(folder, target):
        raise OSError(errno.EROFS, "Read-only file system", str(folder / f".{target.name}.tmp"))

    monkeypatch.setattr(sim.common.files, "_new_temporary_file", refuse)


def signal_csv(path: Path, *, excitation_hz: float = 117.0, bom: bool = False) -> Path:
    """A synthetic measurement of `sim.analysis.impacts` (two impacts per period) as a signal CSV."""
    from sim.analysis.impacts import synthetic_impact_signal

    s = synthetic_impact_signal(2.0, periods=30, excitation_hz=excitation_hz).signal
    rows = np.column_stack([s.t, s["a_left"], s["a_right"], s["a_tip"]])
    text = "t,a_left,a_right,a_tip\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rows)
    path.write_text(("\ufeff" if bom else "") + text, encoding="utf-8")
    return path


def uniform_rows(n: int = 200, fs: float = 51.2e3) -> list[list[str]]:
    t = np.arange(n) / fs
    return [[repr(float(v)) for v in (ti, np.sin(ti * 3e4), np.cos(ti * 3e4), np.sin(ti * 700), np.cos(ti * 700))]
            for ti in t]


HEADER = ["t", "a_left", "a_right", "a_tip", "v_tip"]


def write_rows(path: Path, rows: list[list[str]]) -> Path:
    path.write_text(",".join(HEADER) + "\n" + "".join(",".join(row) + "\n" for row in rows))
    return path


# ---- tracebacks: a read-only or full disk, memory, a bad cell, corrupt data -----------------------------------

@pytest.mark.parametrize("command", [
    ["sweep", "--level", "6", *FAST, "--out", "res"],
    ["sweep", "--level", "6", *FAST, "--plot", "f.png"],
    ["trace", "--level", "6", "--eta", "0.99", "--wait", "0.02", "--periods", "2", "--out", "res"],
    ["modes", "--save", "saved.toml"],
    ["calibrate", "--flat", "--grid", "16", "--points", "2", "--plot", "k_H.png"],
])
def test_a_read_only_disk_is_exit_3_before_any_work(tmp_path, model_file, capsys, monkeypatch, command):
    monkeypatch.chdir(tmp_path)
    no_simulation(monkeypatch)
    monkeypatch.setattr("bem_contact.calibration.calibrate_k_H", lambda *a, **k: pytest.fail("solved before refusing"))
    read_only_disk(monkeypatch)
    model = ["--model", model_file] if command[0] in ("sweep", "trace") else []
    line = one_line(capsys, main([*command, *model]), 3, "resource failure", "Read-only file system",
                    "nothing was computed", absent=(".tmp",))
    assert ("--out res" in line) or ("--plot" in line) or ("--save saved.toml" in line)
    assert names(tmp_path) == ["three.toml"]  # no --out folder left behind


@pytest.mark.parametrize("command, stem", [
    (["trace", "--level", "6", "--eta", "0.99", "--wait", "0.02", "--periods", "2"], "trace"),
    (["sweep", "--level", "6", *FAST], "sweep"),
])
def test_a_full_disk_keeps_the_computed_results_in_a_named_fallback(tmp_path, model_file, capsys, monkeypatch, command,
                                                                    stem):
    monkeypatch.chdir(tmp_path)
    spare = tmp_path / "spare"
    spare.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(spare))
    write_bytes = sim.common.files.write_bytes

    def full_in_res(path, data):
        if Path(path).parent.name == "res":
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return write_bytes(path, data)

    monkeypatch.setattr(sim.common.files, "write_bytes", full_in_res)
    code = main([*command, "--model", model_file, "--out", "res"])
    line = one_line(capsys, code, 3, "No space left on device", f"res/{stem}.csv", "written to")
    fallback = Path(line.split("written to ")[1].split(" instead")[0])
    assert fallback.parent == spare and sorted(p.name for p in fallback.iterdir()) == [f"{stem}.csv", f"{stem}.json"]
    assert json.loads((fallback / f"{stem}.json").read_text())["seed"] == 0
    assert not (tmp_path / "res").exists()  # the empty folder is removed: nothing half-written there


def test_the_writers_error_names_the_users_file_not_its_temporary_file(tmp_path, monkeypatch):
    def full(self, data):
        raise OSError(errno.ENOSPC, "No space left on device", str(self))

    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(OSError) as caught:
        sim.common.files.write_text(tmp_path / "out.csv", "a,b\n")
    assert caught.value.filename == str(tmp_path / "out.csv") and caught.value.errno == errno.ENOSPC
    assert list(tmp_path.iterdir()) == []  # the temporary file is gone


def test_a_trace_too_large_for_memory_is_refused_before_any_work(tmp_path, model_file, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    no_simulation(monkeypatch)
    for args in (["--periods", "100000000"], ["--fs", "1e9"]):
        code = main(["trace", "--level", "6", "--eta", "0.99", "--model", model_file, "--out", "res", *args])
        one_line(capsys, code, 3, "resource failure", "GiB of memory", "nothing was computed")
    assert names(tmp_path) == ["three.toml"]


@pytest.mark.parametrize("value", ["oops", ""])
@pytest.mark.parametrize("command, column", [(["impacts"], 1), (["impacts"], 2), (["impacts"], 3),
                                             (["modal-fit", "--model", "builtin"], 4)])
def test_a_bad_cell_in_any_column_names_that_column(tmp_path, capsys, command, column, value):
    rows = uniform_rows()
    rows[5][column] = value
    path = write_rows(tmp_path / "signal.csv", rows)
    what = f"'{value}'" if value else "an empty cell"
    one_line(capsys, main([command[0], str(path), *command[1:]]), 2, f"{what} in column '{HEADER[column]}' at data row 6")


@pytest.mark.parametrize("kind, data", [("sweep", "{\"level\": 6"), ("overview", "not json"), ("trace", "[1, 2]")])
def test_ies_plot_on_corrupt_data_is_one_line(tmp_path, capsys, kind, data):
    (tmp_path / f"{kind}.json").write_text(data)
    if kind == "trace":
        (tmp_path / "trace.csv").write_text("t,q_tip\n0,1\n")
    one_line(capsys, main(["plot", str(tmp_path), "--out", str(tmp_path / "figs")]), 2, "corrupt or incomplete",
             "rerun the command")
    assert not (tmp_path / "figs").exists() or not any((tmp_path / "figs").iterdir())  # no figure drawn


def test_ies_plot_on_a_corrupt_study_json_is_one_line(tmp_path, capsys):
    (tmp_path / "study.json").write_text("{\"study\": ")
    one_line(capsys, main(["plot", str(tmp_path)]), 2, "corrupt or incomplete")


# ---- results thrown away: checked up front, no overwriting, no false promise ----------------------------------

@pytest.mark.parametrize("command", [["sweep", "--level", "6"], ["overview", "--levels", "5,6"]])
def test_a_plot_into_a_missing_folder_is_refused_before_the_sweep(tmp_path, model_file, capsys, monkeypatch, command):
    monkeypatch.chdir(tmp_path)
    no_simulation(monkeypatch)
    code = main([*command, *FAST, "--model", model_file, "--out", "res", "--plot", "nodir/f.png"])
    one_line(capsys, code, 2, "--plot nodir/f.png", "folder nodir does not exist", "nothing was computed",
             absent=(".sweep.",))
    assert names(tmp_path) == ["three.toml"]


@pytest.mark.parametrize("command", [
    ["sweep", "--level", "6", *FAST],
    ["overview", "--levels", "5,6", *FAST],
    ["trace", "--level", "6", "--eta", "0.99", "--wait", "0.02", "--periods", "2"],
])
def test_a_non_empty_out_folder_is_refused_unless_force(tmp_path, model_file, capsys, monkeypatch, command):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "earlier.csv").write_text("kept\n")
    base = [*command, "--model", model_file, "--out", "res"]
    with monkeypatch.context() as patched:
        no_simulation(patched)
        one_line(capsys, main(base), 2, "--out res is not empty", "--force")
    assert names(tmp_path / "res") == ["earlier.csv"]
    if command[0] == "sweep":  # --force writes beside the earlier file
        assert main([*base, "--force"]) == 0
        assert names(tmp_path / "res") == ["earlier.csv", "sweep.csv", "sweep.json"]


def test_compare_refuses_a_non_empty_out_and_a_folder_given_twice(tmp_path, capsys):
    study = tmp_path / "a"
    study.mkdir()
    one_line(capsys, main(["compare", str(study), str(tmp_path / "." / "a"), "--out", str(tmp_path / "c")]), 2,
             "is given twice", "give each study's folder once")
    out = tmp_path / "c"
    out.mkdir()
    (out / "compare.csv").write_text("earlier\n")
    code = main(["compare", str(study), "--out", str(out)])
    err = capsys.readouterr().err  # `a` is no response study: refused first, the folder untouched either way
    assert code == 2 and (out / "compare.csv").read_text() == "earlier\n", err


def test_compare_checks_out_before_writing(tmp_path, capsys, monkeypatch):
    from uq.outputs import compare

    fake = compare.ResponseFolder("a", tmp_path / "a", {}, {"levels": []})
    monkeypatch.setattr(compare, "read_response_folder", lambda folder: fake)
    out = tmp_path / "c"
    out.mkdir()
    (out / "compare.csv").write_text("earlier\n")
    one_line(capsys, main(["compare", str(tmp_path / "a"), "--out", str(out)]), 2, "is not empty", "--force")
    assert (out / "compare.csv").read_text() == "earlier\n"


def test_ctrl_c_mentions_resume_only_where_it_exists(tmp_path, model_file, capsys, monkeypatch):
    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("sim.stepped_sine.protocol.sweep", interrupt)
    code = main(["sweep", "--level", "6", *FAST, "--model", model_file, "--out", str(tmp_path / "res")])
    assert code == 130
    err = capsys.readouterr().err
    assert "--resume" not in err and "no results were written" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "res").exists()
    monkeypatch.setattr("uq.engine.execution.run_study", interrupt)
    assert main(["interval", str(STUDIES / "fig7-quick.toml"), "--out", str(tmp_path / "study")]) == 130
    assert "rerun with --resume" in capsys.readouterr().err


# ---- silently wrong or meaningless output ---------------------------------------------------------------------

def test_a_scan_read_in_the_wrong_units_is_refused(capsys):
    one_line(capsys, main(["calibrate", "--units", "in"]), 2, "read in in", "wider than the 15.84 mm sphere",
             "use --units mm")


def test_a_scan_in_implausible_units_warns(capsys):
    from bem_contact.pipeline import crater_units_check

    # the paper-like crater (1.10 mm across, 12 um deep in mm) read in cm: 11 mm across, 120 um deep
    warning = crater_units_check(0.011, 120e-6, "cm", "crater.ply")
    assert len(warning) == 1 and "use --units mm" in warning[0]
    assert crater_units_check(0.0011, 12e-6, "mm", "crater.ply") == []


def test_a_decimal_comma_in_one_row_is_refused(tmp_path, capsys):
    rows = uniform_rows()
    rows[7][2] = "0,5"
    path = write_rows(tmp_path / "signal.csv", rows)
    one_line(capsys, main(["impacts", str(path)]), 2, "data row 8 has 6 cells but the header names 5 columns",
             "decimal comma")


def test_impacts_outside_the_signal_are_refused_not_nan(tmp_path, capsys):
    path = write_rows(tmp_path / "signal.csv", uniform_rows())
    impacts = tmp_path / "impacts.json"
    impacts.write_text(json.dumps({"impacts": [{"t": 5.0}, {"t": 6.0}]}))
    one_line(capsys, main(["modal-fit", str(path), "--model", "builtin", "--impacts", str(impacts)]), 2,
             "none of its 2 impact times", "lies within the signal", absent=("nan",))


def test_an_excitation_frequency_far_from_the_signals_is_refused(tmp_path, capsys):
    path = signal_csv(tmp_path / "signal.csv", excitation_hz=114.6)
    one_line(capsys, main(["impacts", str(path), "--excitation-hz", "50"]), 2, "--excitation-hz 50 Hz is far from",
             "dominant frequency 114.6 Hz", "omit --excitation-hz")
    assert main(["impacts", str(path), "--excitation-hz", "114.6"]) == 0  # the right one passes


def test_a_signal_with_a_byte_order_mark_reads_as_without(tmp_path, capsys):
    plain = signal_csv(tmp_path / "plain.csv")
    marked = signal_csv(tmp_path / "marked.csv", bom=True)
    assert marked.read_bytes().startswith(b"\xef\xbb\xbf")
    assert main(["impacts", str(plain), "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert main(["impacts", str(marked), "--json"]) == 0
    second = json.loads(capsys.readouterr().out)
    assert second["impacts_per_period"] == first["impacts_per_period"] and len(second["impacts"]) > 0


def test_sobol_indices_outside_0_1_beyond_their_ci_come_with_advice_on_n(tmp_path, capsys):
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\nseed = 5\n[sobol]\nbootstrap = 100\n")
    assert main(["sobol", str(study), "--n", "4", "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "outside [0, 1] beyond their confidence intervals" in out and "base sample n = 4 is too small" in out
    assert "raise --n" in out
    assert main(["sobol", str(study), "--n", "1024", "--out", str(tmp_path / "big"), "--no-figures", "--quiet"]) == 0
    assert "is too small" not in capsys.readouterr().out


def test_sample_size_advice_counts_indices_beyond_their_ci_or_undetermined():
    from uq.outputs.results import outside_unit_interval, sample_size_advice

    assert outside_unit_interval([-0.05, 1.04, 0.5, -0.5, 2.2], [0.1, 0.1, 0.1, 0.2, 0.5]) == 2
    assert sample_size_advice([0.3, -0.01, 0.99], [0.05, 0.02, 0.03], 1024) is None  # noise about a true 0 or 1
    advice = sample_size_advice([1.3, 0.2], [2.9, 0.1], 4)
    assert "0 lie outside [0, 1] beyond" in advice and "1 have intervals wider than +-0.5" in advice


@pytest.mark.parametrize("levels, phrase", [("5,5,5", "repeats 5"), ("5,6,5", "repeats 5"),
                                            ("5,,6", "has an empty entry"), ("5,6,", "has an empty entry")])
def test_duplicated_or_empty_levels_are_refused(tmp_path, model_file, capsys, monkeypatch, levels, phrase):
    monkeypatch.chdir(tmp_path)
    one_line(capsys, main(["overview", "--levels", levels, *FAST, "--model", model_file, "--out", "res"]), 2, phrase)
    assert names(tmp_path) == ["three.toml"]


def test_an_npz_height_map_under_an_unexpected_key_is_refused(tmp_path, capsys):
    np.savez(tmp_path / "map.npz", mask=np.ones((40, 40)), pixel_size=0.05)
    one_line(capsys, main(["calibrate", str(tmp_path / "map.npz")]), 2, "no 'height' array", "found mask, pixel_size")


def crater_map(hole: tuple[int, int] | None) -> dict:
    """A 12 um deep dent of the 7.92 mm sphere on a 4.5 mm patch (mm, pixel 0.02 mm), a 3 x 3 pixel hole at `hole`."""
    n, pixel = 225, 0.02
    x = (np.arange(n) - n // 2) * pixel
    r2 = x[None, :] ** 2 + x[:, None] ** 2
    height = -np.clip(0.012 - r2 / (2 * 7.92), 0.0, None)
    height += 1e-5 * np.sin(37.0 * x[None, :]) * np.cos(23.0 * x[:, None])  # a little texture, like a scan
    if hole is not None:
        height[hole[0] - 1:hole[0] + 2, hole[1] - 1:hole[1] + 2] = np.nan
    return {"height": height, "pixel_size": pixel}


def test_a_hole_filled_inside_the_contact_zone_is_reported(tmp_path, capsys):
    args = ["--grid", "32", "--points", "3", "--denoise", "0", "--json"]
    np.savez(tmp_path / "inside.npz", **crater_map((112, 112)))
    assert main(["calibrate", str(tmp_path / "inside.npz"), *args]) == 0
    inside = json.loads(capsys.readouterr().out)
    assert inside["holes_in_contact_zone"] and "inside the contact zone" in " ".join(inside["warnings"])
    np.savez(tmp_path / "outside.npz", **crater_map((20, 20)))
    assert main(["calibrate", str(tmp_path / "outside.npz"), *args]) == 0
    assert json.loads(capsys.readouterr().out)["holes_in_contact_zone"] is None


def test_a_negative_value_with_a_unit_reaches_its_check(tmp_path, model_file, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    line = one_line(capsys, main(["sweep", "--level", "6", *FAST, "--model", model_file, "--g", "-0.5mm"]), 2,
                    "clearance g must be a positive number", absent=("expected one argument",))
    assert "-0.0005" in line


# ---- work sized to hang: a cost estimate first, --jobs against the cores --------------------------------------

def test_a_long_sweep_says_what_it_will_cost_before_it_starts(tmp_path, model_file, capsys, monkeypatch):
    monkeypatch.setattr("sim.stepped_sine.cost.probe_cost", lambda *a: 0.05)

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr("sim.stepped_sine.protocol.sweep", interrupt)
    command = ["overview", "--levels", "1:10:1000", "--reps", "1000", "--model", model_file]
    line = one_line(capsys, main(command), 2, "cost estimate: 1000000 run(s) x ", "h on one core",
                    "more than the 1.0 h a command runs without --allow-large", "lower --reps")
    assert main([*command, "--allow-large"]) == 130  # asked for: said, then started
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("warning: cost estimate: 1000000 run(s) x ") and "lower --reps" in err[0]
    assert line.split("cost estimate: ")[1].split(":")[0] in err[0]


def test_the_estimate_is_quiet_for_short_work_and_a_plain_line_for_minutes():
    import io

    from sim.stepped_sine.cost import Estimate, check_estimate

    stream = io.StringIO()
    assert check_estimate(Estimate(10, 0.01), "hint", stream=stream) == pytest.approx(0.1) and stream.getvalue() == ""
    check_estimate(Estimate(100, 2.0), "hint", stream=stream)
    assert stream.getvalue().startswith("cost estimate: 100 run(s) x 2 s") and "3.3 min" in stream.getvalue()


def test_a_trace_at_an_extreme_rate_says_what_it_will_cost(tmp_path, model_file, capsys, monkeypatch):
    monkeypatch.setattr("sim.stepped_sine.cost.available_memory", lambda: 1e15)
    monkeypatch.setattr("sim.analysis.trace.record_trace", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt))
    command = ["trace", "--level", "6", "--eta", "0.99", "--wait", "0.02", "--fs", "1e9", "--model", model_file,
               "--out", str(tmp_path / "res")]
    one_line(capsys, main(command), 2, "cost estimate: 1 run(s)", "--fs", "--allow-large")
    assert main([*command, "--allow-large"]) == 130
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("warning: cost estimate: 1 run(s)") and "--fs" in err[0]


def test_jobs_above_the_cores_warns_and_small_work_runs_serially(monkeypatch):
    import io

    from uq.engine.runner import PARALLEL_OVERHEAD_S, choose_jobs

    stream = io.StringIO()
    assert choose_jobs(64, 1.0, cores=2, stream=stream) == 64
    assert "--jobs 64 is more than the 2 CPU core(s)" in stream.getvalue()
    assert choose_jobs(None, 5.0, cores=2) == 1  # below the measured break-even: serial
    assert choose_jobs(None, 3 * PARALLEL_OVERHEAD_S, cores=2) == 2
    assert choose_jobs(2, 1.0, cores=2, stream=stream) == 2 and stream.getvalue().count("warning") == 1


def test_jobs_above_the_cores_warns_on_the_command_line(tmp_path, capsys):
    import os

    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\nseed = 5\n[sobol]\nn = 8\nbootstrap = 20\n")
    jobs = (os.cpu_count() or 1) + 1
    assert main(["sobol", str(study), "--jobs", str(jobs), "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]) == 0
    assert f"warning: --jobs {jobs} is more than the" in capsys.readouterr().err


# ---- README: the --perturb help -------------------------------------------------------------------------------

def test_the_perturb_help_describes_its_two_choices(capsys):
    assert main(["sweep", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    help_text = text.split("--perturb {start,each-point}")[-1].split("--integrator")[0]
    assert "start (default, the paper's Sect. 5.1)" in help_text and "each-point:" in help_text
    assert "every hold at the nominal frequency (default" not in help_text  # no third behaviour
