"""Response studies (Figs. 5 and 6 through the task store): the same numbers as `ies overview`, serial or parallel,
resumable, drawn, printed, and part of `ies reproduce all`."""
import csv
import json

import numpy as np
import pytest

from uq.cli import main

TINY = ("[study]\nkind = 'response'\nseed = 3\nrepetitions = 2\n[excitation]\nlevels = [1.26, 6.7]\n"
        "eta = {{ start = 0.975, stop = 0.985, n = 3 }}\nwait = 0.1\nhold = 0.1\n{extra}")


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def tiny(tmp_path, extra=""):
    path = tmp_path / "response.toml"
    path.write_text(TINY.format(extra=extra))
    return path


def test_a_response_study_gives_what_ies_overview_gives(tmp_path, capsys):
    """One code path for the numbers: the study's runs are tasks, aggregated exactly as `ies overview` aggregates
    its sweeps (same seed, same repetitions)."""
    assert main(["response", str(tiny(tmp_path)), "--out", str(tmp_path / "study"), "--quiet", "--jobs", "1"]) == 0
    printed = capsys.readouterr().out
    assert main(["overview", "--levels", "1.26,6.7", "--eta", "0.975:0.985:3", "--wait", "0.1", "--hold", "0.1",
                 "--reps", "2", "--seed", "3", "--out", str(tmp_path / "overview")]) == 0
    study, direct = rows(tmp_path / "study" / "overview.csv"), rows(tmp_path / "overview" / "overview.csv")
    assert list(study[0]) == list(direct[0])  # the same columns
    for a, b in zip(study, direct):
        for key in a:
            if key == "regime":
                assert a[key] == b[key]
            else:
                assert float(a[key]) == pytest.approx(float(b[key]), rel=1e-12, abs=1e-15, nan_ok=True), key
    sweeps = rows(tmp_path / "study" / "sweeps.csv")
    assert len(sweeps) == 2 * 3 and {float(r["level"]) for r in sweeps} == {1.26, 6.7}
    for name in ("fig5.png", "fig5.pdf", "fig6.png", "fig6.pdf", "runs.csv", "study.json"):
        assert (tmp_path / "study" / name).is_file(), name
    assert "resonant levels (a / a_noabs*) of the nominal point" in printed and "optimum: a_base/a_base* = " in printed
    meta = json.loads((tmp_path / "study" / "study.json").read_text())
    assert meta["overview"]["levels"] == [1.26, 6.7] and meta["output_folder"] == str((tmp_path / "study").resolve())


def test_a_response_study_in_parallel_and_resumed_is_byte_identical(tmp_path, capsys):
    study = tiny(tmp_path, "[response]\nfigures = ['fig6']\n")
    assert main(["response", str(study), "--out", str(tmp_path / "serial"), "--quiet", "--jobs", "1"]) == 0
    assert main(["response", str(study), "--out", str(tmp_path / "parallel"), "--quiet", "--jobs", "2"]) == 0
    tasks = sorted((tmp_path / "parallel" / "tasks").glob("*.json"))
    tasks[0].unlink()  # as if interrupted: one run missing
    assert main(["response", str(study), "--out", str(tmp_path / "parallel"), "--quiet", "--jobs", "1", "--resume"]) == 0
    assert "(1 run now, 3 reused)" in capsys.readouterr().out
    for name in ("runs.csv", "sweeps.csv", "overview.csv"):
        assert (tmp_path / "serial" / name).read_bytes() == (tmp_path / "parallel" / name).read_bytes(), name
    assert not (tmp_path / "serial" / "fig5.png").exists() and (tmp_path / "serial" / "fig6.png").is_file()


def test_reproduce_all_runs_figures_5_to_8(tmp_path, monkeypatch, capsys):
    import uq.commands.reproduce as commands

    response = tiny(tmp_path, "[response]\nfigures = ['fig5', 'fig6']\n")
    interval = tmp_path / "interval.toml"
    interval.write_text("[study]\nkind = 'interval'\nrepetitions = 2\n[parameters.k_H]\n[excitation]\nlevels = [7.4]\n"
                        "eta = { start = 0.975, stop = 0.98, n = 2 }\nwait = 0.1\nhold = 0.1\n[interval]\ninterior = 0\n")
    monkeypatch.setattr(commands, "study_file", lambda figure, quick: response if figure in ("fig5", "fig6") else interval)
    out = tmp_path / "o"
    assert main(["reproduce", "all", "--no-calibration", "--out", str(out), "--quiet", "--jobs", "1"]) == 0
    text = capsys.readouterr().out
    for figure in ("fig5", "fig6", "fig7", "fig8"):
        assert f"{figure}: " in text and (out / figure / "study.json").is_file(), figure
    assert (out / "fig6" / "fig6.png").is_file() and (out / "fig7" / "fig7.png").is_file()
    # the nominal point's levels are Fig. 6's: no second copy with other numbers beside Fig. 7
    assert not (out / "fig7" / "nominal-levels.png").exists() and not (out / "fig7" / "fig6.png").exists()
    assert "optimum: a_base/a_base* = " in text and "lower +- SE" in text
    # what a reader finds beside the data: the printed tables with the paper's statements, and an index
    from uq.outputs.reproduce_report import PAPER, UNDESCRIBED

    summary = (out / "summary.txt").read_text()
    assert summary.startswith(f"$ ies reproduce all --out {out}\n")
    for figure in ("fig5", "fig6", "fig7", "fig8"):
        table = (out / figure / "table.txt").read_text()
        assert table in summary and f"{figure}: {PAPER[figure]}" in summary, figure
        assert table.startswith(f"{figure}: ") and table in text
    index = (out / "index.md").read_text()
    for name in ("fig6/", "fig7/", "`fig6.png|pdf`", "`fig7.png|pdf`", "`bands.csv`", "`overview.csv`",
                 "`summary.txt`", "`table.txt`"):
        assert name in index, name
    assert UNDESCRIBED not in index and "tasks" not in index
    assert f"wrote {out / 'summary.txt'}" in text and f"wrote {out / 'index.md'}" in text


