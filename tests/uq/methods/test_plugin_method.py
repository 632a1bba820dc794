"""A new UQ method is one file plus one registry line: a Gaussian-process (kriging) surrogate of the Sobol' indices,
written here as a user would write it in `uq/methods/kriging.py`, registered, and run end to end by `ies sobol
--method kriging` (the study file's reading, the command's options, the execution, sobol.csv, variance.csv, the
method's own table, results.nc and the figure all come from the contract, `uq.problem.method`).

Reference: the linear model a + 2 b (+ level) of `uq.problem.test_functions.noisy_linear` over the unit square, whose
noise-free indices are S_a = 1/5, S_b = 4/5 (Var a = 1/12, Var 2b = 4/12; additive: S1 = ST), and whose repetition
noise is SIGMA^2 / r for the mean of r runs.
"""
from __future__ import annotations

import csv
import json
from typing import Any

import numpy as np
import pytest

from tests.support import AB_PARAMETERS

pytest.importorskip("openturns")


def kriging_method() -> Any:
    """The plug-in: what `uq/methods/kriging.py` would hold."""
    from sim.common.options import positive_int
    from sim.common.outputs import Column, OutputFile
    from uq.methods.sobol import SHARED_SETTINGS, SobolMethod, SobolResult, with_noise
    from uq.methods.surrogate import openturns, pce_sample
    from uq.problem.method import Table
    from uq.problem.study import Setting, check_number

    FIT_CSV = OutputFile("kriging.csv", "ies sobol, method kriging", "The Gaussian process's fit per output and level.", (
        Column("output", "", "mean or max"),
        Column("level", "a_base/a_base*", "the excitation level"),
        Column("scale", "-", "the Matern kernel's correlation lengths over the unit box, space separated"),
    ))

    class Kriging(SobolMethod):
        """Sobol' indices of a Gaussian-process surrogate (Matern 5/2 kernel, constant trend, OpenTURNS) fitted to a
        scrambled Sobol' design, by Saltelli's estimators on the surrogate (Marrel et al. 2009)."""

        name = "kriging"
        help = "a Gaussian-process (kriging) surrogate of a scrambled Sobol' design (OpenTURNS)"
        settings = (*SHARED_SETTINGS,
                    Setting("points", 32, lambda v, c: int(check_number("[sobol] points", v, integer=True)),
                            "design points of the surrogate", option="--points", metavar="N", parse=positive_int,
                            identity=False))
        tables = (*SobolMethod.tables, Table(FIT_CSV, dims={"level": "level"}, split="output"))

        def sample(self, study: Any) -> np.ndarray:
            return pce_sample(study.space, study.settings["points"], seed=study.seed)

        def indices(self, study: Any, X: np.ndarray, value: np.ndarray, se: np.ndarray,
                    regimes: list[str]) -> SobolResult:
            ot = openturns()
            space, k = study.space, len(study.space.varied)
            lo, hi = np.array(space.salib_problem()["bounds"], dtype=float).T
            U = (X - lo) / (hi - lo)
            kernel = ot.MaternModel([0.3] * k, [float(np.std(value))], 2.5)
            fitter = ot.GaussianProcessFitter(ot.Sample(U), ot.Sample(value[:, None]), kernel,
                                              ot.ConstantBasisFactory(k).build())
            fitter.run()
            regression = ot.GaussianProcessRegression(fitter.getResult())
            regression.run()
            surrogate = regression.getResult().getMetaModel()
            ot.RandomGenerator.SetSeed(study.seed)
            size = 4096
            design = ot.SobolIndicesExperiment(ot.JointDistribution([ot.Uniform(0.0, 1.0)] * k), size).generate()
            saltelli = ot.SaltelliSensitivityAlgorithm(design, surrogate(design), size)
            saltelli.setBootstrapSize(study.settings["bootstrap"])
            saltelli.setConfidenceLevel(study.settings["confidence"])
            S1, ST = np.array(saltelli.getFirstOrderIndices()), np.array(saltelli.getTotalOrderIndices())
            half = lambda interval: 0.5 * (np.array(interval.getUpperBound()) - np.array(interval.getLowerBound()))
            S1_conf, ST_conf = half(saltelli.getFirstOrderIndicesInterval()), half(saltelli.getTotalOrderIndicesInterval())
            variance, noise = float(np.var(value, ddof=1)), float(np.mean(se**2))
            self.scale = np.array(fitter.getResult().getCovarianceModel().getScale())
            return SobolResult(space.salib_problem()["names"], *with_noise(S1, S1_conf, ST, ST_conf, noise / variance),
                               variance=variance, noise_variance=noise, noise_share=noise / variance,
                               confidence=study.settings["confidence"])

        def level_rows(self, output: str, level: float, result: SobolResult) -> dict[str, list[Any]]:
            return {"kriging.csv": [output, level, " ".join(f"{s:.4g}" for s in self.scale)]}

    return Kriging()


@pytest.fixture
def registered(monkeypatch):
    """The registry with the plug-in added (the one line), restored after the test."""
    import uq.methods

    monkeypatch.setattr(uq.methods, "METHODS", dict(uq.methods.METHODS))
    return uq.methods.register(kriging_method())


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_a_gaussian_process_method_is_one_file_and_one_registry_line(registered, tmp_path, capsys):
    from uq.cli import main
    from uq.outputs.results import open_study
    from uq.problem.test_functions import SIGMA

    study = tmp_path / "gp.toml"
    reps = 4
    study.write_text("[study]\nkind = 'sobol'\nmodel = 'uq.problem.test_functions:noisy_linear'\nseed = 3\n"
                     f"repetitions = {reps}\n[excitation]\nlevels = [1.0]\n[sobol]\nmethod = 'kriging'\npoints = 32\nbootstrap = 50\n"
                     + AB_PARAMETERS)
    assert main(["sobol", str(study), "--out", str(tmp_path / "o"), "--quiet", "--jobs", "1"]) == 0
    out = tmp_path / "o"
    indices = {r["parameter"]: r for r in rows(out / "sobol.csv")}
    for name, exact in (("a", 0.2), ("b", 0.8)):  # the noise-free indices of a + 2 b
        assert float(indices[name]["S1_noise_free"]) == pytest.approx(exact, abs=0.04)
        assert float(indices[name]["ST_noise_free"]) == pytest.approx(exact, abs=0.04)
    share = float(rows(out / "variance.csv")[0]["noise_share"])
    assert share == pytest.approx((SIGMA**2 / reps) / (5 / 12 + SIGMA**2 / reps), rel=0.5)
    assert len(rows(out / "kriging.csv")) == 1 and (out / "sobol.png").stat().st_size > 1000
    meta = json.loads((out / "study.json").read_text())
    assert meta["study"]["sobol"] == {"method": "kriging", "bootstrap": 50, "confidence": 0.95, "points": 32}
    ds = open_study(out)
    assert ds.attrs["sobol_method"] == "kriging" and "value_S1" in ds and "value_scale" in ds
    # the command line's --method chooses it over a study file that names another method
    study.write_text(study.read_text().replace("method = 'kriging'\npoints = 32\nbootstrap = 50\n", "n = 8\nbootstrap = 50\n"))
    assert main(["sobol", str(study), "--method", "kriging", "--out", str(tmp_path / "p"), "--quiet"]) == 0
    assert len(rows(tmp_path / "p" / "sobol.csv")) == 2 and len(rows(tmp_path / "p" / "kriging.csv")) == 1
