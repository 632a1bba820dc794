"""Interval (vertex) propagation with a monotonicity check (seed paper, Sect. 5.4, Figs. 7 and 8).

The paper takes only the interval limits of D, g and k_H and *assumes* that the resonant response level
is monotone in each parameter, so that the band of the response is spanned by the corners of the box.
Here the assumption is checked: interior samples are evaluated too. Where an interior value leaves the
corner envelope (by more than the repetition noise allows), or a one-parameter sequence is not monotone,
the location is flagged and the band is widened to the envelope of *all* evaluated points.

Designs (points in the parameter box; each point is a dict of parameter values in SI units):
* individual variation (Fig. 7): one parameter along its axis (min, interior points, max), the others
  nominal;
* joint variation (Fig. 8): all 2^k corners of the varied parameters plus interior points (the centre
  and a scrambled Sobol' sample); the residual band of Fig. 8 is the joint design of the space with k_H
  fixed at its best estimate (`ParameterSpace.fix`).

The method of interval studies (`IntervalMethod`, ``[study] kind = "interval"``): its settings ([interval] designs,
interior, z, fix), its sampling (every design's points and the nominal point) and its analysis (the bands of each
design per output and level, points.csv and bands.csv); the runs are the engine's (`uq.engine.execution`).
`propagate` evaluates a design on a plain function, which is how the layer is tested on analytic functions.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from sim.common.outputs import Column, OutputFile, header
from sim.model.parameters import PARAMETERS
from uq.errors import StudyError
from uq.outputs.tables import PARAMETERS_COLUMN, parameter_columns
from uq.problem.method import Analysis, Method, Plan, Runs, Table
from uq.problem.space import ParameterSpace, resolve_value
from uq.problem.study import Context, Setting, Study, check_number, check_plausible, numeric


@dataclass(frozen=True)
class DesignPoint:
    """One point of an interval design: its parameter values (SI), its role and a short label."""

    values: Mapping[str, float]
    role: str  # "corner" (interval limit) or "interior"
    label: str

    def key(self) -> tuple:
        """Hashable identity of the parameter values (points shared by designs are evaluated once)."""
        return tuple(sorted((k, float(v)) for k, v in self.values.items()))


@dataclass(frozen=True)
class Design:
    """Points of one band: `kind` is "axis" (ordered along one parameter) or "box" (corners + interior)."""

    name: str
    kind: str
    points: tuple[DesignPoint, ...]
    parameter: str | None = None  # the varied parameter of an axis design


def axis_design(space: ParameterSpace, name: str, n_interior: int = 1) -> Design:
    """Individual variation of `name` (Fig. 7): min, `n_interior` equispaced interior points, max.

    The nominal value is added as an interior point when it lies strictly inside the interval (D in
    Table 2). The others stay nominal. Points are ordered by the value of `name`.
    """
    if n_interior < 0:
        raise StudyError(f"interior points must be >= 0, got {n_interior}")
    p = space[name]
    if not p.varied:
        raise StudyError(f"parameter '{name}' is not varied (min = max = {p.min:g}); widen its interval")
    ts = [0.0, *np.linspace(0.0, 1.0, n_interior + 2)[1:-1].tolist(), 1.0]
    values = sorted({float(p.at(t)) for t in ts} | ({p.nominal} if p.min < p.nominal < p.max else set()))
    base = space.nominal()
    points = []
    for v in values:
        role = "corner" if v in (p.min, p.max) else "interior"
        points.append(DesignPoint({**base, name: v}, role, f"{name}={v:.6g}"))
    return Design(f"individual:{name}", "axis", tuple(points), parameter=name)


def box_design(space: ParameterSpace, n_interior: int = 4, *, name: str = "joint", seed: int = 0) -> Design:
    """Joint variation (Fig. 8): the 2^k corners of the varied parameters, the centre,
    `n_interior - 1` further interior points from a scrambled Sobol' sequence (seeded) and, when
    n_interior >= 1, the nominal point unless it is a corner."""
    varied = space.varied
    if not varied:
        raise StudyError("no parameter is varied; widen at least one interval")
    if n_interior < 0:
        raise StudyError(f"interior points must be >= 0, got {n_interior}")
    points = []
    for corner in itertools.product((0.0, 1.0), repeat=len(varied)):
        vals = space.point(corner)
        label = ",".join(f"{p.name}={'max' if t else 'min'}" for p, t in zip(varied, corner))
        points.append(DesignPoint(vals, "corner", label))
    interior = []
    if n_interior >= 1:
        interior.append(np.full(len(varied), 0.5))
    if n_interior >= 2:
        from scipy.stats import qmc

        m = int(np.ceil(np.log2(n_interior - 1))) if n_interior > 2 else 0
        sample = qmc.Sobol(d=len(varied), scramble=True, seed=seed).random_base2(m)[: n_interior - 1]
        interior.extend(0.05 + 0.9 * sample)  # strictly inside, away from the faces
    for i, t in enumerate(interior):
        vals = space.point(t)
        points.append(DesignPoint(vals, "interior", f"interior{i}"))
    nominal = DesignPoint(space.nominal(), "interior", "nominal")
    if n_interior >= 1 and all(nominal.key() != p.key() for p in points):
        points.append(nominal)  # inside the closed box too: monotonicity puts it within the corner band
    return Design(name, "box", tuple(points))


@dataclass
class Band:
    """Band of a response (one value per output column, e.g. per excitation level).

    lower/upper: the corner band, widened to the envelope of all evaluated points where the check failed;
    corner_lower/corner_upper: the paper's vertex band (interval limits only);
    flagged: where monotonicity failed beyond the noise tolerance; violation: by how much (NaN where untested);
    tested: where the check could be made (False where the values have no noise estimate, e.g. one repetition
    of a chaotic response: a difference cannot be judged against an unknown noise).
    """

    design: str
    lower: np.ndarray
    upper: np.ndarray
    corner_lower: np.ndarray
    corner_upper: np.ndarray
    flagged: np.ndarray
    violation: np.ndarray
    tested: np.ndarray
    notes: list[str] = field(default_factory=list)

    @property
    def monotone(self) -> bool:
        """No significant violation where the check was made."""
        return not bool(np.any(self.flagged))

    @property
    def fully_tested(self) -> bool:
        return bool(np.all(self.tested))


def _as_2d(values: np.ndarray | Sequence) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    return arr[:, None] if arr.ndim == 1 else arr


def band(design: Design, values: np.ndarray, noise: np.ndarray | None = None, *, z: float = 2.0,
         output_labels: Sequence[str] | None = None, pool: bool = True) -> Band:
    """Band of `values` (n_points x n_outputs, rows in `design.points` order) with the monotonicity check.

    `noise` (same shape) is the standard error of each value (repetition noise of a chaotic response;
    zero for a deterministic function, None = all zero; NaN = unknown, e.g. one repetition); two values differ
    significantly when their difference exceeds z * sqrt(se_a^2 + se_b^2). Box designs: an interior value
    outside the corner envelope is a violation. Axis designs: the sequence along the axis must be monotone
    (all steps >= -tol or all <= +tol). Non-finite values are refused (catch failed runs before). A column
    whose noise is unknown is not tested (`Band.tested`): its band is the corner band, and a note says so.
    pool: use the RMS standard error of the design's points with a noise estimate (per output column) for
    every point: a chaotic response scatters alike at nearby parameters, and the standard error of 2-5
    repetitions of one point is itself too uncertain to judge by.
    """
    y = _as_2d(values)
    if y.shape[0] != len(design.points):
        raise StudyError(f"design '{design.name}' has {len(design.points)} points but {y.shape[0]} values were given")
    if not np.all(np.isfinite(y)):
        raise StudyError(f"design '{design.name}': some values are NaN or infinite; report failed runs before banding")
    se = np.zeros_like(y) if noise is None else _as_2d(noise)
    if se.shape != y.shape:
        raise StudyError(f"noise has shape {se.shape} but values have shape {y.shape}")
    if pool:
        known = np.isfinite(se)
        mean_square = np.sum(np.where(known, se, 0.0) ** 2, axis=0) / np.maximum(known.sum(axis=0), 1)
        se = np.broadcast_to(np.where(known.any(axis=0), np.sqrt(mean_square), np.nan), se.shape)
    tested = np.isfinite(se).all(axis=0)
    se = np.nan_to_num(se, nan=0.0)
    corner = np.array([p.role == "corner" for p in design.points])
    labels = output_labels or [str(j) for j in range(y.shape[1])]
    corner_lo, corner_hi = y[corner].min(axis=0), y[corner].max(axis=0)
    violation = np.zeros(y.shape[1])
    notes: list[str] = []
    if design.kind == "box":
        idx_lo, idx_hi = np.where(corner)[0][y[corner].argmin(axis=0)], np.where(corner)[0][y[corner].argmax(axis=0)]
        for i in np.where(~corner)[0]:
            cols = np.arange(y.shape[1])
            tol_lo = z * np.hypot(se[i], se[idx_lo, cols])
            tol_hi = z * np.hypot(se[i], se[idx_hi, cols])
            excess = np.maximum(corner_lo - tol_lo - y[i], y[i] - corner_hi - tol_hi)
            violation = np.maximum(violation, np.maximum(excess, 0.0))
            for j in np.where((excess > 0) & tested)[0]:
                notes.append(f"{design.name}: {design.points[i].label} gives {y[i, j]:.4g} outside the corner band "
                             f"[{corner_lo[j]:.4g}, {corner_hi[j]:.4g}] at {labels[j]} -> band widened")
    elif design.kind == "axis":
        steps = np.diff(y, axis=0)
        tol = z * np.hypot(se[1:], se[:-1])
        down = np.maximum(-steps - tol, 0.0).max(axis=0)  # worst significant decrease
        up = np.maximum(steps - tol, 0.0).max(axis=0)  # worst significant increase
        violation = np.minimum(up, down)  # both directions significant -> not monotone
        for j in np.where((violation > 0) & tested)[0]:
            notes.append(f"{design.name}: response is not monotone in {design.parameter} at {labels[j]} "
                         f"(rises by {up[j]:.4g} and falls by {down[j]:.4g} beyond the noise) -> band widened")
    else:
        raise StudyError(f"unknown design kind '{design.kind}'")
    if not tested.all():
        where = ", ".join(labels[j] for j in np.where(~tested)[0])
        notes.append(f"{design.name}: monotonicity could not be tested at {where}: no noise estimate (one "
                     "repetition per point); run repetitions >= 2")
    flagged = (violation > 0) & tested
    violation = np.where(tested, violation, np.nan)
    lower = np.where(flagged, np.minimum(corner_lo, y.min(axis=0)), corner_lo)
    upper = np.where(flagged, np.maximum(corner_hi, y.max(axis=0)), corner_hi)
    return Band(design=design.name, lower=lower, upper=upper, corner_lower=corner_lo, corner_upper=corner_hi,
                flagged=flagged, violation=violation, tested=tested, notes=notes)


def propagate(func: Callable[[Mapping[str, float]], float | np.ndarray], design: Design, *,
              z: float = 2.0) -> Band:
    """Evaluate a deterministic function at every design point and band it (no noise)."""
    values = np.array([np.atleast_1d(np.asarray(func(p.values), dtype=float)) for p in design.points])
    return band(design, values, None, z=z)


# ---- the method: [interval] settings, sampling and analysis ----------------------------------------------------------

#: the designs an interval study may run (`IntervalMethod`)
DESIGNS = ("individual", "joint", "residual")


def _designs(value: Any, context: Context) -> tuple[str, ...]:
    if not isinstance(value, list) or not value:
        raise StudyError(f"[interval] designs must be a non-empty list from {', '.join(DESIGNS)}, got {value!r}")
    for d in value:
        if d not in DESIGNS:
            raise StudyError(f"[interval] unknown design '{d}'; known: {', '.join(DESIGNS)}")
    return tuple(value)


def _fix(value: Any, context: Context) -> dict[str, float]:
    """[interval] fix: parameters held at a value in the residual design (a number, with a unit where the quantity has
    one, or "best_estimate")."""
    space = context.space
    if not isinstance(value, Mapping):
        raise StudyError(f"[interval] fix must be a table like {{ k_H = \"best_estimate\" }}, got {value!r}")
    out = {}
    for pname, raw in value.items():
        if pname not in space.names:
            raise StudyError(f"[interval] fix: unknown parameter '{pname}'; known: {', '.join(space.names)}")
        if raw == "best_estimate":
            if f"{pname}_best_estimate" not in space.extras:
                raise StudyError(f"[interval] fix: '{pname}' has no best estimate; give a number")
            fixed = space.extras[f"{pname}_best_estimate"]
        elif pname in PARAMETERS and PARAMETERS[pname].quantity is not None:  # k_H, g, k_t: also with a unit
            fixed = resolve_value(pname, raw, base_dir=context.base_dir)
            check_plausible(f"[interval] fix.{pname}", pname, fixed, raw, context.allow_implausible)
        else:
            fixed = check_number(f"[interval] fix.{pname}", raw, positive=space[pname].positive)
        out[pname] = float(fixed)
    return out


POINTS_CSV = OutputFile("points.csv", "ies interval", "The repetition statistics of every design point and level.", (
    Column("design", "", "nominal, individual:NAME, joint or residual"),
    Column("point", "", "the point's label"),
    Column("role", "", "corner (an interval limit), interior (checks monotonicity) or nominal"),
    PARAMETERS_COLUMN,
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("output", "", "mean or max (or the model's output)"),
    Column("mean", "a/a_noabs*", "the resonant level of the repetition-averaged response"),
    Column("se", "a/a_noabs*", "its standard error (NaN for one sample)"),
    Column("n_samples", "-", "the repetition samples"),
    Column("regime", "", "where that point's resonant mean is reached (APR, SMR, linear)"),
))


BANDS_CSV = OutputFile("bands.csv", "ies interval", "One row per design, output and level.", (
    Column("design", "", "individual:NAME, joint or residual"),
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("lower", "a/a_noabs*", "lower edge of the band over the design's points: the corner band, widened to all "
           "points where `flagged`"),
    Column("upper", "a/a_noabs*", "upper edge of the band"),
    Column("corner_lower", "a/a_noabs*", "the paper's vertex band: smallest value at the interval limits (corners) only"),
    Column("corner_upper", "a/a_noabs*", "largest value at the corners"),
    Column("flagged", "-", "1 where the monotonicity check failed (an interior point outside the corner band, or an "
           "axis not monotone, beyond z = 2 combined standard errors)"),
    Column("violation", "a/a_noabs*", "by how much beyond that tolerance (NaN where not tested)"),
    Column("tested", "-", "1 where the check could be made, 0 without a noise estimate (one repetition)"),
    Column("lower_se", "a/a_noabs*", "standard error of the point that gives the lower edge"),
    Column("upper_se", "a/a_noabs*", "standard error of the point that gives the upper edge"),
    Column("nominal", "a/a_noabs*", "the nominal point's value"),
    Column("nominal_se", "a/a_noabs*", "its standard error"),
    Column("nominal_outside", "-", "1 where the nominal lies outside the band beyond z combined standard errors, 0 where "
           "not (or unknown noise), -1 where the nominal point is not in the design's box (residual)"),
))


def interval_designs(study: Study) -> list[Design]:
    """The designs named in the study: individual (one per varied parameter), joint, residual."""
    s = study.settings
    designs: list[Design] = []
    for name in s["designs"]:
        if name == "individual":
            designs.extend(axis_design(study.space, p.name, s["interior"]) for p in study.space.varied)
        elif name == "joint":
            designs.append(box_design(study.space, s["interior"], name="joint", seed=study.seed))
        elif name == "residual":
            designs.append(box_design(study.space.fix(**s["fix"]), s["interior"], name="residual", seed=study.seed))
    if not designs:
        raise StudyError("the study has no design to run; set [interval] designs")
    return designs


class IntervalMethod(Method):
    """Interval (vertex) bands with the monotonicity check, Figs. 7 and 8 (Sect. 5.4)."""

    name = kind = "interval"
    help = "interval bands of the resonant response level for D, g, k_H (paper Sect. 5.4, Figs. 7-8)"
    settings = (
        Setting("designs", ("individual",), _designs, "the designs: individual (one parameter at a time, Fig. 7), "
                "joint (the whole box, Fig. 8), residual (the box with `fix` held, Fig. 8)"),
        numeric("interior", 1, "interior points per axis (individual) or in the box (joint, residual), where the "
                "monotonicity is checked", integer=True, positive=False, minimum=0),
        numeric("z", 2.0, "noise multiple (combined standard errors) below which a monotonicity violation is not "
                "flagged", positive=False, minimum=0.0),
        Setting("fix", None, _fix, "parameters held fixed in the residual band, e.g. { k_H = \"best_estimate\" } (the "
                "default when k_H is a parameter)"),
    )
    tables = (Table(POINTS_CSV), Table(BANDS_CSV, dims={"design": "design", "level": "level"}, split="output"))

    def finish(self, values: dict[str, Any], context: Context) -> dict[str, Any]:
        if values["fix"] is None:
            values["fix"] = _fix({"k_H": "best_estimate"} if "k_H" in context.space.names else {}, context)
        if "residual" in values["designs"] and not values["fix"]:
            raise StudyError("[interval] the residual design needs fixed parameters: fix = { k_H = \"best_estimate\" }")
        return values

    def describe(self, settings: Mapping[str, Any]) -> dict[str, Any]:
        return {"interval": {"method": self.name, "designs": list(settings["designs"]), "interior": settings["interior"],
                             "z": settings["z"], "fix": dict(settings["fix"])}}

    def plan(self, study: Study) -> Plan:
        """The nominal point first, then every design's points, each once."""
        designs = interval_designs(study)
        nominal = DesignPoint(study.space.nominal(), "nominal", "nominal")
        unique: dict[tuple, dict] = {nominal.key(): dict(nominal.values)}
        for d in designs:
            for p in d.points:
                unique.setdefault(p.key(), dict(p.values))
        index = {key: i for i, key in enumerate(unique)}
        return Plan(list(unique.values()), {"designs": designs, "nominal": nominal, "index": index})

    def analyse(self, study: Study, model: Any, plan: Plan, runs: Runs) -> Analysis:
        """points.csv (every design point's repetition statistics) and bands.csv (each design's band per output and
        level with its checks, Sect. 5.4), each design's members in results.nc."""
        import xarray as xr

        from uq.outputs.netcdf import table_variables

        designs, nominal, index = plan.extra["designs"], plan.extra["nominal"], plan.extra["index"]
        z = study.settings["z"]
        names, banded = study.space.names, list(model.banded_outputs)
        level_labels = [f"level {lv:g}" for lv in study.levels]
        out = Analysis()
        point_rows, band_rows = [], []
        bands: dict[tuple[str, str], Band] = {}
        i_nominal = index[nominal.key()]
        every = [Design("nominal", "box", (nominal,))] + designs
        for d in every:
            rows_idx = [index[p.key()] for p in d.points]
            for o in model.outputs:
                mean, se, n = (a[rows_idx] for a in runs.stats[o])
                for row, (p, i) in enumerate(zip(d.points, rows_idx)):
                    for j, level in enumerate(study.levels):
                        point_rows.append([d.name, p.label, p.role, *(p.values[name] for name in names), level, o,
                                           mean[row, j], se[row, j], int(n[row, j]), runs.regimes[i, j]])
                if d.name == "nominal" or o not in banded:
                    continue
                bd = _band_with_failures(d, mean, se, z, level_labels)
                bands[(d.name, o)] = bd
                out.warnings += [f"{o}: {msg}" for msg in bd.notes]
                lower_se, upper_se = _edge_errors(d, mean, se, bd)
                nominal_value, nominal_se = runs.stats[o][0][i_nominal], runs.stats[o][1][i_nominal]
                outside = _nominal_outside(d, study.space.nominal(), nominal_value, nominal_se, bd, lower_se, upper_se, z)
                for j, level in enumerate(study.levels):
                    band_rows.append([d.name, o, level, bd.lower[j], bd.upper[j], bd.corner_lower[j],
                                      bd.corner_upper[j], int(bd.flagged[j]), bd.violation[j], int(bd.tested[j]),
                                      lower_se[j], upper_se[j], nominal_value[j], nominal_se[j], outside[j]])
        out.rows = {"points.csv": point_rows, "bands.csv": band_rows}
        out.columns = {"points.csv": header(POINTS_CSV, parameters=parameter_columns(study.space))}
        members = [[i, d.name, p.label, p.role, index[p.key()]] for i, (d, p) in
                   enumerate((d, p) for d in every for p in d.points)]
        out.datasets = [xr.Dataset(table_variables(["design_point", "member_design", "member_label", "member_role",
                                                    "member_point"], members, {"design_point": "design_point"}))]
        out.summary = {"monotone": {f"{d}/{o}": bd.monotone for (d, o), bd in bands.items()},
                       "untested": [f"{d}/{o}" for (d, o), bd in bands.items() if not bd.fully_tested]}
        return out

    def figures(self, folder: Path, options: Any = None) -> list[Path]:
        """Figs. 7 and 8 (`uq.outputs.paper_figures.interval_figures`)."""
        from uq.outputs.paper_figures import interval_figures

        return interval_figures(folder, options)

    def report(self, folder: Path, summary: Mapping[str, Any], name: str) -> None:
        """The bands with their noise and checks, and for an individual variation the trends (Figs. 7, 8)."""
        from uq.outputs.paper_figures import interval_table

        interval_table(folder, summary, name)