def test_regime_labels_come_from_the_simulator(tmp_path, capsys):
    """points.csv carries the regime that sim.stepped_sine.protocol.aggregate_runs classifies; the tables and figures read it."""
    from uq.outputs.results import nominal_regimes

    path = tmp_path / "i.toml"
    path.write_text("[study]\nkind = 'interval'\nrepetitions = 2\nseed = 3\n[parameters.k_H]\n[excitation]\n"
                    "levels = [1.26, 6.7]\neta = { start = 0.975, stop = 0.985, n = 3 }\nwait = 0.1\nhold = 0.1\n")
    assert main(["interval", str(path), "--out", str(tmp_path / "i"), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    assert main(["response", str(tiny(tmp_path)), "--out", str(tmp_path / "r"), "--quiet", "--jobs", "1",
                 "--no-figures"]) == 0
    capsys.readouterr()
    regimes = nominal_regimes(rows(tmp_path / "i" / "points.csv"))
    overview = rows(tmp_path / "r" / "overview.csv")
    assert regimes == {float(r["level"]): r["regime"] for r in overview}  # the same runs, the same label
    assert set(regimes.values()) <= {"APR", "SMR", "linear"}
    assert np.isfinite([float(r["resonant_mean_se"]) for r in overview]).all()


DAMPED = ("[study]\nkind = 'response'\nseed = 3\nrepetitions = 1\ncontact_law = 'hertz-damped'\n"
          "[parameters.r_cont]\nnominal = 0.9\n[excitation]\nlevels = [6.7]\n"
          "eta = { start = 0.98, stop = 0.985, n = 2 }\nwait = 0.1\nhold = 0.1\n[response]\nfigures = ['fig11']\n"
          "series = { r_cont = [1.0, 0.9] }\n")


def test_a_series_of_contact_laws_gives_what_ies_overview_gives(tmp_path, capsys):
    """Fig. 11's study: one response study per r_cont (OUT/r_cont=VALUE), each the numbers of `ies overview --r-cont`,
    the figure and the table of resonant means and dissipation shares."""
    study = tmp_path / "fig11.toml"
    study.write_text(DAMPED)
    assert main(["response", str(study), "--out", str(tmp_path / "series"), "--quiet", "--jobs", "1"]) == 0
    printed = capsys.readouterr().out
    assert "contact / friction / mode 1 / modes 2..N" in printed and "r_cont=0.9" in printed
    assert (tmp_path / "series" / "fig11.png").is_file()
    for r_cont in ("1", "0.9"):
        assert main(["overview", "--levels", "6.7", "--eta", "0.98:0.985:2", "--wait", "0.1", "--hold", "0.1",
                     "--reps", "1", "--seed", "3", "--r-cont", r_cont, "--out", str(tmp_path / f"o{r_cont}")]) == 0
        got = rows(tmp_path / "series" / f"r_cont={r_cont}" / "overview.csv")
        direct = rows(tmp_path / f"o{r_cont}" / "overview.csv")
        assert got[0]["resonant_mean"] == direct[0]["resonant_mean"]
        contact = float(got[0]["dissipation_contact"])
        assert contact == 0.0 if r_cont == "1" else contact > 0.01
    tasks = json.loads(next((tmp_path / "series" / "r_cont=0.9" / "tasks").glob("*.json")).read_text())
    assert "r_cont" in json.dumps(tasks)


@pytest.mark.parametrize("extra, phrase", [
    ("[parameters.r_cont]\nnominal = 1.2\n", "r_cont must lie in (0, 1]"),
    ("[study2]\n", "unknown table"),
    ("[response]\nseries = { mass = [0.02] }\n", "'mass' is not a parameter of the study"),
])
def test_bad_contact_law_study_is_one_line(tmp_path, capsys, extra, phrase):
    path = tmp_path / "bad.toml"
    path.write_text(TINY.format(extra=extra).replace("[study]\n", "[study]\ncontact_law = 'hertz-damped'\n", 1))
    assert main(["response", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert phrase in err and len(err.strip().splitlines()) == 1 and not (tmp_path / "o").exists()
