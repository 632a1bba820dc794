"""Fidelity landmarks and variants (sim/hosts/variants.py): the switch and optimum read from overviews built by hand, the
rolling sphere's effective mass against its energy, and the higher modes' damping."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.hosts.rig import seed_rig_model
from sim.hosts.variants import landmarks, rolling_mass_factor, with_higher_mode_damping

ETA = np.linspace(0.96, 1.0, 21)


def fake_sweep(level: float, peaks: list[float], cvs: list[float], peak_eta: float = 0.976, maxes=None):
    """A stand-in for sim.stepped_sine.protocol.SweepResult: one repetition sample per peak, each with its resonant mean at
    peak_eta, amplitude spread cv there, and 2 impacts per period everywhere."""
    k = int(np.argmin(np.abs(ETA - peak_eta)))
    mean_samples = np.full((len(peaks), ETA.size), 0.01)
    mean_samples[:, k] = peaks
    cv_samples = np.full_like(mean_samples, 0.5)
    cv_samples[:, k] = cvs
    mean = mean_samples.mean(axis=0)
    maxes = [2 * p for p in peaks] if maxes is None else maxes
    return SimpleNamespace(level=level, eta=ETA, mean_samples=mean_samples, cv_samples=cv_samples,
                           impacts_samples=np.full_like(mean_samples, 2.0),
                           resonant_mean=float(mean.max()), resonant_max=float(np.mean(maxes)),
                           resonant_mean_samples=np.array(peaks), resonant_max_samples=np.array(maxes),
                           regime="APR" if np.mean(cvs) <= 0.1 else "SMR", impacts_per_period=np.full(ETA.size, 2.0))


def test_switch_optimum_and_levels_of_an_overview():
    results = [
        fake_sweep(7.4, [0.20, 0.19, 0.21], [0.05, 0.04, 0.06]),
        fake_sweep(5.0, [0.05, 0.06, 0.05], [0.4, 0.3, 0.5], peak_eta=0.99),
        fake_sweep(6.0, [0.05, 0.15, 0.05], [0.4, 0.05, 0.5]),  # mostly SMR: one sample APR
        fake_sweep(6.7, [0.12, 0.12, 0.12], [0.05, 0.05, 0.05]),
        fake_sweep(8.0, [0.22, 0.21, 0.20], [0.05, 0.15, 0.05]),  # one sample at the APR branch's edge
        fake_sweep(4.0, [0.06, 0.06, 0.06], [0.4, 0.4, 0.4], peak_eta=0.99),
    ]
    lm = landmarks(results)
    assert lm.levels.tolist() == [4.0, 5.0, 6.0, 6.7, 7.4, 8.0]
    assert lm.last_smr == 6.0 and lm.first_apr == 6.7
    assert lm.apr_samples.tolist() == pytest.approx([0, 0, 1 / 3, 1, 1, 2 / 3])
    assert lm.optimum_level == 5.0
    assert lm.reduction_mean == pytest.approx(1 / np.mean([0.05, 0.06, 0.05]))
    assert lm.reduction_max == pytest.approx(1 / np.mean([0.10, 0.12, 0.10]))
    summary = lm.summary()
    assert summary["resonant_mean_7.4"] == pytest.approx(0.2) and summary["resonant_mean_lo_7.4"] == 0.19
    assert summary["impacts_at_apr_eta_7.4"] == 2.0 and math.isnan(summary["resonant_mean_9"])


def test_no_switch_when_the_highest_level_is_not_apr():
    lm = landmarks([fake_sweep(5.0, [0.05], [0.4]), fake_sweep(9.0, [0.05], [0.3])])
    assert lm.first_apr is None and lm.last_smr == 9.0


def test_a_linear_response_is_not_apr():
    """Without impacts the amplitude does not vary either (cv = 0), but that is the linear branch, not APR."""
    quiet = fake_sweep(7.4, [0.1, 0.1], [0.0, 0.0])
    quiet.impacts_samples[:] = 0.0
    lm = landmarks([quiet])
    assert lm.apr_samples.tolist() == [0.0] and lm.first_apr is None


def test_rolling_mass_factor_is_the_kinetic_energy_of_rolling():
    """7/5 on a flat floor; on two rails at +-b the spin is v/h, h = sqrt(R^2 - b^2): checked against the kinetic
    energy of translation plus spin about the rails' line."""
    R, b, m, v = 7.92e-3, 4e-3, 0.0177, 0.3
    assert rolling_mass_factor(R) == pytest.approx(1.4)
    h = math.sqrt(R**2 - b**2)
    energy = 0.5 * m * v**2 + 0.5 * (0.4 * m * R**2) * (v / h) ** 2
    assert rolling_mass_factor(R, b) == pytest.approx(energy / (0.5 * m * v**2))
    assert rolling_mass_factor(R, b) == pytest.approx(1.537, abs=1e-3)
    with pytest.raises(SimulationInputError, match="support_half_width < sphere_radius"):
        rolling_mass_factor(R, R)


