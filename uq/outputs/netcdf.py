"""A study's results as one xarray Dataset in NetCDF (results.nc), beside its CSV tables.

The CSV tables are written for people (one row per number, columns named); results.nc holds the same numbers for
the tools that analyse many-dimensional data (xarray, netCDF4, Panoply, ...): every variable on named dimensions,

* ``point`` (the study's parameter points: vertices and interior points of an interval study, the sample of a
  Sobol' study) with each parameter as a coordinate along it (absent from a response study, whose one point's
  parameters are scalar coordinates), ``level`` (a_base / a_base*), ``repetition``, ``eta`` (Omega / omega_1*,
  response studies), ``design`` and ``design_point`` (interval studies: the bands per design, each design's member points), ``parameter`` (Sobol' studies);
* one variable per model output and table column, named ``OUTPUT_COLUMN`` where a CSV table has an ``output``
  column (e.g. ``mean_lower`` of bands.csv, ``max_S1`` of sobol.csv), else as the column (``mean`` of runs.csv:
  one run's resonant mean);
* CF attributes (``units`` as UDUNITS strings, "1" for dimensionless; ``long_name``) on every variable and
  coordinate, and as global attributes the resolved study (JSON, as in study.json), its kind and name, the
  simulator's code version and ``Conventions = "CF-1.10"``.

Engine: h5netcdf (NetCDF-4 on HDF5): variable-length strings (regimes, error messages), 64-bit integers and
compression, which scipy's NetCDF-3 writer lacks. The file is written under a temporary name and renamed.
"""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.common.files import atomic_path
from uq.errors import StudyError

ENGINE = "h5netcdf"
#: CF units and long names of the models' outputs (`uq.problem.models`); other outputs are dimensionless model values
OUTPUT_META: dict[str, tuple[str, str]] = {
    "mean": ("1", "resonant mean amplitude a / a_noabs* (Sect. 5.3)"),
    "max": ("1", "resonant maximum amplitude a / a_noabs* (Sect. 5.3)"),
    "apr": ("1", "1 where the resonant level lies in the almost periodic regime, else 0"),
    "input_power": ("W", "input power of the excitation at the resonant mean"),
    "value": ("1", "model value"),
}
#: CF units and long names of the table columns that are not model outputs
COLUMN_META: dict[str, tuple[str, str]] = {
    "level": ("1", "excitation level a_base / a_base*"),
    "repetition": ("1", "repetition index"),
    "eta": ("1", "excitation frequency Omega / omega_1*"),
    "error": ("1", "why the run failed (empty: it did not)"),
    "rep_mean": ("", "repetition mean"), "rep_se": ("", "standard error of the repetition mean"),
    "n_samples": ("1", "number of finite repetition samples"),
    "regime": ("1", "regime at the resonant level: APR almost periodic, SMR strongly modulated, linear"),
    "member_point": ("1", "the member's index along the point dimension"), "member_design": ("1", "design name"),
    "member_label": ("1", "the member's label in its design"), "member_role": ("1", "the member's role"),
    "design": ("1", "design name"), "design_point": ("1", "a point of a design (a row of points.csv per level)"),
    "parameter": ("1", "varied parameter"),     "lower": ("", "band lower edge"), "upper": ("", "band upper edge"),
    "corner_lower": ("", "lowest vertex value"), "corner_upper": ("", "highest vertex value"),
    "flagged": ("1", "1 where the monotonicity check failed and the band was widened"),
    "violation": ("", "largest monotonicity violation"), "tested": ("1", "1 where monotonicity was tested"),
    "lower_se": ("", "standard error of the lower edge"), "upper_se": ("", "standard error of the upper edge"),
    "nominal": ("", "value at the nominal point"), "nominal_se": ("", "standard error at the nominal point"),
    "nominal_outside": ("1", "1 nominal outside the band beyond the noise, 0 not, -1 outside the design's box"),
    "S1": ("1", "first-order Sobol' index"), "S1_conf": ("1", "confidence half-width of S1"),
    "ST": ("1", "total Sobol' index"), "ST_conf": ("1", "confidence half-width of ST"),
    "S1_noise_free": ("1", "first-order Sobol' index of the expected response (noise taken out)"),
    "S1_noise_free_conf": ("1", "confidence half-width of S1_noise_free"),
    "ST_noise_free": ("1", "total Sobol' index of the expected response (noise taken out)"),
    "ST_noise_free_conf": ("1", "confidence half-width of ST_noise_free"),
    "variance": ("", "variance of the repetition means over the sample"),
    "noise_variance": ("", "variance of a repetition mean due to the repetition scatter"),
    "noise_share": ("1", "share of the variance that is repetition noise"),
    "failed_runs": ("1", "failed runs"), "message": ("1", "why the output was not analysed"),
    "points": ("1", "design points of the surrogate"), "degree": ("1", "total polynomial degree"),
    "terms": ("1", "polynomial terms kept"), "cv_error": ("1", "cross-validated error over the variance"),
    "noise_floor": ("1", "share of the cross-validated error the repetition noise explains"),
    "smooth": ("1", "1 where the response is smooth, 0 not"), "regimes": ("1", "regimes of the design points"),
    "rough": ("1", "why the response is not smooth"),
    "a_base_m": ("m", "base acceleration amplitude"), "input_power_W": ("W", "input power of the excitation"),
    "cv": ("1", "coefficient of variation of the per-period amplitudes"),
    "impacts_per_period": ("1", "impacts per excitation period"),
}
#: units squared (variances) of these columns
_SQUARED = {"variance", "noise_variance"}


