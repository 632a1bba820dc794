"""What `ies orbits` writes: orbits.csv (one row per orbit of every branch), results.nc (the same columns with the
multipliers and states, CF attributes) and orbits.json (the settings, the branches and the notes). The columns
with their units and meanings are the `OutputFile` table below (`sim.common.outputs`), from which uq/OUTPUTS.md is
generated. Amplitudes are those the stepped sine measures (Sect. 5): the fundamental Fourier coefficient of the tip
relative to the base per excitation period, over a_noabs* at the same level, so orbits and sweeps overlay.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from sim.common.files import atomic_path, dumps, write_csv, write_json
from sim.common.outputs import Column, OutputFile
from sim.orbits.bifurcations import outside_count
from sim.orbits.continuation import Branch, BranchPoint
from sim.orbits.response import OrbitResponse

ORBITS_CSV = OutputFile("orbits.csv", "ies orbits --out DIR", "One row per periodic orbit of every branch, in the order "
                        "of each branch's arclength (`sim.orbits`); the branches of every level one after the other.", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("branch", "-", "the branch's number within its level (0: the start's; the linear orbits last)"),
    Column("origin", "", "how the branch was found: slow-flow / simulation / linear start, symmetry breaking or "
           "period doubling of another branch at a parameter value, linear solution"),
    Column("point", "-", "the orbit's index along its branch"),
    Column("eta", "-", "eta = Omega/omega* of the orbit"),
    Column("amplitude", "a/a_noabs*", "mean over the orbit's k periods of |c_1| of the tip relative to the base per "
           "period (what the stepped sine's mean measures on this orbit)"),
    Column("amplitude_max", "a/a_noabs*", "the largest of the k per-period amplitudes"),
    Column("amplitude_m", "m", "the mean per-period |c_1| of the tip relative to the base"),
    Column("period_multiple", "-", "k: the orbit repeats after k excitation periods"),
    Column("symmetric", "-", "1 for an orbit with y(t + kT/2) = -y(t) (mirror symmetry of the walls), else 0"),
    Column("impacts_per_period", "-", "contact onsets at either wall per excitation period"),
    Column("significant_impacts_per_period", "-", "impacts with at least 0.1 of the orbit's largest impulse, per period "
           "(NaN with ode3)"),
    Column("pattern", "", "the walls hit over the k periods in order of onset: L left, R right; lower case for an "
           "impulse below 0.1 of the largest (a graze, a same-wall rebound)"),
    Column("max_multiplier", "-", "largest Floquet multiplier modulus |mu| of the k-period map (1 for a linear orbit: "
           "its free sphere)"),
    Column("unstable_multipliers", "-", "multipliers outside the unit circle (of the half map for a symmetric orbit)"),
    Column("stable", "-", "1 when every multiplier lies inside the unit circle, else 0 (a linear orbit is 0: a sphere "
           "given any speed drifts into a wall)"),
    Column("bifurcation", "", "fold, symmetry-breaking, period-doubling, neimark-sacker, branch-point or grazing where "
           "this orbit is one (located), else empty"),
    Column("note", "", "loses stability / gains stability at a located multiplier crossing; the impacts before and "
           "after a grazing"),
    Column("residual", "-", "the shooting residual's largest component in units of the clearance g"),
    Column("location_error", "-", "how well a labelled point is located: | |mu| - 1 | of the multiplier that crosses "
           "(below 1e-4), or the smallest free-flight gap over g at a grazing (below 1e-9); empty without a label"),
))
ORBITS_COLUMNS = ORBITS_CSV.names
START_ATTEMPTS_JSON = OutputFile("start-attempts.json", "ies orbits --start simulation, when no start converges",
                                 "What the failed start tried, for a start of your own (`sim.orbits.response`); the "
                                 "command exits with code 3.", (
    Column("level, eta", "a_base/a_base*, -", "where the start was tried"),
    Column("attempts", "", "one per period multiple k: k, residual (units of g: the last Newton iterate's), why "
           "(Newton's method's last words), start and last (the simulated state it started from and its last iterate, "
           "SI: s_1..s_n (m sqrt(kg)), s_1'..s_n' (m sqrt(kg)/s), u_a (m), u_a' (m/s); null where it failed at once)"),
    Column("suggestion", "", "what to try instead"),
))
#: CF units and long names of the columns in results.nc (units as UDUNITS strings, "1" dimensionless).
NC_UNITS = {"a/a_noabs*": "1", "a_base/a_base*": "1", "-": "1", "m": "m", "": ""}


def orbit_rows(responses: Sequence[OrbitResponse]) -> list[tuple]:
    """The rows of orbits.csv (ORBITS_COLUMNS) of the responses, level by level."""
    rows = []
    for response in responses:
        for b, branch in enumerate(response.all_branches):
            for i, point in enumerate(branch.points):
                rows.append(_row(point, b, branch, i))
    return rows


def _row(point: BranchPoint, b: int, branch: Branch, i: int) -> tuple:
    orbit = point.orbit
    s = orbit.setting
    return (s.level, b, branch.origin, i, s.eta, orbit.amplitude, orbit.amplitude_max, orbit.amplitude_m, orbit.k,
            int(orbit.symmetric), orbit.impacts_per_period, orbit.significant, orbit.pattern, orbit.max_multiplier,
            0 if orbit.linear else outside_count(orbit), int(orbit.stable), point.label, point.note, orbit.residual,
            point.location_error if point.label else math.nan)


def stable_ranges(branch: Branch) -> list[list[float]]:
    """The parameter ranges [lo, hi] of a branch's stretches of stable orbits, in branch order (a stable stretch
    of one orbit is [x, x])."""
    ranges, current = [], None
    for point in branch.points:
        value = branch.parameter.get(point.orbit.setting)
        if point.orbit.stable:
            current = [value, value] if current is None else [min(current[0], value), max(current[1], value)]
        elif current is not None:
            ranges.append(current)
            current = None
    if current is not None:
        ranges.append(current)
    return ranges


def response_summary(response: OrbitResponse) -> dict:
    """The JSON object of one level or eta: its range, branches (origin, points, stop, range, stable points, labels)
    and notes."""
    branches = []
    for branch in response.all_branches:
        values = branch.values()
        labels: dict[str, int] = {}
        for p in branch.points:
            if p.label:
                labels[p.label] = labels.get(p.label, 0) + 1
        stable = [p for p in branch.points if p.orbit.stable]
        branches.append({"origin": branch.origin, "period_multiple": branch.k, "symmetric": branch.symmetric,
                         "points": len(branch.points), "stop": branch.stop,
                         "range": [float(values.min()), float(values.max())],
                         "amplitude_range": [min(p.orbit.amplitude for p in branch.points),
                                             max(p.orbit.amplitude for p in branch.points)],
                         "max_multiplier_range": [min(p.orbit.max_multiplier for p in branch.points),
                                                  max(p.orbit.max_multiplier for p in branch.points)],
                         "patterns": sorted({p.orbit.pattern for p in branch.points}),
                         "stable_points": len(stable),
                         "stable_range": ([min(branch.parameter.get(p.orbit.setting) for p in stable),
                                           max(branch.parameter.get(p.orbit.setting) for p in stable)] if stable else None),
                         "stable_ranges": stable_ranges(branch),
                         "labels": labels, "unlocated": [str(u) for u in branch.unlocated]})
    return {"level": response.base.level if response.parameter == "eta" else None,
            "eta": response.base.eta if response.parameter == "level" else None,
            "parameter": response.parameter, "range": list(response.bounds), "impacts": response.impacts,
            "branches": branches, "searches": [search.note for search in response.searches],
            "notes": response.notes}


def write_orbit_files(folder: Path, responses: Sequence[OrbitResponse], settings: dict) -> list[Path]:
    """orbits.csv, results.nc and orbits.json in `folder` (each written atomically); the paths written."""
    rows = orbit_rows(responses)
    data = {**settings, "responses": [response_summary(r) for r in responses]}
    return [write_csv(folder / "orbits.csv", ORBITS_COLUMNS, rows),
            write_results_nc(folder / "results.nc", responses, rows, settings),
            write_json(folder / "orbits.json", data)]


def write_results_nc(path: Path, responses: Sequence[OrbitResponse], rows: list[tuple], settings: dict) -> Path:
    """results.nc: every column of orbits.csv on the dimension `orbit`, the Floquet multipliers (`multiplier_re`,
    `multiplier_im` on (orbit, multiplier), by decreasing modulus) and the states at phase 0 (`state` on (orbit,
    component): s_1..s_n (m sqrt(kg)), s_1'..s_n' (m sqrt(kg)/s), u_a (m), u_a' (m/s)); CF attributes (units,
    long_name) and the settings as a JSON global attribute (xarray, h5netcdf engine, written atomically)."""
    import xarray as xr

    points = [p for r in responses for b in r.all_branches for p in b.points]
    n_state = points[0].orbit.state.size if points else 0
    columns = {c.name: c for c in ORBITS_CSV.columns}
    variables: dict[str, Any] = {}
    for j, name in enumerate(ORBITS_COLUMNS):
        values = [row[j] for row in rows]
        column = columns[name]
        if column.unit == "":
            array = np.array([str(v) for v in values], dtype=object)
        else:
            array = np.array(values, dtype=np.float64 if any(isinstance(v, float) for v in values) else np.int64)
        variables[name] = ("orbit", array, {"units": NC_UNITS.get(column.unit, column.unit), "long_name": column.meaning})
    mult = np.full((len(points), n_state), np.nan + 0j)
    states = np.full((len(points), n_state), np.nan)
    for i, p in enumerate(points):
        mult[i, :p.orbit.multipliers.size] = p.orbit.multipliers
        states[i] = p.orbit.state
    variables["multiplier_re"] = (("orbit", "multiplier"), mult.real,
                                  {"units": "1", "long_name": "Floquet multiplier of the k-period map, real part"})
    variables["multiplier_im"] = (("orbit", "multiplier"), mult.imag,
                                  {"units": "1", "long_name": "Floquet multiplier of the k-period map, imaginary part"})
    variables["state"] = (("orbit", "component"), states,
                          {"units": "SI", "long_name": "state at excitation phase 0: s (m sqrt(kg)), s' (m sqrt(kg)/s), "
                                                       "u_a (m), u_a' (m/s)"})
    ds = xr.Dataset({name: xr.Variable(*spec) for name, spec in variables.items()},
                    coords={"orbit": ("orbit", np.arange(len(points)), {"units": "1", "long_name": "row of orbits.csv"})})
    ds.attrs.update({"Conventions": "CF-1.10", "title": "periodic orbits of the IES model (ies orbits)",
                     "settings": json.dumps(json.loads(dumps(settings)))})
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return Path(path)


def orbit_table(response: OrbitResponse) -> str:
    """The text `ies orbits` prints for one level or eta: one line per branch (its stretches of stable orbits, not
    their hull), one per located point that changes the stability (or is a fold or grazing), the counts of the
    other labels, the changes that could not be located, and the notes (searches among them)."""
    head = (f"level {response.base.level:g}" if response.parameter == "eta" else f"eta {response.base.eta:g}")
    lines = [f"# {head}: {response.parameter} {response.bounds[0]:g}:{response.bounds[1]:g}"]
    for b, branch in enumerate(response.all_branches):
        values = branch.values()
        amp = [p.orbit.amplitude for p in branch.points]
        ranges = stable_ranges(branch)
        patterns = ",".join(sorted({p.orbit.pattern or "-" for p in branch.points}))
        stab = ("stable for " + response.parameter + " " + ", ".join(f"{lo:.4f}..{hi:.4f}" for lo, hi in ranges)
                if ranges else "unstable")
        lines.append(f"branch {b} ({branch.origin}; {branch.k} T{', symmetric' if branch.symmetric else ''}): "
                     f"{len(branch.points)} orbits, {response.parameter} {values.min():.4f}..{values.max():.4f}, "
                     f"a/a_noabs* {min(amp):.4f}..{max(amp):.4f}, impacts {patterns}, {stab}")
        counts: dict[str, int] = {}
        for p in branch.points:
            if p.label and (p.label in ("fold", "grazing") or p.note):
                lines.append(f"  {p.label} at {response.parameter} {branch.parameter.get(p.orbit.setting):.5f}: "
                             f"a/a_noabs* {p.orbit.amplitude:.4f}{', ' + p.note if p.note else ''}")
            elif p.label:
                counts[p.label] = counts.get(p.label, 0) + 1
        if counts:
            lines.append("  also located (unstable on both sides): "
                         + ", ".join(f"{n} {label}" for label, n in sorted(counts.items())))
        lines.extend(f"  not located: {u}" for u in branch.unlocated)
    lines.extend(f"note: {note}" for note in response.notes)
    return "\n".join(lines)


def write_start_attempts(folder: Path, failure: Any) -> Path:
    """start-attempts.json (START_ATTEMPTS_JSON) of a failed "simulation" start (`sim.orbits.response.StartFailed`),
    written atomically."""
    setting = failure.setting
    data = {"level": setting.level, "eta": setting.eta,
            "attempts": [{"k": a.k, "residual": a.residual, "why": a.why, "start": a.start, "last": a.last}
                         for a in failure.attempts],
            "suggestion": "--start slow-flow (the slow flow's two-impact orbit), another --at, or a larger --max-period; "
                          "ies trace --lyapunov at this point tells whether the response is periodic at all"}
    return write_json(folder / "start-attempts.json", data)
