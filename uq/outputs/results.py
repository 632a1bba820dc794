"""Reading a finished study back and summarising it (Sect. 5.4, Figs. 7, 8; Sobol' indices).

`effects(folder)` gives, per parameter and excitation level, the change of the repetition-mean resonant
level from the parameter's min to its max (others nominal), relative to the nominal level, with its
noise (the standard errors combined) and the nominal regime. `trend_table` formats it; `influence` ranks
the parameters by their mean effect over the almost periodic levels (the band widths of Fig. 7);
`band_table` lists the bands with their noise and checks; `sobol_table` the Sobol' indices with their
confidence intervals and the noise share. All read only the study's files.
"""
from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported on use: reading a study's CSV tables needs no xarray
    import xarray


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
    from sim.common.files import read_rows

    return read_rows(path)


def nominal_regimes(points: list[dict], output: str = "mean") -> dict[float, str]:
    """{level: regime} of the nominal point in points.csv: the regime where its repetition-averaged resonant level
    is reached, as the simulator classifies it (`sim.stepped_sine.protocol.aggregate_runs`, `sim.stepped_sine.measures.classify_regime`:
    APR, SMR or linear); the one source of every regime label of a study's tables and figures."""
    return {float(r["level"]): r.get("regime", "") for r in points
            if r["design"] == "nominal" and r["output"] == output}


def parameter_value(row: dict, name: str) -> float:
    """The value of parameter `name` in a row of runs.csv or points.csv, whose column carries the unit (g_m,
    k_H_N_per_m1p5, `sim.model.parameters.column_name`) or is the bare name (dimensionless parameters)."""
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


def _with_se(value: float, se: float) -> str:
    """'0.2136 +- 0.0042' (no error part where the standard error is unknown)."""
    return f"{value:.4f} +- {se:.4f}" if np.isfinite(se) else f"{value:.4f}        "


#: standard errors a band must be wider than to be resolved (`unresolved`)
RESOLVED_Z = 2.0


def unresolved(lower: float, upper: float, lower_se: float, upper_se: float, z: float = RESOLVED_Z) -> bool:
    """Whether a band is narrower than `z` combined standard errors of its edges: the band is noise there, so it is
    not drawn as an area, and where the nominal value lies against it is not judged (the figures and `band_checks`)."""
    width = float(upper) - float(lower)
    noise = z * float(np.hypot(np.nan_to_num(float(lower_se)), np.nan_to_num(float(upper_se))))
    return bool(np.isfinite(width) and width < noise)


def band_checks(row: dict) -> str:
    """The checks of one row of bands.csv in words: the monotonicity check (ok, failed: band widened, not tested), a
    band narrower than its noise (`unresolved`), and elsewhere where the nominal value lies outside the band (beyond
    or within the noise)."""
    words = ["monotonicity not tested" if row["tested"] == "0" else
             ("NOT MONOTONE (band widened)" if row["flagged"] == "1" else "monotone")]
    nominal, lower, upper = (float(row[k]) for k in ("nominal", "lower", "upper"))
    if unresolved(lower, upper, row["lower_se"], row["upper_se"]):
        words.append(f"band not resolved (narrower than {RESOLVED_Z:g} SE of its edges)")
    elif row["nominal_outside"] != "-1" and not lower <= nominal <= upper:  # the figure's legend says it alike
        side = "above" if nominal > upper else "below"
        words.append(f"nominal {side} its band, " + ("BEYOND the noise" if row["nominal_outside"] == "1"
                                                    else "within the noise"))
    return "; ".join(words)


