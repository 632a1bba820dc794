"""Value types of the command-line options that every stage shares (argparse ``type=`` functions).

A bad value is refused by argparse before the command runs: one line ``ies COMMAND: error: argument --X: ...``,
exit code 2, nothing computed or written. Used by `sim.cli`, `bem_contact.cli` and `uq.commands`.

* `figure_file`: a figure path whose suffix matplotlib can write (``--plot``); checked up front, so a long
  computation never ends in an unsupported format.
* `figure_formats`, `level_list`: ``ies plot``'s formats (png,pdf) and levels (5.3,6.7).
* `positive_int`: counts such as ``--jobs``, ``--reps``, ``--n``.

The options of the paper's parameters (``--g 0.58mm``, ``--k-H``, ...) take their value type from their row of
`sim.model.parameters.PARAMETERS` (`UncertainParameter.option_value`: units, bounds and plausible range in one place).
"""
from __future__ import annotations

import argparse
import functools
from pathlib import Path


@functools.lru_cache(maxsize=1)
def figure_suffixes() -> tuple[str, ...]:
    """The file suffixes matplotlib's Agg canvas can write (.png, .pdf, .svg, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(f".{ext}" for ext in FigureCanvasBase.get_supported_filetypes())


def figure_file(text: str) -> str:
    """A figure path with a suffix matplotlib can write; a missing or unknown suffix is refused."""
    suffix = Path(text).suffix.lower()
    if suffix not in figure_suffixes():
        what = f"unsupported figure format {suffix!r}" if suffix else "no file suffix"
        raise argparse.ArgumentTypeError(f"{text!r}: {what}; name the file with one of {', '.join(figure_suffixes())}")
    return text


def figure_formats(text: str) -> tuple[str, ...]:
    """A comma-separated list of figure formats matplotlib can write ("png,pdf" -> (".png", ".pdf"))."""
    formats = tuple(f".{part.strip().lower().lstrip('.')}" for part in text.split(",") if part.strip())
    unknown = [f for f in formats if f not in figure_suffixes()]
    if not formats or unknown:
        raise argparse.ArgumentTypeError(f"unsupported figure format(s) {', '.join(unknown) or repr(text)}; use "
                                         f"{', '.join(s.lstrip('.') for s in figure_suffixes())}")
    return formats


def level_list(text: str) -> tuple[float, ...]:
    """Excitation levels a_base/a_base* as a comma-separated list of positive numbers ("5.3,6.7")."""
    try:
        levels = tuple(float(part) for part in text.split(",") if part.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be numbers like 5.3,6.7, got {text!r}") from None
    if not levels or any(not level > 0 for level in levels):
        raise argparse.ArgumentTypeError(f"must be positive numbers like 5.3,6.7, got {text!r}")
    return levels


def positive_int(text: str) -> int:
    """An integer >= 1."""
    return _int_from(text, 1, "a positive integer (1 or more)")


def count(text: str) -> int:
    """An integer >= 0."""
    return _int_from(text, 0, "an integer >= 0")


def _int_from(text: str, least: int, what: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"must be {what}, got {value}")
    return value
