"""Redrawing a result folder's figures from its saved data, without recomputing (`ies plot DIR`).

Every kind of result folder registers how to recognise it and how to draw its figures from its files:

    @register("sweep", lambda folder: (folder / "sweep.json").is_file())
    def redraw_sweep(folder: Path, options: PlotOptions) -> list[Path]: ...

`redraw(folder, options)` finds the registered kind and draws (in the formats, the matplotlib style and the
subset of excitation levels of `options`, into `options.out`). The simulation stage registers its folders in
`sim.plots.figures` (`ies sweep --out`, `ies overview --out`), the uncertainty stage its studies in `uq.outputs.figures`; a
new kind of result registers its own redraw function in its own module, and `ies plot` imports that module.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, ContextManager, Sequence

from sim.common.errors import SimulationInputError


@dataclass(frozen=True)
class PlotOptions:
    """How to redraw: file suffixes (".png", ...), a matplotlib style (None: the default), the excitation levels
    a_base/a_base* to keep (None: all) and the folder for the figures (None: the result folder itself)."""

    formats: tuple[str, ...] = (".png", ".pdf")
    style: str | None = None
    levels: tuple[float, ...] | None = None
    out: Path | None = None

    def paths(self, folder: Path, stem: str) -> list[Path]:
        """The files of one figure: STEM in every format, in `out` (default `folder`)."""
        return [(self.out or folder) / f"{stem}{suffix}" for suffix in self.formats]

    def keeps(self, level: float) -> bool:
        """Whether an excitation level is among the chosen ones (relative tolerance 1e-9)."""
        return self.levels is None or any(abs(level - kept) <= 1e-9 * max(1.0, abs(kept)) for kept in self.levels)


Redraw = Callable[[Path, PlotOptions], list[Path]]


@dataclass(frozen=True)
class ResultKind:
    """A kind of result folder: its name, how to recognise it from its files, and how to redraw it."""

    name: str
    detect: Callable[[Path], bool]
    redraw: Redraw = field(repr=False)


#: the registered kinds, in registration order (the first that recognises a folder draws it)
KINDS: list[ResultKind] = []


def register(name: str, detect: Callable[[Path], bool]) -> Callable[[Redraw], Redraw]:
    """Decorator: register `redraw(folder, options) -> written paths` for folders that `detect` recognises."""
    def decorate(function: Redraw) -> Redraw:
        KINDS[:] = [kind for kind in KINDS if kind.name != name] + [ResultKind(name, detect, function)]
        return function

    return decorate


def kind_of(folder: Path) -> ResultKind:
    """The registered kind that recognises `folder`; a one-line SimulationInputError when none does."""
    if not folder.is_dir():
        raise SimulationInputError(f"{folder} is not a folder; give a result folder (--out of ies sweep, overview, trace, "
                                   "interval, sobol or reproduce)")
    for kind in KINDS:
        try:
            found = kind.detect(folder)
        except (ValueError, KeyError, TypeError, AttributeError) as exc:  # a corrupt study.json, say
            raise SimulationInputError(f"{folder}: a data file is corrupt or incomplete ({type(exc).__name__}); rerun "
                                       "the command that wrote it") from None
        if found:
            return kind
    raise SimulationInputError(f"{folder} holds no result that can be redrawn (known: "
                               f"{', '.join(kind.name for kind in KINDS)}); give the --out folder of a finished run")


def redraw(folder: Path, options: PlotOptions) -> list[Path]:
    """Redraw the figures of a result folder (`kind_of`) from its data in the style of `options`."""
    kind = kind_of(folder)
    with style(options.style):
        try:
            return kind.redraw(folder, options)
        except SimulationInputError:
            raise
        except (ValueError, KeyError, TypeError, IndexError) as exc:  # json.JSONDecodeError, UnicodeDecodeError, ...
            where = f" at line {exc.lineno}" if hasattr(exc, "lineno") else ""
            raise SimulationInputError(f"{folder}: its {kind.name} data are corrupt or incomplete ({type(exc).__name__}"
                                       f"{where}); rerun the command that wrote them") from None


def style(name: str | None) -> ContextManager[None]:
    """A matplotlib style as a context (nothing for None); an unknown name is a one-line error."""
    from contextlib import nullcontext

    from sim.common.files import pyplot

    if name is None:
        return nullcontext()
    plt = pyplot()
    if name not in plt.style.available and not Path(name).is_file():
        raise SimulationInputError(f"unknown matplotlib style {name!r}; use one of {', '.join(sorted(plt.style.available))} "
                                   "or a .mplstyle file")
    return plt.style.context(name)


def selected(levels: Sequence[float], options: PlotOptions, folder: Path) -> list[float]:
    """The levels of a result that `options` keeps; a one-line error when it keeps none of them."""
    kept = [level for level in levels if options.keeps(level)]
    if not kept:
        raise SimulationInputError(f"{folder} has none of the levels {', '.join(f'{v:g}' for v in options.levels)}; "
                                   f"it has {', '.join(f'{v:g}' for v in levels)}")
    return kept
