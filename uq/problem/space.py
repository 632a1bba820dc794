"""Uncertain parameters and parameter spaces (seed paper, Sect. 4.1-4.2, Table 2).

The three uncertain parameters of the IES are the modal damping ratio of the resonant mode D (= D_1),
the clearance g (m) and the Hertzian spring constant k_H (N/m^1.5). Their nominal values and bounds
default to Table 2; the best estimate k_H = 1.25 k_H* (Sect. 4.1) is carried along, and a k_H
calibrated from a crater scan (`ies calibrate --json`) can replace the upper bound.

A `ParameterSpace` is the box of the varied parameters plus the values of the fixed ones; it gives
the SALib problem dict, the interval corners and unit-cube mappings used by `uq.methods.interval` and
`uq.methods.sobol`.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Mapping

import numpy as np

from sim.common.errors import SimulationInputError
from sim.model.parameters import (K_H_BEST_ESTIMATE_FACTOR, K_H_NOMINAL, PARAMETERS, UncertainParameter,
                                  column_name, table2_parameters)
from uq.errors import StudyError

if TYPE_CHECKING:
    from sim.model.sphere import Sphere
    from sim.model.system import ModalModel

# Table 2 of the seed paper (SI units) is the table2 rows of `sim.model.parameters.PARAMETERS`, the one vocabulary of
# the paper's quantities (names, units, nominal values, intervals, bounds, plausible ranges, CSV columns).
K_H_STAR = K_H_NOMINAL  # Eq. 8, nominal sphere on a flat wall (282e3 N/mm^1.5)
K_H_BEST_ESTIMATE = K_H_BEST_ESTIMATE_FACTOR * K_H_STAR


@dataclass(frozen=True)
class Parameter:
    """One uncertain parameter: nominal value and interval [min, max] in SI units.

    ``upper_limit`` is an exclusive physical limit (1 for a damping ratio); every bound must be > 0
    unless ``positive`` is False (abstract inputs such as those of the Ishigami test function).
    """

    name: str
    nominal: float
    min: float
    max: float
    unit: str = "-"
    label: str = ""
    upper_limit: float = np.inf
    positive: bool = True

    def __post_init__(self) -> None:
        for key in ("nominal", "min", "max"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise StudyError(f"parameter '{self.name}': {key} must be a number, got {value!r}")
            value = float(value)
            object.__setattr__(self, key, value)
            if not np.isfinite(value):
                raise StudyError(f"parameter '{self.name}': {key} = {value!r} must be a finite number ({self.unit})")
            if self.positive and value <= 0:
                raise StudyError(f"parameter '{self.name}': {key} = {value!r} must be a positive number ({self.unit})")
            if value >= self.upper_limit:
                raise StudyError(f"parameter '{self.name}': {key} = {value!r} must be below {self.upper_limit:g}")
        if self.min > self.max:
            raise StudyError(f"parameter '{self.name}': min = {self.min:g} is larger than max = {self.max:g}; swap them")
        if not self.min <= self.nominal <= self.max:
            raise StudyError(f"parameter '{self.name}': nominal = {self.nominal:g} lies outside "
                             f"[min, max] = [{self.min:g}, {self.max:g}]; widen the interval or fix the nominal value")

    @property
    def varied(self) -> bool:
        """True when the interval has a positive width."""
        return self.max > self.min

    @property
    def column(self) -> str:
        """Its name in CSV headers: the name with the unit in machine-friendly form (g_m, k_H_N_per_m1p5); the
        bare name for a dimensionless parameter (D)."""
        return column_name(self.name, self.unit)

    def at(self, t: float | np.ndarray) -> float | np.ndarray:
        """Map a unit-interval coordinate t in [0, 1] to the parameter value min + t (max - min)."""
        return self.min + np.asarray(t, dtype=float) * (self.max - self.min)

    def fixed_at(self, value: float) -> "Parameter":
        """The same parameter held at `value` (a degenerate interval)."""
        return replace(self, nominal=value, min=value, max=value)


@dataclass(frozen=True)
class ParameterSpace:
    """An ordered set of parameters; only those with min < max are varied."""

    parameters: tuple[Parameter, ...]
    extras: Mapping[str, float] = field(default_factory=dict)  # named values, e.g. k_H best estimate

    def __post_init__(self) -> None:
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise StudyError(f"parameters are listed twice: {names}")
        if not self.parameters:
            raise StudyError("the parameter space is empty; give at least one parameter")

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    @property
    def varied(self) -> list[Parameter]:
        return [p for p in self.parameters if p.varied]

    def __getitem__(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise StudyError(f"unknown parameter '{name}'; known: {', '.join(self.names)}")

    def nominal(self) -> dict[str, float]:
        """All parameters at their nominal values."""
        return {p.name: p.nominal for p in self.parameters}

    def point(self, unit: Iterable[float]) -> dict[str, float]:
        """Full parameter dict from unit-cube coordinates of the *varied* parameters (others nominal)."""
        values = self.nominal()
        coords = list(unit)
        if len(coords) != len(self.varied):
            raise StudyError(f"expected {len(self.varied)} coordinates, got {len(coords)}")
        for p, t in zip(self.varied, coords):
            values[p.name] = float(p.at(t))
        return values

    def from_values(self, x: Iterable[float]) -> dict[str, float]:
        """Full parameter dict from values (not unit coordinates) of the varied parameters."""
        values = self.nominal()
        for p, v in zip(self.varied, x, strict=True):
            values[p.name] = float(v)
        return values

    def fix(self, **values: float) -> "ParameterSpace":
        """The space with the named parameters held at the given values (e.g. k_H at its best estimate)."""
        params = []
        for p in self.parameters:
            params.append(p.fixed_at(float(values[p.name])) if p.name in values else p)
        unknown = set(values) - set(self.names)
        if unknown:
            raise StudyError(f"cannot fix unknown parameter(s) {sorted(unknown)}; known: {', '.join(self.names)}")
        return ParameterSpace(tuple(params), dict(self.extras))

    def salib_problem(self) -> dict:
        """The SALib problem dict of the varied parameters: num_vars, names, bounds (SI units)."""
        varied = self.varied
        if not varied:
            raise StudyError("no parameter is varied (every min equals its max); widen at least one interval")
        return {"num_vars": len(varied), "names": [p.name for p in varied],
                "bounds": [[p.min, p.max] for p in varied]}

    def to_dict(self) -> dict:
        """Plain description for the resolved-study metadata."""
        out = {p.name: {"nominal": p.nominal, "min": p.min, "max": p.max, "unit": p.unit, "label": p.label}
               for p in self.parameters}
        if self.extras:
            out["_extras"] = dict(self.extras)
        return out


def parameter_of(row: UncertainParameter) -> Parameter:
    """The `Parameter` of a row of `sim.model.parameters.PARAMETERS`: its nominal value, interval, unit, label and
    limits."""
    low, high = row.interval
    return Parameter(row.name, row.nominal, low, high, row.unit, row.label, upper_limit=row.upper_limit,
                     positive=row.positive)


def table2_space(k_H_max: float | None = None, *, host: "ModalModel | None" = None,
                 sphere: "Sphere | None" = None) -> ParameterSpace:
    """The default IES space of Table 2 (D, g, k_H: the table2 rows of `PARAMETERS`), optionally with a calibrated
    upper bound for k_H. With a `host` (`sim.model.system.ModalModel`), D's nominal value is its D_1* and its interval
    the host's (`ModalModel.damping_box`); with a `sphere` (`sim.model.sphere.Sphere`), k_H's nominal value is its
    k_H* (Eq. 8 with its wall), its interval Table 2's factors on it (1 .. 1.52) and the best estimate 1.25 k_H*
    (extras `k_H_star`, `k_H_best_estimate`). The seed rig and the paper's sphere give Table 2 to the last bit."""
    params = []
    for row in table2_parameters():
        p = parameter_of(row)
        if row.name == "D" and host is not None:
            low, high = host.damping_box()[0]
            p = replace(p, nominal=host.D_star, min=low, max=high)
        elif row.name == "k_H" and sphere is not None:
            low, high = row.spread.ends(sphere.k_H_star)
            p = replace(p, nominal=sphere.k_H_star, min=low, max=high)
        params.append(p)
    k_H_star = K_H_STAR if sphere is None else sphere.k_H_star
    extras = {"k_H_best_estimate": K_H_BEST_ESTIMATE_FACTOR * k_H_star}
    if k_H_star != K_H_STAR:
        extras["k_H_star"] = k_H_star
    if k_H_max is not None:
        params = [replace(p, max=float(k_H_max)) if p.name == "k_H" else p for p in params]
    return ParameterSpace(tuple(params), extras)


