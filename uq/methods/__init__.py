"""The UQ methods, one file each, and their registry `METHODS` (a method is its file plus one line here).

Every method follows the contract of `uq.problem.method.Method`: its kind (the study kind, its study-file table and
its command), its settings, its tables, its sampling and its analysis. The study reader (`load_study`), the `ies`
study commands (`uq.commands.study`), the execution (`uq.engine.execution.run_study`), the written tables, results.nc
and the output reference (uq/OUTPUTS.md) all read this registry.

* interval (`uq.methods.interval`): vertex bands with the monotonicity check, Figs. 7-8 (Sect. 5.4);
* saltelli (`uq.methods.sobol`): Sobol' indices from Saltelli's sampling and SALib's estimators, the reference;
* pce (`uq.methods.surrogate`): Sobol' indices from a polynomial-chaos surrogate (OpenTURNS);
* response (`uq.methods.response`): the nominal point's frequency responses and resonant levels, Figs. 5-6.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from uq.methods.interval import IntervalMethod
from uq.methods.response import Response
from uq.methods.sobol import Saltelli
from uq.methods.surrogate import PCE
from uq.problem.method import Method
from uq.problem.study import Study, kinds_of, parse_study, read_study

#: name -> method, in the order `ies --help` lists their kinds; a kind's first method is its default
METHODS: dict[str, Method] = {m.name: m for m in (IntervalMethod(), Saltelli(), PCE(), Response())}

#: study kinds that another command runs (their file has [study] kind too): kind -> that command
ELSEWHERE = {"design": "ies design"}


def register(method: Method) -> Method:
    """Add a method to the registry (a plug-in, or a test's toy method); returns it."""
    METHODS[method.name] = method
    return method


def kinds() -> dict[str, list[Method]]:
    """kind -> its methods, in registry order (the first is the kind's default)."""
    return kinds_of(METHODS)


def load_study(path: str | Path, *, allow_implausible: bool = False) -> Study:
    """Read and validate a study file (`uq.problem.study`) against the registered methods; one-line StudyError (a value
    of implausible magnitude too, unless `allow_implausible`)."""
    return read_study(path, METHODS, ELSEWHERE, allow_implausible=allow_implausible)


def study_from(data: Mapping[str, Any], *, base_dir: Path = Path("."), source: str = "") -> Study:
    """A study from the parsed TOML of a study file (as `load_study`)."""
    return parse_study(data, METHODS, base_dir=base_dir, source=source, elsewhere=ELSEWHERE)
