"""Response studies (``[study] kind = "response"``, Figs. 5 and 6, Sects. 5.2-5.3): the frequency response of the
nominal point at every excitation level (mean and max amplitude per eta with the spread of the runs) and its resonant
levels, every stepped-sine run a task of the store (resumable, parallel, on a cluster); with ``[response] series``
the whole study once per value of one parameter (Fig. 11, Fig. C.1), each in a sub-folder NAME=VALUE.

Outputs beside runs.csv: sweeps.csv (every level's frequency response, the columns of `ies sweep`'s sweep.csv) and
overview.csv (the resonant levels per level, `ies overview`'s), built from the runs' traces exactly as `ies sweep`
and `ies overview` build theirs; study.json adds the overview and the paper's landmarks (`sim.hosts.variants`).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from sim.common.outputs import Column, OutputFile, header
from sim.stepped_sine.tables import OVERVIEW_CSV
from uq.errors import StudyError
from uq.problem.method import Analysis, Method, Plan, Runs, Table
from uq.problem.space import ParameterSpace
from uq.problem.study import Context, Setting, Study, check_number
from uq.problem.tasks import Task

SWEEPS_CSV = OutputFile("sweeps.csv", "ies response", "The frequency response at every level: the level, then the "
                        "columns of sweep.csv.", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("<sweep>", "", "the columns of sweep.csv"),
))


def _figures(value: Any, context: Context) -> tuple[str, ...]:
    from uq.outputs.paper_figures import response_figure_names

    known = response_figure_names()
    if not isinstance(value, list) or not value or any(f not in known for f in value):
        raise StudyError(f"[response] figures must be a list from {', '.join(known)}, got {value!r}")
    return tuple(value)


def _series(value: Any, context: Context) -> tuple[str, tuple[float, ...]]:
    """[response] series = { NAME = [values] }: one listed parameter and its distinct values."""
    if not isinstance(value, Mapping) or len(value) != 1:
        raise StudyError(f"[response] series must name one parameter and its values, e.g. series = {{ r_cont = [1.0, 0.99] }}, "
                         f"got {value!r}")
    (name, values), = value.items()
    if name not in context.space.names:
        raise StudyError(f"[response] series: '{name}' is not a parameter of the study; list it as [parameters.{name}]")
    if not isinstance(values, list) or not values or len(set(values)) != len(values):
        raise StudyError(f"[response] series: {name} needs a list of distinct values, got {values!r}")
    return name, tuple(float(check_number(f"[response] series.{name}", v, positive=False)) for v in values)


class Response(Method):
    """The nominal point's frequency responses and resonant levels (Figs. 5, 6; module docstring)."""

    name = kind = "response"
    help = ("frequency responses and resonant levels of the nominal point over the excitation levels, run as a "
            "resumable study (paper Sects. 5.2-5.3, Figs. 5-6)")
    settings = (Setting("figures", None, _figures, "the paper's figures to draw: fig5, fig6, figD2, figD3 (and fig11, "
                        "figC1 for a series); default all but the series'"),
                Setting("series", None, _series, "the whole study once per value of one listed parameter, e.g. "
                        "{ r_cont = [1.0, 0.99, 0.9] } (Fig. 11)"))
    tables = (Table(SWEEPS_CSV, dims={"level": "level", "eta": "eta"}, prefix="sweep_"),
              Table(OVERVIEW_CSV, dims={"level": "level"}, prefix="overview_"))
    models = ("ies",)

    def finish(self, values: dict[str, Any], context: Context) -> dict[str, Any]:
        if values["figures"] is None:
            from uq.outputs.paper_figures import response_figure_names

            values["figures"] = response_figure_names()
        return values

    def describe(self, settings: Mapping[str, Any]) -> dict[str, Any]:
        series = settings["series"]
        return {"response": {"method": self.name, "figures": list(settings["figures"])},
                **({"series": {series[0]: list(series[1])}} if series else {})}

    def identity(self, settings: Mapping[str, Any]) -> dict[str, Any]:
        return self.describe(settings)

    def substudies(self, study: Study) -> list[tuple[str, Study]]:
        """[(NAME=VALUE, the study with that parameter fixed at VALUE)] of [response] series; [] without."""
        if not study.settings["series"]:
            return []
        name, values = study.settings["series"]
        out = []
        for value in values:
            params = tuple(p.fixed_at(value) if p.name == name else p for p in study.space.parameters)
            space = ParameterSpace(params, study.space.extras)
            settings = {**study.settings, "series": None}
            out.append((f"{name}={value:g}", dataclasses.replace(study, space=space, settings=settings,
                                                                 name=f"{study.name} {name}={value:g}")))
        return out

    def plan(self, study: Study) -> Plan:
        return Plan([study.space.nominal()])

    def base_dataset(self, ds: Any) -> Any:
        """results.nc's runs on level x repetition: the one point's parameters as scalar coordinates."""
        return ds.isel(point=0).drop_vars("point")

    def analyse(self, study: Study, model: Any, plan: Plan, runs: Runs) -> Analysis:
        """The frequency response at every level (sweeps.csv), the resonant levels (overview.csv), the overview and
        landmarks in study.json."""
        from sim.stepped_sine.landmarks import landmarks
        from sim.stepped_sine.tables import OVERVIEW_COLUMNS, SWEEP_COLUMNS, overview_data, overview_rows, sweep_rows

        point = plan.points[0]
        out = Analysis()
        sweeps, levels = [], []
        for level in study.levels:
            records = [runs.records[Task.make(point, level, r)] for r in range(study.repetitions)]
            sweep = model.sweep_result([rec for rec in records if not rec["error"]])
            if sweep is None:
                out.warnings.append(f"every run failed at level {level:g}; the level is left out")
                continue
            sweeps.append(sweep)
            levels.append(level)
        if not sweeps:
            raise StudyError("every run of the response study failed; see runs.csv")
        overview = overview_data(levels, sweeps)
        out.rows = {"sweeps.csv": [[s.level, *row] for s in sweeps for row in sweep_rows(s)],
                    "overview.csv": overview_rows(overview)}
        out.columns = {"sweeps.csv": header(SWEEPS_CSV, sweep=SWEEP_COLUMNS), "overview.csv": OVERVIEW_COLUMNS}
        out.metadata = {"overview": overview, "landmarks": landmarks(sweeps).summary()}
        return out

    def figures(self, folder: Path, options: Any = None) -> list[Path]:
        """The figures its [response] figures ask for (`uq.outputs.paper_figures.response_figures`)."""
        from uq.outputs.paper_figures import response_figures

        return response_figures(folder, options)

    def report(self, folder: Path, summary: Mapping[str, Any], name: str) -> None:
        """The table of the figure the study is named after when it has one (Figs. D.2, D.3: the impacts and
        scattering measures), else the resonant levels and the optimum (Fig. 6)."""
        from uq.outputs.paper_figures import PAPER_FIGURES, response_table

        row = PAPER_FIGURES.get(name)
        (response_table if row is None else row.table)(folder, summary, name)


def series_traces(study: Study, folder: Path, levels: Sequence[float], periods: int = 20) -> list[Path]:
    """Fig. C.1b: with the series' last value (e.g. friction on), the time history (`sim.analysis.trace`, 51.2 kHz) of the
    point of the resonant mean at each of `levels`, reached as the study's runs reach it (its grid up to that eta,
    the first run's random offset), into folder/trace-LEVEL: trace.csv, trace.json, Figs. 4/9a (trace.png) and
    the walls and the sphere (motion.png)."""
    from sim.common.files import read_rows
    from sim.plots.figures import plot_motion, plot_trace
    from uq.outputs.figures import series_label
    from sim.analysis.trace import record_trace, write_trace

    sub, one = Response().substudies(study)[-1]
    resonant = {float(r["level"]): float(r["eta_resonant_mean"]) for r in read_rows(folder / sub / "overview.csv")}
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
        visit = dataclasses.replace(protocol, eta_stop=float(grid[last]), n_eta=last + 1)
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
