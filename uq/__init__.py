"""The uncertainty stage: study files, UQ methods (interval bands, Sobol' indices from Saltelli's sampling or a
surrogate, response studies), cached runs on local processes, a Dask scheduler or a batch cluster, result tables,
NetCDF and figures (seed paper Sects. 5.2-5.4, Figs. 5-8), and the design of an IES for a user's structure.

Pipeline: k_H (bem_contact) and modal model (sim) -> **uq** -> bands, indices, figures, designs. uq imports sim; of
the other stages only the `ies` front door (`uq.cli`) imports them. Its parts, each a sub-package:
  problem:  what a study asks: study files (`uq.problem.study`), parameter spaces, response models, the method
            contract (`uq.problem.method`), tasks
  methods:  the UQ methods, one file each, and their registry (`uq.methods.METHODS`)
  engine:   running: the task store and runner (joblib, Dask), batch clusters, the execution of a study
  outputs:  tables, results.nc, reading results back, figures, the paper's figure table, compare, reproduce report
  design:   `ies design` (problem, search, results, figures)
  commands: the stage's words of the `ies` command line (`uq.commands.commands()`): interval, sobol, response,
            reproduce, plot, compare, design

Public names, each imported from its module on first use, so that `import uq.errors` stays light:
  load_study (a study file against the registered methods), Study, Parameter, ParameterSpace, table2_space,
  run_study -> StudyResult, open_study (a finished folder's results.nc as an xarray Dataset).
"""
from __future__ import annotations

import importlib
from typing import Any

from uq.errors import StudyError

_MODULE_OF = {
    "load_study": "methods", "Study": "problem.study",
    "Parameter": "problem.space", "ParameterSpace": "problem.space", "table2_space": "problem.space",
    "run_study": "engine.execution", "StudyResult": "engine.execution", "open_study": "outputs.results",
}
__all__ = ["StudyError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
