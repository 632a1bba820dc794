"""The figure style every stage shares (`sim.plots`, signal analysis, calibration, uq): legends beside or below the
axes, never on data, at one text size, and the typeset labels and units (mathtext)."""
from __future__ import annotations

from typing import Any

#: legend text size (pt): every legend of the workbench sits beside or below its axes, never on data
LEGEND_PT = 8.0
#: axis labels and units as typeset on every figure (mathtext)
LEVEL_LABEL = r"excitation level $a_\mathrm{base}/a_\mathrm{base}^*$"
RESPONSE_LABEL = r"$a/a_\mathrm{noabs}^*$"
ETA_LABEL = r"$\eta = \Omega/\omega^*$"
N_PER_MM15 = r"N/mm$^{1.5}$"
MICROMETRE = r"$\mu$m"


def legend_beside(ax: Any, *, title: str | None = None, **kwargs: Any) -> Any:
    """A legend to the right of `ax`, outside the axes (off the data), LEGEND_PT text; None without entries.
    When `ax` has a secondary axis on its right (`secondary_mm`) the legend goes to the figure's right margin
    (constrained layout), beyond that axis's labels."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    style = dict(fontsize=LEGEND_PT, title=title, title_fontsize=LEGEND_PT, alignment="left", frameon=False, **kwargs)
    if ax.child_axes and ax.figure.get_layout_engine() is not None:
        return ax.figure.legend(handles, labels, loc="outside right upper", **style)
    return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, **style)


def legend_below(ax: Any, *, title: str | None = None, ncols: int = 1, **kwargs: Any) -> Any:
    """A legend under `ax` (below its x label, outside the axes), LEGEND_PT text; None without entries."""
    if not ax.get_legend_handles_labels()[0]:
        return None
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), borderaxespad=0.0, fontsize=LEGEND_PT,
                     title=title, title_fontsize=LEGEND_PT, ncols=ncols, frameon=False, **kwargs)
