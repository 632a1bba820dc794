"""A study's unit of work (`Task`: one model evaluation at a parameter point, an excitation level and a repetition), and
the most of them a study runs without being told it is meant (`check_run_total`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from uq.errors import StudyError

#: runs (points x levels x repetitions) above which a study is refused unless the command says --allow-large:
#: days of work on a workstation, a number a typo makes more often than a plan (the shipped studies stay far below)
MAX_RUNS = 20_000


@dataclass(frozen=True)
class Task:
    """One model evaluation: parameter values (SI), level a_base / a_base*, repetition index."""

    params: tuple[tuple[str, float], ...]
    level: float
    rep: int

    @staticmethod
    def make(params: Mapping[str, float], level: float, rep: int) -> "Task":
        return Task(tuple(sorted((k, float(v)) for k, v in params.items())), float(level), int(rep))


def check_run_total(points: int, levels: int, repetitions: int, *, allow_large: bool = False,
                    per_run_s: float | None = None) -> int:
    """The run total points x levels x repetitions, refused (one line with the count, the time at `per_run_s` seconds
    per run, the model's typical cost where it has one, and how to ask for less) above `MAX_RUNS` unless
    `allow_large`."""
    from sim.stepped_sine.cost import duration_text

    runs = points * levels * repetitions
    if runs > MAX_RUNS and not allow_large:
        time = "" if not per_run_s else f", about {duration_text(runs * per_run_s)} on one core"
        raise StudyError(f"{runs:,} runs ({points:,} parameter points x {levels} levels x {repetitions} repetitions"
                         f"{time}) exceed the {MAX_RUNS:,} a study runs without --allow-large: ask for fewer points, "
                         "levels or repetitions, or pass --allow-large")
    return runs
