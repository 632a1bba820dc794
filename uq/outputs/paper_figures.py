"""The paper's figures that the workbench reproduces: `PAPER_FIGURES`, one row per figure.

A row (`PaperFigure`) says everything `ies reproduce NAME` and the figure code need: the figure's name (also the
file stem of its drawing and the folder OUT/NAME), its study file, the function that draws it from a response
study's data (`draw`; for a study run once per value of a parameter when `series`), the table printed after the
run, whether `ies reproduce all` runs it, and for the interval studies the joint-band figure of an output. Adding a
figure is adding a row: `ies reproduce`'s choices, the [response] figures a study file may ask for (`uq.methods.response`),
the drawing of a response folder (`response_figures`, also `ies plot`) and the printed summary all read
this table.

The printed tables (`response_table`, `scattering_table`, `interval_table`) are the library functions behind the
text of `ies reproduce`, `ies response` and `ies interval`.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

from sim.plots.redraw import register
from uq.outputs.results import study_kind

if TYPE_CHECKING:
    from sim.plots.redraw import PlotOptions
    from uq.outputs.figures import ResponseData

#: draws one figure of a response study: (the study's data, the figure's file stem) -> the files written
ResponsePanel = Callable[["ResponseData", str], list[Path]]
#: prints a figure's table after its study ran: (result folder, the run's summary, the name it is printed under)
TablePrinter = Callable[[Path, Mapping, str], None]


def _figures(name: str, *args: Any) -> Callable[..., list[Path]]:
    """`uq.outputs.figures.NAME` (or, with `args`, the drawer `uq.outputs.figures.NAME(*args)` makes), imported when first drawn:
    the table stays light enough for `ies --help`."""
    def draw(*call_args: Any) -> list[Path]:
        import uq.outputs.figures

        function = getattr(uq.outputs.figures, name)
        return (function(*args) if args else function)(*call_args)

    draw.__name__ = draw.__qualname__ = name
    return draw


def interval_figures(folder: str | Path, options: "PlotOptions | None" = None) -> list[Path]:
    """Figs. 7 and 8 of an interval study (`uq.outputs.figures.interval_figures`). A study `ies reproduce` ran (its
    study.json names the `paper_figure`) names them after this table, the individual variation INDIVIDUAL_FIGURE and
    the joint band of an output after the row that shows it (`box_figure`), and leaves the nominal point's levels to
    Fig. 6 (a study of its own); a study of one's own names them by what they show (OWN_FIGURES) and draws the nominal
    point's levels too."""
    from uq.outputs.figures import interval_figures as draw

    paper = json.loads((Path(folder) / "study.json").read_text()).get("paper_figure")

    def box(output: str) -> tuple[str, str, tuple[float, str] | None]:
        row = box_figure(output)
        title = row.box_titles.get(output) or next(iter(row.box_titles.values()))
        return (row.name if paper else OWN_FIGURES["joint"]), title, row.reference

    return draw(folder, options, individual_stem=INDIVIDUAL_FIGURE if paper else OWN_FIGURES["individual"],
                box_figure=box, nominal_levels=not paper)


def response_figures(folder: str | Path, options: "PlotOptions | None" = None) -> list[Path]:
    """The figures a response study's [response] figures ask for, each drawn by its row's `draw` (Figs. 5, 6, D.2,
    D.3 from sweeps.csv, overview.csv and runs.csv; a series study's Fig. 11 or C.1, its first figure, from each
    value's overview.csv), in the order of the table."""
    from sim.plots.redraw import PlotOptions
    from uq.outputs.figures import response_data

    data = response_data(Path(folder), options or PlotOptions())
    listed = data.meta["study"]["response"]["figures"]
    if "series_folders" in data.meta:
        row = PAPER_FIGURES[listed[0]]
        return row.draw(data, row.name) if row.draw is not None and row.series else []
    paths: list[Path] = []
    for row in PAPER_FIGURES.values():
        if row.name in listed and row.draw is not None and not row.series:
            paths += row.draw(data, row.name)
    return paths


def response_table(folder: Path, summary: Mapping, name: str) -> None:
    """The resonant levels per excitation level and the optimum (Fig. 6, Sect. 5.3); for a series study the
    resonant mean and the dissipation shares of each value (Fig. 11, C.1)."""
    from sim.stepped_sine.landmarks import switch_line
    from sim.stepped_sine.tables import optimum_line, overview_text, series_text
    from uq.outputs.figures import series_overviews

    data = json.loads((folder / "study.json").read_text())
    if "series_folders" in data:
        print(f"{name}: resonant mean (a / a_noabs*) and the input's dissipation shares at the resonant eta "
              f"(contact / friction / mode 1 / modes 2..N) for each value:")
        print(series_text(series_overviews(folder)))
        return
    overview = data["overview"]
    print(f"{name}: resonant levels (a / a_noabs*) of the nominal point:")
    print(overview_text(overview))
    print(f"{name}: {optimum_line(overview)}")
    if "landmarks" in data:
        print(f"{name}: {switch_line(data['landmarks'])}")


def scattering_table(folder: Path, summary: Mapping, name: str) -> None:
    """Impacts, restitution and energy scattering at the resonant eta of the nominal point (Figs. D.2, D.3)."""
    from sim.stepped_sine.tables import scattering_text

    data = json.loads((folder / "study.json").read_text())
    if "series_folders" in data:
        response_table(folder, summary, name)
        return
    print(f"{name}: impacts, restitution and energy scattering at the resonant eta of the nominal point:")
    print(scattering_text(data["overview"]))


