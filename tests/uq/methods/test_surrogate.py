"""Sobol' indices from a polynomial-chaos surrogate (uq.methods.surrogate, `ies sobol --method pce`): the Ishigami function's
analytic indices (SALib's test function), a toy study end to end, the not-smooth verdict, and bad input in one line."""
import csv
import json

import numpy as np
import pytest

from tests.support import AB_PARAMETERS
from uq.cli import main
from uq.problem.space import Parameter, ParameterSpace

pytest.importorskip("openturns")
from uq.methods.surrogate import basis_size, pce_indices, pce_sample

A, B = 7.0, 0.1
AB = AB_PARAMETERS


def ishigami(X):
    return np.sin(X[:, 0]) + A * np.sin(X[:, 1]) ** 2 + B * X[:, 2] ** 4 * np.sin(X[:, 0])


def ishigami_analytic():
    """Closed-form indices (Ishigami & Homma 1990; Sobol' & Levitan 1999): S1 and ST of x1, x2, x3."""
    pi = np.pi
    V1, V2, V13 = 0.5 * (1 + B * pi**4 / 5) ** 2, A**2 / 8, B**2 * pi**8 * (1 / 18 - 1 / 50)
    V = V1 + V2 + V13
    return np.array([V1, V2, 0.0]) / V, np.array([V1 + V13, V2, V13]) / V


@pytest.fixture(scope="module")
def space():
    return ParameterSpace(tuple(Parameter(f"x{i + 1}", 0.0, -np.pi, np.pi, positive=False) for i in range(3)))


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_ishigami_indices_match_the_analytic_ones(space):
    X = pce_sample(space, 300, seed=1)  # 300 runs against Saltelli's 8192 (k + 2) of test_uq_sobol
    res = pce_indices(space, X, ishigami(X), degree=8, num_resamples=10, seed=2)
    S1, ST = ishigami_analytic()
    assert np.max(np.abs(res.S1 - S1)) < 0.02 and np.max(np.abs(res.ST - ST)) < 0.02, (res.S1, res.ST)
    assert res.smooth and res.cv_error < 0.01 and res.noise_share == 0.0
    assert np.all(res.S1_conf > 0) and np.all(res.ST_conf < 0.02)


def test_a_jump_is_flagged_not_smooth(space):
    X = pce_sample(space, 120, seed=0)
    jump = np.where(X[:, 0] > 0.3, 1.0, 0.0) + 0.05 * X[:, 1]  # the jump carries most of the variance
    res = pce_indices(space, X, jump, degree=4, num_resamples=5)
    assert not res.smooth and "cross-validated error" in res.rough
    smooth = pce_indices(space, X, 0.2 * X[:, 1] + X[:, 0], degree=4, num_resamples=5,
                         regimes=["APR"] * 60 + ["SMR"] * 60)
    assert not smooth.smooth and "different regimes (APR 60, SMR 60 points)" in smooth.rough  # the regime column


def test_toy_study_end_to_end(tmp_path, capsys):
    # noisy_linear: a + 2 b + level + noise: S_a = (1/12) / (5/12) = 0.2, S_b = 0.8, no interaction
    path = tmp_path / "s.toml"
    path.write_text("[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:noisy_linear'\nrepetitions = 3\nseed = 4\n"
                    + AB + "[sobol]\nmethod = 'pce'\npoints = 24\ndegree = 2\nbootstrap = 50\n")
    out = tmp_path / "o"
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    printed = capsys.readouterr().out
    assert "from a polynomial-chaos surrogate" in printed and "surrogate: degree 2" in printed
    assert len(rows(out / "runs.csv")) == 24 * 3
    res = {r["parameter"]: r for r in rows(out / "sobol.csv")}
    for name, exact in (("a", 0.2), ("b", 0.8)):
        for index in ("S1", "ST"):
            assert float(res[name][index]) == pytest.approx(exact, abs=0.05)
            assert abs(float(res[name][index]) - exact) <= 3 * float(res[name][f"{index}_conf"]) + 0.01
    fit = rows(out / "surrogate.csv")[0]
    assert fit["smooth"] == "1" and int(fit["points"]) == 24 and float(fit["cv_error"]) < 0.1
    share = float(rows(out / "variance.csv")[0]["noise_share"])  # (0.2^2 / 3) / (5/12 + 0.2^2 / 3)
    assert share == pytest.approx(0.04 / 3 / (5 / 12 + 0.04 / 3), rel=0.5)
    meta = json.loads((out / "study.json").read_text())
    assert meta["summary"]["method"] == "pce" and meta["summary"]["smooth"] is True
    assert meta["study"]["sobol"]["method"] == "pce" and meta["study"]["sobol"]["points"] == 24


