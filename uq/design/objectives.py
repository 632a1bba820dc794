"""What `ies design` minimises: the design objectives, one row each (quantity, statistic, unit, screening predictor).

A design's objective value is the worst case, over the operating levels and the uncertainty box's corners and
centre, of the row's value per (point, level) averaged over the repetitions. A row says what that value is for one
simulated stepped-sine run (`of_run`, from the run's record: its outputs and its per-frequency trace, Sect. 5.2)
and how the slow flow's screening predicts it from the predicted resonant tip amplitude (`screened`). The
similarity law's prediction (`sim.reduced.similarity`) needs nothing more: it takes `of_run` of its reference
runs per a_noabs*, which the law scales to any clearance.

A new objective is one more row (`OBJECTIVES[name] = Objective(...)`); `--objective NAME` and the study files'
`objective` key read the table.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Objective:
    """One design objective.

    name: the `--objective` value; quantity and statistic: what it is, in words (the statistic of one run at its
    resonance, Sect. 5.3); unit: its SI unit; shown_in, shown_scale: the unit of the printed table and figures and the
    factor to it from SI; of_run(record, omega_1): the value of one run (SI) from its record (`uq.engine.runner`:
    "outputs", and "trace" with a_noabs in m and the per-frequency eta and mean amplitudes / a_noabs*) and the host's
    first natural angular frequency (rad/s); NaN for a failed run; screened(tip_m, omega_1): the slow flow's
    prediction (SI) from its predicted resonant tip amplitude (m) at the resonance omega_1.
    """

    name: str
    quantity: str
    statistic: str
    unit: str
    shown_in: str
    shown_scale: float
    of_run: Callable[[Mapping[str, Any], float], float]
    screened: Callable[[np.ndarray, float], np.ndarray]

    def describe(self) -> dict[str, str]:
        return {"name": self.name, "quantity": self.quantity, "statistic": self.statistic, "unit": self.unit,
                "key_suffix": self.suffix}

    @property
    def suffix(self) -> str:
        """The unit's suffix of the output keys holding this objective's values: `_m` for an amplitude (`worst_m`),
        `_m_per_s2` for m/s^2 (`worst_m_per_s2`): one name per quantity, its unit in the name."""
        text = self.unit.replace("^", "").replace("/", "_per_").replace(" ", "")
        return "_" + text if text not in ("", "-", "1") else ""

    def shown(self, value: float) -> str:
        """`value` (SI) in the printed unit, 3 significant digits."""
        return f"{value * self.shown_scale:.3g}"


def _failed(record: Mapping[str, Any]) -> bool:
    return bool(record.get("error")) or "trace" not in record


def resonant_amplitude(output: str) -> Callable[[Mapping[str, Any], float], float]:
    """of_run of the resonant tip amplitude (m): the run's `output` ("mean" or "max" of the per-period amplitudes at
    the resonant frequency, / a_noabs*) times its a_noabs* (Sect. 5)."""

    def of_run(record: Mapping[str, Any], omega_1: float) -> float:
        if _failed(record):
            return math.nan
        return float(record["outputs"].get(output, math.nan)) * float(record["trace"]["a_noabs"])

    return of_run


def _tip_amplitude(tip_m: np.ndarray, omega_1: float) -> np.ndarray:
    return np.asarray(tip_m, dtype=float)


#: name -> row; the first is the default
OBJECTIVES: dict[str, Objective] = {
    "mean": Objective("mean", "resonant tip amplitude", "mean of the per-period amplitudes |c_1| over the hold at the "
                      "resonant frequency", "m", "mm", 1e3, resonant_amplitude("mean"), _tip_amplitude),
    "max": Objective("max", "resonant tip amplitude", "largest per-period amplitude |c_1| over the hold at the "
                     "resonant frequency", "m", "mm", 1e3, resonant_amplitude("max"), _tip_amplitude),
}


def objective_named(name: str) -> Objective:
    """The row of `name`; one line (StudyError) naming the known objectives otherwise."""
    from uq.errors import StudyError

    try:
        return OBJECTIVES[name]
    except KeyError:
        raise StudyError(f"--objective must be one of {', '.join(OBJECTIVES)}, got {name!r}") from None
