"""The scan stage: scanned crater surfaces read, levelled, measured and resampled into the gap maps of the
contact stage; synthetic and shipped example scans (seed paper Sect. 4.1, Fig. 3).

Pipeline: scan file -> **scans** -> height map -> bem_contact -> k_H -> uq (sim for writing files).
One function per step, data in between::

    scan = read_scan("crater.stl", units="mm")          # Scan (m)
    surface = level_scan(scan, imprint=False)           # LevelledSurface: h outward, crater < 0
    metrics = crater_metrics(surface)                   # depth, rim height, diameter
    contact = scan_contact(surface, Sphere(R=7.92e-3))  # sphere above the crater, BEM domain side
    gap, dx = contact.gap_at(128)                       # gap map for bem_contact (calibrate_k_H)

Public names, each imported from its module on first use, so that `import scans.errors` (done by the `ies`
front door) stays light (importing all of them takes 0.8-1.5 s more):
  contact:   DEFAULT_DENOISE, PAPER_CLEARANCE, PAPER_DELTA_MAX, PAPER_FLATTENING, PAPER_RADIUS, PLACEMENTS,
             ScanContact, Sphere, denoise, scan_contact
  examples:  EXAMPLES, example_path, example_scan, write_examples
  io:        SUPPORTED, UNITS, Scan, check_units, read_scan, write_scan
  metrics:   CraterMetrics, clearance_bounds, crater_metrics
  raster:    HoleReport, fill_holes, rasterize
  surface:   LevelledSurface, level_scan
  synthetic: FLAT_WALL, PAPER_CRATER, CraterShape, synthetic_scan
"""
from __future__ import annotations

import importlib
from typing import Any

from scans.errors import ScanError

_MODULE_OF = {
    "DEFAULT_DENOISE": "contact", "PAPER_CLEARANCE": "contact", "PAPER_DELTA_MAX": "contact",
    "PAPER_FLATTENING": "contact", "PAPER_RADIUS": "contact", "PLACEMENTS": "contact", "ScanContact": "contact",
    "Sphere": "contact", "denoise": "contact", "scan_contact": "contact",
    "EXAMPLES": "examples", "example_path": "examples", "example_scan": "examples", "write_examples": "examples",
    "SUPPORTED": "io", "UNITS": "io", "Scan": "io", "check_units": "io", "read_scan": "io", "write_scan": "io",
    "CraterMetrics": "metrics", "clearance_bounds": "metrics", "crater_metrics": "metrics",
    "HoleReport": "raster", "fill_holes": "raster", "rasterize": "raster",
    "LevelledSurface": "surface", "level_scan": "surface",
    "FLAT_WALL": "synthetic", "PAPER_CRATER": "synthetic", "CraterShape": "synthetic", "synthetic_scan": "synthetic",
}
__all__ = ["ScanError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
