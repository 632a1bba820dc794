"""The figure style every stage shares (`sim.plots`, signal analysis, calibration, uq): legends beside or below the
axes, never on data, at one text size, and the typeset labels and units (mathtext)."""
from __future__ import annotations

import re
from typing import Any, Sequence

#: legend text size (pt): every legend of the workbench sits beside or below its axes, never on data
LEGEND_PT = 8.0
#: axis labels and units as typeset on every figure (mathtext)
LEVEL_LABEL = r"excitation level $a_\mathrm{base}/a_\mathrm{base}^*$"
RESPONSE_LABEL = r"$a/a_\mathrm{noabs}^*$"
ETA_LABEL = r"$\eta = \Omega/\omega^*$"
N_PER_MM15 = r"N/mm$^{1.5}$"
MICROMETRE = r"$\mu$m"


#: characters of a legend line beside the axes (entries and title are wrapped there): the legend then takes at most
#: a third of a figure's width (tests/test_figure_layout.py), the axes the rest
LEGEND_LINE_CHARS = 30


def wrap_label(text: str, width: int = LEGEND_LINE_CHARS) -> str:
    """`text` broken into lines of at most `width` characters of what is shown (a mathtext span ``$...$`` counts by
    its letters and is never broken; existing line breaks are kept)."""
    lines = []
    for paragraph in text.split("\n"):
        line, shown = "", 0
        for word in re.findall(r"(?:\$[^$]*\$|[^\s$])+", paragraph):
            length = len(re.sub(r"\\[a-zA-Z]+|[${}^_]", "", word))
            if line and shown + 1 + length > width:
                lines.append(line)
                line, shown = word, length
            else:
                line, shown = (f"{line} {word}", shown + 1 + length) if line else (word, length)
        lines.append(line)
    return "\n".join(lines)


def legend_beside(ax: Any, *, title: str | None = None, handles_of: Sequence[Any] = (), **kwargs: Any) -> Any:
    """A legend to the right of `ax`, outside the axes (off the data), LEGEND_PT text, its entries and title wrapped to
    LEGEND_LINE_CHARS; None without entries. handles_of: the panels whose entries it lists, each label once (default
    `ax`'s own). When `ax` has a secondary axis on its right (`secondary_mm`) the legend goes to the figure's right
    margin (constrained layout), beyond that axis's labels."""
    entries: dict[str, Any] = {}
    for panel in handles_of or (ax,):
        for handle, label in zip(*panel.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    handles, labels = list(entries.values()), list(entries)
    if not handles:
        return None
    labels = [wrap_label(label) for label in labels]
    title = wrap_label(title) if title else title
    style = dict(fontsize=LEGEND_PT, title=title, title_fontsize=LEGEND_PT, alignment="left", frameon=False, **kwargs)
    if ax.child_axes and ax.figure.get_layout_engine() is not None:
        return ax.figure.legend(handles, labels, loc="outside right upper", **style)
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, **style)


def legend_below(ax: Any, *, title: str | None = None, ncols: int = 1, **kwargs: Any) -> Any:
    """A legend under `ax` (below its x label, outside the axes), LEGEND_PT text; None without entries."""
    if not ax.get_legend_handles_labels()[0]:
        return None
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), borderaxespad=0.0, fontsize=LEGEND_PT,
                     title=title, title_fontsize=LEGEND_PT, ncols=ncols, frameon=False, **kwargs)
