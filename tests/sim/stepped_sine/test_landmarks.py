"""The Fig. 6 landmarks (sim/stepped_sine/landmarks.py): the switch and optimum read from overviews built by hand, and
the line that sets them beside the paper's."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from sim.stepped_sine.landmarks import landmarks, switch_line

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


def test_switch_line_names_the_switch_and_the_papers_landmarks():
    line = switch_line({"last_smr": 5.3, "first_apr": 5.5, "resonant_mean_7.4": 0.3641})
    assert "between a_base/a_base* = 5.3 and 5.5" in line and "0.364" in line and "6.7" in line
    assert "no switch" in switch_line({"last_smr": 9.0, "first_apr": None, "resonant_mean_7.4": None})
    assert "from the lowest level (4.5)" in switch_line({"last_smr": None, "first_apr": 4.5})
