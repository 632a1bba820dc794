"""Reading a finished interval study back and summarising the paper's trends (Sect. 5.4, Figs. 7, 8).

`effects(folder)` gives, per parameter and excitation level, the change of the repetition-mean resonant
level from the parameter's min to its max (others nominal), relative to the nominal level, with its
noise (the standard errors combined) and the nominal regime. `trend_table` formats it; `influence` ranks
the parameters by their mean effect over the almost periodic levels (the band widths of Fig. 7);
`band_table` lists the joint and residual bands. All read only the study's CSV files.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Effect:
    """Change of the resonant level from a parameter's min to its max at one excitation level.

    delta: value(max) - value(min) (a / a_noabs*); relative: delta / nominal value; noise: the
    combined standard error of the two values; regime: the nominal point's regime ("APR", "SMR", "linear").
    """

    parameter: str
    level: float
    delta: float
    relative: float
    noise: float
    regime: str
    nominal: float


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def nominal_regimes(points: list[dict], output: str = "mean") -> dict[float, str]:
    """{level: regime} of the nominal point in points.csv: the regime where its repetition-averaged resonant level
    is reached, as the simulator classifies it (`sim.protocol.aggregate_runs`, `sim.measures.classify_regime`:
    APR, SMR or linear); the one source of every regime label of a study's tables and figures."""
    return {float(r["level"]): r.get("regime", "") for r in points
            if r["design"] == "nominal" and r["output"] == output}


def parameter_value(row: dict, name: str) -> float:
    """The value of parameter `name` in a row of runs.csv or points.csv, whose column carries the unit (g_m,
    k_H_N_per_m1p5, `uq.space.column_name`) or is the bare name (dimensionless parameters)."""
    if name in row:
        return float(row[name])
    (column,) = [c for c in row if c.startswith(f"{name}_")]
    return float(row[column])


def effects(folder: str | Path, output: str = "mean") -> list[Effect]:
    """Effects of the individual variation (designs "individual:NAME") in a study folder."""
    points = _rows(Path(folder) / "points.csv")
    nominal = {float(r["level"]): float(r["mean"]) for r in points if r["design"] == "nominal" and r["output"] == output}
    regime = nominal_regimes(points, output)
    out = []
    designs = sorted({r["design"] for r in points if r["design"].startswith("individual:")})
    for design in designs:
        name = design.split(":", 1)[1]
        rows = [r for r in points if r["design"] == design and r["output"] == output and r["role"] == "corner"]
        for level in sorted({float(r["level"]) for r in rows}):
            at = sorted((r for r in rows if float(r["level"]) == level), key=lambda r: parameter_value(r, name))
            lo, hi = at[0], at[-1]
            delta = float(hi["mean"]) - float(lo["mean"])
            noise = float(np.hypot(float(hi["se"]), float(lo["se"])))
            out.append(Effect(name, level, delta, delta / nominal[level], noise, regime.get(level, "?"), nominal[level]))
    return out


def trend_table(folder: str | Path, output: str = "mean") -> str:
    """Text table of `effects`: one row per level, one column per parameter (relative change +- noise)."""
    eff = effects(folder, output)
    names = list(dict.fromkeys(e.parameter for e in eff))
    levels = sorted({e.level for e in eff})
    head = f"{'level':>6} {'regime':>6} " + " ".join(f"{'d' + n + ' (max-min)/nominal':>26}" for n in names)
    lines = [head]
    for lv in levels:
        row = {e.parameter: e for e in eff if e.level == lv}
        regime = next(iter(row.values())).regime
        cells = " ".join(f"{row[n].relative:+8.1%} (noise {row[n].noise / row[n].nominal:5.1%})".rjust(26)
                         for n in names)
        lines.append(f"{lv:6.2f} {regime:>6} {cells}")
    return "\n".join(lines)


@dataclass(frozen=True)
class Influence:
    """A parameter's mean |relative change| (and mean relative noise) over the levels it is averaged on."""

    parameter: str
    mean_change: float
    mean_noise: float
    levels: tuple[float, ...]


def influence(folder: str | Path, output: str = "mean", regime: str = "APR") -> list[Influence]:
    """Parameters ranked by their influence, largest first: the mean over the excitation levels whose nominal
    point is in `regime` of |value(max) - value(min)| / nominal (Fig. 7's band width relative to the curve).

    Fig. 7 of the paper spans the almost periodic range from the optimum upwards; the strongly modulated
    level hardly depends on the parameters (Sect. 5.4), so it is left out by default ("any" keeps all levels).
    """
    eff = [e for e in effects(folder, output) if regime == "any" or e.regime == regime]
    out = []
    for name in dict.fromkeys(e.parameter for e in eff):
        mine = [e for e in eff if e.parameter == name]
        out.append(Influence(name, float(np.mean([abs(e.relative) for e in mine])),
                             float(np.mean([e.noise / e.nominal for e in mine])), tuple(e.level for e in mine)))
    return sorted(out, key=lambda i: -i.mean_change)


def influence_line(folder: str | Path, output: str = "mean") -> str:
    """One line: the ranking of `influence`, e.g. "k_H 23.1 % > g 16.9 % > D 14.4 % (mean |change| ...)"."""
    ranked = influence(folder, output)
    if not ranked:
        return "no almost periodic level: influence not ranked"
    levels = ", ".join(f"{lv:g}" for lv in ranked[0].levels)
    return ("largest influence first, mean |change| over the almost periodic levels " + levels + ": "
            + " > ".join(f"{i.parameter} {i.mean_change:.1%} (noise {i.mean_noise:.1%})" for i in ranked))


def band_table(folder: str | Path, output: str = "mean") -> str:
    """Text table of the box bands (joint, residual) and the nominal value per level."""
    folder = Path(folder)
    bands = [r for r in _rows(folder / "bands.csv") if r["output"] == output and not r["design"].startswith("individual")]
    points = _rows(folder / "points.csv")
    nominal = {float(r["level"]): float(r["mean"]) for r in points if r["design"] == "nominal" and r["output"] == output}
    lines = [f"{'design':>9} {'level':>6} {'lower':>8} {'nominal':>8} {'upper':>8} {'flagged':>7}"]
    for r in bands:
        lv = float(r["level"])
        lines.append(f"{r['design']:>9} {lv:6.2f} {float(r['lower']):8.4f} {nominal.get(lv, np.nan):8.4f} "
                     f"{float(r['upper']):8.4f} {r['flagged']:>7}")
    return "\n".join(lines)