def _edge_errors(design: Design, mean: np.ndarray, se: np.ndarray, bd: Band) -> tuple[np.ndarray, np.ndarray]:
    """The standard errors of the points that give each level's lower and upper band edge (the corners, or every
    evaluated point where the band was widened); NaN where the band has no value."""
    corner = np.array([p.role == "corner" for p in design.points])
    lower_se, upper_se = np.full(mean.shape[1], np.nan), np.full(mean.shape[1], np.nan)
    for j in range(mean.shape[1]):
        candidates = np.isfinite(mean[:, j]) & (corner | bool(bd.flagged[j]))
        if candidates.any():
            values = np.where(candidates, mean[:, j], np.nan)
            lower_se[j], upper_se[j] = se[np.nanargmin(values), j], se[np.nanargmax(values), j]
    return lower_se, upper_se


def _nominal_outside(design: Design, nominal: dict, value: np.ndarray, se: np.ndarray, bd: Band, lower_se: np.ndarray,
                     upper_se: np.ndarray, z: float) -> np.ndarray:
    """Per level: 1 where the nominal value lies outside the band by more than z combined standard errors (its own
    and the edge's), 0 where not or where a standard error is unknown, -1 where the nominal point lies outside the
    design's parameter box (e.g. the residual band, whose k_H is fixed at its best estimate)."""
    box = {name: (min(p.values[name] for p in design.points), max(p.values[name] for p in design.points))
           for name in nominal}
    if any(not lo <= nominal[name] <= hi for name, (lo, hi) in box.items()):
        return np.full(value.shape, -1)
    with np.errstate(invalid="ignore"):
        below = bd.lower - value > z * np.hypot(se, lower_se)
        above = value - bd.upper > z * np.hypot(se, upper_se)
    return (below | above).astype(int)


