"""The figure seam (issue 27): one row of `uq.outputs.paper_figures.PAPER_FIGURES` is all a new paper figure needs.

The toy row, added inside the test only, draws one column of a response study (the resonant mean against the
excitation level) and prints one line; `ies reproduce NAME` runs it end to end on a tiny study: its study file,
the [response] figures check of the study file, the run, the drawing and the printed table. `ies plot` redraws it
from the data alone, through the same row.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from uq.cli import main
from uq.outputs.paper_figures import PAPER_FIGURES, PaperFigure, figures_of_all, response_figure_names


def one_column(data, stem: str) -> list[Path]:
    """The toy figure: overview.csv's resonant mean against the excitation level, one line."""
    from sim.common.files import plot_to

    paths = data.options.paths(data.folder, stem)
    for path in paths:
        with plot_to(path, figsize=(4, 3)) as (fig, ax):
            ax.plot(data.overview["levels"], data.overview["resonant_mean"], "o-")
    return paths


def one_line(folder: Path, summary, name: str) -> None:
    print(f"{name}: {len(json.loads((folder / 'study.json').read_text())['overview']['levels'])} level(s) drawn")


@pytest.fixture
def toy_row(tmp_path, monkeypatch: pytest.MonkeyPatch) -> PaperFigure:
    study = tmp_path / "toy.toml"
    study.write_text("[study]\nkind = 'response'\nrepetitions = 1\n[excitation]\nlevels = [2.0]\n"
                     "eta = { start = 0.975, stop = 0.98, n = 2 }\nwait = 0.1\nhold = 0.1\n"
                     "[response]\nfigures = ['figToy']\n")
    row = PaperFigure("figToy", "the resonant mean, one column", str(study), one_column, one_line, in_all=False)
    monkeypatch.setitem(PAPER_FIGURES, row.name, row)
    return row


def test_the_toy_figure_is_reproduced_end_to_end(toy_row: PaperFigure, tmp_path, capsys) -> None:
    assert "figToy" in response_figure_names() and "figToy" not in figures_of_all()
    out = tmp_path / "o"
    assert main(["reproduce", "figToy", "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    text = capsys.readouterr().out
    assert "figToy: 1 level(s) drawn" in text and "figToy.png" in text
    assert (out / "figToy" / "figToy.png").is_file() and (out / "figToy" / "figToy.pdf").is_file()
    assert not (out / "figToy" / "fig6.png").exists()  # only the figures the study lists
    (out / "figToy" / "figToy.png").unlink()
    assert main(["plot", str(out / "figToy"), "--format", "png"]) == 0
    assert (out / "figToy" / "figToy.png").is_file()


def test_a_study_file_may_only_list_figures_of_the_table(tmp_path, capsys) -> None:
    study = tmp_path / "s.toml"
    study.write_text("[study]\nkind = 'response'\n[excitation]\nlevels = [2.0]\n[response]\nfigures = ['figToy']\n")
    assert main(["response", str(study), "--out", str(tmp_path / "o")]) == 2
    assert "[response] figures must be a list from fig5, fig6, figD2, figD3, fig11, figC1" in capsys.readouterr().err


@pytest.mark.parametrize("quick", [True, False])
def test_each_figure_folder_holds_only_its_own_figure(quick):
    """`ies reproduce all` writes each figure into its own folder: a response study of the table draws only its own
    row's figure (Fig. 6's study once also drew a second, different fig5.png into fig6/)."""
    from uq.methods import load_study

    for name in figures_of_all():
        study = load_study(PAPER_FIGURES[name].study_file(quick))
        if study.kind == "response":
            assert list(study.settings["figures"]) == [name], (name, study.settings)
