"""No text in the repository pins a measurement to a day or a commit (issue 27): no "today", no "as measured
on", no "measured on <date>", no commit hash on a line with a number. Measured figures go in the closing note
of a change and in tests/benchmarks/README.md as the latest figure; history lives in git.

Commit hashes alone are allowed (an A/B benchmark names the revision it compares against), and so are
numbers that only look like hex (1.5e9 and the like).
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SUFFIXES = (".md", ".py", ".toml")
#: folders that are not the repository's text (environments, outputs, caches)
SKIP = {".git", ".venv", "venv", "ies-out", "build", "dist", "__pycache__", ".pytest_cache", "node_modules"}
MONTHS = "Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec"
DATED = re.compile(rf"\btoday\b|\bas measured on\b|\bmeasured on (?:\d{{4}}-\d\d-\d\d|\d{{1,2}} (?:{MONTHS})|(?:{MONTHS})\w* \d)",
                   re.I)
HEX = re.compile(r"(?<![\w.+-])([0-9a-f]{7,40})(?![\w.])")
NUMBER = re.compile(r"(?<![\w.])\d+(?:\.\d+)?")


def dated(line: str) -> str | None:
    """Why a line pins a measurement to a day or a commit, or None."""
    if match := DATED.search(line):
        return f"dated: {match.group(0)!r}"
    for match in HEX.finditer(line):
        token = match.group(1)
        if not (re.search(r"[a-f]", token) and re.search(r"\d", token)) or re.fullmatch(r"\d+e\d*", token):
            continue  # a word or a number, not a hash
        rest = line[:match.start()] + " " + line[match.end():]
        if NUMBER.search(rest):
            return f"commit {token} next to a number"
    return None


def text_files() -> list[Path]:
    return sorted(p for p in ROOT.rglob("*") if p.suffix in SUFFIXES and p.is_file()
                  and not SKIP.intersection(p.relative_to(ROOT).parts) and p != Path(__file__).resolve())


def test_no_dated_measurements_in_the_repository():
    hits = [f"{path.relative_to(ROOT)}:{n}: {why}" for path in text_files()
            for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1) if (why := dated(line))]
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize("line", [
    "Run on all 24 study files today, it gives every row",
    "the bookkeeping costs 9 % (as measured on the shared machine)",
    "k_H = 1.52 k_H*, measured on 2026-03-01",
    "1.9 s whole command, measured on 3 May",
    "same-run A/B against 780af5c: x1.050 (18.6 -> 19.7 ms)",
    "0.6-9 % longer than at commit 4dda93fe12",
])
def test_a_dated_line_is_found(line):
    assert dated(line)


@pytest.mark.parametrize("line", [
    'BASELINE_REV = os.environ.get("IES_BASELINE_REV", "780af5c")',
    "k = 6147241e9  # N/m",
    "E = 2.15e11, added 1234567 items",
    "the measured FRF shows one mode",
    "a decade of effaced data",
])
def test_an_undated_line_passes(line):
    assert dated(line) is None
