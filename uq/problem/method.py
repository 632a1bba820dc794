"""The contract of a UQ method: what one declares so that the study reader, the `ies` command, the execution, the
tables and results.nc are derived from it.

A method (`Method`) is one file in `uq/methods/` plus one line in its registry (`uq.methods.METHODS`). It declares

* its **kind**: the study kind it serves (``[study] kind``), which is also the name of its table in a study file
  (``[interval]``, ``[sobol]``, ...) and of the command that runs it (``ies interval``, ``ies sobol``, ...); several
  methods may serve one kind (Saltelli's sampling and the polynomial-chaos surrogate both compute Sobol' indices),
  chosen by the table's ``method`` key or the command's ``--method``;
* its **settings** (`uq.problem.study.Setting`): the keys of its table with their defaults and checks, and the command-line option
  of those a user may also give there;
* its **tables** (`Table`): the files it writes beside runs.csv, with their columns (`sim.common.outputs.OutputFile`,
  which also generates uq/OUTPUTS.md) and their dimensions in results.nc;
* its **sampling** (`plan`: the parameter points to run) and its **analysis** (`analyse`: the rows of its tables,
  the summary and the warnings, from the runs' repetition statistics);
* how a finished folder is drawn (`figures`) and printed (`report`).

The execution (`uq.engine.execution.run_study`) is the same for every method: plan, run every (point, level,
repetition) through the task store (cached, resumable, joblib or Dask), aggregate the repetitions, analyse, write
runs.csv, the method's tables, results.nc and study.json.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Mapping, Sequence

from sim.common.outputs import OutputFile
from uq.problem.study import Context, Setting, Study

if TYPE_CHECKING:
    import numpy as np


@dataclass(frozen=True)
class Table:
    """One file a method writes: its columns (file.names, or `columns` of the analysis where the header depends on
    the study, e.g. one column per parameter) and its place in results.nc: `dims` maps a column to a dimension
    (None: not in results.nc), `split` names the column whose values prefix the variables (``mean_lower``),
    `prefix` is put before every variable name."""

    file: OutputFile
    dims: Mapping[str, str] | None = None
    split: str | None = None
    prefix: str = ""


@dataclass
class Plan:
    """The parameter points a study runs (SI values by parameter name) and whatever the analysis needs of the
    sampling (the designs of an interval study, the sample matrix of a Sobol' study)."""

    points: list[dict[str, float]]
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class Runs:
    """A study's finished runs: every record by task (`uq.problem.tasks.Task`), and per model output the repetition
    statistics of each point and level as arrays (n_points, n_levels): value, standard error, samples; the regime
    of each point and level; how many runs failed."""

    records: Mapping[Any, dict]
    stats: Mapping[str, tuple["np.ndarray", "np.ndarray", "np.ndarray"]]
    regimes: "np.ndarray"
    failed: int


@dataclass
class Analysis:
    """What a method made of the runs: rows of its tables (by file name; `columns` where a table's header depends on
    the study), further results.nc variables that are no table (`datasets`, xarray Datasets), the summary of
    study.json, further study.json keys (`metadata`) and the warnings."""

    rows: dict[str, list[list[Any]]] = field(default_factory=dict)
    columns: dict[str, Sequence[str]] = field(default_factory=dict)
    datasets: list[Any] = field(default_factory=list)
    summary: dict[str, Any] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


class Method(ABC):
    """A UQ method (see the module docstring); subclasses set the class attributes and implement `plan` and
    `analyse`."""

    #: the registry's name of the method ("interval", "saltelli", "pce", "response", ...)
    name: ClassVar[str]
    #: the study kind it serves: [study] kind, the table [KIND] and the command `ies KIND`
    kind: ClassVar[str]
    #: one line: what the method computes
    help: ClassVar[str]
    #: one line: what a study of its kind computes (the help of `ies KIND`, from the kind's first method)
    kind_help: ClassVar[str] = ""
    settings: ClassVar[tuple[Setting, ...]] = ()
    tables: ClassVar[tuple[Table, ...]] = ()
    #: the models it can run: None for any (`uq.problem.models`), else e.g. ("ies",) for the simulator only
    models: ClassVar[tuple[str, ...] | None] = None
    #: keys of its table that a file of an earlier release may hold and that it ignores, each with the setting that
    #: does that job here (key -> setting): the file still runs, with one line saying so (`uq.problem.study`)
    superseded: ClassVar[Mapping[str, str]] = {}

    def finish(self, values: dict[str, Any], context: Context) -> dict[str, Any]:
        """The settings after the cross-key checks and computed defaults (one-line StudyError); the values as read."""
        return values

    def describe(self, settings: Mapping[str, Any]) -> dict[str, Any]:
        """The study.json entries of the settings: ``{kind: {"method": name, key: value, ...}}``."""
        return {self.kind: {"method": self.name, **settings}}

    def identity(self, settings: Mapping[str, Any]) -> dict[str, Any]:
        """What of the settings makes the study's identity (`Setting.identity`)."""
        return {self.kind: {"method": self.name, **{s.key: settings[s.key] for s in self.settings if s.identity}}}

    def substudies(self, study: Study) -> list[tuple[str, Study]]:
        """[(folder name, study)] when the study runs as several studies of this method in sub-folders (a response
        series, Fig. 11); [] to run it as one."""
        return []

    @abstractmethod
    def plan(self, study: Study) -> Plan:
        """The parameter points to run (sampling)."""

    @abstractmethod
    def analyse(self, study: Study, model: Any, plan: Plan, runs: Runs) -> Analysis:
        """The method's tables, summary and warnings from the runs (analysis)."""

    def base_dataset(self, ds: Any) -> Any:
        """results.nc's runs and repetition statistics (`uq.outputs.netcdf.base_dataset`) as this method keeps them."""
        return ds

    def figures(self, folder: Path, options: Any = None) -> list[Path]:
        """Draw a finished folder's figures (from its data files); the files written."""
        return []

    def report(self, folder: Path, summary: Mapping[str, Any], name: str) -> None:
        """Print the finished study's table on stdout."""
