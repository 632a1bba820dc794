"""`ies compare`: the Fig. 6 landmarks of several response studies side by side, next to the paper's (the
fidelity report, uq/studies/fidelity/README.md): one row per study (the switch from SMR to APR, the optimum and its reductions, the resonant level
with its repetition range and regime at 7.4 and 9, the impacts, significant impacts, restitution r (Eq. D.1)
and share of modes 2..N after the impacts at 7.4), and one figure with every study's resonant mean against the
excitation level and the paper's landmarks (Sect. 5.3, Appendices B and D).

Only the data files of the folders are read (study.json, overview.csv), never the runs: the fidelity report's
table is `ies compare ies-out/fidelity/* --out ies-out/fidelity-compare`.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from sim.common.outputs import Column, OutputFile
from sim.stepped_sine.measures import PAPER_APR_LEVEL, PAPER_IMPACTS_PER_PERIOD, PAPER_OPTIMUM_LEVEL, PAPER_REDUCTION_MAX, \
    PAPER_REDUCTION_MEAN
from uq.errors import StudyError

#: the levels a_base/a_base* at which the table reports the resonant level (7.4: the paper's APR landmark)
LANDMARK_LEVELS = (7.4, 9.0)
#: measures of overview.csv reported at the first landmark level (the resonant eta there)
SCATTERING_AT_7_4 = ("impacts_per_period", "significant_impacts_per_period", "restitution", "higher_mode_energy_share")
COMPARE_CSV = OutputFile("compare.csv", "ies compare --out DIR", "One row per study folder and the paper's last "
                         "(switch and optimum at 6.7 with 20x / 10x, APR level at 7.4 0.14-0.19 as resonant_mean_lo_7.4 "
                         "and _hi_7.4, 2 significant impacts per period, r = 0.8, 15 % in modes 2-9; what it does not "
                         "state is nan). compare.json (also --json) holds `studies` (these rows) and `paper`.", (
    Column("study", "", "the study's name"),
    Column("folder", "", "its folder"),
    Column("last_smr", "a_base/a_base*", "the last level with a strongly modulated resonance (the switch's lower end)"),
    Column("first_apr", "a_base/a_base*", "the first level from which the resonance is almost periodic"),
    Column("optimum_level", "a_base/a_base*", "the level of the lowest resonant mean"),
    Column("reduction_mean", "-", "1 / resonant mean at the optimum"),
    Column("reduction_max", "-", "1 / resonant max at the optimum"),
    *(Column(f"{key}_{level:g}", unit, f"{what} at level {level:g} (from overview.csv; nan or empty where missing)")
      for level in LANDMARK_LEVELS
      for key, unit, what in (("resonant_mean", "a/a_noabs*", "the resonant mean"),
                              ("resonant_mean_lo", "a/a_noabs*", "its smallest repetition sample"),
                              ("resonant_mean_hi", "a/a_noabs*", "its largest repetition sample"),
                              ("regime", "", "the regime"))),
    *(Column(f"{key}_7.4", "-", f"overview.csv's {key} at 7.4") for key in SCATTERING_AT_7_4),
))
#: compare.csv's columns, in order
COMPARE_COLUMNS = COMPARE_CSV.names
#: the paper's row (Sect. 5.3, Fig. 6; Appendix B: the APR level at 7.4; Appendix D: two significant impacts per
#: period, r ~ 0.8, 15 % of the energy in modes 2..9 after the impacts, simulated)
PAPER_ROW = {"study": "paper", "folder": "", "last_smr": math.nan, "first_apr": PAPER_OPTIMUM_LEVEL,
             "optimum_level": PAPER_OPTIMUM_LEVEL, "reduction_mean": PAPER_REDUCTION_MEAN,
             "reduction_max": PAPER_REDUCTION_MAX, "resonant_mean_7.4": math.nan,
             "resonant_mean_lo_7.4": PAPER_APR_LEVEL[0], "resonant_mean_hi_7.4": PAPER_APR_LEVEL[1], "regime_7.4": "APR",
             "resonant_mean_9": math.nan, "resonant_mean_lo_9": math.nan, "resonant_mean_hi_9": math.nan,
             "regime_9": "", "impacts_per_period_7.4": math.nan,
             "significant_impacts_per_period_7.4": PAPER_IMPACTS_PER_PERIOD, "restitution_7.4": 0.8,
             "higher_mode_energy_share_7.4": 0.15}


@dataclass(frozen=True)
class ResponseFolder:
    """A finished response study's folder: its name, path, study.json `landmarks` and overview.csv (as
    `sim.stepped_sine.tables.overview_data` keys)."""

    name: str
    folder: Path
    landmarks: dict
    overview: dict[str, list]


def read_response_folder(folder: str | Path) -> ResponseFolder:
    """A response study's folder (`ies response`, `ies reproduce fig6`); a StudyError naming it when it is not one."""
    from uq.outputs.figures import read_overview

    folder = Path(folder)
    if not folder.is_dir():
        raise StudyError(f"{folder} is not a folder; give the --out folders of response studies")
    try:
        meta = json.loads((folder / "study.json").read_text())
    except (OSError, json.JSONDecodeError):
        raise StudyError(f"{folder} has no readable study.json; give the --out folder of an ies response study")
    kind = meta.get("study", {}).get("kind")
    if kind != "response" or "series_folders" in meta:
        what = "a series response study; compare its NAME=VALUE subfolders" if "series_folders" in meta else \
            f"not a response study (kind {kind!r}); ies compare takes the folders of response studies"
        raise StudyError(f"{folder} is {what}")
    if "landmarks" not in meta or not (folder / "overview.csv").is_file():
        raise StudyError(f"{folder} has no landmarks or overview.csv (unfinished?); finish it with ies response "
                         f"STUDY.toml --out {folder} --resume")
    return ResponseFolder(meta["study"].get("name", folder.name), folder, meta["landmarks"], read_overview(folder))


