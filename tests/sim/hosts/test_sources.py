"""The host-source seam: one row of `sim.hosts.sources.HOST_SOURCES` is all a new source of modal models needs, and the
one resolver (`sim.hosts.sources.resolve_host`) takes it to every command and study. The toy row, added inside the
test only, builds a 3-mode model; `ies modes` selects it by its own option, prints and saves it, and the saved file
reads back as the same model (`sim.hosts.modal_file`). A second toy row also reads a file kind of its own (".beam3":
a text file holding f1): it reaches `ies sweep` by its option and by `--model FILE`, a study by its `modal_model`,
and `ies design` by `--model`, each checked against the toy model's own numbers (a_base*, a_noabs* by hand).

Files a new host source touches: the file that defines it (here this test) and the registry line."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from sim.hosts.sources import HOST_SOURCES, HostModel, HostSource
from sim.model.system import ModalModel
from tests.support import interval_runs, tiny_design
from uq.cli import main


def three_modes(args: argparse.Namespace) -> HostModel:
    """The toy source: a 3-mode model with frequencies f0 (--toy-beam F0), 4 f0 and 9 f0 (Hz)."""
    f0 = float(args.toy_beam)
    model = ModalModel(frequencies_hz=f0 * np.array([1.0, 4.0, 9.0]), damping_ratios=np.array([0.001, 0.002, 0.003]),
                       phi_wall_left=np.array([2.0, -1.5, 1.0]), phi_wall_right=np.array([2.0, -1.5, 1.0]),
                       phi_tip=np.array([1.8, -1.2, 0.6]), participation=np.array([0.8, 0.3, 0.1]),
                       source=f"toy beam at {f0:g} Hz")
    return HostModel(model, report=["toy source: three modes"])


@pytest.fixture
def toy_row(monkeypatch: pytest.MonkeyPatch) -> HostSource:
    row = HostSource("toy", "--toy-beam", {"metavar": "F0", "help": "a toy 3-mode beam (Hz)"}, three_modes)
    monkeypatch.setitem(HOST_SOURCES, row.name, row)
    return row


def test_ies_modes_shows_and_saves_the_toy_source(toy_row: HostSource, tmp_path, capsys) -> None:
    saved = tmp_path / "toy.toml"
    assert main(["modes", "--toy-beam", "20", "--json", "--save", str(saved)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["n_modes"] == 3 and data["frequencies_hz"] == pytest.approx([20.0, 80.0, 180.0])
    assert data["source"] == "toy beam at 20 Hz" and "rig" not in data
    # a_base* = 2 D* g* / (phi_c phi^T M b) (Sect. 5.3) with phi_c = 2, phi^T M b = 0.8, D* the host's own D_1
    D_star = data["damping_ratios"][0]
    assert data["D_star"] == D_star and data["g_star_m"] == 0.58e-3
    assert data["a_base_star"] == pytest.approx(2 * D_star * 0.58e-3 / (2.0 * 0.8))
    assert main(["modes", "--model", str(saved), "--json"]) == 0
    back = json.loads(capsys.readouterr().out)
    assert back["frequencies_hz"] == pytest.approx(data["frequencies_hz"])
    assert back["phi_tip"] == pytest.approx(data["phi_tip"])


def test_the_toy_source_prints_its_report_and_excludes_the_others(toy_row: HostSource, capsys) -> None:
    assert main(["modes", "--toy-beam", "20"]) == 0
    assert capsys.readouterr().out.startswith("toy source: three modes\nmodal model: toy beam at 20 Hz")
    assert main(["modes", "--toy-beam", "20", "--solid"]) == 2  # one source at a time
    assert main(["modes", "--toy-beam", "20", "--joint-stiffness", "1e9"]) == 2
    assert "--joint-stiffness re-updates the built-in rig; drop --model, --solid, --from-calculix and --toy-beam" \
        in capsys.readouterr().err


#: the toy beam's mode values: the rig's scales (the fixture `model_file`'s), frequencies f1, 21.2 f1 and 168.7 f1
BEAM3 = dict(damping_ratios=[0.00085, 0.0005, 0.001], phi_wall_left=[1.05, 0.95, 0.6], phi_wall_right=[1.05, 0.95, 0.6],
             phi_tip=[1.0, 0.8, 0.3], participation=[0.95, 0.35, 0.1])


def beam3(f1: float, where: str) -> HostModel:
    """The second toy source: three beam-like modes above f1 (Hz)."""
    return HostModel(ModalModel(frequencies_hz=f1 * np.array([1.0, 2494.0 / 117.4, 19800.0 / 117.4]), **BEAM3,
                                source=f"toy beam3 {where}"))


@pytest.fixture
def beam3_row():
    """The toy row, registered by its one registry line for one test and removed after it: its option --beam3 F1 and
    the files *.beam3 (text: f1 in Hz)."""
    saved = dict(HOST_SOURCES)
    HOST_SOURCES["beam3"] = HostSource("beam3", "--beam3", {"metavar": "F1", "type": float, "help": "a toy 3-mode beam"},
                                       lambda args: beam3(args.beam3, "from its option"), reads=(".beam3",),
                                       load=lambda path: beam3(float(Path(path).read_text()), f"file {Path(path).name}"))
    yield HOST_SOURCES["beam3"]
    HOST_SOURCES.clear()
    HOST_SOURCES.update(saved)


def test_a_host_source_reaches_sweep_by_its_option_and_its_files(beam3_row, tmp_path, capsys) -> None:
    beam = tmp_path / "rig.beam3"
    beam.write_text("117.4")
    argv = ["sweep", "--level", "7.4", "--eta", "0.99", "--wait", "0.02", "--hold", "0.05", "--reps", "1", "--json"]
    assert main([*argv, "--beam3", "117.4"]) == 0
    by_option = json.loads(capsys.readouterr().out)
    assert by_option["model"] == "toy beam3 from its option"
    # a_base* = 2 D* g* / (phi_c phi^T M b) (Sect. 5.3), phi_c = 1.05, phi^T M b = 0.95
    assert by_option["a_base"] == pytest.approx(7.4 * 2 * 0.00085 * 0.58e-3 / (1.05 * 0.95), rel=1e-14)
    assert main([*argv, "--model", str(beam)]) == 0
    by_file = json.loads(capsys.readouterr().out)
    assert by_file["model"] == "toy beam3 file rig.beam3" and by_file["mean"] == by_option["mean"]
    assert main(["modes", "--model", str(beam), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["frequencies_hz"][0] == 117.4


def test_a_host_source_reaches_a_study_by_its_files(beam3_row, tmp_path) -> None:
    from uq.problem.models import make_model

    beam = tmp_path / "rig.beam3"
    beam.write_text("117.4")
    _, runs = interval_runs(tmp_path, "modal_model = 'rig.beam3'\n[parameters.D]\n")
    assert {float(r["D"]) for r in runs} == {0.00075, 0.00085, 0.0009}  # its ends and the nominal point
    rig = make_model("ies", modal_model=beam).with_rig().rig
    assert rig.source == "toy beam3 file rig.beam3" and rig.frequencies_hz[0] == 117.4


def test_a_host_source_reaches_the_design_by_its_files(beam3_row, tmp_path) -> None:
    beam = tmp_path / "rig.beam3"
    beam.write_text("117.4")
    data = tiny_design(tmp_path, beam)
    # the structure without IES is the toy's: phi_tip phi^T M b a_base / (2 D_1) at the lower end of D (Sect. 5)
    assert data["no_absorber"]["tip_m"] == pytest.approx([1.0 * 0.95 * 1.5e-6 / (2 * 0.00075)], rel=1e-14)
    assert data["host"]["omega_1_rad_per_s"] == pytest.approx(2 * np.pi * 117.4, rel=1e-12)