def band_table(folder: str | Path, output: str | None = None) -> str:
    """Text table of the bands of `output` (default the study's first output) per design and level, with the
    standard errors of the band edges and of the nominal value, and the checks (`band_checks`)."""
    folder = Path(folder)
    if output is None:
        output = json.loads((folder / "study.json").read_text())["outputs"][0]
    bands = [r for r in _rows(folder / "bands.csv") if r["output"] == output]
    width = max([len(r["design"]) for r in bands] + [6])
    lines = [f"{'design':>{width}} {'level':>6} {'lower +- SE':>16} {'nominal +- SE':>16} {'upper +- SE':>16}  checks"]
    for r in bands:
        cells = [_with_se(float(r[k]), float(r[f"{k}_se"])) for k in ("lower", "nominal", "upper")]
        lines.append(f"{r['design']:>{width}} {float(r['level']):6.2f} " + " ".join(f"{c:>16}" for c in cells)
                     + f"  {band_checks(r)}")
    return "\n".join(lines)


#: the noise share of the output variance above which `sobol_table` says that the indices describe noise
NOISE_DOMINATES = 0.5


def outside_unit_interval(values: Sequence[float], conf: Sequence[float]) -> int:
    """How many Sobol' indices lie outside [0, 1] by more than their confidence half-width (an index is a share of
    the variance: beyond its CI outside [0, 1] it says the base sample n is too small, not something about the model)."""
    v, c = np.asarray(values, dtype=float), np.nan_to_num(np.asarray(conf, dtype=float))
    return int(np.sum(np.isfinite(v) & ((v < -c) | (v > 1.0 + c))))


#: a confidence half-width above which an index says nothing (its interval spans most of [0, 1])
UNDETERMINED_CONF = 0.5


def undetermined(conf: Sequence[float]) -> int:
    """How many Sobol' indices have a confidence half-width above UNDETERMINED_CONF (or none at all)."""
    c = np.asarray(conf, dtype=float)
    return int(np.sum(~np.isfinite(c) | (c > UNDETERMINED_CONF)))


def sample_size_advice(values: Sequence[float], conf: Sequence[float], n: int) -> str | None:
    """The line that says indices outside [0, 1] beyond their CI (`outside_unit_interval`) or with CIs wider than
    +-UNDETERMINED_CONF mean too small a base sample n, and what to do; None when neither occurs."""
    outside, wide = outside_unit_interval(values, conf), undetermined(conf)
    if not (outside or wide):
        return None
    return (f"of {len(values)} indices (S1, ST) {outside} lie outside [0, 1] beyond their confidence intervals and "
            f"{wide} have intervals wider than +-{UNDETERMINED_CONF:g}: the base sample n = {n} is too small for them "
            f"to mean anything; raise --n (a power of two, {max(4 * n, 256)} or more) or [sobol] n")


