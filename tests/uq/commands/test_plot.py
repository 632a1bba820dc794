"""`ies plot DIR`: every kind of result folder is redrawn from its data (formats, style, levels, --out) without
recomputing; bad requests are one line and create nothing. Also what `ies interval` and `ies sobol` print."""
import json

import pytest

from uq.cli import main

FAST = ["--eta", "0.975:0.985:3", "--wait", "0.1", "--hold", "0.1", "--reps", "2"]
AB = "[parameters.a]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n[parameters.b]\nnominal = 0.5\nmin = 0.0\nmax = 1.0\n"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """One folder of each kind: ies sweep --out, ies overview --out, an interval, a Sobol' and a response study."""
    root = tmp_path_factory.mktemp("results")
    assert main(["sweep", "--level", "6.7", *FAST, "--out", str(root / "sweep")]) == 0
    assert main(["overview", "--levels", "5.3,6.7", *FAST, "--out", str(root / "overview")]) == 0
    interval = root / "interval.toml"
    interval.write_text("[study]\nkind = 'interval'\nrepetitions = 2\n[parameters.k_H]\n[parameters.g]\n[excitation]\n"
                        "levels = [5.3, 6.7]\neta = { start = 0.975, stop = 0.985, n = 3 }\nwait = 0.1\nhold = 0.1\n"
                        "[interval]\ndesigns = ['individual', 'joint', 'residual']\n")
    assert main(["interval", str(interval), "--out", str(root / "reproduce" / "fig7"), "--quiet", "--jobs", "1"]) == 0
    sobol = root / "sobol.toml"
    sobol.write_text("[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:noisy_linear'\nrepetitions = 2\n" + AB +
                     "[sobol]\nn = 16\n")
    assert main(["sobol", str(sobol), "--out", str(root / "sobol"), "--quiet", "--jobs", "1"]) == 0
    response = root / "response.toml"
    response.write_text("[study]\nkind = 'response'\nrepetitions = 2\n[excitation]\nlevels = [5.3, 6.7]\n"
                        "eta = { start = 0.975, stop = 0.985, n = 3 }\nwait = 0.1\nhold = 0.1\n")
    assert main(["response", str(response), "--out", str(root / "reproduce" / "fig6"), "--quiet", "--jobs", "1"]) == 0
    return root


def stamps(folder):
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if p.suffix in (".csv", ".json")}


@pytest.mark.parametrize("folder, figures", [
    ("sweep", ["fig5.svg"]), ("overview", ["fig6.svg"]), ("reproduce/fig7", ["individual-variation.svg", "joint-variation.svg",
                                                                               "nominal-levels.svg"]),
    ("sobol", ["sobol.svg"]), ("reproduce/fig6", ["fig5.svg", "fig6.svg"]),
    ("reproduce", ["fig7/individual-variation.svg", "fig6/fig6.svg"])])
def test_every_result_folder_is_redrawn_from_its_data(results, tmp_path, capsys, folder, figures):
    data = stamps(results)
    out = tmp_path / "figures"
    assert main(["plot", str(results / folder), "--format", "svg", "--style", "grayscale", "--out", str(out)]) == 0
    written = capsys.readouterr().out.splitlines()
    for name in figures:
        assert (out / name).stat().st_size > 1000 and f"wrote {out / name}" in written, name
    assert stamps(results) == data  # nothing recomputed or rewritten
    assert not list(out.rglob("*.png"))  # only the formats asked for


def test_a_subset_of_levels(results, tmp_path, capsys):
    out = tmp_path / "figures"
    assert main(["plot", str(results / "overview"), "--levels", "6.7", "--out", str(out), "--format", "png"]) == 0
    assert (out / "fig6.png").is_file()
    assert main(["plot", str(results / "reproduce" / "fig7"), "--levels", "5.3", "--out", str(out)]) == 0
    assert (out / "joint-variation.pdf").is_file()  # a study of one's own: its figures named by what they show
    capsys.readouterr()


@pytest.mark.parametrize("args, phrase", [
    (["--levels", "9.9"], "has none of the levels 9.9"),
    (["--style", "no-such-style"], "unknown matplotlib style 'no-such-style'"),
    (["--format", "xyz"], "unsupported figure format(s) .xyz"),
])
def test_bad_requests_are_one_line_and_create_nothing(results, tmp_path, capsys, args, phrase):
    out = tmp_path / "figures"
    assert main(["plot", str(results / "overview"), *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert phrase in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    if "--levels" not in args:
        assert not out.exists()


def test_a_folder_without_results_is_one_line(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "holds no result that can be redrawn" in err and len(err.strip().splitlines()) == 1
    assert main(["plot", str(tmp_path / "missing")]) == 2
    assert "is not a folder" in capsys.readouterr().err


def test_interval_prints_its_bands_with_noise_and_checks(results, tmp_path, capsys):
    interval = results / "interval.toml"
    assert main(["interval", str(interval), "--out", str(tmp_path / "again"), "--quiet", "--jobs", "1",
                 "--no-figures"]) == 0
    text = capsys.readouterr().out
    assert "lower +- SE" in text and "change of the resonant level from each parameter's min to its max" in text
    bands = json.loads((tmp_path / "again" / "study.json").read_text())["summary"]["monotone"]
    for design in ("individual:k_H", "individual:g", "joint", "residual"):
        assert f"{design}/mean" in bands
        assert any(line.strip().startswith(design) for line in text.splitlines())


def test_sobol_prints_indices_and_says_when_noise_dominates(tmp_path, capsys):
    path = tmp_path / "s.toml"
    head = "[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:{f}'\nrepetitions = 2\nseed = 1\n" + AB + "[sobol]\nn = 32\n"
    path.write_text(head.format(f="noisy_linear"))
    assert main(["sobol", str(path), "--out", str(tmp_path / "signal"), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    text = capsys.readouterr().out
    assert "Sobol' indices (95% confidence intervals" in text and "S1 " in text and "ST " in text
    assert "repetition noise" in text and "dominates" not in text  # Var(a + 2b) = 5/12 >> 0.2^2 / 2
    path.write_text(head.format(f="pure_noise"))
    assert main(["sobol", str(path), "--out", str(tmp_path / "noise"), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    text = capsys.readouterr().out
    assert "the repetition noise dominates" in text and "raise [study] repetitions" in text
