"""The CalculiX reader (sim/hosts/calculix.py) against the solid model (sim/hosts/solid.py) on the same mesh, and its input checks.

tests/sim/data/calculix/beam.* is a real ccx 2.20 job (45 mm cantilever, 10 x 8 mm, 12 C3D20 elements, 5 modes:
y-bending, x-bending, torsion, y-bending, x-bending), written by sim.hosts.calculix.write_calculix_job from
solid_mesh(SHIPPED_GEOMETRY, element_size=0.015) with node sets WALL_LEFT, WALL_RIGHT, TIP at the solid model's
wall and measurement points, and solved by `ccx beam`. When ccx is installed, a rig-like job (neck, cavity with
groove, block) is written, solved and read back as well.
"""
import math
import shutil
import subprocess

import numpy as np
import pytest

from sim.hosts.calculix import calculix_modal_model, read_dat, read_frd, read_inp
from sim.common.errors import SimulationInputError
from sim.hosts.modal_file import load_modal_model, load_provenance, save_modal_model

DATA = __import__("pathlib").Path(__file__).parents[1] / "data" / "calculix"
SETS = dict(wall_left="WALL_LEFT", wall_right="WALL_RIGHT", tip="TIP")


def shipped_geometry():
    from sim.hosts.solid import SolidGeometry

    return SolidGeometry(free_length=0.045, section_x=0.01, section_y=0.008, neck_length=0.0, cavity_z=0.0,
                         groove_depth=0.0, block_edge=0.0, measurement_below_contact=0.015, measurement_on_face=True)


def compare(calculix, solid, rtol=1e-3, keys=("participation",)):
    for key in ("frequencies_hz", "phi_wall_left", "phi_wall_right", "phi_tip", "damping_ratios") + keys:
        np.testing.assert_allclose(getattr(calculix, key), getattr(solid, key), rtol=rtol, err_msg=key)


def test_shipped_job_reads_and_matches_the_solid_model():
    pytest.importorskip("skfem")
    from sim.hosts.solid import solid_mesh, solid_modal_model, solve_solid_modes

    result = calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", n_modes=2, **SETS)
    assert result.provenance["selected_modes"] == [2, 5]
    assert result.provenance["rejected_modes"][0].startswith("mode 1: y-participation")
    assert "mode 3: no translational participation" in result.provenance["rejected_modes"]
    mesh = solid_mesh(shipped_geometry(), element_size=0.015)
    modes = solve_solid_modes(mesh, n_modes=2)
    solid = solid_modal_model(modes)
    compare(result.model, solid, keys=())
    # same mesh, element and quadrature: frequencies and values agree to the printed digits of the .frd/.dat
    np.testing.assert_allclose(result.model.frequencies_hz, solid.frequencies_hz, rtol=1e-8)
    np.testing.assert_allclose(result.model.phi_tip, solid.phi_tip, rtol=1e-5)
    assert np.all(result.model.phi_wall_left > 0)
    # ccx's participation is phi^T M_ff b_f: the clamped nodes' consistent-mass coupling M_fc b_c, which the solid
    # model keeps, is left out (0.2-0.3 % on this 3-element beam, below 1e-3 on the rig-like mesh of the ccx test)
    ccx_definition = modes.phi.T @ (mesh.M @ (mesh.component == 0).astype(float))
    np.testing.assert_allclose(result.model.participation, ccx_definition, rtol=1e-5)
    np.testing.assert_allclose(result.model.participation, solid.participation, rtol=4e-3)


def test_floor_node_set_and_beam_mass_reach_the_modal_file(tmp_path):
    """--floor NSET gives phi_floor (the set's mean x-values, signed as the walls), --beam-mass the key of Eq. 10;
    both survive the modal file."""
    result = calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", n_modes=2, floor="TIP", beam_mass=0.0283, **SETS)
    np.testing.assert_array_equal(result.model.phi_floor, result.model.phi_tip)
    assert result.provenance["node_sets"]["floor"] == "TIP"
    saved = load_modal_model(save_modal_model(result.model, tmp_path / "ccx.toml"))
    assert saved.beam_mass == 0.0283 and np.allclose(saved.phi_floor, result.model.phi_tip)
    with pytest.raises(SimulationInputError, match="--beam-mass must be a positive mass"):
        calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", n_modes=2, beam_mass=-1.0, **SETS)


def test_readers_on_the_shipped_job():
    frd = read_frd(DATA / "beam.frd")
    assert frd.mode_numbers.tolist() == [1, 2, 3, 4, 5]
    assert np.allclose(frd.generalized_mass, 1.0)
    assert frd.displacements.shape == (5, frd.node_ids.size, 3)
    dat = read_dat(DATA / "beam.dat")
    np.testing.assert_allclose(dat.frequencies, frd.frequencies, rtol=1e-6)
    np.testing.assert_allclose(dat.effective_mass[:, 0], dat.participation[:, 0] ** 2, rtol=1e-5, atol=1e-20)
    deck = read_inp(DATA / "beam.inp")
    assert deck.node_set("tip").size == 1 and deck.node_set("NALL").size == deck.node_ids.size


