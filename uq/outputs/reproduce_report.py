"""What `ies reproduce` leaves for a reader beside its data: `OUT/summary.txt` (what ran, the
tables it printed, the paper's statement beside each figure's table), each figure's printed table in
`OUT/FIG/table.txt`, and `OUT/index.md`, which lists every figure and table of the folder with one line on
what it shows. Column-level detail stays in the output reference (uq/OUTPUTS.md).

The paper's statements are quoted from its text (Sects. 5.2-5.5, Appendices B-D) with the numbers of
`sim.stepped_sine.measures`.
"""
from __future__ import annotations

import io
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from sim.common.files import write_text
from sim.stepped_sine.measures import (PAPER_APR_LEVEL, PAPER_IMPACTS_PER_PERIOD, PAPER_OPTIMUM_LEVEL,
                                       PAPER_REDUCTION_MAX, PAPER_REDUCTION_MEAN)

#: what the paper says that each figure's table is to be read against
PAPER = {
    "fig5": "the paper (Sect. 5.2, Fig. 5): strongly modulated resonances at 1.26 and 5.3, almost periodic ones at 6.7 "
            "and 7.4 near eta = 0.976",
    "fig6": f"the paper (Sect. 5.3, Fig. 6; Appendix B): switch and optimum at {PAPER_OPTIMUM_LEVEL:g}, resonant mean "
            f"reduced {PAPER_REDUCTION_MEAN:.0f}x and max {PAPER_REDUCTION_MAX:.0f}x there; almost periodic level at 7.4 "
            f"{PAPER_APR_LEVEL[0]:g}-{PAPER_APR_LEVEL[1]:g}",
    "fig7": "the paper (Sect. 5.4, Fig. 7): the strongly modulated level almost invariant; in the almost periodic regime "
            "larger D lowers the level, g mainly shifts the curve along the level axis, larger k_H lowers it; k_H has "
            "the largest influence",
    "fig8": "the paper (Sect. 5.4, Fig. 8): a large joint spread; with k_H at its best estimate 1.25 k_H* the "
            "measurements lie largely within the residual band",
    "figD2": f"the paper (Appendix D, Fig. D.2): {PAPER_IMPACTS_PER_PERIOD:g} significant impacts per period in the "
             "almost periodic regime",
    "figD3": "the paper (Appendix D, Fig. D.3): modal coefficient of restitution r of about 0.8 in the almost periodic "
             "regime",
    "fig11": "the paper (Sect. 5.5, Fig. 11): contact dissipation matters only above 7.5; at r_cont,diss = 0.99 the "
             "contact takes 5 % of the input, mode 1 10 % and modes 2-9 85 %",
    "figC1": "the paper (Appendix C, Fig. C.1): with friction long and deep modulation cycles at 1.26, little "
             "influence at 5.3",
}

#: one line per file `ies reproduce` writes, by file name (figures by their stem: .png and .pdf alike)
FILES = {
    "summary.txt": "what ran, every table printed, and the paper's statements beside them",
    "calibration.json": "the k_H calibration on the shipped crater (the object of `ies calibrate --json`)",
    "table.txt": "the table `ies reproduce` printed for this figure",
    "study.json": "the resolved study, its protocol, code version, warnings, timings (and landmarks)",
    "runs.csv": "every stepped-sine run: parameters, level, repetition, its resonant levels",
    "points.csv": "repetition statistics of every design point and level (value, standard error, regime)",
    "bands.csv": "the bands per design and level with their standard errors and monotonicity checks",
    "sweeps.csv": "the frequency response (mean, max, spread, regime, scattering) at every level",
    "overview.csv": "the resonant levels against the excitation level (Fig. 6's data)",
    "trace.csv": "a time history at 51.2 kHz (tip, walls, sphere, contact forces)",
    "trace.json": "the time history's settings, per-period amplitudes and impacts",
    "results.nc": "every number of the CSV tables as one xarray Dataset with units (`uq.outputs.results.open_study`)",
    "fig5": "Fig. 5: frequency responses (mean and max amplitude per eta with the runs' range) of the nominal system",
    "fig6": "Fig. 6: resonant mean and max against the excitation level, regimes and the optimum (the paper's marked)",
    "fig7": "Fig. 7: the resonant mean's band from D, g and k_H varied one at a time",
    "fig8": "Fig. 8: the joint band of D, g, k_H and the residual band with k_H at its best estimate",
    "nominal-levels": "the nominal point's resonant mean and max at an interval study's levels (a study of one's own)",
    "individual-variation": "an interval study's band of each parameter varied alone (as Fig. 7)",
    "joint-variation": "an interval study's joint band and residual band (as Fig. 8)",
    "figD2": "Fig. D.2: impacts and significant impacts per period at the resonant eta against the level",
    "figD3": "Fig. D.3: modal coefficient of restitution r with its band from D and g",
    "fig11": "Fig. 11: the resonant mean for each r_cont,diss of the damped contact law (Eq. 10)",
    "figC1": "Fig. C.1 and the low end of Fig. 6: the resonant mean with and without dry friction",
    "trace": "Figs. 4 and 9a: tip response with per-period amplitudes, and tip velocity with the impacts",
    "motion": "Fig. C.1b: the walls and the sphere against time",
}
UNDESCRIBED = "(see uq/OUTPUTS.md)"


