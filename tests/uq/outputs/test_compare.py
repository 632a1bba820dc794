"""`ies compare`: the landmarks of response studies side by side, read back from the studies' own files (study.json
landmarks, overview.csv), with the paper's row; bad folders are one line, exit 2, nothing written."""
import csv
import json
import math

import pytest

from uq.cli import main

STUDY = ("[study]\nkind = 'response'\nname = '{name}'\nseed = 5\nrepetitions = 2\n[excitation]\nlevels = [6.7, 7.4]\n"
         "eta = {{ start = 0.97, stop = 0.98, n = 3 }}\nwait = 0.2\nhold = 0.3\n{extra}[response]\nfigures = ['fig6']\n")


@pytest.fixture(scope="module")
def studies(tmp_path_factory):
    """Two small response studies: the built-in rig and the sphere 20 % heavier in x."""
    root = tmp_path_factory.mktemp("compare")
    folders = []
    for name, extra in (("nominal", ""), ("heavier", "[variant]\nsphere_mass_factor = 1.2\n")):
        path = root / f"{name}.toml"
        path.write_text(STUDY.format(name=name, extra=extra))
        assert main(["response", str(path), "--out", str(root / name), "--quiet", "--jobs", "1", "--no-figures"]) == 0
        folders.append(root / name)
    return folders


def test_the_rows_are_the_studies_own_landmarks_and_resonant_measures(studies, tmp_path, capsys):
    capsys.readouterr()
    out = tmp_path / "cmp"
    assert main(["compare", *map(str, studies), "--out", str(out), "--format", "png"]) == 0
    text = capsys.readouterr().out
    assert "nominal" in text and "heavier" in text and "paper" in text and "~6.7" in text
    with open(out / "compare.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["study"] for r in rows] == ["nominal", "heavier", "paper"]
    for row, folder in zip(rows, studies):
        meta = json.loads((folder / "study.json").read_text())
        with open(folder / "overview.csv", newline="") as fh:
            at_7_4 = next(r for r in csv.DictReader(fh) if float(r["level"]) == 7.4)
        for key in ("optimum_level", "reduction_mean", "reduction_max"):
            assert float(row[key]) == meta["landmarks"][key], key
        for key in ("last_smr", "first_apr"):
            expected = meta["landmarks"][key]
            assert (math.isnan(float(row[key])) and expected is None) or float(row[key]) == expected, key
        for key in ("resonant_mean", "resonant_mean_lo", "resonant_mean_hi", "significant_impacts_per_period",
                    "restitution", "higher_mode_energy_share", "impacts_per_period"):
            assert row[f"{key}_7.4"] == at_7_4[key], key
        assert row["regime_7.4"] == at_7_4["regime"] and row["resonant_mean_9"] == "nan"  # 9 is not a level
    assert float(rows[2]["resonant_mean_lo_7.4"]) == 0.14 and float(rows[2]["significant_impacts_per_period_7.4"]) == 2
    assert json.loads((out / "compare.json").read_text())["paper"]["optimum_level"] == 6.7
    assert (out / "fig6-compare.png").is_file() and not (out / "fig6-compare.pdf").exists()


def test_json_rows_on_stdout(studies, tmp_path, capsys):
    capsys.readouterr()
    assert main(["compare", str(studies[0]), "--out", str(tmp_path / "c"), "--format", "svg", "--json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert [r["study"] for r in data["studies"]] == ["nominal"] and "wrote" in captured.err


@pytest.mark.parametrize("what, phrase", [("missing", "is not a folder"), ("empty", "no readable study.json"),
                                          ("interval", "not a response study (kind 'interval')"), ("unfinished", "no landmarks"),
                                          ("series", "series response study")])
def test_a_folder_that_is_not_a_finished_response_study_is_one_line(studies, tmp_path, capsys, what, phrase):
    bad = tmp_path / what
    if what != "missing":
        bad.mkdir()
    if what == "interval":
        (bad / "study.json").write_text(json.dumps({"study": {"kind": "interval"}}))
    if what in ("unfinished", "series"):
        extra = {"series_folders": ["D=0.001"]} if what == "series" else {}
        (bad / "study.json").write_text(json.dumps({"study": {"kind": "response"}, **extra}))
    capsys.readouterr()
    out = tmp_path / "cmp"
    assert main(["compare", str(studies[0]), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert phrase in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()


def test_out_that_is_a_file_and_an_unknown_style_write_nothing(studies, tmp_path, capsys):
    target = tmp_path / "file"
    target.write_text("keep")
    assert main(["compare", str(studies[0]), "--out", str(target)]) == 2
    assert "exists and is not a folder" in capsys.readouterr().err and target.read_text() == "keep"
    assert main(["compare", str(studies[0]), "--out", str(tmp_path / "c"), "--style", "no-such-style"]) == 2
    assert "unknown matplotlib style" in capsys.readouterr().err and not (tmp_path / "c").exists()