def compare_row(study: ResponseFolder) -> dict[str, Any]:
    """The landmarks of one response study as a row of COMPARE_COLUMNS (NaN or "" where a level is not among the
    study's)."""
    row: dict[str, Any] = {"study": study.name, "folder": str(study.folder)}
    for key in ("last_smr", "first_apr", "optimum_level", "reduction_mean", "reduction_max"):
        value = study.landmarks.get(key)
        row[key] = math.nan if value is None else float(value)
    levels = study.overview["levels"]
    for level in LANDMARK_LEVELS:
        at = next((i for i, lv in enumerate(levels) if math.isclose(lv, level, rel_tol=1e-9)), None)
        keys = ("resonant_mean", "resonant_mean_lo", "resonant_mean_hi", "regime") + \
            (SCATTERING_AT_7_4 if level == LANDMARK_LEVELS[0] else ())
        for key in keys:
            missing = "" if key == "regime" else math.nan
            row[f"{key}_{level:g}"] = missing if at is None or key not in study.overview else study.overview[key][at]
    return row


def _number(value: float, fmt: str, unit: str = "") -> str:
    return "–" if value is None or (isinstance(value, float) and math.isnan(value)) else format(value, fmt) + unit


def switch_text(row: dict[str, Any]) -> str:
    """The switch SMR->APR of a row ("5.3->5.5"; "none" without APR at the highest level; "APR from 4.5")."""
    last, first = row["last_smr"], row["first_apr"]
    if math.isnan(first):
        return "none"
    return f"APR from {first:g}" if math.isnan(last) else f"{last:g}->{first:g}"


def compare_text(rows: Sequence[dict[str, Any]]) -> str:
    """The rows as a text table (the fidelity report's table), the paper's row last."""
    head = (f"{'study':<34} {'switch':>10} {'optimum':>14} {'level at 7.4 [range]':>28} {'level at 9 [range]':>28} "
            f"{'imp/T':>6} {'sig/T':>6} {'r':>5} {'E2..N':>6}")
    lines = [head]
    for row in (*rows, PAPER_ROW):
        optimum = f"{row['optimum_level']:g}: {row['reduction_mean']:.0f}x/{row['reduction_max']:.0f}x"
        levels = []
        for level in LANDMARK_LEVELS:
            mean, lo, hi = (row[f"{key}_{level:g}"] for key in ("resonant_mean", "resonant_mean_lo", "resonant_mean_hi"))
            text = "" if math.isnan(mean) else f"{mean:.3f} "
            text += "" if math.isnan(lo) else f"[{lo:.3f}, {hi:.3f}] "
            levels.append(f"{text}{row[f'regime_{level:g}']}" if text else "–")
        switch = switch_text(row) if row is not PAPER_ROW else f"~{PAPER_OPTIMUM_LEVEL:g}"
        lines.append(f"{row['study']:<34} {switch:>10} {optimum:>14} {levels[0]:>28} {levels[1]:>28} "
                     f"{_number(row['impacts_per_period_7.4'], '.2f'):>6} "
                     f"{_number(row['significant_impacts_per_period_7.4'], '.2f'):>6} "
                     f"{_number(row['restitution_7.4'], '.2f'):>5} "
                     f"{_number(100 * row['higher_mode_energy_share_7.4'], '.1f', '%'):>6}")
    return "\n".join(lines)
