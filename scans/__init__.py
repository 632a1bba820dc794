"""Scanned crater surfaces: reading, levelling, resampling, metrics, synthetic scans (Sect. 4.1, Fig. 3).

Pipeline (one function per step, data in between)::

    scan = read_scan("crater.stl", units="mm")          # Scan (m)
    surface = level_scan(scan, imprint=False)           # LevelledSurface: h outward, crater < 0
    metrics = crater_metrics(surface)                   # depth, rim height, diameter
    contact = scan_contact(surface, Sphere(R=7.92e-3))  # sphere above the crater, BEM domain side
    gap, dx = contact.gap_at(128)                       # gap map for bem_contact (calibrate_k_H)
"""
from scans.contact import (
    PAPER_CLEARANCE,
    PAPER_DELTA_MAX,
    PAPER_FLATTENING,
    PAPER_RADIUS,
    PLACEMENTS,
    ScanContact,
    Sphere,
    scan_contact,
)
from scans.errors import ScanError
from scans.examples import EXAMPLES, example_path, example_scan, write_examples
from scans.io import SUPPORTED, UNITS, Scan, check_units, read_scan, write_scan
from scans.metrics import CraterMetrics, clearance_bounds, crater_metrics
from scans.raster import HoleReport, fill_holes, rasterize
from scans.surface import LevelledSurface, level_scan
from scans.synthetic import FLAT_WALL, PAPER_CRATER, CraterShape, synthetic_scan

__all__ = [
    "CraterMetrics", "CraterShape", "EXAMPLES", "FLAT_WALL", "HoleReport", "LevelledSurface", "PAPER_CLEARANCE",
    "PAPER_CRATER", "PAPER_DELTA_MAX", "PAPER_FLATTENING", "PAPER_RADIUS", "PLACEMENTS", "SUPPORTED", "Scan",
    "ScanContact", "ScanError", "Sphere", "UNITS", "check_units", "clearance_bounds", "crater_metrics",
    "example_path", "example_scan", "fill_holes", "level_scan", "rasterize", "read_scan", "scan_contact",
    "synthetic_scan", "write_examples", "write_scan",
]
