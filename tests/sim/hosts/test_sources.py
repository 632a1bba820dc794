"""The host-source seam (issue 27): one row of `sim.hosts.sources.HOST_SOURCES` is all a new source of modal models
needs. The toy row, added inside the test only, builds a 3-mode model; `ies modes` selects it by its own option,
prints and saves it, and the saved file reads back as the same model (`sim.hosts.modal_file`)."""
from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

from sim.hosts.sources import HOST_SOURCES, HostModel, HostSource
from sim.model.system import ModalModel
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
    # a_base* = 2 D* g* / (phi_c phi^T M b) (Sect. 5.3) with phi_c = 2, phi^T M b = 0.8
    assert data["a_base_star"] == pytest.approx(2 * 0.00085 * 0.58e-3 / (2.0 * 0.8))
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
