"""Study files and parameter spaces: Table 2 defaults, k_H sources, one-line errors for bad input."""
import json
import os
from pathlib import Path

import numpy as np
import pytest

from uq.cli import main
from uq.problem.space import K_H_STAR, calibrated_k_H, resolve_k_H, table2_space
from uq.methods import load_study

MINIMAL = """
[study]
kind = "interval"
[excitation]
levels = [6.7]
"""


def write(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_table2_defaults_and_salib_problem():
    space = table2_space()
    assert space["D"].min == 0.00075 and space["D"].max == 0.00090 and space["D"].nominal == 0.00085
    assert space["g"].max == pytest.approx(0.612e-3)
    # 282e3 N/mm^1.5 = 282e3 * 1000^1.5 N/m^1.5; the upper bound is +52 % (428e3)
    assert space["k_H"].nominal == pytest.approx(282e3 * 1e3**1.5)
    assert space["k_H"].max / space["k_H"].nominal == pytest.approx(428 / 282)
    assert space.extras["k_H_best_estimate"] == pytest.approx(1.25 * K_H_STAR)
    problem = space.salib_problem()
    assert problem["names"] == ["D", "g", "k_H"] and problem["num_vars"] == 3
    assert problem["bounds"][1] == [0.58e-3, 0.612e-3]


def test_k_H_from_ratio_and_calibration(tmp_path):
    assert resolve_k_H("1.52 k_H*") == pytest.approx(1.52 * K_H_STAR)
    calib = tmp_path / "calib.json"
    calib.write_text(json.dumps({"k_H": 1.4e10, "k_H_star": K_H_STAR}))
    assert calibrated_k_H(calib) == 1.4e10
    study = load_study(write(tmp_path, MINIMAL + '[parameters.k_H]\nmax = "calibrated:calib.json"\n'))
    assert study.space["k_H"].max == 1.4e10
    assert not study.space["D"].varied  # unlisted parameters stay nominal


def test_resolved_study_lists_every_setting(tmp_path):
    study = load_study(write(tmp_path, MINIMAL + "eta = { start = 0.95, stop = 1.0, n = 11 }\nsequence = 'up-down-up'\n"))
    d = study.to_dict()
    assert d["levels"] == [6.7] and d["interval"]["fix"]["k_H"] == pytest.approx(1.25 * K_H_STAR)
    resolved = study.make_model().resolved_protocol()  # every protocol default filled in
    assert resolved["eta_start"] == 0.95 and resolved["n_eta"] == 11 and resolved["sequence"] == "up-down-up"
    assert {"wait", "hold", "perturbation", "integrator"} <= set(resolved)


@pytest.mark.parametrize("extra, message", [
    ("[study]\nkind = 'interval'\nbogus = 1\n[excitation]\nlevels=[1.0]\n", "unknown key 'bogus' in [study]"),
    (MINIMAL + "[parameters.E]\nmin = 1.0\n", "unknown parameter 'E'"),
    (MINIMAL + "[parameters.g]\nmin = 0.7e-3\nmax = 0.6e-3\n", "min = 0.0007 is larger than max"),
    (MINIMAL + "[parameters.k_H]\nmin = -1.0\n", "must be a positive number"),
    (MINIMAL + "[parameters.D]\nmax = 1.5\n", "must be below 1"),
    (MINIMAL + "[parameters.g]\nnominal = 0.7e-3\n", "outside [min, max]"),
    (MINIMAL + "[sobol]\nn = 100\n", "[sobol] applies to kind = \"sobol\" only; this is an interval study"),
    (MINIMAL.replace("interval", "sobol") + "[parameters.g]\n[sobol]\nn = 100\n", "power of two"),
    (MINIMAL + "[interval]\nz = -1\n", "[interval] z must be >= 0"),
    ("[excitation]\nlevels = [6.7]\n", "[study] kind is missing: say what the study computes, one of interval, sobol, "
                                        "response, design"),
    ("[study]\nkind = 'design'\n", "run it with `ies design FILE`"),
    (MINIMAL + "[extras]\n", "unknown table [extras]"),
    ("[study]\nkind = 'grid'\n", "kind must be one of"),
    (MINIMAL + "[interval]\ndesigns = ['diagonal']\n", "unknown design 'diagonal'"),
    (MINIMAL.replace("levels = [6.7]", "levels = [0.0]"), "levels must be positive"),
    ("[study]\nkind = 'interval'\nmodel = 'nosuchmodule:f'\n[parameters.a]\nnominal=1\nmin=0\nmax=2\n", "cannot be imported"),
    ("[study\nkind=", "not valid TOML"),
    (MINIMAL.replace("kind", "modal_model = 'none.toml'\nkind"), "modal file"),
    (MINIMAL.replace("kind", "modal_model = 3\nkind"), "modal_model must be the path"),
    ("[study]\nkind = 'interval'\nmodel = 'ishigami'\nmodal_model = 'm.toml'\n", "only applies to model"),
    (MINIMAL + "[variant]\nhigher_mode_damping = 1.5\n", "higher_mode_damping must lie in (0, 1)"),
    (MINIMAL + "[variant]\nsphere_mass_factor = -1\n", "sphere_mass_factor must be positive"),
    (MINIMAL + "[variant]\nspin = 1\n", "unknown key 'spin' in [variant]"),
    ("[study]\nkind = 'interval'\nmodel = 'ishigami'\n[variant]\nsphere_mass_factor = 1.4\n", "only applies to model"),
])
def test_bad_study_is_one_line_exit_2(tmp_path, capsys, extra, message):
    path = write(tmp_path, extra)
    out = tmp_path / "out"
    code = main(["interval", str(path), "--out", str(out), "--quiet", "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert err.startswith("ies interval: error: ")
    assert not out.exists()  # nothing written


def test_missing_study_file(tmp_path, capsys):
    assert main(["sobol", str(tmp_path / "none.toml")]) == 2
    assert "not found" in capsys.readouterr().err


def test_unwritable_output_folder(tmp_path, capsys):
    path = write(tmp_path, "[study]\nkind = 'interval'\nmodel = 'ishigami'\n")
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert main(["interval", str(path), "--out", str(blocker / "sub"), "--quiet", "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert "cannot write to output folder" in err and len(err.strip().splitlines()) == 1
    if os.geteuid() != 0:  # root can write anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        assert main(["interval", str(path), "--out", str(locked / "x"), "--quiet", "--jobs", "1"]) == 2


def test_existing_results_are_not_overwritten_without_resume(tmp_path, capsys):
    path = write(tmp_path, "[study]\nkind = 'interval'\nmodel = 'ishigami'\n")
    out = tmp_path / "out"
    assert main(["interval", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    before = sorted((out / "tasks").iterdir())
    capsys.readouterr()
    assert main(["interval", str(path), "--out", str(out), "--quiet", "--jobs", "1"]) == 2
    assert "--resume" in capsys.readouterr().err
    assert sorted((out / "tasks").iterdir()) == before


def test_wrong_kind_for_command(tmp_path, capsys):
    path = write(tmp_path, "[study]\nkind = 'sobol'\nmodel = 'ishigami'\n")
    assert main(["interval", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "run it with `ies sobol`" in capsys.readouterr().err


def test_a_modal_model_file_replaces_the_built_in_rig(tmp_path):
    """The built-in rig saved as a modal file (`ies modes --save`) gives the same numbers; the file's content,
    not its path, is part of the task key, so an edited file is recomputed."""
    from sim.hosts.modal_file import save_modal_model
    from sim.hosts.rig import seed_rig_model

    save_modal_model(seed_rig_model(n_modes=9), tmp_path / "rig.toml")
    tiny = ("[study]\nkind = 'interval'\n{}[parameters.k_H]\n[excitation]\nlevels = [7.4]\n"
            "eta = {{ start = 0.975, stop = 0.98, n = 2 }}\nwait = 0.05\nhold = 0.1\n[interval]\ninterior = 0\n")
    builtin = load_study(write(tmp_path, tiny.format(""), "builtin.toml"))
    own = load_study(write(tmp_path, tiny.format("modal_model = 'rig.toml'\n"), "own.toml"))
    assert own.modal_model == tmp_path / "rig.toml" and own.to_dict()["modal_model"] == str(tmp_path / "rig.toml")
    a, b = builtin.make_model().with_rig(), own.make_model().with_rig()
    params = {"D": 0.00085, "g": 0.58e-3, "k_H": K_H_STAR}
    ra, rb = a(params, 7.4, 0, 1), b(params, 7.4, 0, 1)
    assert (ra["mean"], ra["max"]) == (rb["mean"], rb["max"])
    key = b.describe()["modal_model_sha256"]
    (tmp_path / "rig.toml").write_text((tmp_path / "rig.toml").read_text().replace("0.00085", "0.0009", 1))
    assert own.make_model().describe()["modal_model_sha256"] != key


def test_variant_table_changes_the_sphere_mass_and_the_higher_modes_damping(tmp_path):
    """[variant] sphere_mass_factor scales m_a, higher_mode_damping sets D of modes 5..N; both enter the task key,
    and a study without [variant] keeps its key (cached results stay valid)."""
    from sim.hosts.rig import seed_rig_model
    from sim.model.system import SPHERE_MASS

    tiny = ("[study]\nkind = 'response'\n{}[excitation]\nlevels = [7.4]\n"
            "eta = {{ start = 0.975, stop = 0.98, n = 2 }}\nwait = 0.05\nhold = 0.1\n")
    plain = load_study(write(tmp_path, tiny.format(""), "plain.toml")).make_model()
    varied = load_study(write(tmp_path, tiny.format("[variant]\nsphere_mass_factor = 1.4\nhigher_mode_damping = 0.004\n"),
                              "varied.toml")).make_model()
    assert "variant" not in plain.describe() and varied.describe()["variant"] == {
        "sphere_mass_factor": 1.4, "higher_mode_damping": 0.004}
    params = {"D": 0.00085, "g": 0.58e-3, "k_H": K_H_STAR}
    assert varied.simulated_system(params)[1].mass == pytest.approx(1.4 * SPHERE_MASS)
    builtin = seed_rig_model(n_modes=9).damping_ratios
    damping = varied.with_rig().rig.damping_ratios
    assert np.all(damping[4:] == 0.004) and np.array_equal(damping[:4], builtin[:4])


def test_reproduce_with_a_bad_modal_model_writes_nothing(tmp_path, capsys):
    out = tmp_path / "o"
    (tmp_path / "bad.toml").write_text("format = 'something else'\n")
    assert main(["reproduce", "fig7", "--quick", "--model", str(tmp_path / "bad.toml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "modal_model" in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()


SHIPPED = Path(__file__).resolve().parents[3] / "uq" / "studies"
SHIPPED_FILES = sorted(SHIPPED.rglob("*.toml"))


@pytest.mark.parametrize("path", [p for p in SHIPPED_FILES if "ies-modal-model" not in p.read_text()],
                         ids=lambda p: str(p.relative_to(SHIPPED)))
def test_every_shipped_study_loads_and_builds_its_model(path):
    study = load_study(path)
    model = study.make_model()
    assert study.levels and model is not None
    if study.modal_model is not None:
        assert study.modal_model.is_file()


def test_the_wheel_ships_every_study_and_modal_file():
    import tomllib
    from pathlib import PurePosixPath

    globs = tomllib.loads((SHIPPED.parents[1] / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["uq"]
    # setuptools globs do not cross folders: the pattern must match every part of the path
    shipped = [PurePosixPath(p.relative_to(SHIPPED.parent).as_posix()) for p in SHIPPED_FILES]
    missing = [str(p) for p in shipped if not any(len(p.parts) == len(PurePosixPath(g).parts) and p.match(g)
                                                  for g in globs)]
    assert len(SHIPPED_FILES) > 40 and not missing


def test_the_papers_study_space_is_table_2_to_the_last_bit(tmp_path):
    """The host and sphere descriptions change nothing for the rig and the paper's sphere: the space of a study
    without [impactor] is Table 2's rows exactly (and so are its tasks' keys)."""
    from sim.model.parameters import table2_parameters

    study = load_study(write(tmp_path, MINIMAL + "[parameters.D]\n[parameters.g]\n[parameters.k_H]\n"))
    for row in table2_parameters():
        p = study.space[row.name]
        assert (p.nominal, p.min, p.max) == (row.nominal, *row.interval)
    assert study.space.extras == table2_space().extras and "impactor" not in study.to_dict()


def test_a_study_of_ones_own_host_and_sphere(tmp_path, capsys):
    """[impactor] gives k_H's nominal value by Eq. 8 (steel on the host's aluminium walls), "1.25 k_H*" is relative to
    it; D's default interval is the host's [host] damping_interval around its own D_1*; g_star sets a_base*."""
    from sim.hosts.modal_file import save_modal_model
    from sim.hosts.rig import seed_rig_model
    from sim.model.materials import WALL_MATERIALS
    from sim.model.sphere import sphere_of
    from sim.model.system import ModalModel

    rig = seed_rig_model()
    fields = {k: getattr(rig, k) for k in ("frequencies_hz", "phi_wall_left", "phi_wall_right", "phi_tip", "participation")}
    d = rig.damping_ratios.copy()
    d[0] = 0.001
    save_modal_model(ModalModel(**fields, damping_ratios=d, damping_interval=(0.0009, 0.0012),
                                wall=WALL_MATERIALS["aluminium"]), tmp_path / "host.toml")
    text = MINIMAL.replace('kind = "interval"', 'kind = "interval"\nmodal_model = "host.toml"') + """
g_star = "1 mm"
[impactor]
radius = "5 mm"
material = "steel"
[parameters.D]
[parameters.k_H]
best_estimate = "1.25 k_H*"
"""
    study = load_study(write(tmp_path, text))
    k_H_star = sphere_of(5e-3, "steel", wall="aluminium").k_H_star
    assert study.space["k_H"].nominal == k_H_star and study.space["k_H"].max == pytest.approx(428 / 282 * k_H_star)
    assert study.space.extras["k_H_best_estimate"] == pytest.approx(1.25 * k_H_star)
    D = study.space["D"]
    assert (D.nominal, D.min, D.max) == (0.001, 0.0009, 0.0012)
    assert study.g_star == 1e-3 and study.impactor == {"radius": 5e-3, "material": "steel"}
    model = study.make_model().with_rig()
    system_model, impactor = model.simulated_system(study.space.nominal())
    assert impactor.mass == pytest.approx(4 / 3 * np.pi * 5e-3**3 * 7810.0) and impactor.k_H == k_H_star
    assert model.describe()["impactor"] == {"radius": 5e-3, "material": "steel"} and model.describe()["g_star"] == 1e-3


@pytest.mark.parametrize("table, message", [
    ('[impactor]\nmaterial = "gold"', "[impactor] unknown sphere material 'gold'"),
    ('[impactor]\nwall_material = "wood"', "[impactor] unknown wall material 'wood'"),
    ('[impactor]\nradius = "5 mm"\nmaterial = "steel"\nmass = "1 g"', "disagrees with a solid steel sphere"),
    ('[impactor]\ncolour = "red"', "unknown key 'colour' in [impactor]"),
])
def test_a_bad_impactor_table_is_one_line(tmp_path, capsys, table, message):
    path = write(tmp_path, MINIMAL + table)
    assert main(["interval", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1 and not (tmp_path / "out").exists()
