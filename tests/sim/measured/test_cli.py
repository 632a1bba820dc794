"""`ies identify`, `ies update`, `ies linearity`, `ies synthetic-tests` from the command line: the README's path on the
regenerated synthetic set of the rig (its numbers against what the set was made of), the JSON, and every bad input of
the issue as one line, exit code 2 and nothing written."""
from __future__ import annotations

import glob
import json
import re
import shlex
import tomllib
from pathlib import Path

import numpy as np
import pytest

from uq.cli import build_parser, main

from tests.support import refused

README = Path(__file__).resolve().parents[3] / "README.md"


def readme_path() -> list[str]:
    """The `ies ...` lines of the README's bash block after "Your measured host"."""
    text = README.read_text()
    block = re.search(r"\*\*Your measured host\*\*.*?```bash\n(.*?)```", text, flags=re.S).group(1)
    return [line.split("  #")[0].strip() for line in block.splitlines() if line.startswith("ies ")]


@pytest.fixture(scope="module")
def walked(tmp_path_factory) -> Path:
    """A folder where the README's path ran (the design parsed only: it takes minutes)."""
    folder = tmp_path_factory.mktemp("path")
    import os

    here = os.getcwd()
    os.chdir(folder)
    try:
        for command in readme_path():
            words = shlex.split(command)[1:]
            if words[0] == "design":
                build_parser().parse_args(words)
                continue
            words = [w for word in words for w in (sorted(glob.glob(word)) if "*" in word else [word])]
            assert main(words) == 0, command
    finally:
        os.chdir(here)
    return folder


def test_the_readme_walks_identify_update_linearity_design():
    assert [shlex.split(c)[1] for c in readme_path()] == ["synthetic-tests", "identify", "update", "linearity", "design"]


def test_the_identified_modes_are_the_sets(walked):
    truth = json.loads((walked / "rig-tests" / "truth.json").read_text())["hammer"]
    rows = np.genfromtxt(walked / "id" / "modes.csv", delimiter=",", names=True)
    bending = [0, 1, 3, 4]  # the set's modes 1, 2, 4, 5: the third is the clamping's, which --modes 4 leaves out
    assert np.allclose(rows["frequency_hz"], np.array(truth["frequencies_hz"])[bending], rtol=5e-4)
    assert np.allclose(rows["damping_ratio"], np.array(truth["damping_ratios"])[bending], rtol=0.1)
    for name in ("modes.csv", "frf.csv", "poles.csv", "identification.json", "stabilization.png", "frf.png"):
        assert (walked / "id" / name).stat().st_size > 0


def test_the_modal_file_carries_the_update_and_the_interval(walked):
    doc = tomllib.loads((walked / "my-rig.toml").read_text())
    truth = json.loads((walked / "rig-tests" / "truth.json").read_text())["shaker"]
    low, high = doc["host"]["damping_interval"]
    assert low == pytest.approx(truth["damping_interval_0.58_0.95mm"][0], rel=0.1)
    assert high == pytest.approx(truth["damping_interval_0.58_0.95mm"][1], rel=0.1)
    assert low <= doc["damping_ratios"][0] <= high  # --set-nominal: D_1* measured over the range
    assert doc["damping_ratios"][1:4] == pytest.approx([0.0044, 0.0005, 0.0031], rel=0.1)
    assert doc["damping_ratios"][4:] == [0.001] * 5
    errors = [p["error"] for p in doc["provenance"]["pairs"]]
    assert errors == pytest.approx([0.0, -0.01055, 0.00284, -0.00378], abs=2e-4)  # Table A.1 on the built-in beam
    from sim.hosts.modal_file import load_modal_model

    assert load_modal_model(walked / "my-rig.toml").damping_interval == (low, high)