def test_a_jump_in_a_study_is_said_not_smooth(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text("[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:step'\n" + AB
                    + "[sobol]\nmethod = 'pce'\npoints = 40\ndegree = 3\nbootstrap = 5\n")
    out = tmp_path / "o"
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    captured = capsys.readouterr()
    assert "NOT SMOOTH" in captured.err and "unreliable" in captured.out and "method = \"saltelli\"" in captured.out
    meta = json.loads((out / "study.json").read_text())
    assert meta["summary"]["smooth"] is False and meta["summary"]["per_level"]["value@1"]["smooth"] is False
    assert rows(out / "surrogate.csv")[0]["smooth"] == "0"


BAD = [
    ("[study]\nkind = 'interval'\nmodel = 'ishigami'\n[sobol]\nmethod = 'pce'\n", [], "applies to kind = \"sobol\" only"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\nmethod = 'pce'\npoints = 12\ndegree = 3\n", [],
     "points = 12 is too few for degree 3 in 3 parameters (20 polynomial terms)"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n", ["--method", "pce", "--points", "9"], "too few for degree 2"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n", ["--method", "pce", "--n", "64"], "--n applies to method saltelli only"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n", ["--points", "40"], "--points applies to method pce only"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\nmethod = 'kriging'\n", [], "method must be one of"),
    ("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\ndegree = 3\n", [], "degree only applies to method"),
]


@pytest.mark.parametrize("text, options, message", BAD)
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, capsys, text, options, message):
    path = tmp_path / "s.toml"
    path.write_text(text)
    kind = "interval" if "interval" in text else "sobol"
    assert main([kind, str(path), "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1", *options]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "o").exists()


def test_bad_degree_on_resume_loses_nothing(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\nmethod = 'pce'\npoints = 20\nbootstrap = 5\n")
    out = tmp_path / "o"
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--resume", "--degree", "4"]) == 2
    assert f"too few for degree 4 in 3 parameters ({basis_size(3, 4)} polynomial terms)" in capsys.readouterr().err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_missing_openturns_names_the_extra(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "openturns", None)  # import openturns -> ImportError
    path = tmp_path / "s.toml"
    path.write_text("[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\nmethod = 'pce'\n")
    assert main(["sobol", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "ies-workbench[surrogate]" in err and len(err.splitlines()) == 1


def test_noisy_ishigami_both_definitions_both_methods(space):
    """Ishigami plus noise drawn anew at every evaluation (as the chaotic IES scatters): analytically, Saltelli's
    estimators see S1 = V_i / (V + s2) and ST = (V_Ti + s2) / (V + s2) (s2 the noise variance of a repetition mean),
    and the noise-free indices are V_i / V, V_Ti / V. Saltelli's sample and the surrogate, with 68 times fewer
    points, must give both definitions (uq.methods.sobol.noise_free / with_noise)."""
    from uq.methods.sobol import sobol_indices, sobol_sample

    S1, ST = ishigami_analytic()
    pi = np.pi
    V = 0.5 * (1 + B * pi**4 / 5) ** 2 + A**2 / 8 + B**2 * pi**8 * (1 / 18 - 1 / 50)
    s2 = 0.25 * V  # noise variance of the mean of two repetitions: a share of 0.2 of the variance
    S1_noisy, ST_noisy = S1 * V / (V + s2), (ST * V + s2) / (V + s2)
    rng = np.random.default_rng(11)

    def runs(X):  # two repetitions per point, each with noise variance 2 s2
        return ishigami(X)[:, None] + np.sqrt(2 * s2) * rng.standard_normal((len(X), 2))

    X = sobol_sample(space, 2**13, seed=7)
    saltelli = sobol_indices(space, X, runs(X), num_resamples=100, seed=3)
    X = pce_sample(space, 600, seed=1)
    Y = runs(X)
    pce = pce_indices(space, X, Y.mean(axis=1), degree=6, noise=Y.var(axis=1, ddof=1) / 2, num_resamples=3, seed=2)
    for res in (saltelli, pce):
        assert res.noise_share == pytest.approx(0.2, abs=0.03)
        assert np.max(np.abs(res.S1 - S1_noisy)) < 0.04 and np.max(np.abs(res.ST - ST_noisy)) < 0.04, (res.S1, res.ST)
        S1_free, _, ST_free, _ = res.noise_free()
        assert np.max(np.abs(S1_free - S1)) < 0.04 and np.max(np.abs(ST_free - ST)) < 0.04, (S1_free, ST_free)


@pytest.mark.parametrize("method, small, large", [("saltelli", "n = 8", "n = 16"), ("pce", "points = 16", "points = 32")])
def test_a_study_grown_with_resume_reuses_every_run(tmp_path, capsys, method, small, large):
    """Saltelli's sample and the surrogate's Sobol' design are nested: doubling n or points with --resume runs only
    the new points (a convergence check costs the difference)."""
    path = tmp_path / "s.toml"
    text = f"[study]\nkind = 'sobol'\nmodel = 'ishigami'\n[sobol]\nmethod = '{method}'\nbootstrap = 5\n{small}\n"
    path.write_text(text)
    out = tmp_path / "o"
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    first = len(rows(out / "runs.csv"))
    path.write_text(text.replace(small, large))
    capsys.readouterr()
    assert main(["sobol", str(path), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures", "--resume"]) == 0
    assert f"{2 * first} runs ({first} run now, {first} reused)" in capsys.readouterr().out
