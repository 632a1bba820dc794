"""Model updating (Appendix A): the rig updated to Table A.1's frequencies, the stiffness scale against sqrt(E)
scaling of the beam model itself (an independent recomputation of its eigenproblem), the pairing and the damping."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.hosts.rig import rig_modal_model, seed_rig_model, variant_parameters
from sim.measured.update import MeasuredModes, read_modes, update_model

TABLE_A1 = MeasuredModes(np.array([117.4, 886.0, 2494.0, 4712.0]), np.array([0.0006, 0.0044, 0.0005, 0.0031]), "A.1")
PAPER_ERRORS = np.array([0.0005, 0.014, 0.005, 0.007])


def test_the_rig_updated_to_table_a1():
    params = variant_parameters("joint-spring")
    result = update_model(seed_rig_model(), TABLE_A1, E_0=params.E)
    assert result.E == pytest.approx(214.99e9, rel=1e-4)  # the paper: 207 GPa (sim.measured.update's docstring)
    assert np.allclose(100 * result.errors, [0.0, -1.055, 0.284, -0.378], atol=2e-3)
    assert np.all(np.abs(result.errors[1:]) < PAPER_ERRORS[1:])  # smaller than the paper's: the neck was updated too
    assert np.allclose(result.model.damping_ratios, [0.0006, 0.0044, 0.0005, 0.0031, 0.001, 0.001, 0.001, 0.001, 0.001])
    assert result.model.damping_interval is None and "dropped" in result.note  # Table 2's does not hold 0.06 %


def test_the_stiffness_scale_is_the_beams_own_sqrt_e_scaling():
    """Frequencies scale with the square root of the stiffness and the mass-normalised mode values stay: the beam
    recomputed with its stiffness scaled (E and the joint spring: the scale is the whole stiffness matrix's)."""
    params = variant_parameters("joint-spring")
    shifted = MeasuredModes(TABLE_A1.frequencies_hz * 1.02, TABLE_A1.damping_ratios, "shifted")
    result = update_model(seed_rig_model(), shifted, E_0=params.E)
    again = rig_modal_model(replace(params, E=result.E, joint_translational_stiffness=result.scale
                                    * params.joint_translational_stiffness))
    assert np.allclose(result.model.frequencies_hz, again.frequencies_hz, rtol=1e-9)
    for key in ("phi_tip", "phi_wall_left", "participation"):
        assert np.allclose(getattr(result.model, key), getattr(again, key), rtol=1e-7)
    everything = update_model(seed_rig_model(), shifted, fit_mode=None)
    assert everything.scale == pytest.approx(np.exp(2 * np.mean(np.log(shifted.frequencies_hz
                                                                       / seed_rig_model().frequencies_hz[:4]))))


def test_a_measured_mode_without_a_partner_is_one_line():
    clamp = MeasuredModes(np.array([117.4, 886.0, 1500.0]), np.array([0.0006, 0.0044, 0.001]), "modes.csv")
    with pytest.raises(SimulationInputError, match="modes.csv: the measured mode at 1500 Hz pairs with no model mode"):
        update_model(seed_rig_model(n_modes=3), clamp)


def test_modes_csv_is_read_and_checked(tmp_path):
    good = tmp_path / "modes.csv"
    good.write_text("mode,frequency_hz,damping_ratio,modal_constant_tip_per_kg\n1,117.4,0.0006,1.8\n2,886,0.0044,1.4\n")
    assert np.allclose(read_modes(good).frequencies_hz, [117.4, 886.0])
    bad = tmp_path / "bad.csv"
    bad.write_text("mode,f,damping_ratio\n1,117.4,0.0006\n")
    with pytest.raises(SimulationInputError, match="no column frequency_hz"):
        read_modes(bad)
