"""Scanned crater surfaces: reading, levelling, resampling, metrics, synthetic scans (Sect. 4.1, Fig. 3).

Pipeline (one function per step, data in between)::

    scan = read_scan("crater.stl", units="mm")          # Scan (m)
    surface = level_scan(scan, imprint=False)           # LevelledSurface: h outward, crater < 0
    metrics = crater_metrics(surface)                   # depth, rim height, diameter
    contact = scan_contact(surface, Sphere(R=7.92e-3))  # sphere above the crater, BEM domain side
    gap, dx = contact.gap_at(128)                       # gap map for bem_contact (calibrate_k_H)

Names are imported lazily so that `import scans.errors` (done by the `ies` entry point) stays cheap.
"""
from __future__ import annotations

import importlib
from typing import Any

from scans.errors import ScanError

_WHERE = {
    "scans.contact": ["DEFAULT_DENOISE", "PAPER_CLEARANCE", "PAPER_DELTA_MAX", "PAPER_FLATTENING", "PAPER_RADIUS", "PLACEMENTS",
                      "ScanContact", "Sphere", "denoise", "scan_contact"],
    "scans.examples": ["EXAMPLES", "example_path", "example_scan", "write_examples"],
    "scans.io": ["SUPPORTED", "UNITS", "Scan", "check_units", "read_scan", "write_scan"],
    "scans.metrics": ["CraterMetrics", "clearance_bounds", "crater_metrics"],
    "scans.raster": ["HoleReport", "fill_holes", "rasterize"],
    "scans.surface": ["LevelledSurface", "level_scan"],
    "scans.synthetic": ["FLAT_WALL", "PAPER_CRATER", "CraterShape", "synthetic_scan"],
}
_MODULE_OF = {name: module for module, names in _WHERE.items() for name in names}
__all__ = ["ScanError", *sorted(_MODULE_OF)]


def __getattr__(name: str) -> Any:
    if name in _MODULE_OF:
        return getattr(importlib.import_module(_MODULE_OF[name]), name)
    raise AttributeError(f"module 'scans' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__
