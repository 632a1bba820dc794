"""Speed of `ies identify` (Appendix A): a hammer record of 6 hits of 2^17 samples each at 16.384 kHz (the synthetic
rig: 4 bending modes and the clamping's, 1 % noise, a double hit), read from its CSV, the hits cut out, H_v, LSCF in
sub-bands with the stabilization diagram, LSFD, and every output file and figure written. Target: within 10 s of CPU
on one core (the process's CPU time, all threads counted; median of 3). The modes found are checked as well.

Run: pytest -m benchmark tests/benchmarks/test_identify_speed.py -s
"""
import os
import statistics
import time

import numpy as np
import pytest

from sim.measured.synthetic import HammerTest, hammer_record, rig_truth
from uq.cli import main

pytestmark = pytest.mark.benchmark
REPEATS = 3


def test_identify_a_six_hit_record_of_2_17_samples_per_hit(tmp_path, capsys):
    truth = rig_truth()
    model = truth["model"]
    record = hammer_record(HammerTest(truth["frequencies_hz"][:5], truth["damping_ratios"][:5],
                                      np.array([model.phi_tip[:5] ** 2]), ("tip",), block=2**17))
    t = np.arange(record.force.size) / record.fs
    path = tmp_path / "hammer.csv"
    path.write_text("time_s,force_N,tip_m_s2\n" + "\n".join(
        f"{a:.9g},{b:.7g},{c:.7g}" for a, b, c in zip(t, record.force, record.responses["tip"])) + "\n")
    cpu, wall = [], []
    for i in range(REPEATS):
        c0, w0 = time.process_time(), time.perf_counter()
        assert main(["identify", str(path), "--modes", "4", "--out", str(tmp_path / f"out{i}"), "--json"]) == 0
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    out = capsys.readouterr().out
    found = np.genfromtxt(tmp_path / "out0" / "modes.csv", delimiter=",", names=True)
    print(f"\n{record.force.size} samples ({record.force.size // 2**17} blocks of 2^17): CPU {statistics.median(cpu):.2f} s "
          f"(runs {', '.join(f'{c:.2f}' for c in cpu)}), wall {statistics.median(wall):.2f} s, load average "
          f"{os.getloadavg()[0]:.1f}; f = {', '.join(f'{f:.3f}' for f in found['frequency_hz'])} Hz, "
          f"D = {', '.join(f'{100 * d:.4f}' for d in found['damping_ratio'])} %")
    assert out
    assert np.allclose(found["frequency_hz"], [117.4, 886.0, 2494.0, 4712.0], rtol=5e-4)
    assert statistics.median(cpu) <= 10.0
