"""Running a study end to end, whatever its method (`uq.problem.method`): plan -> tasks -> runner -> repetition
statistics -> analysis -> files.

Data first: every run (runs.csv), the method's tables (its `Table`s: points.csv and bands.csv of an interval study,
sobol.csv and variance.csv of a Sobol' study, ...), results.nc (every number of the tables on named dimensions) and
study.json with the resolved study, code version, warnings and timings. Figures (`Method.figures`) are drawn from the
same tables afterwards. CSV files hold no timings, so reruns (serial, parallel, Dask, resumed) can be compared byte by
byte.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from sim.common.files import dumps, write_csv, write_text
from sim.common.outputs import header
from sim.common.folder_lock import locked
from uq.engine.runner import (ResultStore, check_cost, check_writable, dask_client, describe_model, pending_tasks,
                              prepare_output, release_output, run_tasks)
from uq.outputs.tables import RUNS_CSV, parameter_columns, runs_rows
from uq.problem.method import Analysis, Plan, Runs
from uq.problem.study import Study
from uq.problem.tasks import Task, check_run_total

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


def statistics(model: Any, records: dict, points: Sequence[dict],
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
            runs = [records[Task.make(p, level, r)] for r in range(study.repetitions)]
            agg = model.aggregate([rec for rec in runs if not rec["error"]])
            for o in outputs:
                for k in range(3):
                    stats[o][k][i, j] = agg[o][k]
            regimes[i, j] = agg.get("regime", "")
    return stats, regimes


def study_key(study: Study, model: Any) -> str:
    """SHA-256 of what defines a study's runs (`Study.identity`: the resolved study without its output folder and
    file path, and the method's settings that are part of its identity) and the model's settings. `--resume`
    continues a folder only with the same key. Sample sizes whose samples are nested (Saltelli's sample, the
    surrogate's Sobol' design with a fixed seed) and analysis settings are left out, so that a study grown with
    --resume reuses every run it has (a convergence check)."""
    import hashlib
    import json

    text = json.dumps({"study": study.identity(), "model": describe_model(model)}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def run_study(study: Study, *, out: Path | None = None, jobs: int | None = 1, scheduler: str | None = None,
              resume: bool = False, progress: bool = True, client: Any = None, allow_large: bool = False,
              paper_figure: str | None = None) -> StudyResult:
    """Run a study with its method: every (point, level, repetition) of its plan through the task store (cached,
    resumable; serially, on local workers or on Dask), then its analysis, and write its files into `out` (default:
    the study's [study] output). A study of sub-studies (`Method.substudies`) runs each into a sub-folder.
    paper_figure: the paper's figure the study reproduces (`ies reproduce`), kept in study.json: its figures carry
    the paper's names (`uq.outputs.paper_figures`)."""
    method = study.method
    parts = method.substudies(study)
    if parts:
        return _run_parts(study, parts, out=out, jobs=jobs, scheduler=scheduler, resume=resume, progress=progress,
                          client=client, allow_large=allow_large)
    model = study.make_model()
    model.check()
    plan = method.plan(study)
    typical = getattr(model, "typical_seconds_per_run", None)
    check_run_total(len(plan.points), len(study.levels), study.repetitions, allow_large=allow_large,
                    per_run_s=typical() if typical is not None else None)
    folder = Path(out or study.output)
    try:
        return _run(study, model, plan, folder, jobs=jobs, scheduler=scheduler, resume=resume, progress=progress,
                    client=client, allow_large=allow_large, paper_figure=paper_figure)
    finally:
        release_output(folder)  # the lock prepare_output took, once the last file is written


def _run(study: Study, model: Any, plan: Plan, folder: Path, *, jobs: int | None, scheduler: str | None, resume: bool,
         progress: bool, client: Any, allow_large: bool, paper_figure: str | None) -> StudyResult:
    """`run_study` of one study from its output folder on: the kernels, the cost estimate (refused above an hour
    unless `allow_large`), the tasks, the analysis and the files."""
    method = study.method
    tasks = _tasks(plan.points, study)
    with dask_client(scheduler, client) as client:
        if hasattr(model, "with_rig"):
            model = model.with_rig()
        if hasattr(model, "warm_up"):
            model.warm_up()  # compile the kernels before the estimate and the progress bar (workers load them)
        todo = pending_tasks(model, tasks, study.seed, folder) if resume else tasks
        work = check_cost(model, todo, jobs=jobs, client=client, allow_large=allow_large,
                          quiet=not progress)  # before the first run
        folder = prepare_output(folder, resume=resume, study=(study.name, study_key(study, model)))
        started = time.perf_counter()
        records, ran = run_tasks(model, tasks, study.seed, ResultStore(folder), jobs=jobs, progress=progress,
                                 client=client, expected_s=work.per_run_s if work is not None else None)
        elapsed = time.perf_counter() - started
    result = StudyResult(folder)
    failed = sum(1 for rec in records.values() if rec["error"])
    if failed:
        _warn(result, f"{failed} of {len(records)} runs failed (see the 'error' column of runs.csv)")
    stats, regimes = statistics(model, records, plan.points, study)
    analysis = method.analyse(study, model, plan, Runs(records, stats, regimes, failed))
    for message in analysis.warnings:
        _warn(result, message)
    result.files.append(write_csv(folder / "runs.csv", header(RUNS_CSV, parameters=parameter_columns(study.space),
                                                               outputs=model.outputs),
                                  runs_rows(records, plan.points, study.levels, study.repetitions, model.outputs,
                                            study.space.names)))
    for table in method.tables:
        if table.file.file in analysis.rows:
            result.files.append(write_csv(folder / table.file.file, _columns(table, analysis),
                                          analysis.rows[table.file.file]))
    result.files.append(_netcdf(study, model, folder, plan, records, stats, regimes, analysis))
    result.summary = {"tasks": len(records), "ran": ran, "reused": len(records) - ran, "failed_runs": failed,
                      "wall_time_s": elapsed, "points": len(plan.points), **analysis.summary}
    result.files.append(_metadata(study, model, result, {"summary": result.summary, **analysis.metadata,
                                                          **({"paper_figure": paper_figure} if paper_figure else {})}))
    return result


def _columns(table: Any, analysis: Analysis) -> Sequence[str]:
    return analysis.columns.get(table.file.file, table.file.names)


def _netcdf(study: Study, model: Any, folder: Path, plan: Plan, records: dict, stats: dict, regimes: np.ndarray,
            analysis: Analysis) -> Path:
    """results.nc (`uq.outputs.netcdf`): the runs and repetition statistics per point (`base_dataset`, as the method
    shapes it), every table of the method that has dimensions, and the analysis' own datasets."""
    import xarray as xr

    from uq.outputs.netcdf import base_dataset, finish, table_variables

    method = study.method
    base = base_dataset(study, model, plan.points, records, stats, regimes)
    parts = [method.base_dataset(base)]
    for table in method.tables:
        if table.dims is not None and table.file.file in analysis.rows:
            parts.append(xr.Dataset(table_variables(list(_columns(table, analysis)), analysis.rows[table.file.file],
                                                    table.dims, split=table.split, prefix=table.prefix)))
    parts += analysis.datasets
    return finish(xr.merge(parts, combine_attrs="override"), study, model, folder,
                  {f"{study.kind}_method": method.name})


def _metadata(study: Study, model: Any, result: StudyResult, extra: dict) -> Path:
    meta = {"study": {**study.to_dict(), "output": str(result.folder)}, "output_folder": str(result.folder.resolve()),
            "code_version": model.version(), "outputs": list(model.banded_outputs), "warnings": result.warnings,
            **extra}
    if hasattr(model, "resolved_protocol"):
        meta["study"]["protocol_resolved"] = model.resolved_protocol()
    if hasattr(model, "normalisation"):  # what a / a_noabs* and the levels are normalised by (Sect. 5)
        meta["normalisation"] = model.normalisation()
    path = result.folder / "study.json"
    write_text(path, dumps(meta))
    return path


def _run_parts(study: Study, parts: list[tuple[str, Study]], *, out: Path | None, jobs: int | None,
               scheduler: str | None, resume: bool, progress: bool, client: Any, allow_large: bool) -> StudyResult:
    """A study of sub-studies (a response series, Fig. 11): each in its own folder OUT/NAME=VALUE (resumable like any
    study), OUT/results.nc with their datasets along the dimension NAME (the values its coordinate) and
    OUT/study.json naming them."""
    folder = Path(out) if out is not None else study.output
    check_writable(folder)
    with locked(folder):  # the series' own files (results.nc, study.json) beside its parts' folders
        return _series(study, parts, folder, jobs=jobs, scheduler=scheduler, resume=resume, progress=progress,
                       client=client, allow_large=allow_large)


def _series(study: Study, parts: list[tuple[str, Study]], folder: Path, *, jobs: int | None, scheduler: str | None,
            resume: bool, progress: bool, client: Any, allow_large: bool) -> StudyResult:
    """`_run_parts` in its locked folder."""
    import xarray as xr

    from uq.outputs.netcdf import finish, open_results

    result = StudyResult(folder)
    totals = {"tasks": 0, "ran": 0, "reused": 0, "failed_runs": 0, "wall_time_s": 0.0, "points": 0}
    names = []
    for sub, one in parts:
        part = run_study(one, out=folder / sub, jobs=jobs, scheduler=scheduler, resume=resume, progress=progress,
                         client=client, allow_large=allow_large)
        result.files += part.files
        result.warnings += part.warnings
        for key in totals:
            totals[key] += part.summary[key]
        names.append(sub)
    result.summary = totals
    dimension = names[0].split("=")[0]
    ds = xr.concat([open_results(folder / sub) for sub in names], dim=dimension, data_vars="all", coords="different",
                   compat="equals", join="outer", combine_attrs="drop_conflicts")
    model = study.make_model()
    result.files.append(finish(ds, study, model, folder, {"series_folders": " ".join(names)}))
    result.files.append(_metadata(study, model, result, {"summary": totals, "series_folders": names}))
    return result
