"""The calibration as a library (`bem_contact.pipeline`): the command's defaults are the library's, and the flat
wall's k_H agrees with Hertz's k_H* (Eq. 8, a reference that is not our code) from Python, without argparse."""
from __future__ import annotations

import argparse

import pytest

from bem_contact.cli import add_arguments, settings_of
from bem_contact.pipeline import CalibrationSettings, calibrate, summary


def test_the_command_defaults_are_the_library_defaults() -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    assert settings_of(parser.parse_args([])) == CalibrationSettings()


def test_flat_wall_from_python_matches_eq_8() -> None:
    result, source, E_star = calibrate(CalibrationSettings(flat=True, grid=64, points=4))
    data = summary(result, source, E_star)
    assert data["geometry"] == "flat" and data["grid"] == 64
    assert data["k_H_ratio"] == pytest.approx(1.0, abs=0.01)  # Hertz, sphere on a flat: k_H* of Eq. 8
