"""`ies modes`: JSON keys and values, the table, --save/--model, and one-line errors for malformed model files."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from sim.hosts.rig import F_MEASURED_HZ, F_PAPER_MODEL_ERROR, seed_rig_model
from sim.model.system import SPHERE_MASS, a_base_star
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
    assert "beam mass (free length without block, Eq. 10): 1.5730 kg (paper: ca. 1.8 kg)" in out
    assert len(out.splitlines()) == 2 + 9 + 10  # + the host line and the sphere line
    assert "host: D_1* = 0.085 %, interval 0.075-0.09 %; walls steel" in out
    assert "sphere R = 7.92 mm brass, m_a = 17.7 g, k_H* = 282000 N/mm^1.5 (Eq. 8 on steel)" in out


def test_the_host_line_says_when_the_sphere_is_pressed_on_another_wall(capsys):
    assert main(["modes", "--radius", "5mm", "--material", "steel", "--wall-material", "aluminium"]) == 0
    out = capsys.readouterr().out
    assert "walls steel; --wall-material aluminium used for Eq. 8" in out
    assert "(Eq. 8 on aluminium)" in out


def test_save_then_load_through_the_cli(tmp_path, capsys):
    path = tmp_path / "rig.toml"
    assert main(["modes", "--save", str(path)]) == 0
    capsys.readouterr()
    built_in = run_json(capsys)
    loaded = run_json(capsys, "--model", str(path))
    for key in KEYS | {"beam_mass_kg", "phi_floor"}:
        assert loaded[key] == built_in[key], key
    assert "rig" not in loaded
    assert built_in["beam_mass_kg"] == pytest.approx(1.573, abs=1e-3)
    assert len(built_in["phi_floor"]) == 9


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


# ---- --from-calculix and --solid ------------------------------------------------------------------------------

CALCULIX = os.path.join(os.path.dirname(__file__), "data", "calculix")
JOB = ["--from-calculix", os.path.join(CALCULIX, "beam.frd"), "--mesh", os.path.join(CALCULIX, "beam.inp"),
       "--wall-left", "WALL_LEFT", "--wall-right", "WALL_RIGHT", "--tip", "TIP", "--n-modes", "2"]


def test_from_calculix_saves_the_same_model_with_its_provenance(tmp_path, capsys):
    from sim.hosts.calculix import calculix_modal_model
    from sim.hosts.modal_file import load_modal_model, load_provenance

    data = run_json(capsys, *JOB, "--save", str(tmp_path / "ccx.toml"))
    direct = calculix_modal_model(JOB[1], JOB[3], "WALL_LEFT", "WALL_RIGHT", "TIP", n_modes=2).model
    assert data["frequencies_hz"] == pytest.approx(direct.frequencies_hz.tolist(), rel=1e-12)
    assert data["source"].startswith("CalculiX job beam.frd")
    saved = load_modal_model(tmp_path / "ccx.toml")
    assert np.allclose(saved.phi_wall_left, direct.phi_wall_left, rtol=1e-12)
    assert load_provenance(tmp_path / "ccx.toml") == data["provenance"]


def test_solid_model_of_a_small_beam_through_the_cli(tmp_path, capsys):
    pytest.importorskip("skfem")
    geometry = tmp_path / "short.toml"
    geometry.write_text("[geometry]\nfree_length = 0.12\nneck_length = 0.0\nblock_edge = 0.0\n")
    assert main(["modes", "--solid", "--geometry", str(geometry), "--n-modes", "2", "--save",
                 str(tmp_path / "short-rig.toml")]) == 0
    out = capsys.readouterr().out
    assert "solid model: hex20" in out and "mesh convergence against 12 mm" in out
    assert "modal model: 3D solid model (sim.hosts.solid" in out
    assert (tmp_path / "short-rig.toml").is_file()


def test_solid_variant_through_the_cli(tmp_path, capsys):
    """A named solid variant (sim.hosts.variants.SOLID_VARIANTS) saves its name, justification and contact offset."""
    pytest.importorskip("skfem")
    path = tmp_path / "rig3d.toml"
    assert main(["modes", "--solid", "--variant", "updated-contact+2mm", "--json", "--save", str(path)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["provenance"]["variant"] == "updated-contact+2mm"
    assert data["provenance"]["contact_offset_m"] == 0.002 and "2 mm above" in data["provenance"]["justification"]
    assert "variant updated-contact+2mm" in data["source"] and path.is_file()


@pytest.mark.parametrize("args, message", [
    (["--from-calculix", "missing.frd", *JOB[2:]], "missing.frd"),
    ([*JOB[:5], "NOPE", *JOB[6:]], "node set 'NOPE' is not defined"),
    (JOB[:2], "--from-calculix also needs --mesh JOB.inp, --wall-left, --wall-right, --tip"),
    (["--solid", "--mesh", "huge"], "with --solid give a mesh level"),
    (["--mesh", "coarse"], "belong to --solid or --from-calculix"),
    (["--solid", "--variant", "joint-spring"], "'joint-spring' is not a solid-model variant; choose one of beam-neck"),
    (["--solid", "--variant", "updated", "--patch-radius", "0.001"], "--variant fixes the solid model's geometry"),
    ([*JOB, "--variant", "updated"], "the job defines the model; drop --variant"),
    (["--n-modes", "0"], "--n-modes must lie in 1..30"),
    (["--joint-stiffness", "-1"], "--joint-stiffness must be positive in N/m"),
    (["--joint-stiffness", "nan"], "--joint-stiffness must be positive in N/m"),
    (["--joint-stiffness", "1e9", "--solid"], "--joint-stiffness re-updates the built-in rig"),
    (["--joint-stiffness", "1e9", "--variant", "effective-modulus"], "needs an updating variant that frees it"),
])
def test_bad_solid_and_calculix_input_one_line_exit_2_nothing_written(tmp_path, capsys, args, message):
    assert main(["modes", *args, "--save", str(tmp_path / "out.toml")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("content, message", [
    ("[geometry]\ncavity_x = 0.03\n", "the cavity (30 x 16.4 mm) must be narrower than the section"),
    ("[geometry]\nneck_length = -0.01\n", "neck_length must be a non-negative length"),
    ("[geometry]\nwidth = 1\n", "unknown key(s) width in [geometry]"),
    ("[shape]\nx = 1\n", "unknown table(s) shape"),
    ("[geometry\n", "not valid TOML"),
])
def test_solid_geometry_that_does_not_fit_one_line_exit_2_nothing_written(tmp_path, capsys, content, message):
    pytest.importorskip("skfem")
    geometry = tmp_path / "geometry.toml"
    geometry.write_text(content)
    assert main(["modes", "--solid", "--geometry", str(geometry), "--save", str(tmp_path / "out.toml")]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["geometry.toml"]
