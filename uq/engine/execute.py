"""Running interval and Sobol' studies end to end: designs -> tasks -> runner -> statistics -> files.

Data first: every run (runs.csv), the repetition statistics per design point and level (points.csv),
the bands (bands.csv) or Sobol' indices (sobol.csv), and study.json with the resolved study, code
version, warnings and timings. Figures (uq.outputs.figures) are drawn from the same tables afterwards.
CSV files hold no timings, so reruns (serial, parallel, Dask, resumed) can be compared byte by byte.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from sim.common.files import dumps, write_csv, write_text
from sim.common.outputs import Column, OutputFile, header
from uq.errors import StudyError
from uq.methods.interval import Band, Design, DesignPoint, axis_design, band, box_design
from uq.engine.runner import ResultStore, Task, dask_client, prepare_output, run_tasks
from uq.problem.study import Study


_PARAMETERS = Column("<parameters>", "SI", "the run's parameters: D (damping ratio of mode 1, -), g_m (clearance, m), "
                     "k_H_N_per_m1p5 (Hertzian spring constant, N/m^1.5); other models' parameters by their name; "
                     "r_cont, friction, k_t_N_per_m when the study lists them")
RUNS_CSV = OutputFile("runs.csv", "every study folder", "One row per stepped-sine run (task).", (
    _PARAMETERS,
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("rep", "-", "repetition index (its random stream: seed and rep)"),
    Column("<outputs>", "a/a_noabs*", "the run's own resonant levels `mean`, `max` and `apr` (1 when its resonant mean "
           "is almost periodic); other models: `value`"),
    Column("error", "", "empty, or why the run failed (it is left out of every statistic)"),
))
POINTS_CSV = OutputFile("points.csv", "ies interval", "The repetition statistics of every design point and level.", (
    Column("design", "", "nominal, individual:NAME, joint or residual"),
    Column("point", "", "the point's label"),
    Column("role", "", "corner (an interval limit), interior (checks monotonicity) or nominal"),
    _PARAMETERS,
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
SOBOL_CSV = OutputFile("sobol.csv", "ies sobol", "", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("parameter", "", "the parameter's name"),
    Column("S1", "-", "first-order Sobol' index of the repetition mean, the noise counted in (`uq.methods.sobol`)"),
    Column("S1_conf", "-", "half-width of its confidence interval"),
    Column("ST", "-", "total Sobol' index, the noise counted into it as an input of its own"),
    Column("ST_conf", "-", "half-width of its confidence interval"),
    Column("S1_noise_free", "-", "first-order index of the expected response: S1 / (1 - noise_share)"),
    Column("S1_noise_free_conf", "-", "half-width of its confidence interval"),
    Column("ST_noise_free", "-", "total index of the expected response: (ST - noise_share) / (1 - noise_share)"),
    Column("ST_noise_free_conf", "-", "half-width of its confidence interval"),
))
VARIANCE_CSV = OutputFile("variance.csv", "ies sobol", "", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("variance", "(a/a_noabs*)^2", "variance of the repetition-mean output over the sample"),
    Column("noise_variance", "(a/a_noabs*)^2", "the part that is repetition noise (mean squared standard error)"),
    Column("noise_share", "-", "noise_variance / variance"),
    Column("failed_runs", "-", "runs that failed"),
    Column("message", "", "why a level was not analysed (empty otherwise)"),
))
SWEEPS_CSV = OutputFile("sweeps.csv", "ies response", "The frequency response at every level: the level, then the "
                        "columns of sweep.csv.", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("<sweep>", "", "the columns of sweep.csv"),
))
STUDY_JSON = OutputFile("study.json", "every study folder", "", (
    Column("study", "", "the resolved study: name, kind, model, modal_model, seed, repetitions, output (the folder used), "
           "source (the study file read), levels, protocol and protocol_resolved (as sweep.json's protocol), parameters "
           "(per parameter nominal, min, max, unit, label; _extras: k_H_best_estimate, k_H_calibrated in N/m^1.5), "
           "interval, sobol, response, contact_law, series"),
    Column("series_folders", "", "a series study: its values' folders"),
    Column("output_folder", "", "absolute path of the folder"),
    Column("code_version", "", "hash of the simulator's source (part of every task key)"),
    Column("outputs, warnings", "", "the banded outputs; every warning of the run"),
    Column("summary", "", "tasks, ran, reused, failed_runs, wall_time_s (s), points; interval: monotone per "
           "design/output, untested; Sobol': base_sample, per_level"),
    Column("overview", "", "response studies: overview.csv's columns as lists"),
    Column("landmarks", "", "response studies: last_smr and first_apr (the switch; null where none), optimum_level, "
           "reduction_mean, reduction_max; resonant_mean, resonant_mean_lo, resonant_mean_hi and impacts_at_apr_eta "
           "(contact onsets per period at eta = 0.976) at 7.4 and 9 as KEY_7.4, KEY_9"),
))
TASK_JSON = OutputFile("tasks/KEY.json", "every study folder", "One finished run; KEY is the SHA-256 of its "
                       "parameters, level, repetition, protocol, seed, the simulator's source and the modal file. "
                       "tasks/STUDY.txt names the study the folder belongs to.", (
    Column("params", "SI", "the run's parameters"),
    Column("level, rep", "a_base/a_base*, -", "excitation level and repetition"),
    Column("outputs", "a/a_noabs*", "the run's outputs"),
    Column("error", "", "null, or why it failed"),
    Column("seconds", "s", "its wall time"),
    Column("trace", "", "its per-point measures eta, eta_actual, leg, mean, max, min, std, impacts_per_period, "
           "hold_periods, with a_base and a_noabs in m"),
))


@dataclass
class StudyResult:
    """What a finished study produced: output folder, files, warnings and a short summary."""

    folder: Path
    files: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    summary: dict = field(default_factory=dict)


def _warn(result: StudyResult, message: str) -> None:
    result.warnings.append(message)
    sys.stderr.write(f"warning: {message}\n")


def _tasks(points: Sequence[dict], study: Study) -> list[Task]:
    return [Task.make(p, level, rep) for p in points for level in study.levels for rep in range(study.repetitions)]


def statistics(model: Any, results: dict, points: Sequence[dict],
               study: Study) -> tuple[dict[str, tuple[np.ndarray, ...]], np.ndarray]:
    """Per output: (value, standard error, samples), arrays (n_points, n_levels), from the model's own
    aggregation over the repetitions of each point and level (failed runs left out, NaN if all), and the regime
    of each point and level as the model classifies it ("" for models without regimes)."""
    outputs = list(model.outputs)
    shape = (len(points), len(study.levels))
    stats = {o: (np.full(shape, np.nan), np.full(shape, np.nan), np.zeros(shape, dtype=int)) for o in outputs}
    regimes = np.full(shape, "", dtype=object)
    for i, p in enumerate(points):
        for j, level in enumerate(study.levels):
            records = [results[Task.make(p, level, r)] for r in range(study.repetitions)]
            agg = model.aggregate([rec for rec in records if not rec["error"]])
            for o in outputs:
                for k in range(3):
                    stats[o][k][i, j] = agg[o][k]
            regimes[i, j] = agg.get("regime", "")
    return stats, regimes


def parameter_columns(space: Any) -> list[str]:
    """The CSV column of each parameter: its name with its unit, e.g. g_m, k_H_N_per_m1p5 (`Parameter.column`)."""
    return [p.column for p in space.parameters]


def _runs_rows(results: dict, points: Sequence[dict], study: Study, outputs: Sequence[str], names: Sequence[str]):
    rows = []
    for p in points:
        for level in study.levels:
            for r in range(study.repetitions):
                rec = results[Task.make(p, level, r)]
                rows.append([*(p[n] for n in names), level, r, *(float(rec["outputs"].get(o, np.nan)) for o in outputs),
                             rec["error"]])
    return rows


def _checked_model(study: Study) -> Any:
    model = study.make_model()
    model.check()
    return model


def study_key(study: Study, model: Any) -> str:
    """SHA-256 of what defines a study's runs: the resolved study (without its output folder and file path) and the
    model's settings. `--resume` continues a folder only with the same key. The Sobol' sample size and the
    analysis settings are left out: Saltelli's sample and the surrogate's Sobol' design with a fixed seed are
    nested (the first points of a larger sample are the smaller one's), so a study grown with --resume reuses every
    run it has (a convergence check)."""
    import hashlib
    import json

    from uq.engine.runner import describe_model

    data = {k: v for k, v in study.to_dict().items() if k not in ("output", "source")}
    data["sobol"] = {"method": study.sobol_method}
    text = json.dumps({"study": data, "model": describe_model(model)}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _run_points(study: Study, model: Any, points: list[dict], out: Path | None, *, resume: bool, jobs: int | None,
                scheduler: str | None, progress: bool, client: Any) -> tuple[Any, StudyResult, dict, int, float]:
    """Connect to the cluster once (if any), then prepare the output folder and run every task of `points`.

    Returns the model (rig built), the StudyResult, results by task, how many ran now, and the time (s)."""
    with dask_client(scheduler, client) as client:
        if hasattr(model, "with_rig"):
            model = model.with_rig()
        folder = prepare_output(out or study.output, resume=resume, study=(study.name, study_key(study, model)))
        if hasattr(model, "warm_up"):
            model.warm_up()  # compile the kernels before the progress bar (workers load them from the cache)
        t0 = time.perf_counter()
        results, ran = run_tasks(model, _tasks(points, study), study.seed, ResultStore(folder), jobs=jobs,
                                 progress=progress, client=client)
        return model, StudyResult(folder), results, ran, time.perf_counter() - t0


def _metadata(study: Study, model: Any, result: StudyResult, extra: dict) -> Path:
    meta = {"study": {**study.to_dict(), "output": str(result.folder)}, "output_folder": str(result.folder.resolve()),
            "code_version": model.version(), "outputs": list(model.banded_outputs), "warnings": result.warnings,
            **extra}
    if hasattr(model, "resolved_protocol"):
        meta["study"]["protocol_resolved"] = model.resolved_protocol()
    path = result.folder / "study.json"
    write_text(path, dumps(meta))
    return path


def interval_designs(study: Study) -> list[Design]:
    """The designs named in the study: individual (one per varied parameter), joint, residual."""
    designs: list[Design] = []
    for name in study.designs:
        if name == "individual":
            designs.extend(axis_design(study.space, p.name, study.interior) for p in study.space.varied)
        elif name == "joint":
            designs.append(box_design(study.space, study.interior, name="joint", seed=study.seed))
        elif name == "residual":
            designs.append(box_design(study.space.fix(**study.fix), study.interior, name="residual", seed=study.seed))
    if not designs:
        raise StudyError("the study has no design to run; set [interval] designs")
    return designs


def run_interval_study(study: Study, *, out: Path | None = None, jobs: int | None = 1, scheduler: str | None = None,
                       resume: bool = False, progress: bool = True, client: Any = None) -> StudyResult:
    """Interval study (Figs. 7 and 8): bands of the repetition-mean resonant levels per excitation level."""
    model = _checked_model(study)
    designs = interval_designs(study)
    nominal = DesignPoint(study.space.nominal(), "nominal", "nominal")
    unique: dict[tuple, dict] = {nominal.key(): dict(nominal.values)}
    for d in designs:
        for p in d.points:
            unique.setdefault(p.key(), dict(p.values))
    points = list(unique.values())
    index = {key: i for i, key in enumerate(unique)}
    model, result, results, ran, elapsed = _run_points(study, model, points, out, resume=resume, jobs=jobs,
                                                       scheduler=scheduler, progress=progress, client=client)
    folder = result.folder
    names, outputs = study.space.names, list(model.banded_outputs)
    level_labels = [f"level {lv:g}" for lv in study.levels]
    stats, regimes = statistics(model, results, points, study)
    n_failed = sum(1 for rec in results.values() if rec["error"])
    if n_failed:
        _warn(result, f"{n_failed} of {len(results)} runs failed (see the 'error' column of runs.csv)")

    point_rows, band_rows = [], []
    bands: dict[tuple[str, str], Band] = {}
    i_nominal = index[nominal.key()]
    for d in [Design("nominal", "box", (nominal,))] + designs:
        rows_idx = [index[p.key()] for p in d.points]
        for o in model.outputs:
            mean, se, n = (a[rows_idx] for a in stats[o])
            for row, (p, i) in enumerate(zip(d.points, rows_idx)):
                for j, level in enumerate(study.levels):
                    point_rows.append([d.name, p.label, p.role, *(p.values[name] for name in names), level, o,
                                       mean[row, j], se[row, j], int(n[row, j]), regimes[i, j]])
            if d.name == "nominal" or o not in outputs:
                continue
            bd = _band_with_failures(d, mean, se, study.z, level_labels)
            bands[(d.name, o)] = bd
            for msg in bd.notes:
                _warn(result, f"{o}: {msg}")
            lower_se, upper_se = _edge_errors(d, mean, se, bd)
            nominal_value, nominal_se = stats[o][0][i_nominal], stats[o][1][i_nominal]
            outside = _nominal_outside(d, study.space.nominal(), nominal_value, nominal_se, bd, lower_se, upper_se,
                                       study.z)
            for j, level in enumerate(study.levels):
                band_rows.append([d.name, o, level, bd.lower[j], bd.upper[j], bd.corner_lower[j], bd.corner_upper[j],
                                  int(bd.flagged[j]), bd.violation[j], int(bd.tested[j]), lower_se[j], upper_se[j],
                                  nominal_value[j], nominal_se[j], outside[j]])
    columns = parameter_columns(study.space)
    result.files.append(write_csv(folder / "runs.csv", header(RUNS_CSV, parameters=columns, outputs=model.outputs),
                                   _runs_rows(results, points, study, model.outputs, names)))
    result.files.append(write_csv(folder / "points.csv", header(POINTS_CSV, parameters=columns), point_rows))
    result.files.append(write_csv(folder / "bands.csv", BAND_COLUMNS, band_rows))
    members = [[d.name, p.label, p.role, index[p.key()]] for d in [Design("nominal", "box", (nominal,))] + designs
               for p in d.points]
    result.files.append(_interval_netcdf(study, model, folder, points, results, stats=stats, regimes=regimes,
                                         members=members, band_rows=band_rows))
    monotone = {f"{d}/{o}": bd.monotone for (d, o), bd in bands.items()}
    untested = [f"{d}/{o}" for (d, o), bd in bands.items() if not bd.fully_tested]
    result.summary = {"tasks": len(results), "ran": ran, "reused": len(results) - ran, "failed_runs": n_failed,
                      "wall_time_s": elapsed, "monotone": monotone, "untested": untested, "points": len(points)}
    result.files.append(_metadata(study, model, result, {"summary": result.summary}))
    return result


def _interval_netcdf(study: Study, model: Any, folder: Path, points: list[dict], results: dict, *, stats: dict,
                     regimes: np.ndarray, members: list[list], band_rows: list[list]) -> Path:
    """results.nc of an interval study (`uq.outputs.netcdf`): the runs and repetition statistics per point, each design's
    members (on design_point: member_design, member_label, member_role and member_point, the index along point; the
    rows of points.csv) and the bands per design and level."""
    import xarray as xr

    from uq.outputs.netcdf import base_dataset, finish, table_variables

    ds = base_dataset(study, model, points, results, stats, regimes)
    member = table_variables(["design_point", "member_design", "member_label", "member_role", "member_point"],
                             [[i, *m] for i, m in enumerate(members)], {"design_point": "design_point"})
    bands = table_variables(list(BAND_COLUMNS), band_rows, {"design": "design", "level": "level"}, split="output")
    return finish(xr.merge([ds, xr.Dataset(member), xr.Dataset(bands)], combine_attrs="override"), study, model,
                  folder)


#: the columns of bands.csv
BAND_COLUMNS = BANDS_CSV.names


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


def run_sobol_study(study: Study, *, out: Path | None = None, n: int | None = None, jobs: int | None = 1,
                    scheduler: str | None = None, resume: bool = False, progress: bool = True,
                    client: Any = None) -> StudyResult:
    """Sobol' study: S1, ST (bootstrap CI) of the repetition-mean resonant levels per excitation level,
    with the share of their variance that is repetition noise; from Saltelli's sample of n (k + 2) points
    (`uq.methods.sobol`), or with [sobol] method = "pce" from a polynomial-chaos surrogate of a scrambled Sobol' design
    (`uq.methods.surrogate`; its fit and smoothness verdict in surrogate.csv)."""
    from uq.outputs.results import sample_size_advice
    from uq.methods.sobol import sobol_indices, sobol_sample
    from uq.methods.surrogate import pce_indices, pce_sample

    model = _checked_model(study)
    pce = study.sobol_method == "pce"
    if pce:
        X = pce_sample(study.space, study.surrogate_points, seed=study.seed)
    else:
        n = study.sobol_n if n is None else n
        X = sobol_sample(study.space, n, seed=study.seed)
    points = [study.space.from_values(x) for x in X]
    model, result, results, ran, elapsed = _run_points(study, model, points, out, resume=resume, jobs=jobs,
                                                       scheduler=scheduler, progress=progress, client=client)
    folder = result.folder
    names, outputs = study.space.names, list(model.banded_outputs)
    rows, summary_rows, per_level, fit_rows = [], [], {}, []
    stats, regimes = statistics(model, results, points, study)
    n_failed = sum(1 for rec in results.values() if rec["error"])
    if n_failed:
        _warn(result, f"{n_failed} of {len(results)} runs failed (see the 'error' column of runs.csv); points "
                      "with some finite runs use those")
    for o in outputs:
        value, se, _ = stats[o]
        for j, level in enumerate(study.levels):
            if pce:
                res = pce_indices(study.space, X, value[:, j], degree=study.surrogate_degree, noise=se[:, j] ** 2,
                                  regimes=list(regimes[:, j]), num_resamples=study.bootstrap,
                                  confidence=study.confidence, seed=study.seed, max_misfit=study.max_misfit)
            else:
                res = sobol_indices(study.space, X, value[:, j], num_resamples=study.bootstrap,
                                    confidence=study.confidence, seed=study.seed, noise=se[:, j] ** 2)
            for note in res.notes:
                _warn(result, f"{o} at level {level:g}: {note}")
            if res.message:
                _warn(result, f"{o} at level {level:g}: not analysed: {res.message}")
            free = res.noise_free()
            for k, pname in enumerate(res.names):
                rows.append([o, level, pname, res.S1[k], res.S1_conf[k], res.ST[k], res.ST_conf[k],
                             *(column[k] for column in free)])
            advice = None if pce else sample_size_advice([*res.S1, *res.ST], [*res.S1_conf, *res.ST_conf], n)
            if advice and not res.message:
                _warn(result, f"{o} at level {level:g}: {advice}")
            summary_rows.append([o, level, res.variance, res.noise_variance, res.noise_share, res.failed_runs,
                                 res.message])
            per_level[f"{o}@{level:g}"] = {"noise_share": res.noise_share, "failed_runs": res.failed_runs}
            if pce:
                if not res.message and not res.smooth:
                    _warn(result, f"{o} at level {level:g}: NOT SMOOTH: {res.rough}; the surrogate's indices are not "
                                  "reliable there: use method = \"saltelli\"")
                fit_rows.append([o, level, res.points, res.degree, res.terms, res.cv_error, res.noise_floor,
                                 int(res.smooth) if not res.message else "", " ".join(res.regimes), res.rough])
                per_level[f"{o}@{level:g}"].update(cv_error=res.cv_error, noise_floor=res.noise_floor,
                                                   smooth=bool(res.smooth and not res.message))
    result.files.append(write_csv(folder / "runs.csv", header(RUNS_CSV, parameters=parameter_columns(study.space),
                                                               outputs=model.outputs),
                                   _runs_rows(results, points, study, model.outputs, names)))
    result.files.append(write_csv(folder / "sobol.csv", SOBOL_CSV.names, rows))
    result.files.append(write_csv(folder / "variance.csv", VARIANCE_CSV.names, summary_rows))
    result.files.append(_sobol_netcdf(study, model, folder, points, results, stats=stats, regimes=regimes, rows=rows,
                                      summary_rows=summary_rows, fit_rows=fit_rows if pce else None))
    if pce:
        result.files.append(write_csv(folder / "surrogate.csv", SURROGATE_COLUMNS, fit_rows))
        sample = {"method": "pce", "design_points": study.surrogate_points, "degree": study.surrogate_degree,
                  "smooth": all(v["smooth"] for v in per_level.values())}
    else:
        sample = {"base_sample": n}
    result.summary = {"tasks": len(results), "ran": ran, "reused": len(results) - ran, "failed_runs": n_failed,
                      **sample, "points": len(points), "wall_time_s": elapsed, "per_level": per_level}
    result.files.append(_metadata(study, model, result, {"summary": result.summary}))
    return result


def _sobol_netcdf(study: Study, model: Any, folder: Path, points: list[dict], results: dict, *, stats: dict,
                  regimes: np.ndarray, rows: list[list], summary_rows: list[list], fit_rows: list[list] | None) -> Path:
    """results.nc of a Sobol' study (`uq.outputs.netcdf`): the runs and repetition statistics per sample point, the indices
    per parameter and level (OUTPUT_S1, ...), the variance and noise per level, and the surrogate's fit (pce)."""
    import xarray as xr

    from uq.outputs.netcdf import base_dataset, finish, table_variables

    parts = [base_dataset(study, model, points, results, stats, regimes),
             xr.Dataset(table_variables(list(SOBOL_CSV.names), rows,
                                        {"parameter": "parameter", "level": "level"}, split="output")),
             xr.Dataset(table_variables(["output", "level", "variance", "noise_variance", "noise_share", "failed_runs",
                                         "message"], summary_rows, {"level": "level"}, split="output"))]
    if fit_rows is not None:
        parts.append(xr.Dataset(table_variables(list(SURROGATE_COLUMNS), fit_rows, {"level": "level"}, split="output")))
    method = {"sobol_method": study.sobol_method}
    return finish(xr.merge(parts, combine_attrs="override"), study, model, folder, method)


SURROGATE_CSV = OutputFile("surrogate.csv", "ies sobol, method pce", "The polynomial-chaos surrogate's fit per "
                           "output and level (`uq.methods.surrogate`).", (
    Column("output", "", "mean or max"),
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("points", "-", "the design's points (scrambled Sobol')"),
    Column("degree", "-", "the basis' total degree"),
    Column("terms", "-", "the polynomial terms LARS kept"),
    Column("cv_error", "-", "10-fold cross-validated error, a share of the output variance"),
    Column("noise_floor", "-", "the part of cv_error the repetition noise explains"),
    Column("smooth", "-", "1 where the response is smooth, 0 not (NOT SMOOTH: indices unreliable), empty: not analysed"),
    Column("regimes", "", "the regimes the design points fall into"),
    Column("rough", "", "why it is not smooth"),
))
SURROGATE_COLUMNS = SURROGATE_CSV.names
RESULTS_NC = OutputFile("results.nc", "every study folder, ies design", "Every number of the CSV tables as one xarray "
                        "Dataset (NetCDF 4, h5netcdf) on named dimensions, with CF `units` and `long_name` on every "
                        "variable and the resolved study and code version as attributes; open it with "
                        "`uq.outputs.results.open_study(DIR)` (`uq.outputs.netcdf`).", (
    Column("point", "-", "dimension: the parameter points (the parameters as coordinates along it)"),
    Column("level", "a_base/a_base*", "dimension: the excitation levels"),
    Column("repetition", "-", "dimension: the repetitions"),
    Column("design, parameter, eta", "-", "dimensions of the bands, the indices and the frequency responses"),
))


def run_response_study(study: Study, *, out: Path | None = None, jobs: int | None = 1, scheduler: str | None = None,
                       resume: bool = False, progress: bool = True, client: Any = None) -> StudyResult:
    """Response study (Figs. 5 and 6): the frequency response of the nominal point at every level (mean and max
    amplitude per eta with the spread of the runs, Sect. 5.2) and its resonant levels (Sect. 5.3), every
    stepped-sine run a task of the store (resumable, parallel, on a cluster)."""
    from sim.stepped_sine.tables import OVERVIEW_COLUMNS, SWEEP_COLUMNS, overview_data, overview_rows, sweep_rows
    from sim.stepped_sine.landmarks import landmarks

    if study.series:
        return _run_response_series(study, out=out, jobs=jobs, scheduler=scheduler, resume=resume, progress=progress,
                                    client=client)
    model = _checked_model(study)
    point = study.space.nominal()
    model, result, results, ran, elapsed = _run_points(study, model, [point], out, resume=resume, jobs=jobs,
                                                       scheduler=scheduler, progress=progress, client=client)
    folder = result.folder
    n_failed = sum(1 for rec in results.values() if rec["error"])
    if n_failed:
        _warn(result, f"{n_failed} of {len(results)} runs failed (see the 'error' column of runs.csv)")
    sweeps, levels = [], []
    for level in study.levels:
        records = [results[Task.make(point, level, r)] for r in range(study.repetitions)]
        sweep = model.sweep_result([rec for rec in records if not rec["error"]])
        if sweep is None:
            _warn(result, f"every run failed at level {level:g}; the level is left out")
            continue
        sweeps.append(sweep)
        levels.append(level)
    if not sweeps:
        raise StudyError("every run of the response study failed; see runs.csv")
    overview = overview_data(levels, sweeps)
    result.files.append(write_csv(folder / "runs.csv", header(RUNS_CSV, parameters=parameter_columns(study.space),
                                                               outputs=model.outputs),
                                   _runs_rows(results, [point], study, model.outputs, study.space.names)))
    result.files.append(write_csv(folder / "sweeps.csv", header(SWEEPS_CSV, sweep=SWEEP_COLUMNS),
                                   [[s.level, *row] for s in sweeps for row in sweep_rows(s)]))
    result.files.append(write_csv(folder / "overview.csv", OVERVIEW_COLUMNS, overview_rows(overview)))
    result.files.append(_response_netcdf(study, model, folder, point, results, sweeps, overview))
    result.summary = {"tasks": len(results), "ran": ran, "reused": len(results) - ran, "failed_runs": n_failed,
                      "wall_time_s": elapsed, "points": 1}
    result.files.append(_metadata(study, model, result, {"summary": result.summary, "overview": overview,
                                                         "landmarks": landmarks(sweeps).summary()}))
    return result


def _response_netcdf(study: Study, model: Any, folder: Path, point: dict, results: dict, sweeps: list,
                     overview: dict) -> Path:
    """results.nc of a response study (`uq.outputs.netcdf`): the runs on level x repetition (the one point's parameters as
    scalar coordinates), the frequency responses on level x eta (sweep_COLUMN) and the resonant levels per level
    (overview_COLUMN)."""
    import xarray as xr

    from sim.stepped_sine.tables import OVERVIEW_COLUMNS, SWEEP_COLUMNS, overview_rows, sweep_rows
    from uq.outputs.netcdf import base_dataset, finish, table_variables

    ds = base_dataset(study, model, [point], results).isel(point=0).drop_vars("point")
    sweep = table_variables(["level", *SWEEP_COLUMNS], [[s.level, *row] for s in sweeps for row in sweep_rows(s)],
                            {"level": "level", "eta": "eta"}, prefix="sweep_")
    over = table_variables(list(OVERVIEW_COLUMNS), overview_rows(overview), {"level": "level"}, prefix="overview_")
    return finish(xr.merge([ds, xr.Dataset(sweep), xr.Dataset(over)], combine_attrs="override"), study, model,
                  folder)


def _run_response_series(study: Study, *, out: Path | None, jobs: int | None, scheduler: str | None, resume: bool,
                         progress: bool, client: Any) -> StudyResult:
    """[response] series (Fig. 11): the response study once per value of the series' parameter, each in its own
    folder OUT/NAME=VALUE (resumable like any study), and OUT/study.json naming them."""
    folder = Path(out) if out is not None else study.output
    result = StudyResult(folder)
    totals = {"tasks": 0, "ran": 0, "reused": 0, "failed_runs": 0, "wall_time_s": 0.0, "points": 0}
    parts = []
    for sub, one in study.series_studies():
        part = run_response_study(one, out=folder / sub, jobs=jobs, scheduler=scheduler, resume=resume,
                                  progress=progress, client=client)
        result.files += part.files
        result.warnings += part.warnings
        for key in totals:
            totals[key] += part.summary[key]
        parts.append(sub)
    result.summary = totals
    result.files.append(_series_netcdf(study, folder, parts))
    result.files.append(_metadata(study, study.make_model(), result, {"summary": totals, "series_folders": parts}))
    return result


def _series_netcdf(study: Study, folder: Path, parts: list[str]) -> Path:
    """OUT/results.nc of a response series: the series' studies' datasets along a dimension named after the series'
    parameter (its values the coordinate)."""
    import xarray as xr

    from uq.outputs.netcdf import finish, open_results

    name, _ = study.series
    ds = xr.concat([open_results(folder / sub) for sub in parts], dim=name, data_vars="all", coords="different",
                   compat="equals", join="outer", combine_attrs="drop_conflicts")
    return finish(ds, study, study.make_model(), folder, {"series_folders": " ".join(parts)})


def series_traces(study: Study, folder: Path, levels: Sequence[float], periods: int = 20) -> list[Path]:
    """Fig. C.1b: with the series' last value (e.g. friction on), the time history (`sim.analysis.trace`, 51.2 kHz) of the
    point of the resonant mean at each of `levels`, reached as the study's runs reach it (its grid up to that eta,
    the first run's random offset), into folder/trace-LEVEL: trace.csv, trace.json, Figs. 4/9a (trace.png) and
    the walls and the sphere (motion.png)."""
    import csv
    import dataclasses

    from sim.plots.figures import plot_motion, plot_trace
    from uq.outputs.figures import series_label
    from sim.analysis.trace import record_trace, write_trace

    sub, one = study.series_studies()[-1]
    with open(folder / sub / "overview.csv", newline="") as fh:
        resonant = {float(r["level"]): float(r["eta_resonant_mean"]) for r in csv.DictReader(fh)}
    model = one.make_model().with_rig()
    point = one.space.nominal()
    rig, impactor = model.simulated_system(point)
    protocol = model.stepped_sine()
    grid = protocol.eta
    written: list[Path] = []
    for level in levels:
        if level not in resonant:
            raise StudyError(f"level {level:g} is not among the study's levels; it cannot be traced")
        last = int(np.argmin(np.abs(grid - resonant[level])))
        visit = dataclasses.replace(protocol, eta_stop=float(grid[last]), n_eta=last + 1) if last else \
            dataclasses.replace(protocol, eta_stop=float(grid[0]), n_eta=1)
        trace = record_trace(rig, impactor, level, visit, periods=periods, seed=study.seed)
        out = folder / f"trace-{level:g}"
        out.mkdir(parents=True, exist_ok=True)
        settings = {"integrator": visit.integrator, "seed": study.seed, "protocol": dataclasses.asdict(visit),
                    "series": sub, "study": study.name}
        _, paths = write_trace(out, trace, settings, out / "trace.png", draw=plot_trace)
        title = (f"{series_label(sub)}: $a_\\mathrm{{base}}/a_\\mathrm{{base}}^*$ = {level:g}, $\\eta$ = {trace.eta_actual:.4f} "
                 "(cf. Fig. C.1b), "
                 f"{trace.amplitudes.size} periods")
        plot_motion(trace.signal.t, trace.signal, out / "motion.png", title)
        written += [Path(p) for p in paths] + [out / "motion.png"]
    return written
