"""results.nc (uq.outputs.netcdf) of every study kind holds the numbers of the study's CSV tables, on named dimensions with
CF units and long names, and `uq.outputs.results.open_study` returns it."""
import csv
import json
import math

import numpy as np
import pytest

from uq.cli import main
from uq.errors import StudyError
from uq.outputs.results import open_study

AB = "[parameters.a]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n[parameters.b]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n"
NOISY = "[study]\nkind = '{kind}'\nmodel = 'uq.problem.test_functions:noisy_linear'\nrepetitions = 3\nseed = 2\n" + AB \
    + "[excitation]\nlevels = [1.0, 2.5]\n"
RESPONSE = ("[study]\nkind = 'response'\nseed = 3\nrepetitions = 2\n[excitation]\nlevels = [1.26, 6.7]\n"
            "eta = { start = 0.975, stop = 0.985, n = 3 }\nwait = 0.1\nhold = 0.1\n[response]\nfigures = ['fig6']\n")


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def same(cell, value):
    """A CSV cell (csv_value: repr of floats, "nan") and a NetCDF value hold the same number or text."""
    value = value.item() if hasattr(value, "item") else value
    if isinstance(value, str):
        return cell == value
    if cell == "nan":
        return isinstance(value, float) and math.isnan(value)
    return float(cell) == value


def check(ds, path, locate):
    """Every cell of the table at `path` equals the dataset's value that `locate(row, column)` picks."""
    table = rows(path)
    assert table
    for i, row in enumerate(table):
        for column, cell in row.items():
            value = locate({**row, "_i": i}, column)
            assert same(cell, value), (path.name, column, cell, value)
    return len(table)