def sobol_table(folder: str | Path) -> str:
    """Text table of S1 and ST with their confidence intervals per output, level and parameter, the repetition
    noise's share of the variance per level, and, where noise dominates, what it means and what to change."""
    folder = Path(folder)
    meta = json.loads((folder / "study.json").read_text())
    confidence = meta["study"]["sobol"]["confidence"]
    repetitions = meta["study"]["repetitions"]
    rows, variance = _rows(folder / "sobol.csv"), _rows(folder / "variance.csv")
    fits = {(f["output"], float(f["level"])): f for f in _rows(folder / "surrogate.csv")} \
        if (folder / "surrogate.csv").is_file() else None
    how = "" if fits is None else ", from a polynomial-chaos surrogate"
    lines = [f"Sobol' indices ({confidence:.0%} confidence intervals; S1 first order, ST total{how}; the "
             "repetition noise counts into ST as an input of its own):"]
    for v in variance:
        o, level = v["output"], float(v["level"])
        share = float(v["noise_share"])
        noise = "unknown (one repetition)" if not np.isfinite(share) else f"{share:.0%}"
        lines.append(f"{o} at level {level:g}: repetition noise {noise} of the variance"
                     + (f"; not analysed: {v['message']}" if v["message"] else ""))
        fit = (fits or {}).get((o, level))
        rough = fit is not None and fit["smooth"] == "0"
        if fit is not None and fit["smooth"] != "":
            lines.append(f"  surrogate: degree {fit['degree']}, {fit['terms']} terms from {fit['points']} points; "
                         f"cross-validated error {float(fit['cv_error']):.0%} of the variance (the noise explains "
                         f"{float(fit['noise_floor']):.0%})")
        here = [r for r in rows if r["output"] == o and float(r["level"]) == level]
        for r in here:
            lines.append(f"  {r['parameter']:>6}  S1 {float(r['S1']):6.3f} +- {float(r['S1_conf']):5.3f}   "
                         f"ST {float(r['ST']):6.3f} +- {float(r['ST_conf']):5.3f}" + ("   unreliable" if rough else ""))
        if here and here[0].get("S1_noise_free") and np.isfinite(share) and 0 < share < 1:
            lines.append("  without the noise (expected response): " + ", ".join(
                f"{r['parameter']} S1 {float(r['S1_noise_free']):.3f} ST {float(r['ST_noise_free']):.3f}" for r in here))
        if rough:
            lines.append(f"  -> NOT SMOOTH: {fit['rough']}; a polynomial smears the jump over every term, so these "
                         "indices are unreliable: run this study with method = \"saltelli\".")
        if np.isfinite(share) and share >= NOISE_DOMINATES:
            lines.append(f"  -> the repetition noise dominates ({share:.0%} of the variance; 100 % or more: no parameter "
                         "effect is resolved): these indices mostly describe noise. The noise variance falls as "
                         f"1/repetitions (now {repetitions}): raise [study] repetitions or the hold time, or choose "
                         "levels away from the switch between the strongly modulated and the almost periodic response, "
                         "where the response is chaotic.")
    indices = [float(r[key]) for r in rows for key in ("S1", "ST")]
    conf = [float(r[f"{key}_conf"]) for r in rows for key in ("S1", "ST")]
    base_sample = meta.get("summary", {}).get("base_sample", meta["study"]["sobol"].get("n"))
    # a surrogate's indices have no base sample n: its fit lines above say how far to trust them
    advice = None if fits is not None or base_sample is None else sample_size_advice(indices, conf, int(base_sample))
    if advice:
        lines.append(f"warning: {advice}")
    return "\n".join(lines)


def open_study(folder: str | Path) -> xarray.Dataset:
    """A finished study's results as an xarray Dataset (its results.nc, `uq.outputs.netcdf`), read into memory.

    Dimensions as the study has them: ``point`` (with each parameter as a coordinate along it), ``level``
    (a_base / a_base*), ``repetition``; ``design``/``design_point`` (interval), ``parameter`` (Sobol'), ``eta``
    (response; a series adds a dimension named after its parameter); ``design`` x ``level`` and ``screened`` for
    `ies design` (`uq.design.results.write_design_netcdf`). Every variable has CF ``units`` and
    ``long_name``; ``ds.attrs["study"]`` is the resolved study (JSON) and ``ds.attrs["code_version"]`` the
    simulator's code version. Example, in Python or a notebook::

        >>> from uq.outputs.results import open_study
        >>> ds = open_study("ies-out/sobol")                    # doctest: +SKIP
        >>> ds["mean_ST"].sel(level=6.7).to_series()            # doctest: +SKIP
        >>> ds["mean"].mean("repetition").plot.scatter(x="g")   # doctest: +SKIP

    A path that does not exist, a folder without results.nc (not a study's output) and a results.nc that cannot be
    read (damaged or cut short) are each a one-line `StudyError` saying what to do.
    """
    from uq.outputs.netcdf import open_results

    return open_results(folder)


def study_kind(kind: str) -> Callable[[Path], bool]:
    """Whether a folder holds a study of `kind` (its study.json says so)."""
    def detect(folder: Path) -> bool:
        path = folder / "study.json"
        return path.is_file() and json.loads(path.read_text()).get("study", {}).get("kind") == kind

    return detect
