"""Every file the workbench writes is an ordinary file: mode 0644 under the usual umask 022 (sim.common.files), on
every writing path of every stage, with no temporary file left behind."""
import os
import stat

import numpy as np
import pytest

from scans import write_scan
from sim.common.files import write_text
from uq.cli import main
from uq.commands.reproduce import run_calibration

FAST_SWEEP = ["--eta", "0.98:1.0:3", "--wait", "0.02", "--hold", "0.03", "--reps", "2"]
FAST_CALIBRATION = ["--grid", "32", "--points", "4"]
ISHIGAMI = "[study]\nkind = 'interval'\nmodel = 'ishigami'\n[interval]\ndesigns = ['individual', 'joint']\n"


@pytest.fixture
def umask_022():
    previous = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(previous)


def modes_of_files(folder):
    return {str(p.relative_to(folder)): stat.S_IMODE(p.stat().st_mode) for p in folder.rglob("*") if p.is_file()}


def test_every_written_file_is_0644_under_umask_022(tmp_path, umask_022, capsys):
    commands = [
        ["calibrate", *FAST_CALIBRATION, "--plot", str(tmp_path / "crater.png")],
        ["calibrate", "--flat", *FAST_CALIBRATION, "--plot", str(tmp_path / "flat.pdf")],
        ["modes", "--save", str(tmp_path / "rig.toml")],
        ["sweep", "--level", "6", *FAST_SWEEP, "--out", str(tmp_path / "sweep"), "--plot", str(tmp_path / "fig5.png")],
        ["overview", "--levels", "5,6", *FAST_SWEEP, "--out", str(tmp_path / "overview"),
         "--plot", str(tmp_path / "fig6.png")],
    ]
    study = tmp_path / "study" / "ishigami.toml"
    study.parent.mkdir()
    study.write_text(ISHIGAMI)
    commands.append(["interval", str(study), "--out", str(tmp_path / "interval"), "--jobs", "1", "--quiet"])
    for command in commands:
        assert main(command) == 0, command
    capsys.readouterr()
    points = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0]], dtype=float)
    write_scan(tmp_path / "scan.stl", points, np.array([[0, 1, 2]]))
    write_scan(tmp_path / "scan.xyz", points, None)
    assert run_calibration(lambda: {"k_H": 1.355e10}, tmp_path) == {"k_H": 1.355e10}
    modes = modes_of_files(tmp_path)
    expected = {"crater.png", "flat.pdf", "rig.toml", "sweep/sweep.csv", "sweep/sweep.json", "fig5.png",
                "overview/overview.csv", "overview/overview.json", "fig6.png", "interval/runs.csv",
                "interval/points.csv", "interval/bands.csv", "interval/study.json",
                "interval/individual-variation.png", "interval/joint-variation.pdf", "scan.stl", "scan.xyz", "calibration.json"}
    assert expected <= set(modes), sorted(expected - set(modes))
    assert any(name.startswith("interval/tasks/") for name in modes)
    assert not [name for name in modes if os.path.basename(name).startswith(".")], "temporary file left behind"
    assert {name: mode for name, mode in modes.items() if mode != 0o644} == {}


def test_the_mode_follows_the_umask(tmp_path):
    """0666 & ~umask, as open() gives: a stricter umask gives stricter files."""
    previous = os.umask(0o077)
    try:
        write_text(tmp_path / "private.txt", "x")
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "private.txt").stat().st_mode) == 0o600
