"""Hammer records to FRFs and modes (Appendix A), against a known modal model: the issue's synthetic hammer test (4
modes, damping 0.05-0.44 %, 1 % noise, records that end while mode 1 still rings, one double hit) must give every
frequency within 0.05 % and every damping ratio within 10 %; the estimators against their definitions; the bad records
one line each."""
from __future__ import annotations

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.measured.hammer import HammerRecord, HammerSettings, frf_estimate, remove_window_damping
from sim.measured.identification import Band, identify
from sim.measured.synthetic import HammerTest, hammer_record

F_HZ = np.array([117.4, 886.0, 2494.0, 4712.0])
DAMPING = np.array([0.0006, 0.0044, 0.0005, 0.0031])
PHI_TIP = np.array([1.355, 1.180, 1.008, 0.758])


def known_test(**kw) -> HammerTest:
    return HammerTest(F_HZ, DAMPING, np.array([PHI_TIP**2]), ("tip",), **kw)


@pytest.fixture(scope="module")
def record() -> HammerRecord:
    # 2^15 samples per hit at 16.384 kHz: 2 s, mode 1 (decay time 1/(D omega) = 2.3 s) still rings at each block's end
    return hammer_record(known_test(block=2**15))


def test_the_issues_synthetic_hammer_test(record):
    estimate = frf_estimate([record])
    assert [h.double for h in estimate.hits] == [False, False, True, False, False, False]
    assert [h.used for h in estimate.hits].count(True) == 5
    ring = np.exp(-DAMPING[0] * 2 * np.pi * F_HZ[0] * estimate.block / record.fs)
    assert ring > 0.3  # the record ends while mode 1 still rings
    result = identify(estimate.frequencies_hz, np.array([estimate.Hv["tip"]]), ["tip"], Band(50, 6400), modes=4,
                      window_decay=estimate.window_decay)
    assert np.max(np.abs(result.frequencies_hz / F_HZ - 1)) < 5e-4
    assert np.max(np.abs(result.damping_ratios / DAMPING - 1)) < 0.10
    # the modal constants of a driving point are phi^2 (1/kg); the LSFD's within 10 %
    assert np.allclose(result.modal_constants[0].real, PHI_TIP**2, rtol=0.1)


def test_without_the_window_correction_the_damping_of_mode_1_is_the_windows(record):
    estimate = frf_estimate([record])
    raw = identify(estimate.frequencies_hz, np.array([estimate.Hv["tip"]]), ["tip"], Band(50, 6400), modes=4)
    sigma_window = estimate.window_decay
    assert raw.damping_ratios[0] > 3 * DAMPING[0]  # the window's decay rate dominates mode 1's
    corrected = remove_window_damping(np.array([-raw.damping_ratios[0] * 2 * np.pi * raw.frequencies_hz[0] + 1j]),
                                      sigma_window)
    assert abs(-corrected.real[0] / (2 * np.pi * F_HZ[0]) / DAMPING[0] - 1) < 0.1


def test_estimators_on_noise_free_records():
    """Without noise (one hit per record: no earlier hit rings into the block) H1 = H2 = Hv and the coherence is 1; with
    noise on the response only, |H1| <= |Hv| <= |H2| and Hv is their geometric mean."""
    clean = [hammer_record(known_test(block=2**16, hits=1, noise=0.0, double_hit=None, seed=s)) for s in (1, 2, 3)]
    est = frf_estimate(clean, HammerSettings(exp_window_end=0.001))
    band = (est.frequencies_hz > 50) & (est.frequencies_hz < 6000)
    assert np.allclose(est.H1["tip"][band], est.H2["tip"][band], rtol=1e-4)
    assert np.min(est.coherence["tip"][band]) > 0.9999
    rng = np.random.default_rng(0)
    noisy = [HammerRecord(c.fs, c.force, {"tip": c.responses["tip"] + 0.05 * np.std(c.responses["tip"])
                                          * rng.standard_normal(c.force.size)}, c.quantities) for c in clean]
    est2 = frf_estimate(noisy, HammerSettings(exp_window_end=0.001))
    h1, hv, h2 = (np.abs(e["tip"][band]) for e in (est2.H1, est2.Hv, est2.H2))
    assert np.all(h1 <= hv * (1 + 1e-12)) and np.all(hv <= h2 * (1 + 1e-12))
    assert np.allclose(hv, np.sqrt(h1 * h2))


def test_a_record_without_hits_is_one_line():
    rng = np.random.default_rng(0)
    rec = HammerRecord(16384.0, rng.standard_normal(4096) * 0.0, {"a": rng.standard_normal(4096)}, {"a": "acceleration"},
                       "quiet.csv")
    with pytest.raises(SimulationInputError, match="quiet.csv: no hit found"):
        frf_estimate([rec])


def test_a_clipped_force_is_one_line(record):
    force = np.clip(record.force, None, 0.4 * record.force.max())
    with pytest.raises(SimulationInputError, match="force is clipped at the hit at t = .* overloaded"):
        frf_estimate([HammerRecord(record.fs, force, record.responses, record.quantities, "clip.csv")])


def test_only_double_hits_leave_nothing_to_average():
    rec = hammer_record(known_test(block=2**12, hits=1, double_hit=0))
    with pytest.raises(SimulationInputError, match="no hit left to average"):
        frf_estimate([rec])
    kept = frf_estimate([rec], HammerSettings(reject_double_hits=False))
    assert kept.hits[0].double and kept.hits[0].used