class Tee(io.TextIOBase):
    """A text stream that writes to the given stream and keeps a copy."""

    def __init__(self, stream: io.TextIOBase) -> None:
        self.stream, self.copy = stream, io.StringIO()

    def write(self, text: str) -> int:
        self.copy.write(text)
        return self.stream.write(text)

    def flush(self) -> None:
        self.stream.flush()


@contextmanager
def captured_stdout() -> Iterator[Tee]:
    """Standard output as usual, with a copy kept in the yielded Tee's `copy`."""
    tee = Tee(sys.stdout)
    old, sys.stdout = sys.stdout, tee
    try:
        yield tee
    finally:
        sys.stdout = old


def describe_file(path: Path) -> str:
    """The one line on a file of a reproduction (by name, figures by stem; traces' folders by their stem)."""
    return FILES.get(path.name) or FILES.get(path.stem) or UNDESCRIBED


def write_index(out: Path) -> Path:
    """OUT/index.md: every figure and table below `out`, grouped by folder, one line each."""
    lines = ["# Results of `ies reproduce`", "", "Column-level detail of every table: uq/OUTPUTS.md "
             "in the workbench's source. Figures are written as PNG and PDF.", ""]
    folders = sorted({p.parent for p in out.rglob("*") if p.is_file() and "tasks" not in p.relative_to(out).parts})
    for folder in folders:
        files = sorted(p for p in folder.iterdir() if p.is_file() and p.name != "index.md"
                       and not p.name.startswith("."))  # not the run's lock (sim.common.folder_lock)
        if not files:
            continue
        rel = folder.relative_to(out).as_posix()
        lines += [f"## `{rel}/`" if rel != "." else "## this folder", ""]
        seen: set[str] = set()
        for p in files:
            if p.suffix in (".png", ".pdf", ".svg"):
                if p.stem in seen:
                    continue
                seen.add(p.stem)
                name = f"{p.stem}.png|pdf" if p.suffix in (".png", ".pdf") else p.name
            else:
                name = p.name
            lines.append(f"- `{name}`: {describe_file(p)}")
        lines.append("")
    return write_text(out / "index.md", "\n".join(lines))


def write_summary(out: Path, command: str, sections: list[tuple[str, str]]) -> list[Path]:
    """OUT/summary.txt (the command, then per figure what it printed and the paper's statement) and each figure's
    printed text in OUT/FIG/table.txt. sections: (figure, printed text)."""
    written = []
    parts = [f"$ {command}", ""]
    for figure, text in sections:
        parts += [text.rstrip("\n"), f"{figure}: {PAPER[figure]}" if figure in PAPER else "", ""]
        if (out / figure).is_dir():
            written.append(write_text(out / figure / "table.txt", text.rstrip("\n") + "\n"))
    written.insert(0, write_text(out / "summary.txt", "\n".join(parts).rstrip("\n") + "\n"))
    return written
