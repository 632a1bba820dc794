"""Benchmarks of the calibration on scans (run with `pytest -m benchmark -s tests/benchmarks/test_scans_calibrate.py`).

Prints the k_H invariance table at the command's default grid, with the default denoising of the wall
(second-order Gaussian, 90 um) and with the raw scan (--denoise 0), the shipped
scans' k_H / k_H*, and the wall time of the default `ies calibrate` (shipped crater), median of three
runs in fresh processes.
"""
from __future__ import annotations

import statistics
import subprocess
import sys
import time

import numpy as np
import pytest

from scans import DEFAULT_DENOISE, PAPER_CRATER, Sphere, example_path, level_scan, read_scan, scan_contact, synthetic_scan
from scans.examples import EXAMPLES

GRID = 256  # the command's default
DELTAS = np.linspace(2e-6, 40e-6, 20)
R = 7.92e-3
BASE = dict(side=4e-3, triangle=30e-6, seed=21)
VARIANTS = {
    "reference scan (4 mm patch, 30 um triangles, no noise)": {},
    "tilted 5 deg": dict(tilt_deg=5.0, tilt_azimuth_deg=35.0),
    "tilted 5 deg, other azimuth": dict(tilt_deg=5.0, tilt_azimuth_deg=160.0),
    "shifted (7, -3, 12) mm": dict(shift=(7e-3, -3e-3, 12e-3)),
    "rotated 37 deg about the normal": dict(rotation_deg=37.0),
    "noise 0.05 um": dict(noise=0.05e-6),
    "noise 0.1 um": dict(noise=0.1e-6),
    "noise 0.2 um": dict(noise=0.2e-6),
    "noise 0.5 um": dict(noise=0.5e-6),
    "noise 0.5 um, seed 22": dict(noise=0.5e-6, seed=22),
    "noise 0.5 um, seed 23": dict(noise=0.5e-6, seed=23),
    "noise 1 um": dict(noise=1e-6),
    "noise 1 um, seed 22": dict(noise=1e-6, seed=22),
    "noise 1 um, seed 23": dict(noise=1e-6, seed=23),
    "noise 1 um on 60 um triangles": dict(noise=1e-6, triangle=60e-6),
    "meshed 2x finer (15 um)": dict(triangle=15e-6),
    "meshed 2x coarser (60 um)": dict(triangle=60e-6),
    "imprint (read with --imprint)": dict(orientation="imprint"),
    "all at once: tilt, shift, rotation, 0.1 um noise, imprint": dict(
        tilt_deg=5.0, tilt_azimuth_deg=80.0, shift=(2e-3, 5e-3, -8e-3), rotation_deg=-50.0, noise=0.1e-6, orientation="imprint"),
}


def _calibrate(scan, imprint=False, sphere=Sphere(R), denoise=DEFAULT_DENOISE):
    from bem_contact import BRASS, STEEL, contact_modulus
    from bem_contact.calibration import calibrate_k_H

    contact = scan_contact(level_scan(scan, imprint=imprint), sphere, denoise=denoise)
    return calibrate_k_H(contact.gap_at, GRID, contact_modulus(STEEL, BRASS), DELTAS, R=R)


@pytest.mark.benchmark
def test_invariance_table():
    rows = []
    base = {}
    for name, extra in VARIANTS.items():
        kwargs = {**BASE, **extra}
        scan = synthetic_scan(PAPER_CRATER, **kwargs)
        row = [name]
        for denoise in (DEFAULT_DENOISE, 0.0):
            start = time.perf_counter()
            cal = _calibrate(scan, imprint=kwargs.get("orientation") == "imprint", denoise=denoise)
            elapsed = time.perf_counter() - start
            base.setdefault(denoise, cal.k_H_ratio)
            row += [cal.k_H_ratio, cal.k_H_ratio / base[denoise] - 1.0, cal.k_H_error / cal.k_H_star, elapsed]
        rows.append(row)
    print(f"\nk_H invariance, grid {GRID}, {len(DELTAS)} indentations 2..40 um, ideal sphere R = 7.92 mm; "
          f"default: wall denoised over {DEFAULT_DENOISE * 1e6:g} um; raw: --denoise 0")
    print("| scan | k_H/k_H* default | change | error bar (/k_H*) | time | k_H/k_H* raw | change |\n"
          "| --- | --- | --- | --- | --- | --- | --- |")
    for name, ratio, change, err, elapsed, raw, raw_change, _, _ in rows:
        print(f"| {name} | {ratio:.4f} | {100 * change:+.2f} % | {err:.4f} | {elapsed:.1f} s | {raw:.4f} | {100 * raw_change:+.2f} % |")
    assert all(abs(row[2]) < (0.015 if "1 um" in row[0] else 0.01) for row in rows)  # within 1 %; 1 um: spread over seeds
    assert abs(rows[0][1] / rows[0][5] - 1) < 0.002  # the noise-free crater keeps its k_H


@pytest.mark.benchmark
def test_shipped_scans():
    print()
    for name, (filename, imprint, _) in EXAMPLES.items():
        for sphere in (Sphere(R), Sphere(R, flattening=0.02e-3)):
            cal = _calibrate(read_scan(example_path(name)), imprint=imprint, sphere=sphere)
            print(f"{filename:28s} {sphere.describe():80s} k_H/k_H* = {cal.k_H_ratio:.4f} +- {cal.k_H_error / cal.k_H_star:.4f}"
                  f"  fit residual {cal.fit_residual:.4f}")


@pytest.mark.benchmark
def test_default_command_time():
    times = []
    for _ in range(3):
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "uq", "calibrate"], capture_output=True, text=True)
        times.append(time.perf_counter() - start)
        assert proc.returncode == 0, proc.stderr
    print(f"\n`ies calibrate` (shipped crater): median {statistics.median(times):.1f} s of {['%.1f' % t for t in times]}")
    print(proc.stdout)
    assert statistics.median(times) <= 30.0
