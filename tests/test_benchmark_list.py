"""tests/benchmarks/README.md has one line per benchmark file, with a target and its latest figure."""
from __future__ import annotations

import re
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent / "benchmarks"


def listed() -> dict[str, str]:
    """File name -> its line in tests/benchmarks/README.md (lines "- `test_x.py`: ...")."""
    lines = re.findall(r"^- `(test_\w+\.py)`: (.+)$", (BENCHMARKS / "README.md").read_text(), flags=re.M)
    return dict(lines)


def test_every_benchmark_file_is_listed_once_with_target_and_latest_figure():
    lines = re.findall(r"^- `(test_\w+\.py)`", (BENCHMARKS / "README.md").read_text(), flags=re.M)
    assert len(lines) == len(set(lines)), "a benchmark listed twice"
    files = sorted(p.name for p in BENCHMARKS.glob("test_*.py"))
    assert sorted(lines) == files
    for name, line in listed().items():
        assert "Latest: " in line and line.index("Latest: ") > 10, name  # a target first, then the figure

