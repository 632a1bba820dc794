"""The example scans shipped in `scans/data/`, and the seeded recipe that made them (Sect. 4.1, Fig. 3b).

* ``flat_wall.stl``: an undamaged wall (binary STL, mm): 4 mm patch, 60 um triangles, 0.05 um noise.
* ``paper_crater.ply``: a crater like the paper's, as the wall (binary PLY, mm): 12 um deep, bowl radius
  0.75 mm, 6 um pile-up; 4.5 mm patch, 30 um triangles, 0.05 um noise.
* ``paper_crater_imprint.stl``: the same crater as its resin imprint, the way the paper scanned it
  (binary STL, mm): 50 um triangles, tilted 3 deg, turned 20 deg and shifted as a scan on a table would be;
  read it with ``--imprint``.

Regenerate with ``python -m scans.examples FOLDER``; the test suite checks that the shipped files match.
"""
from __future__ import annotations

import sys
from importlib import resources
from pathlib import Path

from scans.errors import ScanError
from scans.io import Scan, write_scan
from scans.synthetic import FLAT_WALL, PAPER_CRATER, synthetic_scan

#: name -> (file name, read with --imprint, recipe for `synthetic_scan`)
EXAMPLES: dict[str, tuple[str, bool, dict]] = {
    "flat": ("flat_wall.stl", False, dict(shape=FLAT_WALL, side=4e-3, triangle=60e-6, noise=0.05e-6, seed=1)),
    "crater": ("paper_crater.ply", False, dict(shape=PAPER_CRATER, side=4.5e-3, triangle=30e-6, noise=0.05e-6, seed=2)),
    "imprint": ("paper_crater_imprint.stl", True, dict(
        shape=PAPER_CRATER, side=4.5e-3, triangle=50e-6, noise=0.05e-6, seed=3, orientation="imprint",
        tilt_deg=3.0, tilt_azimuth_deg=60.0, rotation_deg=20.0, shift=(12e-3, -4e-3, 25e-3))),
}
DEFAULT_EXAMPLE = "crater"


def example_path(name: str = DEFAULT_EXAMPLE) -> Path:
    """Path of a shipped example scan ("flat", "crater" or "imprint")."""
    if name not in EXAMPLES:
        raise ScanError(f"unknown example {name!r}; choose one of {', '.join(EXAMPLES)}")
    return Path(str(resources.files("scans") / "data" / EXAMPLES[name][0]))


def example_scan(name: str) -> Scan:
    """The in-memory scan (m) the example file was written from."""
    return synthetic_scan(**EXAMPLES[name][2])


def write_examples(folder: str | Path) -> list[Path]:
    """Write every example scan into `folder` (in mm, as scanners deliver them)."""
    folder = Path(folder)
    written = []
    for name, (filename, _, _) in EXAMPLES.items():
        scan = example_scan(name)
        written.append(write_scan(folder / filename, scan.vertices, scan.faces, units="mm"))
    return written


if __name__ == "__main__":  # pragma: no cover
    for path in write_examples(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "data"):
        print(path, path.stat().st_size, "bytes")
