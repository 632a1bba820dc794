"""The files every study folder holds, whatever its method: runs.csv (one row per run), study.json (the resolved
study and its summary), tasks/KEY.json (one finished run) and results.nc, with their columns (they generate
uq/OUTPUTS.md); a method's own tables are declared beside it (`uq.problem.method.Table`)."""
from __future__ import annotations

from typing import Any, Mapping, Sequence

from sim.common.outputs import Column, OutputFile

PARAMETERS_COLUMN = Column("<parameters>", "SI", "the run's parameters: D (damping ratio of mode 1, -), g_m (clearance, m), "
                     "k_H_N_per_m1p5 (Hertzian spring constant, N/m^1.5); other models' parameters by their name; "
                     "r_cont, friction, k_t_N_per_m when the study lists them")


RUNS_CSV = OutputFile("runs.csv", "every study folder", "One row per stepped-sine run (task).", (
    PARAMETERS_COLUMN,
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("rep", "-", "repetition index (its random stream: seed and rep)"),
    Column("<outputs>", "a/a_noabs*", "the run's own resonant levels `mean`, `max` and `apr` (1 when its resonant mean "
           "is almost periodic); other models: `value`"),
    Column("error", "", "empty, or why the run failed (it is left out of every statistic)"),
))


STUDY_JSON = OutputFile("study.json", "every study folder", "", (
    Column("study", "", "the resolved study: name, kind, model, modal_model, seed, repetitions, output (the folder used), "
           "source (the study file read), levels, protocol and protocol_resolved (as sweep.json's protocol), parameters "
           "(per parameter nominal, min, max, unit, label; _extras: k_H_best_estimate, k_H_calibrated in N/m^1.5), "
           "interval, sobol, response, contact_law, series"),
    Column("series_folders", "", "a series study: its values' folders"),
    Column("paper_figure", "", "a study `ies reproduce` ran: the paper's figure it reproduces (its figures carry the "
           "paper's names; a study of one's own names them by what they show)"),
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


RESULTS_NC = OutputFile("results.nc", "every study folder, ies design", "Every number of the CSV tables as one xarray "
                        "Dataset (NetCDF 4, h5netcdf) on named dimensions, with CF `units` and `long_name` on every "
                        "variable and the resolved study and code version as attributes; open it with "
                        "`uq.outputs.results.open_study(DIR)` (`uq.outputs.netcdf`).", (
    Column("point", "-", "dimension: the parameter points (the parameters as coordinates along it)"),
    Column("level", "a_base/a_base*", "dimension: the excitation levels"),
    Column("repetition", "-", "dimension: the repetitions"),
    Column("design, parameter, eta", "-", "dimensions of the bands, the indices and the frequency responses"),
))


def parameter_columns(space: Any) -> list[str]:
    """The CSV column of each parameter: its name with its unit, e.g. g_m, k_H_N_per_m1p5 (`Parameter.column`)."""
    return [p.column for p in space.parameters]


def runs_rows(records: Mapping[Any, dict], points: Sequence[Mapping[str, float]], levels: Sequence[float],
              repetitions: int, outputs: Sequence[str], names: Sequence[str]) -> list[list[Any]]:
    """The rows of runs.csv: every point, level and repetition with its outputs and error (records by task)."""
    import numpy as np

    from uq.problem.tasks import Task

    rows = []
    for p in points:
        for level in levels:
            for r in range(repetitions):
                rec = records[Task.make(p, level, r)]
                rows.append([*(p[n] for n in names), level, r, *(float(rec["outputs"].get(o, np.nan)) for o in outputs),
                             rec["error"]])
    return rows