def _band_with_failures(design: Design, mean: np.ndarray, se: np.ndarray, z: float, labels: list[str]) -> Band:
    """`band` level by level, leaving out points whose every run failed at that level (noted)."""
    n_levels = mean.shape[1]
    parts, notes = [], []
    for j in range(n_levels):
        ok = np.isfinite(mean[:, j])
        if ok.all():
            parts.append(band(design, mean[:, j], se[:, j], z=z, output_labels=[labels[j]]))
            continue
        kept = tuple(p for p, keep in zip(design.points, ok) if keep)
        if not any(p.role == "corner" for p in kept):
            nan = np.array([np.nan])
            parts.append(Band(design.name, nan, nan, nan, nan, np.array([False]), nan, np.array([False])))
            notes.append(f"{design.name}: every corner failed at {labels[j]}; no band")
            continue
        sub = Design(design.name, design.kind, kept, design.parameter)
        parts.append(band(sub, mean[ok, j], se[ok, j], z=z, output_labels=[labels[j]]))
        notes.append(f"{design.name}: {int((~ok).sum())} point(s) failed at {labels[j]} and were left out")
    cat = lambda attr: np.concatenate([getattr(b, attr) for b in parts])  # noqa: E731
    for b in parts:
        notes.extend(b.notes)
    return Band(design=design.name, lower=cat("lower"), upper=cat("upper"), corner_lower=cat("corner_lower"),
                corner_upper=cat("corner_upper"), flagged=cat("flagged"), violation=cat("violation"),
                tested=cat("tested"), notes=notes)