def test_units_mm_tonne_second_scale_values_and_participation():
    si = calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", n_modes=2, **SETS).model
    mm = calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", n_modes=2, units="mm-t-s", **SETS).model
    np.testing.assert_allclose(mm.phi_tip * math.sqrt(1000), si.phi_tip)
    np.testing.assert_allclose(mm.participation / math.sqrt(1000), si.participation)
    explicit = calculix_modal_model(DATA / "beam.frd", DATA / "beam.inp", modes=[5], **SETS).model
    assert explicit.frequencies_hz[0] == si.frequencies_hz[1]


def copy_job(tmp_path, edit_frd=None, edit_dat=None):
    for suffix, edit in ((".frd", edit_frd), (".dat", edit_dat), (".inp", None)):
        text = (DATA / f"beam{suffix}").read_text()
        (tmp_path / f"beam{suffix}").write_text(edit(text) if edit else text)
    return tmp_path / "beam.frd", tmp_path / "beam.inp"


def without_disp(text):
    out, skip = [], False
    for line in text.splitlines():
        if line.startswith(" -4  DISP"):
            skip = True
        if not skip:
            out.append(line)
        if skip and line.startswith(" -3"):
            skip = False
    return "\n".join(out) + "\n"


@pytest.mark.parametrize("case, message", [
    ("no eigenvectors", "no eigenvectors .*add \\*NODE FILE with U"),
    ("unknown set", "node set 'WALL' is not defined in the .inp \\(defined: CLAMPED, NALL, TIP, WALL_LEFT, WALL_RIGHT\\)"),
    ("no dat", "beam.dat not found: the participation"),
    ("binary", "binary .frd is not supported"),
    ("not frd", "not a CalculiX .frd result file"),
    ("not normalised", "effective modal mass differs .*not mass-normalised"),
    ("missing frd", "nothing.frd not found"),
    ("other job's dat", "frequencies in .* differ"),
    ("too few modes", "only 2 x-bending modes among its 5"),
    ("unknown units", "unknown units 'inch'"),
])
def test_bad_calculix_input_is_one_line(tmp_path, case, message):
    frd, inp = copy_job(
        tmp_path,
        edit_frd={"no eigenvectors": without_disp, "not frd": lambda t: "hello\nworld\n",
                  "binary": lambda t: t.replace("    1MODAL      1", "    1MODAL      2")}.get(case),
        edit_dat={"not normalised": lambda t: t.replace("0.1718467E-01", "0.1818467E-01"),
                  "other job's dat": lambda t: t.replace("0.4070373E+04", "0.4170373E+04")}.get(case))
    kwargs = dict(SETS, n_modes=2)
    if case == "unknown set":
        kwargs["wall_left"] = "WALL"
    if case == "no dat":
        (tmp_path / "beam.dat").unlink()
    if case == "missing frd":
        frd = tmp_path / "nothing.frd"
    if case == "too few modes":
        kwargs["n_modes"] = 3
    if case == "unknown units":
        kwargs["units"] = "inch"
    with pytest.raises(SimulationInputError, match=message) as info:
        calculix_modal_model(frd, inp, **kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.skipif(shutil.which("ccx") is None,
                    reason="CalculiX is not installed (`apt-get install calculix-ccx` gives `ccx`): the live cross-check "
                           "of the solid model against ccx on a small rig-like mesh is skipped")
def test_ccx_on_a_small_rig_like_model_gives_the_solid_models_modal_file(tmp_path):
    pytest.importorskip("skfem")
    from sim.hosts.calculix import write_calculix_job
    from sim.hosts.solid import SolidGeometry, solid_mesh, solid_modal_model, solve_solid_modes

    geometry = SolidGeometry(free_length=0.1, neck_length=0.03, block_edge=0.06)  # the rig's section, cavity, groove
    solid = solid_mesh(geometry, element_size=0.012)
    modes = solve_solid_modes(solid, n_modes=3)
    job = write_calculix_job(solid, tmp_path / "rig.inp", n_modes=20,
                             node_sets={"WALL_LEFT": [geometry.wall_point("left")],
                                        "WALL_RIGHT": [geometry.wall_point("right")], "TIP": [geometry.measurement_point]})
    run = subprocess.run(["ccx", "rig"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:]
    result = calculix_modal_model(tmp_path / "rig.frd", job, n_modes=3, **SETS)
    solid_model = solid_modal_model(modes)
    save_modal_model(result.model, tmp_path / "ccx.toml", result.provenance)
    save_modal_model(solid_model, tmp_path / "solid.toml")
    compare(load_modal_model(tmp_path / "ccx.toml"), load_modal_model(tmp_path / "solid.toml"))
    assert load_provenance(tmp_path / "ccx.toml")["selected_modes"] == (modes.selected + 1).tolist()