def output_meta(name: str) -> tuple[str, str]:
    """(CF units, long name) of a model output."""
    from sim.stepped_sine.measures import SCATTERING_MEASURES

    if name in OUTPUT_META:
        return OUTPUT_META[name]
    if name in SCATTERING_MEASURES:
        return "1", f"{name.replace('_', ' ')} at the resonant mean (sim.stepped_sine.measures)"
    return "1", f"model output {name}"


def _attrs(column: str, output: str | None = None) -> dict[str, str]:
    """CF attributes of a table column; of one output's table (`output`), units "" in COLUMN_META are the output's."""
    from sim.stepped_sine.measures import SCATTERING_MEASURES

    if column in COLUMN_META:
        units, long_name = COLUMN_META[column]
    elif column.startswith("eta_resonant"):
        units, long_name = "1", f"Omega / omega_1* of the {column[4:].replace('_', ' ')}"
    elif column.split("_")[0] in ("mean", "max", "resonant"):
        units, long_name = "1", f"{column.replace('_', ' ')} amplitude a / a_noabs* (Sects. 5.2-5.3)"
    elif column in SCATTERING_MEASURES:
        units, long_name = output_meta(column)
    else:
        units, long_name = "1", column.replace("_", " ")
    if output is not None:
        out_units, out_name = output_meta(output)
        if units == "":
            units = f"({out_units})2" if column in _SQUARED and out_units != "1" else out_units
        long_name = f"{out_name}: {long_name}"
    return {"units": units or "1", "long_name": long_name}


def _array(values: list, dtype: Any = None) -> np.ndarray:
    """Numbers as float (or int when all are integers), anything else as str."""
    if all(isinstance(v, (bool, int, np.integer)) for v in values):
        return np.asarray(values, dtype=np.int64)
    if all(isinstance(v, (float, int, np.floating, np.integer)) for v in values):
        return np.asarray(values, dtype=float)
    return np.asarray(["" if v is None else str(v) for v in values], dtype=object)


