"""`ies calibrate [SCAN]`: output on good scans; one line, exit 2 and nothing written on bad ones."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from scans import CraterShape, FLAT_WALL, PAPER_CRATER, example_path, synthetic_scan, write_scan
from uq.cli import main

FAST = ["--grid", "32", "--points", "6"]


def test_default_is_the_shipped_crater_with_metrics_and_clearance(capsys):
    assert main(["calibrate", "--json", *FAST]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("k_H", "k_H_star", "k_H_ratio", "k_H_error", "crater_depth", "clearance_min", "clearance_max", "grid", "solver"):
        assert key in data
    assert data["scan"].endswith("paper_crater.ply") and data["geometry"] == "scan"
    assert data["crater_depth"] == pytest.approx(PAPER_CRATER.depth, abs=0.5e-6)
    assert data["clearance_min"] == pytest.approx(0.58e-3)
    assert data["clearance_max"] == pytest.approx(0.58e-3 + data["crater_depth"] + 0.02e-3)
    assert 1.4 < data["k_H_ratio"] < 1.65 and data["sphere"].startswith("ideal sphere")
    assert data["grid"] == 32 and data["solver"] == "pk"


def test_text_output_names_geometry_metrics_and_clearance(capsys):
    assert main(["calibrate", *FAST, "--sphere", "flattened", "--flattening", "0.01"]) == 0
    out = capsys.readouterr().out
    for words in ("crater: depth", "flattened sphere", "k_H/k_H*", "clearance: 0.580 to 0.602 mm", "holes:"):
        assert words in out


def test_imprint_in_metres_with_plot(tmp_path, capsys):
    scan = synthetic_scan(PAPER_CRATER, orientation="imprint", tilt_deg=2.0, side=4e-3, triangle=50e-6, seed=3)
    path = write_scan(tmp_path / "imprint.stl", scan.vertices, scan.faces, units="m")
    figure = tmp_path / "cal.png"
    assert main(["calibrate", str(path), "--units", "m", "--imprint", "--json", "--plot", str(figure), *FAST]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["imprint"] is True and data["crater_depth"] == pytest.approx(12e-6, abs=0.5e-6)
    assert figure.stat().st_size > 10_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cal.png", "imprint.stl"]


def test_imprint_without_the_flag_is_warned_about(tmp_path, capsys):
    scan = synthetic_scan(PAPER_CRATER, orientation="imprint", side=4e-3, triangle=50e-6, seed=3)
    path = write_scan(tmp_path / "imprint.ply", scan.vertices, scan.faces)
    assert main(["calibrate", str(path), *FAST]) == 0
    warnings = [line for line in capsys.readouterr().out.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "use --imprint" in warnings[0]


def test_indentation_reference_is_reported_and_the_raw_scan_stays_available(tmp_path, capsys):
    """Default: the wall denoised over 90 um, said in the text and the JSON; --denoise 0 is the raw scan,
    warned about when the scan is noisy; a bad --denoise is one line, exit 2."""
    scan = synthetic_scan(PAPER_CRATER, side=4e-3, triangle=50e-6, noise=0.5e-6, seed=4)
    path = write_scan(tmp_path / "noisy.ply", scan.vertices, scan.faces)
    assert main(["calibrate", str(path), *FAST]) == 0
    out = capsys.readouterr().out
    assert "indentation delta from the first touch on the wall denoised by a second-order Gaussian filter of 90 um" in out
    assert "warning:" not in out
    assert main(["calibrate", str(path), "--denoise", "0", "--json", *FAST]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["denoise"] == 0 and data["indentation_reference"].startswith("first touch on the raw scan")
    assert any("--denoise 0" in w for w in data["warnings"]) and data["units"]["denoise"] == "m"
    assert main(["calibrate", "--flat", "--json", *FAST]) == 0
    assert json.loads(capsys.readouterr().out)["indentation_reference"].startswith("first touch of the ideal sphere")
    assert main(["calibrate", str(path), "--denoise", "-3", *FAST]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1 and "--denoise -3" in captured.err
    from scans import DEFAULT_DENOISE
    from bem_contact.cli import DEFAULT_DENOISE_UM

    assert DEFAULT_DENOISE_UM * 1e-6 == pytest.approx(DEFAULT_DENOISE, rel=1e-12)  # the CLI's copy of the default
    assert main(["calibrate", str(path), "--denoise", "400", "--json", *FAST]) == 0
    assert any("wide against the crater" in w for w in json.loads(capsys.readouterr().out)["warnings"])


def _bad_scans(tmp_path):
    """name -> (file, extra arguments, words the message must contain)."""
    cases = {"missing file": (tmp_path / "nope.stl", [], "no such file")}
    (tmp_path / "scan.step").write_text("ISO-10303-21;")
    cases["unknown format"] = (tmp_path / "scan.step", [], "unknown scan format")
    (tmp_path / "empty.stl").write_bytes(b"")
    cases["empty file"] = (tmp_path / "empty.stl", [], "empty")
    crater = synthetic_scan(PAPER_CRATER, side=4e-3, triangle=50e-6)
    full = write_scan(tmp_path / "full.ply", crater.vertices, crater.faces).read_bytes()
    (tmp_path / "truncated.ply").write_bytes(full[: len(full) // 2])
    (tmp_path / "full.ply").unlink()
    cases["truncated file"] = (tmp_path / "truncated.ply", [], "truncated")
    points = crater.vertices.copy()
    points[100, 1] = np.nan
    cases["NaN coordinates"] = (write_scan(tmp_path / "nan.csv", points, None), [], "NaN")
    big = synthetic_scan(CraterShape(radius=1.6e-3, rim_width=0.3e-3), side=3e-3, triangle=50e-6)
    cases["no flat region"] = (write_scan(tmp_path / "all_crater.ply", big.vertices, big.faces), [], "no flat region")
    cases["implausible units"] = (write_scan(tmp_path / "in_m.ply", crater.vertices, crater.faces, units="m"), [], "--units m")
    small = synthetic_scan(FLAT_WALL, side=1.2e-3, triangle=30e-6)
    cases["crater larger than the scan"] = (write_scan(tmp_path / "small.ply", small.vertices, small.faces), [], "edge of the scanned area")
    cases["crater larger than the grid"] = (example_path("crater"), ["--side-mm", "1.0"], "smaller than the region")
    cases["scan and --flat"] = (example_path("crater"), ["--flat"], "not both")
    cases["unknown unit"] = (example_path("crater"), ["--units", "furlong"], "unknown unit")
    cases["negative flattening"] = (example_path("crater"), ["--flattening", "-0.02"], "--flattening")
    return cases


def test_bad_scans_are_one_line_exit_2_and_write_nothing(tmp_path, capsys):
    inputs = tmp_path / "inputs"
    out = tmp_path / "out"
    inputs.mkdir()
    out.mkdir()
    for name, (path, extra, words) in _bad_scans(inputs).items():
        code = main(["calibrate", str(path), *extra, "--plot", str(out / "fig.png"), *FAST])
        err = capsys.readouterr().err
        assert code == 2, name
        assert err.startswith("ies calibrate: error:") and words in err, (name, err)
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, name
        assert not any(out.iterdir()), name


def test_subprocess_bad_scan_has_no_traceback(tmp_path):
    (tmp_path / "garbage.stl").write_bytes(bytes(range(256)) * 7)
    proc = subprocess.run([sys.executable, "-m", "uq", "calibrate", str(tmp_path / "garbage.stl")], capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and proc.stdout == ""
