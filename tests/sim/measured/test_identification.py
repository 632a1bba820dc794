"""LSCF/LSFD identification (Appendix A) against analytic FRFs and against an independent implementation, sdypy-EMA's
LSCF, on the same data after a round trip through UFF 58 written and read by pyuff: frequencies within 0.1 %."""
from __future__ import annotations

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.measured.identification import Band, identify, sub_bands
from sim.measured.records import read_uff, write_uff_frf

F_HZ = np.array([117.4, 886.0, 2494.0, 4712.0])
DAMPING = np.array([0.0006, 0.0044, 0.0005, 0.0031])
A = np.array([1.84, 1.39, 1.016, 0.574])  # phi_tip^2 of the rig, 1/kg


def receptance(f: np.ndarray, A: np.ndarray = A) -> np.ndarray:
    """sum_j A_j / (omega_j^2 - omega^2 + 2 i D_j omega_j omega) (m/N)."""
    w, wj = 2 * np.pi * f[:, None], 2 * np.pi * F_HZ[None, :]
    return np.sum(A / (wj**2 - w**2 + 2j * DAMPING * wj * w), axis=1)


def test_noise_free_frfs_give_the_poles_and_the_modal_constants():
    f = np.arange(1, 65537) * 0.125
    H = np.array([receptance(f), receptance(f, 0.5 * A)])
    result = identify(f, H, ["tip", "wall"], Band(50, 6400), modes=4)
    assert np.allclose(result.frequencies_hz, F_HZ, rtol=1e-6)
    assert np.allclose(result.damping_ratios, DAMPING, rtol=1e-3)
    assert np.allclose(result.modal_constants.real, [A, 0.5 * A], rtol=1e-3)
    assert np.max(result.complexity) < 1e-3


def test_the_sub_bands_cover_the_band_once():
    pairs = sub_bands(Band(50, 6400))
    kept = [(k.lo, k.hi) for _, k in pairs]
    assert kept[0][0] == 50 and kept[-1][1] == 6400
    assert all(a[1] == pytest.approx(b[0]) for a, b in zip(kept, kept[1:]))
    assert all(fit.lo <= k.lo and k.hi <= fit.hi for fit, k in pairs)


def test_uff58_round_trip_and_sdypy_ema_agree(tmp_path):
    EMA = pytest.importorskip("sdypy.EMA")
    f = np.arange(1, 65537) * 0.125
    rng = np.random.default_rng(3)
    noisy = receptance(f) * (1 + 0.01 * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) / np.sqrt(2))
    path = write_uff_frf(tmp_path / "frf.uff", f, {"tip": noisy})
    back = read_uff(path)
    assert np.allclose(back.frequencies_hz, f) and np.allclose(back.frf["tip"], noisy, rtol=1e-6)  # pyuff's ASCII digits
    ours = identify(back.frequencies_hz, np.array([back.frf["tip"]]), ["tip"], Band(50, 6400), modes=4)
    band = back.frequencies_hz <= 6400
    theirs = EMA.Model(frf=back.frf["tip"][None, band], freq=back.frequencies_hz[band], lower=50, upper=6400,
                       pol_order_high=40, frf_form="receptance")
    theirs.get_poles(method="lscf", show_progress=False)
    theirs.select_closest_poles(list(ours.frequencies_hz), f_window=20)
    assert np.allclose(ours.frequencies_hz, theirs.nat_freq, rtol=1e-3)
    assert np.allclose(ours.frequencies_hz, F_HZ, rtol=1e-4)  # and both against the truth
    assert np.allclose(theirs.nat_freq, F_HZ, rtol=1e-3)
    assert np.allclose(ours.damping_ratios, theirs.nat_xi, rtol=0.05)


def test_a_band_without_a_stable_pole_is_one_line():
    f = np.arange(1, 65537) * 0.125
    rng = np.random.default_rng(0)
    noise = 1e-9 * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
    with pytest.raises(SimulationInputError, match="no stable pole in 5000-6000 Hz"):
        identify(f, noise[None], ["tip"], Band(5000, 6000))
    with pytest.raises(SimulationInputError, match="4 stable mode"):
        identify(f, receptance(f)[None], ["tip"], Band(50, 6400), modes=5)