def table_variables(columns: Sequence[str], rows: Sequence[Sequence[Any]], dims: Mapping[str, str],
                    split: str | None = None, prefix: str = "") -> dict[str, Any]:
    """The data variables of a CSV table: `dims` maps the key columns to dimension names; every other column
    becomes a variable on those dimensions (per value of the `split` column, named VALUE_COLUMN), with its CF
    attributes. Cells a table lacks are NaN (numbers) or "" (text)."""
    import xarray as xr

    keys = [c for c in dims]
    at = {c: columns.index(c) for c in columns}
    groups: dict[str, list] = {}
    for row in rows:
        groups.setdefault("" if split is None else str(row[at[split]]), []).append(row)
    out = {}
    for group, members in groups.items():
        coords = {dims[c]: list(dict.fromkeys(r[at[c]] for r in members)) for c in keys}
        shape = tuple(len(v) for v in coords.values())
        where = [tuple(coords[dims[c]].index(r[at[c]]) for c in keys) for r in members]
        for column in columns:
            if column in keys or column == split:
                continue
            values = _array([r[at[column]] for r in members])
            fill = "" if values.dtype == object else (np.nan if values.dtype.kind == "f" else -1)
            data = np.full(shape, fill, dtype=values.dtype if values.dtype != object else object)
            for index, value in zip(where, values):
                data[index] = value
            name = f"{prefix}{group}_{column}" if split is not None else f"{prefix}{column}"
            out[name] = xr.DataArray(data, dims=tuple(coords), coords=coords,
                                     attrs=_attrs(column, group if split is not None else None))
    return out


def base_dataset(study: Any, model: Any, points: Sequence[Mapping[str, float]], results: Mapping[Any, dict],
                 stats: Mapping[str, tuple] | None = None, regimes: np.ndarray | None = None) -> Any:
    """Coordinates (point with the parameters along it, level, repetition) and the runs (one variable per model
    output on point x level x repetition, and `error`), with the repetition statistics of each point and level
    (`uq.engine.execution.statistics`: OUTPUT_rep_mean, OUTPUT_rep_se, OUTPUT_n_samples, regime) where given."""
    import xarray as xr

    from uq.problem.tasks import Task

    names = study.space.names
    shape = (len(points), len(study.levels), study.repetitions)
    runs = {o: np.full(shape, np.nan) for o in model.outputs}
    error = np.full(shape, "", dtype=object)
    for i, p in enumerate(points):
        for j, level in enumerate(study.levels):
            for r in range(study.repetitions):
                rec = results[Task.make(p, level, r)]
                for o in model.outputs:
                    runs[o][i, j, r] = float(rec["outputs"].get(o, np.nan))
                error[i, j, r] = rec["error"]
    coords: dict[str, Any] = {
        "point": ("point", np.arange(len(points)), {"long_name": "parameter point", "units": "1"}),
        "level": ("level", np.asarray(study.levels, dtype=float), _attrs("level")),
        "repetition": ("repetition", np.arange(study.repetitions), _attrs("repetition")),
    }
    for p in study.space.parameters:
        coords[p.name] = ("point", np.array([pt[p.name] for pt in points], dtype=float),
                          {"units": _cf_unit(p.unit), "long_name": p.label or p.name})
    dims = ("point", "level", "repetition")
    data = {o: (dims, runs[o], {**dict(zip(("units", "long_name"), output_meta(o))),
                                "long_name": f"{output_meta(o)[1]}, one run"}) for o in model.outputs}
    data["error"] = (dims, error, _attrs("error"))
    if stats is not None:
        for o, (value, se, n) in stats.items():
            units, long_name = output_meta(o)
            data[f"{o}_rep_mean"] = (dims[:2], value, {"units": units, "long_name": f"{long_name}, repetition mean"})
            data[f"{o}_rep_se"] = (dims[:2], se, {"units": units, "long_name": f"{long_name}, its standard error"})
            data[f"{o}_n_samples"] = (dims[:2], np.asarray(n, dtype=np.int64), _attrs("n_samples"))
    if regimes is not None:
        data["regime"] = (dims[:2], np.asarray(regimes, dtype=object), _attrs("regime"))
    assert set(names) <= set(coords)
    return xr.Dataset(data, coords=coords)


