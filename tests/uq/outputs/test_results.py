"""Reading a finished interval study back: the trend table and the influence ranking (uq.outputs.results)."""
import csv

import pytest

from uq.outputs.results import effects, influence, influence_line


def _study(folder, rows):
    fields = ["design", "role", "output", "level", "D", "k_H_N_per_m1p5", "mean", "se", "regime"]
    with open(folder / "points.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fields)
        writer.writeheader()
        for r in rows:
            writer.writerow({**{"D": "", "k_H_N_per_m1p5": "", "regime": ""}, **r})


def _rows(level, nominal, regime, d_lo, d_hi, k_lo, k_hi, se=0.001):
    rows = [dict(design="nominal", role="nominal", output="mean", level=level, mean=nominal, se=se, regime=regime)]
    for name, column, lo, hi in (("D", "D", d_lo, d_hi), ("k_H", "k_H_N_per_m1p5", k_lo, k_hi)):
        rows.append(dict(design=f"individual:{name}", role="corner", output="mean", level=level, mean=hi, se=se,
                         **{column: 2.0}))  # the max first: effects() orders by the parameter's value
        rows.append(dict(design=f"individual:{name}", role="corner", output="mean", level=level, mean=lo, se=se,
                         **{column: 1.0}))
    return rows


def test_influence_ranks_by_the_mean_change_over_the_almost_periodic_levels(tmp_path):
    # level 5: SMR, D would dominate but is ignored; 7: D -10 %, k_H -30 %; 9: D -20 %, k_H -10 %
    _study(tmp_path, _rows(5.0, 0.05, "SMR", 0.06, 0.01, 0.05, 0.05) + _rows(7.0, 0.3, "APR", 0.33, 0.30, 0.36, 0.27)
           + _rows(9.0, 0.4, "APR", 0.44, 0.36, 0.42, 0.38))
    assert [e.relative for e in effects(tmp_path) if e.parameter == "D"] == pytest.approx([-1.0, -0.1, -0.2])
    ranked = influence(tmp_path)
    assert [i.parameter for i in ranked] == ["k_H", "D"]
    assert ranked[0].mean_change == pytest.approx(0.2) and ranked[1].mean_change == pytest.approx(0.15)
    assert ranked[0].levels == (7.0, 9.0)
    assert [i.parameter for i in influence(tmp_path, regime="any")] == ["D", "k_H"]
    assert influence_line(tmp_path).startswith("largest influence first, mean |change| over the almost periodic "
                                               "levels 7, 9: k_H 20.0%")


def test_influence_without_almost_periodic_levels(tmp_path):
    _study(tmp_path, _rows(5.0, 0.05, "linear", 0.06, 0.01, 0.05, 0.05))
    assert influence(tmp_path) == []
    assert "not ranked" in influence_line(tmp_path)