_RATIO = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*\*?\s*k_H\*\s*$")


def resolve_k_H(value: object, *, base_dir: Path | None = None, k_H_star: float = K_H_STAR) -> float:
    """A k_H value in N/m^1.5 from a number, a ratio string like ``"1.25 k_H*"`` (of `k_H_star`: the study's sphere's
    Eq. 8 value, Table 2's 282e3 N/mm^1.5 for the paper's), or a calibration.

    A calibration is a path to the JSON object printed by ``ies calibrate --json`` (key ``k_H``, in
    N/m^1.5), written as ``"calibrated:PATH"`` (PATH relative to `base_dir`).
    """
    if isinstance(value, bool):
        raise StudyError(f"k_H must be a number in N/m^1.5, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        match = _RATIO.match(value)
        if match:
            return float(match.group(1)) * k_H_star
        if value.startswith("calibrated:"):
            path = Path(value.split(":", 1)[1])
            if base_dir is not None and not path.is_absolute():
                path = base_dir / path
            return calibrated_k_H(path)
        try:
            return PARAMETERS["k_H"].parse(value)
        except SimulationInputError:
            pass
    raise StudyError(f"cannot read k_H = {value!r}: give N/m^1.5, a value with its unit like \"282e3 N/mm^1.5\", "
                     "a ratio like \"1.25 k_H*\" or \"calibrated:FILE.json\" (the output of `ies calibrate --json`)")


def resolve_value(name: str, value: object, *, base_dir: Path | None = None, k_H_star: float = K_H_STAR) -> object:
    """A parameter value of a study file in SI units: k_H through `resolve_k_H`, a row's value with its unit ("0.58
    mm", `sim.model.parameters.UncertainParameter.parse`); a number of a row checked against the row's physical
    bounds, as on the command line (`UncertainParameter.problem`); other values unchanged (checked by `Parameter`)."""
    row = PARAMETERS.get(name)
    if name == "k_H":
        value = resolve_k_H(value, base_dir=base_dir, k_H_star=k_H_star)
    elif row is not None and row.quantity is not None and isinstance(value, str):
        try:
            value = row.parse(value)
        except SimulationInputError as exc:
            raise StudyError(str(exc)) from None
    if row is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
        problem = row.problem(value)
        if problem is not None:
            raise StudyError(f"[parameters.{row.study_key}] {problem}")
    return value


def calibrated_k_H(source: str | Path | Mapping) -> float:
    """k_H (N/m^1.5) from the JSON output of `ies calibrate --json` (a file path or the parsed dict)."""
    if isinstance(source, Mapping):
        data, where = source, "calibration"
    else:
        where = str(source)
        try:
            data = json.loads(Path(source).read_text())
        except FileNotFoundError:
            raise StudyError(f"calibration file {where} not found; write it with `ies calibrate --json > {where}`")
        except (OSError, json.JSONDecodeError) as exc:
            raise StudyError(f"calibration file {where} is not the JSON of `ies calibrate --json` ({exc})")
    value = data.get("k_H") if isinstance(data, Mapping) else None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
        raise StudyError(f"{where} has no positive 'k_H' (N/m^1.5); is it the output of `ies calibrate --json`?")
    return float(value)