def test_higher_mode_damping():
    model = seed_rig_model()
    changed = with_higher_mode_damping(model, 0.002)
    assert changed.damping_ratios[:4].tolist() == model.damping_ratios[:4].tolist()
    assert np.all(changed.damping_ratios[4:] == 0.002)
    with pytest.raises(SimulationInputError, match="damping of the higher modes"):
        with_higher_mode_damping(model, 1.5)


def test_solid_variants_name_their_contact_points():
    from sim.hosts.variants import SOLID_VARIANTS, solid_variant_model

    up = SOLID_VARIANTS["updated-contact+2mm"]
    left, right = up.wall_points()
    g = up.geometry
    assert left[2] == right[2] == pytest.approx(g.contact_height + 0.002)
    assert right[0] == -left[0] == pytest.approx(0.5 * g.cavity_x)
    assert all(v.justification for v in SOLID_VARIANTS.values())
    with pytest.raises(SimulationInputError, match="unknown solid variant 'best'; choose one of beam-neck"):
        solid_variant_model("best")


def test_hertz_patch_variant_averages_over_the_contact_disc():
    """The Hertz patch (a = 0.45 mm, HERTZ_PATCH_RADIUS) is recorded in the provenance and changes the wall values
    as (a / 3 mm)^2 times what a 3 mm disc changes, within a factor 2 for the field's higher-order terms over the
    larger disc: the average of a smooth field over a disc departs from its centre value as the radius squared
    (medium mesh, 1.01-1.11 times; on a 16 mm mesh the slope's kink at the element face through the contact point
    makes the departure first order in the radius, 6-7 times the r^2 law, and this fails)."""
    pytest.importorskip("skfem")
    from sim.hosts.variants import HERTZ_PATCH_RADIUS, SOLID_VARIANTS, solid_variant_model

    assert SOLID_VARIANTS["updated-hertz-patch"].patch_radius == HERTZ_PATCH_RADIUS == 0.00045
    point, hertz, wide = (solid_variant_model(name, "medium", convergence=False)
                          for name in ("updated", "updated-hertz-patch", "updated-patch-3mm"))
    assert hertz.provenance["patch_radius_m"] == HERTZ_PATCH_RADIUS and point.provenance["patch_radius_m"] == 0
    d_hertz = np.abs(hertz.model.phi_wall_left / point.model.phi_wall_left - 1)
    d_wide = np.abs(wide.model.phi_wall_left / point.model.phi_wall_left - 1)
    expected = (0.45 / 3) ** 2 * d_wide
    assert np.all((d_hertz >= 0.5 * expected) & (d_hertz <= 2 * expected)) and d_wide[-1] > 1e-3


def test_switch_line_names_the_switch_and_the_papers_landmarks():
    from sim.hosts.variants import switch_line

    line = switch_line({"last_smr": 5.3, "first_apr": 5.5, "resonant_mean_7.4": 0.3641})
    assert "between a_base/a_base* = 5.3 and 5.5" in line and "0.364" in line and "6.7" in line
    assert "no switch" in switch_line({"last_smr": 9.0, "first_apr": None, "resonant_mean_7.4": None})
    assert "from the lowest level (4.5)" in switch_line({"last_smr": None, "first_apr": 4.5})
