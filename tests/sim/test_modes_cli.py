"""`ies modes`: JSON keys and values, the table, --save/--model, and one-line errors for malformed model files."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from sim.rig import F_MEASURED_HZ, F_PAPER_MODEL_ERROR, seed_rig_model
from sim.system import SPHERE_MASS, a_base_star
from uq.cli import main

KEYS = {"frequencies_hz", "damping_ratios", "phi_wall_left", "phi_wall_right", "phi_tip", "participation",
        "modal_mass_ratio", "phi_tip_over_phi_c", "a_base_star", "dt"}


def run_json(capsys, *extra):
    assert main(["modes", "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_of_the_built_in_rig(capsys):
    data = run_json(capsys)
    assert KEYS <= set(data)
    model = seed_rig_model()
    assert len(data["frequencies_hz"]) == 9
    assert np.allclose(data["frequencies_hz"], model.frequencies_hz, rtol=1e-12)
    assert np.all(np.abs(np.array(data["frequencies_hz"][:4]) / F_MEASURED_HZ - 1) < F_PAPER_MODEL_ERROR)
    assert data["damping_ratios"] == [0.00085, 0.0044, 0.0005, 0.0031] + [0.001] * 5
    assert data["dt"] == pytest.approx(2 * np.pi / (15 * 2 * np.pi * model.frequencies_hz[8]), rel=1e-12)
    assert data["a_base_star"] == pytest.approx(a_base_star(model), rel=1e-12)
    assert data["modal_mass_ratio"] == pytest.approx(SPHERE_MASS * model.phi_wall_left[0] ** 2)
    assert data["phi_tip_over_phi_c"] == pytest.approx(0.96, abs=0.005)
    rig = data["rig"]
    assert 200e9 <= rig["updated_parameters"]["E_Pa"] <= 215e9
    assert rig["updated_parameters"]["joint_translational_stiffness_N_per_m"] > 0
    assert rig["f_model_error"] == pytest.approx((np.array(data["frequencies_hz"][:4]) / F_MEASURED_HZ - 1).tolist())
    assert rig["f9_hz"] == pytest.approx(19.8e3, rel=0.005)
    assert rig["modal_mass_ratio"] == pytest.approx(data["modal_mass_ratio"])


def test_variant_option(capsys):
    data = run_json(capsys, "--variant", "effective-modulus")
    assert np.allclose(data["frequencies_hz"][:4], F_MEASURED_HZ, rtol=1e-6)
    assert "effective-modulus" in data["source"]
    assert "joint_translational_stiffness_N_per_m" not in data["rig"]["updated_parameters"]
    assert main(["modes", "--variant", "soft"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown rig variant 'soft'" in err
    assert main(["modes", "--variant", "joint-spring", "--model", "x.toml"]) == 2
    assert "cannot be used with --model" in capsys.readouterr().err


def test_table_is_readable(capsys):
    assert main(["modes"]) == 0
    out = capsys.readouterr().out
    assert "117.40" in out and "modal mass ratio" in out and "a_base*" in out
    assert len(out.splitlines()) == 2 + 9 + 6


def test_save_then_load_through_the_cli(tmp_path, capsys):
    path = tmp_path / "rig.toml"
    assert main(["modes", "--save", str(path)]) == 0
    capsys.readouterr()
    built_in = run_json(capsys)
    loaded = run_json(capsys, "--model", str(path))
    for key in KEYS:
        assert loaded[key] == built_in[key], key
    assert "rig" not in loaded


@pytest.mark.parametrize("content, message", [
    ("frequencies_hz = [1.0]\n", "missing key(s)"),
    ("frequencies_hz = [2.0, 1.0]\ndamping_ratios = [0.1, 0.1]\nphi_wall_left = [1, 1]\nphi_wall_right = [1, 1]\n"
     "phi_tip = [1, 1]\nparticipation = [1, 1]\n", "strictly ascending"),
    ("frequencies_hz = [1.0, 2.0]\ndamping_ratios = [0.1, 1.5]\nphi_wall_left = [1, 1]\nphi_wall_right = [1, 1]\n"
     "phi_tip = [1, 1]\nparticipation = [1, 1]\n", "damping ratios"),
    ("this is not toml", "not valid TOML"),
])
def test_malformed_model_file_one_line_exit_2_nothing_written(tmp_path, capsys, content, message):
    bad = tmp_path / "bad.toml"
    bad.write_text(content)
    out_file = tmp_path / "out.toml"
    assert main(["modes", "--json", "--model", str(bad), "--save", str(out_file)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ies modes: error:") and message in lines[0]
    assert not out_file.exists()


def test_missing_model_file_and_bad_save_path(tmp_path, capsys):
    assert main(["modes", "--model", str(tmp_path / "nope.toml")]) == 2
    assert "not found" in capsys.readouterr().err
    assert main(["modes", "--save", str(tmp_path / "missing" / "m.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "does not exist" in err
    assert os.listdir(tmp_path) == []


def test_subprocess_has_no_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("frequencies_hz = [1.0]\n")
    proc = subprocess.run([sys.executable, "-m", "uq", "modes", "--model", str(bad)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
