"""Modal-model files (sim.hosts.modal_file): exact round trip, hand-written files, one-line errors for malformed ones."""
import os
import tomllib

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.hosts.modal_file import ARRAY_KEYS, load_modal_model, save_modal_model
from sim.hosts.rig import seed_rig_model
from sim.model.system import ModalModel

GOOD = """\
# two modes from some FE tool
source = "hand-written"
frequencies_hz = [117.4, 886]          # an integer is a number too
damping_ratios = [0.00085, 0.0044]
phi_wall_left = [1.38, 1.39]
phi_wall_right = [1.37, 1.40]
phi_tip = [1.32, 1.19]
participation = [1.1055, -0.5525]

[units]
frequencies_hz = "Hz"
phi = "1/sqrt(kg)"
"""


def write(tmp_path, text, name="modes.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_round_trip_is_exact(tmp_path):
    model = seed_rig_model()
    path = save_modal_model(model, tmp_path / "rig.toml")
    again = load_modal_model(path)
    for key in ARRAY_KEYS + ("phi_floor",):
        assert np.array_equal(getattr(again, key), getattr(model, key)), key
    assert again.source == model.source
    assert again.beam_mass == model.beam_mass is not None
    assert sorted(os.listdir(tmp_path)) == ["rig.toml"]  # no temporary file left behind
    text = path.read_text()
    assert text.startswith("# ies modal model")
    assert tomllib.loads(text)["units"]["phi"] == "1/sqrt(kg)"


def test_hand_written_file(tmp_path):
    model = load_modal_model(write(tmp_path, GOOD))
    assert isinstance(model, ModalModel) and model.n_modes == 2
    assert model.frequencies_hz.tolist() == [117.4, 886.0]
    assert model.phi_wall_right[1] == 1.40 and model.source == "hand-written"


def test_files_without_the_optional_keys_load_unchanged(tmp_path):
    """A file of the first format (no beam_mass_kg, no phi_floor) gives the same model as before, and saving
    it again writes neither key."""
    model = load_modal_model(write(tmp_path, GOOD))
    assert model.beam_mass is None and model.phi_floor is None
    again = tomllib.loads(save_modal_model(model, tmp_path / "again.toml").read_text())
    assert "beam_mass_kg" not in again and "phi_floor" not in again
    assert {k: again[k] for k in ARRAY_KEYS} == {k: tomllib.loads(GOOD)[k] for k in ARRAY_KEYS} | {
        "frequencies_hz": [117.4, 886.0]}


def test_optional_keys_are_read(tmp_path):
    model = load_modal_model(write(tmp_path, GOOD.replace("[units]", "beam_mass_kg = 1.8\nphi_floor = [1.3, 1.2]\n\n[units]")))
    assert model.beam_mass == 1.8 and model.phi_floor.tolist() == [1.3, 1.2]


def replace_line(key, new_line):
    """GOOD with the top-level line of `key` (not the one in [units]) replaced."""
    lines = GOOD.splitlines()
    index = next(i for i, line in enumerate(lines) if line.startswith(f"{key} ="))
    lines[index] = new_line
    return "\n".join(lines) + "\n"


MALFORMED = [
    (GOOD.replace("phi_tip = [1.32, 1.19]\n", ""), "missing key(s) phi_tip"),
    (replace_line("phi_tip", "phi_tip = [1.32]"), "phi_tip has 1"),
    (replace_line("participation", 'participation = [1.1, "x"]'), "non-numeric value 'x'"),
    (replace_line("participation", "participation = [1.1, true]"), "non-numeric value True"),
    (replace_line("participation", "participation = 1.1"), "must be a non-empty array"),
    (replace_line("phi_tip", "phi_tip = []"), "must be a non-empty array"),
    (replace_line("phi_tip", "phi_tip = [1.0, nan]"), "must be finite"),
    (replace_line("frequencies_hz", "frequencies_hz = [886.0, 117.4]"), "strictly ascending"),
    (replace_line("frequencies_hz", "frequencies_hz = [117.4, 117.4]"), "strictly ascending"),
    (replace_line("frequencies_hz", "frequencies_hz = [-117.4, 886]"), "positive"),
    (replace_line("damping_ratios", "damping_ratios = [0.0, 0.0044]"), "damping ratios must lie in (0, 1)"),
    (replace_line("damping_ratios", "damping_ratios = [0.001, 1.2]"), "damping ratios must lie in (0, 1)"),
    ("frequencies_hz = [117.4,\n", "not valid TOML"),
    ('format = "something-else"\n' + GOOD, "expected 'ies-modal-model'"),
    ("version = 7\n" + GOOD, "version 7 is not supported"),
    (GOOD.replace('frequencies_hz = "Hz"', 'frequencies_hz = "kHz"'), "units.frequencies_hz is 'kHz'"),
    (GOOD.replace("[units]", "phi_floor = [1.3]\n[units]"), "phi_floor has 1"),
    (GOOD.replace("[units]", "phi_floor = [1.3, \"a\"]\n[units]"), "non-numeric value 'a'"),
    (GOOD.replace("[units]", "beam_mass_kg = -1.0\n[units]"), "beam mass must be a positive number"),
    (GOOD.replace("[units]", "beam_mass_kg = \"1.8 kg\"\n[units]"), "'beam_mass_kg' must be a number"),
    (GOOD.replace("[units]", "beam_mass_kg = [1.8]\n[units]"), "'beam_mass_kg' must be a number"),
]


@pytest.mark.parametrize("text, message", MALFORMED)
def test_malformed_files_give_one_clear_line(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(SimulationInputError) as info:
        load_modal_model(path)
    text = str(info.value)
    assert message in text
    assert str(path) in text and "\n" not in text


def test_missing_file_directory_and_binary(tmp_path):
    with pytest.raises(SimulationInputError, match="not found"):
        load_modal_model(tmp_path / "nope.toml")
    with pytest.raises(SimulationInputError, match="is a folder"):
        load_modal_model(tmp_path)
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\xff\xfe\x00\x01")
    with pytest.raises(SimulationInputError, match="not a text"):
        load_modal_model(binary)


def test_save_into_missing_folder_or_onto_a_folder(tmp_path):
    model = seed_rig_model(2)
    with pytest.raises(SimulationInputError, match="does not exist"):
        save_modal_model(model, tmp_path / "no" / "x.toml")
    with pytest.raises(SimulationInputError, match="is a folder"):
        save_modal_model(model, tmp_path)
    assert os.listdir(tmp_path) == []


def test_save_replaces_an_existing_file_atomically(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text("old")
    save_modal_model(seed_rig_model(3), path)
    assert load_modal_model(path).n_modes == 3
    assert sorted(os.listdir(tmp_path)) == ["m.toml"]
