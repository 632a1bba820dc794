"""The fidelity report's table (uq/studies/fidelity/README.md) is `ies compare`'s output over the fidelity studies.

Always: the table lists every response study of uq/studies/fidelity once, by its name, and the paper's row last as
`uq.outputs.compare` states it; every row reads back into the values `ies compare` prints and prints back identically
(its format is `uq.outputs.compare.compare_text`'s). With IES_FIDELITY_RESULTS=DIR (DIR/NAME the --out folder of each
study, e.g. after the loop in the report), the table must equal `ies compare`'s output on those folders.
"""
from __future__ import annotations

import math
import os
import re
import tomllib
from pathlib import Path

import pytest

from uq.outputs.compare import LANDMARK_LEVELS, PAPER_ROW, compare_text

FOLDER = Path(__file__).resolve().parents[3] / "uq" / "studies" / "fidelity"
#: compare_text's column widths: study, switch, optimum, level at 7.4, level at 9, imp/T, sig/T, r, E2..N
WIDTHS = (34, 10, 14, 28, 28, 6, 6, 5, 6)


def report_table() -> list[str]:
    """The lines of the report's ```text block that holds the table (header first)."""
    head = compare_text([]).splitlines()[0]
    for block in re.findall(r"^```text\n(.*?)^```", (FOLDER / "README.md").read_text(), flags=re.M | re.S):
        lines = block.splitlines()
        if lines and lines[0] == head:
            return lines
    raise AssertionError("the report has no table in `ies compare`'s format")


def response_studies() -> dict[str, str]:
    """Study file stem -> study name of every response study in the folder."""
    found = {}
    for path in sorted(FOLDER.glob("*.toml")):
        study = tomllib.loads(path.read_text()).get("study", {})
        if study.get("kind") == "response":
            found[path.stem] = study["name"]
    return found


def _number(text: str) -> float:
    return math.nan if text.strip() in ("–", "") else float(text.rstrip("%"))


def parse_row(line: str) -> dict:
    """A row of compare_text read back into compare.csv's keys."""
    cells, at = [], 0
    for width in WIDTHS:
        cells.append(line[at:at + width])
        at += width + 1
    study, switch, optimum, *levels, impacts, significant, r, share = (c.strip() for c in cells)
    row = {"study": study}
    if switch == "none":
        row["last_smr"], row["first_apr"] = math.nan, math.nan
    elif switch.startswith("APR from "):
        row["last_smr"], row["first_apr"] = math.nan, float(switch[9:])
    else:
        row["last_smr"], row["first_apr"] = map(float, switch.split("->"))
    level, reductions = optimum.split(": ")
    row["optimum_level"] = float(level)
    row["reduction_mean"], row["reduction_max"] = (float(x.rstrip("x")) for x in reductions.split("/"))
    for value, text in zip(LANDMARK_LEVELS, levels):
        m = re.fullmatch(r"(?:(\S+) )?(?:\[(\S+), (\S+)\] )?(\S*)", text)
        mean, lo, hi, regime = m.groups() if text != "–" else (None, None, None, "")
        row.update({f"resonant_mean_{value:g}": _number(mean or ""), f"resonant_mean_lo_{value:g}": _number(lo or ""),
                    f"resonant_mean_hi_{value:g}": _number(hi or ""), f"regime_{value:g}": regime})
    row.update({"impacts_per_period_7.4": _number(impacts), "significant_impacts_per_period_7.4": _number(significant),
                "restitution_7.4": _number(r), "higher_mode_energy_share_7.4": _number(share) / 100})
    return row


def test_the_table_lists_every_fidelity_study_once_and_the_paper_last():
    lines = report_table()
    names = [line[:WIDTHS[0]].strip() for line in lines[1:-1]]
    assert sorted(names) == sorted(response_studies().values()) and len(set(names)) == len(names)
    assert lines[-1] == compare_text([]).splitlines()[-1] and lines[-1].startswith(PAPER_ROW["study"])


def test_every_row_is_in_the_format_ies_compare_prints():
    lines = report_table()
    rows = [parse_row(line) for line in lines[1:-1]]
    assert compare_text(rows).splitlines() == lines


@pytest.mark.skipif(not os.environ.get("IES_FIDELITY_RESULTS"), reason="set IES_FIDELITY_RESULTS to the studies' results")
def test_the_table_is_ies_compare_on_the_results(capsys):
    from uq.cli import main

    root = Path(os.environ["IES_FIDELITY_RESULTS"])
    by_name = {name: stem for stem, name in response_studies().items()}
    folders = [str(root / by_name[line[:WIDTHS[0]].strip()]) for line in report_table()[1:-1]]
    capsys.readouterr()
    assert main(["compare", *folders, "--out", str(root / "compare-check")]) == 0
    printed = [line for line in capsys.readouterr().out.splitlines() if not line.startswith("wrote ")]
    assert printed == report_table()