def _cf_unit(unit: str) -> str:
    """A parameter's unit as a UDUNITS string ("-" dimensionless -> "1", "N/m^1.5" -> "N m-1.5")."""
    return {"-": "1", "": "1", "N/m^1.5": "N m-1.5", "N/m": "N m-1"}.get(unit, unit)


def finish(ds: Any, study: Any, model: Any, folder: Path, extra: Mapping[str, Any] | None = None) -> Path:
    """Set the global attributes (the resolved study as JSON, its kind, name and the code version) and write
    folder/results.nc atomically; returns its path."""
    from sim.common.files import dumps

    for name in [*ds.coords, *ds.data_vars]:  # table coordinates (level, eta, parameter, design, ...)
        if "units" not in ds[name].attrs:
            ds[name].attrs.update(_attrs(str(name)))
    ds.attrs.update({"Conventions": "CF-1.10", "title": f"ies-workbench {study.kind} study '{study.name}'",
                     "kind": study.kind, "name": study.name, "code_version": model.version(),
                     "study": dumps({**study.to_dict(), "output": str(folder)}), **(extra or {})})
    path = Path(folder) / "results.nc"
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=ENGINE)
    return path


def open_results(folder: str | Path) -> Any:
    """The Dataset of folder/results.nc (or of the .nc file `folder` names), read into memory (the file is closed).
    One-line StudyErrors: a path that does not exist, a folder without results.nc, a file that cannot be read (damaged
    or cut short: rewritten by rerunning the study with --resume, which recomputes nothing). See
    `uq.outputs.results.open_study`."""
    import xarray as xr

    folder = Path(folder)
    if not folder.exists():
        raise StudyError(f"{folder} does not exist; give the output folder (--out) of ies interval, sobol, response "
                         "or design, or a figure folder of ies reproduce")
    path = folder if folder.is_file() else folder / "results.nc"
    if not path.is_file():
        raise StudyError(f"{folder} holds no results.nc; give the output folder of ies interval, sobol, response or "
                         "design, or a figure folder of ies reproduce")
    try:
        return xr.load_dataset(path, engine=ENGINE)
    except (OSError, ValueError, KeyError, RuntimeError) as exc:
        raise StudyError(f"{path} cannot be read ({_reason(exc)}: damaged or cut short); {_rewrite(path)}") from None


def _reason(exc: BaseException) -> str:
    detail = re.search(r"\(([^()]*)\)\s*$", str(exc))
    return detail.group(1) if detail else (str(exc).splitlines() or [type(exc).__name__])[0]


def _rewrite(path: Path) -> str:
    """How to write a damaged results.nc again: its study's command with --resume, which reads the stored runs and
    recomputes nothing (the study file and kind from study.json where it can be read)."""
    import json

    try:
        study = json.loads((path.parent / "study.json").read_text())["study"]
        command = f"`ies {study['kind']} {study['source']} --out {path.parent} --resume`"
    except (OSError, ValueError, KeyError, TypeError):
        command = f"the study's command with --resume and --out {path.parent}"
    return f"rerun {command} to write it again from the stored runs (nothing is recomputed)"


def check_readable(folder: str | Path) -> None:
    """One line (StudyError) when a results.nc in `folder` or a folder in it (`ies reproduce`'s figures, a series'
    values) is damaged or cut short: the tables beside it were written by the same run and may be no better, so
    `ies plot` and `ies compare` name it instead of drawing from them; the line says how to write it again."""
    import h5py

    folder = Path(folder)
    for path in [folder / "results.nc", *sorted(folder.glob("*/results.nc"))]:
        if not path.is_file():
            continue
        try:
            with h5py.File(path, "r") as handle:  # the whole file's structure and every variable's data
                handle.visititems(lambda name, item: item[()] if isinstance(item, h5py.Dataset) else None)
        except (OSError, ValueError, KeyError, RuntimeError) as exc:
            raise StudyError(f"{path} is damaged or cut short ({_reason(exc)}); {_rewrite(path)}, then run this "
                             "command again") from None
