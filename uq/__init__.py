"""The uncertainty stage: parameter spaces and study files, interval propagation and Sobol' indices of the
simulated response, response studies of the nominal point, cached runs on local processes or a Dask cluster,
result tables and figures (seed paper Sects. 5.2-5.4, Figs. 5-8).

Pipeline: k_H (bem_contact) and modal model (sim) -> **uq** -> bands, indices, figures. uq imports sim; of
the other stages only the `ies` front door (`uq.cli`) imports them. Its commands `ies interval`, `ies sobol`,
`ies response`, `ies reproduce`, `ies plot` live in `uq.commands`; analytic test functions for studies in
`uq.problem.test_functions`.

Public names, each imported from its module on first use, so that `import uq.errors` stays light
(importing all of them takes 0.2-0.3 s more), as in the other stages:
  study:   Study, load_study (study files; all keys in its docstring)
  space:   Parameter, ParameterSpace, table2_space (Table 2)
  execute: run_interval_study, run_sobol_study, run_response_study -> StudyResult
  figures: sobol_figure; paper_figures: PAPER_FIGURES, interval_figures, response_figures (Figs. 5-8)
"""
from __future__ import annotations

import importlib
from typing import Any

from uq.errors import StudyError

_MODULE_OF = {
    "Study": "problem.study", "load_study": "problem.study",
    "Parameter": "problem.space", "ParameterSpace": "problem.space", "table2_space": "problem.space",
    "run_interval_study": "engine.execute", "run_sobol_study": "engine.execute", "run_response_study": "engine.execute",
    "StudyResult": "engine.execute", "open_study": "outputs.results",
    "interval_figures": "outputs.paper_figures", "sobol_figure": "outputs.figures", "response_figures": "outputs.paper_figures",
}
__all__ = ["StudyError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