def interval_table(folder: Path, summary: Mapping, name: str) -> None:
    """The bands with their noise and checks, and for an individual variation the trends (Figs. 7, 8, Sect. 5.4)."""
    from uq.outputs.results import band_table, influence_line, trend_table

    for key in summary["untested"]:
        print(f"{name}: monotonicity could not be tested for {key} (one repetition: no noise estimate)")
    if any(key.startswith("individual:") for key in summary["monotone"]):
        print(f"{name}: change of the resonant level from each parameter's min to its max:")
        print(trend_table(folder))
        print(f"{name}: {influence_line(folder)}")
    print(f"{name}: bands (lower, nominal, upper +- standard error) and their checks:")
    print(band_table(folder))


@dataclass(frozen=True)
class PaperFigure:
    """One row of `PAPER_FIGURES`.

    name: the figure (its file stem and the folder OUT/NAME of `ies reproduce`); help: what it shows;
    study: the stem of a shipped study file (uq/studies/STEM.toml, STEM-quick.toml with --quick) or the path of a
    study file; draw: how a response study that lists the figure in [response] figures draws it (None: drawn by
    an interval study's designs, Figs. 7, 8); table: what a response study named after the figure prints (an
    interval study prints its bands, `interval_table`); in_all: run by `ies reproduce all`; series: `draw` draws a
    series study (one run per value of a parameter, Fig. 11); traced: the levels whose time histories are traced
    after the run (Fig. C.1b); box_titles: for an interval study, {banded output: title} of the joint-band figure
    drawn under this name; reference: a level of the paper drawn on that figure (value, label).
    """

    name: str
    help: str
    study: str
    draw: ResponsePanel | None
    table: TablePrinter
    in_all: bool
    series: bool = False
    traced: tuple[float, ...] = ()
    box_titles: Mapping[str, str] = field(default_factory=dict)
    reference: tuple[float, str] | None = None

    def study_file(self, quick: bool) -> Path:
        """The study file: a shipped study (its -quick variant with `quick`) or the row's own path."""
        if self.study.endswith(".toml"):
            return Path(self.study)
        return Path(str(files("uq") / "studies" / f"{self.study}{'-quick' if quick else ''}.toml"))


#: the paper's figures, in the order `ies reproduce all` runs them
PAPER_FIGURES: dict[str, PaperFigure] = {row.name: row for row in (
    PaperFigure("fig5", "frequency responses (Sects. 5.1-5.2)", "fig5", _figures("frequency_responses"),
                response_table, True),
    PaperFigure("fig6", "resonant level vs excitation level (Sect. 5.3)", "fig6", _figures("resonant_levels"),
                response_table, True),
    PaperFigure("fig7", "individual variation of D, g, k_H (Sect. 5.4)", "fig7", None, response_table, True),
    PaperFigure("fig8", "joint and residual variation of D, g, k_H (Sect. 5.4)", "fig8", None, response_table, True,
                box_titles={"mean": "Joint variation (cf. Fig. 8)"}),
    PaperFigure("figD2", "impacts per period vs excitation level (Appendix D)", "figD2",
                _figures("scattering_figure", "impacts", "Impacts per period (cf. Fig. D.2)"), scattering_table, True),
    PaperFigure("figD3", "restitution vs excitation level (Appendix D)", "figD3",
                _figures("scattering_figure", "restitution", "Restitution, APR levels (cf. Fig. D.3)"),
                scattering_table, True,
                box_titles={"restitution": "Modal coefficient of restitution $r$ from the tip",
                            "restitution_wall": "Modal coefficient of restitution $r$ from the wall"},
                reference=(0.8, "paper: $r$ ~ 0.8 (Fig. D.3)")),
    PaperFigure("fig11", "damped contact law, Eq. 10 (Sect. 5.5)", "fig11",
                _figures("series_figure", "cf. Fig. 11", (7.5, "paper: contact dissipation matters above 7.5")),
                response_table, False, series=True),
    PaperFigure("figC1", "dry friction (Appendix C)", "figC1",
                _figures("series_figure", "cf. Fig. C.1 and the low end of Fig. 6"), response_table, False,
                series=True, traced=(1.26, 5.3)),
)}

#: the name under which `interval_figures` writes the individual variation (Fig. 7) of the paper's study
INDIVIDUAL_FIGURE = "fig7"
#: the names of an interval study's figures of one's own: by what they show
OWN_FIGURES = {"individual": "individual-variation", "joint": "joint-variation"}
#: the joint band's figure when no row claims the banded output
DEFAULT_BOX_FIGURE = "fig8"


def response_figure_names() -> tuple[str, ...]:
    """The figures a response study may list in [response] figures (rows with a response or series panel)."""
    return tuple(row.name for row in PAPER_FIGURES.values() if row.draw is not None)


def figures_of_all() -> tuple[str, ...]:
    """What `ies reproduce all` runs, in order."""
    return tuple(row.name for row in PAPER_FIGURES.values() if row.in_all)


def box_figure(output: str) -> PaperFigure:
    """The row whose joint-band figure shows `output` of an interval study (Fig. 8 for the resonant level)."""
    for row in PAPER_FIGURES.values():
        if output in row.box_titles:
            return row
    return PAPER_FIGURES[DEFAULT_BOX_FIGURE]


register("ies interval", study_kind("interval"))(interval_figures)
register("response study (ies response, ies reproduce of a response figure)", study_kind("response"))(response_figures)