def test_identify_json(walked, capsys):
    assert main(["identify", str(walked / "id" / "frf.csv"), "--modes", "4", "--out", str(walked / "again"),
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["frequencies_hz"]) == len(data["damping_ratios"]) == 4
    assert data["frequencies_hz"][0] == pytest.approx(117.4, rel=5e-4)
    assert data["damping_ratios"][0] == pytest.approx(0.0006, rel=0.1)  # the window's damping known from frf.csv


def write(path: Path, header: str, rows: np.ndarray) -> str:
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    return str(path)


T = np.arange(256) / 1024.0
HIT = np.where(np.arange(256) == 20, 100.0, 0.0)


@pytest.mark.parametrize("header, columns, phrase", [
    ("time_s,force_N,accel_m_s2", [T, 0 * T, np.sin(T)], "no hit found"),
    ("time_s,force_N,accel_m_s2", [T, np.where((T > 0.02) & (T < 0.03), 50.0, 0.0), np.sin(T)], "force is clipped"),
    ("time_s,accel_m_s2", [T, np.sin(T)], "no force column"),
    ("time_s,,accel_m_s2", [T, HIT, np.sin(T)], "has no name"),
    ("time_s,force_N,accel_furlong", [T, HIT, np.sin(T)], "no unit this reader knows"),
    ("time_s,force_N,accel_m_s2", [T, HIT, np.r_[np.nan, T[1:]]], "is nan at data row 1"),
    ("frequency_Hz,tip_real_m_N,tip_imag_m_N", [T[::-1] + 1, T, T], "must increase"),
])
def test_bad_records_are_one_line_and_write_nothing(tmp_path, capsys, header, columns, phrase):
    path = write(tmp_path / "r.csv", header, np.column_stack(columns))
    refused(capsys, main(["identify", path, "--out", str(tmp_path / "out")]), path, phrase)
    assert not (tmp_path / "out").exists()


def test_a_uff_of_another_kind_and_a_band_without_poles_are_one_line(tmp_path, capsys):
    import pyuff

    other = tmp_path / "nodes.uff"
    pyuff.UFF(str(other)).write_sets(pyuff.prepare_15(node_nums=[1], def_cs=[0], disp_cs=[0], color=[1], x=[0.0],
                                                      y=[0.0], z=[0.0]), mode="add")
    refused(capsys, main(["identify", str(other), "--out", str(tmp_path / "out")]), "nodes.uff", "type 15")
    f = np.linspace(1, 1000, 4000)
    noise = np.random.default_rng(0).standard_normal((2, f.size)) * 1e-9
    path = write(tmp_path / "noise.csv", "frequency_Hz,tip_real_m_N,tip_imag_m_N", np.column_stack([f, *noise]))
    refused(capsys, main(["identify", path, "--band", "500:900", "--out", str(tmp_path / "out")]), "no stable pole")
    assert not (tmp_path / "out").exists()


def test_modes_that_pair_with_no_model_mode_are_one_line(tmp_path, capsys):
    modes = tmp_path / "modes.csv"
    modes.write_text("mode,frequency_hz,damping_ratio\n1,117.4,0.0006\n2,1500,0.001\n")
    refused(capsys, main(["update", "--measured", str(modes), "--out", str(tmp_path / "m.toml")]),
            "1500 Hz pairs with no model mode")
    assert not (tmp_path / "m.toml").exists()


def test_bad_linearity_options_are_one_line(walked, tmp_path, capsys):
    levels = sorted(glob.glob(str(walked / "rig-tests" / "level-*.csv")))
    out = str(tmp_path / "out")
    refused(capsys, main(["linearity", *levels, "--range", "0.95mm:0.58mm", "--out", out]), "--range")
    refused(capsys, main(["linearity", levels[0], "--out", out]), "one level only")
    refused(capsys, main(["linearity", *levels, "--set-nominal", "--out", out]), "give --model FILE")
    refused(capsys, main(["linearity", *levels, "--model", str(walked / "my-rig.toml"), "--out", out]),
            "--write FILE2 or --in-place")
    assert not Path(out).exists()


def test_a_models_shapes_survive_its_rewrites(walked, tmp_path, capsys):
    """A modal file's [shapes] (the points MAC pairs by) is the user's data: `ies linearity --write` and `ies modes
    --save` carry it into the file they write."""
    from sim.hosts.modal_file import load_shapes

    shaped = tmp_path / "shaped.toml"
    shapes = {"tip": [1.0] * 9, "mid": [0.5] * 9, "root": [0.1] * 9}
    shaped.write_text((walked / "my-rig.toml").read_text().replace(
        "[units]", "[shapes]\n" + "\n".join(f"{k} = {v}" for k, v in shapes.items()) + "\n\n[units]", 1))
    levels = sorted(glob.glob(str(walked / "rig-tests" / "level-*.csv")))
    assert main(["linearity", *levels, "--model", str(shaped), "--write", str(tmp_path / "lin.toml"),
                 "--out", str(tmp_path / "lin")]) == 0
    assert main(["modes", "--model", str(shaped), "--save", str(tmp_path / "saved.toml")]) == 0
    capsys.readouterr()
    for name in ("lin.toml", "saved.toml"):
        assert {k: list(v) for k, v in load_shapes(tmp_path / name, 9).items()} == shapes, name
