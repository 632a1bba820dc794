"""Scanned crater surfaces: reading, levelling, resampling, metrics, synthetic scans (Sect. 4.1)."""
from scans.errors import ScanError

__all__ = ["ScanError"]