def check_runs(ds, folder, study_levels, reps, point_dim=True):
    names = [n for n in ds.coords if n not in ("point", "level", "repetition", "parameter", "design", "design_point",
                                              "eta") and ds[n].ndim <= 1 and (not point_dim or ds[n].dims == ("point",))]

    def locate(row, column):
        i = int(row["_i"])
        at = {"level": float(row["level"]), "repetition": int(row["rep"])}
        if column == "level":
            return ds.level.sel(level=at["level"])
        if column == "rep":
            return ds.repetition.sel(repetition=at["repetition"])
        param = next((n for n in names if column == n or column.startswith(n + "_")), None)
        if param is not None:
            return ds[param][i // (len(study_levels) * reps)] if point_dim else ds[param]
        var = ds[column].sel(**at)
        return var[i // (len(study_levels) * reps)] if point_dim else var

    return check(ds, folder / "runs.csv", locate)  # row _i: point _i // (levels x repetitions)


def check_cf(ds):
    for name in [*ds.coords, *ds.data_vars]:
        assert ds[name].attrs.get("units") and ds[name].attrs.get("long_name"), name
    assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["code_version"]
    assert json.loads(ds.attrs["study"])["kind"] == ds.attrs["kind"]


def by_output(ds, table_keys):
    def locate(row, column):
        if column in table_keys:
            return row[column] if column != "level" else ds.level.sel(level=float(row["level"]))
        sel = {k: (float(row[k]) if k == "level" else row[k]) for k in table_keys if k != "output"}
        return ds[f"{row['output']}_{column}"].sel(**sel)
    return locate


def test_interval_study(tmp_path):
    path = tmp_path / "i.toml"
    path.write_text(NOISY.format(kind="interval") + "[interval]\ndesigns = ['individual', 'joint']\ninterior = 1\n")
    out = tmp_path / "o"
    assert main(["interval", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    ds = open_study(out)
    check_cf(ds)
    assert ds["value"].dims == ("point", "level", "repetition") and ds["a"].dims == ("point",)
    assert ds["value_lower"].dims == ("design", "level") and ds["a"].attrs["units"] == "1"
    n = check_runs(ds, out, [1.0, 2.5], 3)
    assert n == ds.sizes["point"] * 2 * 3

    def point_row(row, column):
        member = int(np.flatnonzero((ds.member_design.values == row["design"])
                                    & (ds.member_label.values == row["point"]))[0])
        i = int(ds.member_point[member])
        if column in ("design", "point", "role"):
            return ds[{"design": "member_design", "point": "member_label", "role": "member_role"}[column]][member]
        if column in ("a", "b"):
            return ds[column][i]
        if column == "level":
            return ds.level.sel(level=float(row["level"]))
        if column == "output":
            return row["output"]
        if column == "regime":
            return ds.regime.sel(level=float(row["level"]))[i]
        name = {"mean": "rep_mean", "se": "rep_se", "n_samples": "n_samples"}[column]
        return ds[f"{row['output']}_{name}"].sel(level=float(row["level"]))[i]

    check(ds, out / "points.csv", point_row)
    check(ds, out / "bands.csv", by_output(ds, ("design", "output", "level")))


@pytest.mark.parametrize("method", ["saltelli", "pce"])
def test_sobol_study(tmp_path, method):
    if method == "pce":
        pytest.importorskip("openturns")
    path = tmp_path / "s.toml"
    path.write_text(NOISY.format(kind="sobol") + ("[sobol]\nn = 8\nbootstrap = 20\n" if method == "saltelli" else
                                                  "[sobol]\nmethod = 'pce'\npoints = 12\nbootstrap = 5\n"))
    out = tmp_path / "o"
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    ds = open_study(out)
    check_cf(ds)
    assert ds["value_S1"].dims == ("parameter", "level") and list(ds.parameter.values) == ["a", "b"]
    assert check_runs(ds, out, [1.0, 2.5], 3) == ds.sizes["point"] * 2 * 3
    check(ds, out / "sobol.csv", by_output(ds, ("output", "level", "parameter")))
    check(ds, out / "variance.csv", by_output(ds, ("output", "level")))
    assert ds.attrs["sobol_method"] == method
    if method == "pce":
        check(ds, out / "surrogate.csv", by_output(ds, ("output", "level")))


def test_response_study(tmp_path):
    path = tmp_path / "r.toml"
    path.write_text(RESPONSE)
    out = tmp_path / "o"
    assert main(["response", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    ds = open_study(out)
    check_cf(ds)
    assert ds["sweep_mean"].dims == ("level", "eta") and ds["mean"].dims == ("level", "repetition")
    assert ds["g"].ndim == 0 and ds["g"].attrs["units"] == "m" and ds["k_H"].attrs["units"] == "N m-1.5"
    assert check_runs(ds, out, [1.26, 6.7], 2, point_dim=False) == 2 * 2

    def prefixed(prefix, keys):
        def locate(row, column):
            sel = {k: float(row[k]) for k in keys}
            return ds[column].sel(**{k: v for k, v in sel.items() if k == column}) if column in keys \
                else ds[prefix + column].sel(**sel)
        return locate

    assert check(ds, out / "sweeps.csv", prefixed("sweep_", ("level", "eta"))) == 2 * 3
    check(ds, out / "overview.csv", prefixed("overview_", ("level",)))


def test_open_study_of_a_folder_without_results(tmp_path):
    with pytest.raises(StudyError, match="holds no results.nc; give the output folder of ies interval, sobol, response "
                                         "or design"):
        open_study(tmp_path)
    with pytest.raises(StudyError, match=f"^{tmp_path / 'nowhere'} does not exist; give the output folder"):
        open_study(tmp_path / "nowhere")


@pytest.mark.parametrize("damage", ["garbage", "truncated"])
def test_open_study_of_a_damaged_results_file_is_one_line(tmp_path, damage):
    """A results.nc that h5py cannot open (not HDF5 at all, or cut short as by a full disk) is one line that says how to
    get it back, not h5py's raw OSError."""
    import xarray as xr

    path = tmp_path / "results.nc"
    xr.Dataset({"mean": ("level", np.arange(200.0))}).to_netcdf(path, engine="h5netcdf")
    whole = path.read_bytes()
    path.write_bytes(b"not a NetCDF file" * 10 if damage == "garbage" else whole[: len(whole) // 2])
    with pytest.raises(StudyError) as caught:
        open_study(tmp_path)
    line = str(caught.value)
    assert "\n" not in line and line.startswith(f"{path} cannot be read (")
    assert "damaged or cut short" in line and "--resume" in line and "nothing is recomputed" in line
    path.write_bytes(whole)  # the file itself may be named too
    assert open_study(path)["mean"].values.tolist() == list(np.arange(200.0))
