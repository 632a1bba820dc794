"""What a finished design is (the screening, the verified designs, the recommendation) and what `ies design` writes
and prints: design.csv, design-levels.csv, design.json, results.nc and the table of the verified designs."""
from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sim.common.outputs import Column, OutputFile
from uq.design.problem import DesignProblem, Sphere, micrometres


@dataclass(frozen=True)
class Screened:
    """The screening of the grid: per design (`designs`, grid order) the worst case over the uncertainty ends of the
    predicted resonant tip amplitude (m) at each operating level (`tip`, shape designs x levels), its regime there
    (`regime`), the base amplitude of the predicted switch to the almost periodic response (`switch`, m) and the
    design's worst case over the levels (`worst`, m; inf for designs that do not fit)."""

    designs: list[Sphere]
    tip: np.ndarray
    regime: np.ndarray
    switch: np.ndarray
    worst: np.ndarray
    seconds: float


@dataclass(frozen=True)
class Verified:
    """One verified design: per operating level the band (m) of the resonant tip amplitude over the corners (low,
    high; averaged over the repetitions), the nominal point's value, the fraction of runs in the almost periodic
    regime, whether the nominal point left the corners' band beyond the repetition noise (monotonicity check), and
    the worst case over the levels (m)."""

    sphere: Sphere
    low: np.ndarray
    high: np.ndarray
    nominal: np.ndarray
    apr: np.ndarray
    outside: np.ndarray
    runs: int

    @property
    def worst(self) -> float:
        """The worst case (m): the corners' and the nominal point's highest value over the levels."""
        return float(np.max(np.maximum(self.high, self.nominal)))


@dataclass(frozen=True)
class DesignResult:
    """A finished design: the problem, the screening, the verified designs (best first), the recommendation (the best
    verified design), the baseline's verification (if asked), and the folder of its files."""

    problem: DesignProblem
    screened: Screened
    verified: list[Verified]
    folder: Any
    levels: np.ndarray
    no_absorber: np.ndarray
    files: list[Any]

    @property
    def recommendation(self) -> Verified:
        return self.verified[0]

    @property
    def baseline(self) -> Verified | None:
        return next((v for v in self.verified if v.sphere == self.problem.baseline), None)

    def sentence(self) -> str:
        """The recommendation in words and units."""
        best, p = self.recommendation, self.problem
        s = best.sphere
        lo, hi = min(p.excitation), max(p.excitation)
        ratio = float(np.max(self.no_absorber)) / best.worst
        return (f"clearance {s.clearance * 1e3:.2f} mm, {s.material} sphere of radius {s.radius * 1e3:.2f} mm "
                f"({s.mass * 1e3:.1f} g): worst case {best.worst * 1e3:.3g} mm over {micrometres(lo)}-{micrometres(hi)} um, "
                f"{ratio:.1f}x below the structure without IES ({float(np.max(self.no_absorber)) * 1e3:.3g} mm)")


DESIGN_JSON = OutputFile("design.json", "ies design", "The design's settings, host and result.", (
    Column("settings", "", "the design problem (SI units: excitation, clearances, radii in m; D, tolerance and k_H "
                           "factor intervals; objective, candidates, repetitions, restitution, protocol)"),
    Column("host", "", "the host's mode 1 as the slow flow uses it (omega_1 rad/s, D_1, phi_c, phi_tip, participation) "
                       "and the operating levels a_base/a_base*"),
    Column("screening", "", "designs screened, how many fit the cavity, seconds, the restitution r used"),
    Column("verified", "", "every verified design: its variables, worst_m (m), runs, per level low_m, high_m, "
                           "nominal_m (m), apr_fraction, the levels where the monotonicity check failed"),
    Column("recommendation", "", "the best verified design (as in verified), its sentence and "
                                 "reduction_vs_no_absorber (-)"),
    Column("baseline", "", "the baseline's verification and ratio_to_recommendation (-); null without --baseline"),
    Column("no_absorber", "", "the structure without IES: D_1 and tip_m (m) per level"),
    Column("notes", "", "what the design neglects"),
))


DESIGN_KEYS = DESIGN_JSON.names


DESIGN_CSV = OutputFile("design.csv", "ies design", "One row per evaluated design (verified first, best first; then the "
                        "screened ones).", (
    Column("status", "-", "verified, baseline (verified) or screened"),
    Column("material", "-", "sphere material (sim.model.materials)"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("mass_kg", "kg", "sphere mass m_a from R and the density"),
    Column("k_H_N_per_m1p5", "N/m^1.5", "Eq. 8's k_H against the host's steel wall"),
    Column("cavity_m", "m", "cavity width 2R + 2g"),
    Column("fits", "-", "1 if the cavity leaves walls of the minimum thickness"),
    Column("predicted_worst_m", "m", "slow-flow worst case over levels and the D, tolerance ends"),
    Column("predicted_switch_m", "m", "slow-flow base amplitude of the switch to the almost periodic response"),
    Column("worst_m", "m", "verified worst case over levels, uncertainty corners and the nominal point (empty if screened)"),
    Column("worst_level_m", "m", "base amplitude a_base where the verified worst case occurs"),
    Column("regimes", "-", ("per operating level: A (almost periodic in most runs), S (strongly modulated), L (no impacts "
                      "predicted); verified designs from the runs, screened ones from the slow flow")),
))


DESIGN_LEVELS_CSV = OutputFile("design-levels.csv", "ies design", "One row per verified design and operating level.", (
    Column("material", "-", "sphere material"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("a_base_m", "m", "operating base amplitude"),
    Column("level", "-", "a_base / a_base* (a_base* of the paper's nominal D*, g*)"),
    Column("low_m", "m", "lowest resonant tip amplitude over the uncertainty corners (mean of the repetitions)"),
    Column("high_m", "m", "highest resonant tip amplitude over the uncertainty corners"),
    Column("nominal_m", "m", "resonant tip amplitude at the box's centre"),
    Column("outside", "-", "1 if the centre left the corners' band beyond 2 standard errors (monotonicity check failed)"),
    Column("apr_fraction", "-", "fraction of runs in the almost periodic regime"),
    Column("predicted_m", "m", "slow-flow prediction (worst over the D and tolerance ends)"),
    Column("no_absorber_m", "m", "the structure without IES at the lower end of D"),
))


def _regime_letters(values: Sequence[Any]) -> str:
    return "".join({"APR": "A", "SMR": "S", "linear": "L"}.get(str(v), "?") for v in values)


def write_design(result: DesignResult, mode: Any) -> list[Any]:
    """design.csv, design-levels.csv and design.json (all written atomically)."""
    from sim.common.files import dumps, write_csv, write_text

    p, s = result.problem, result.screened
    verified = {v.sphere: v for v in result.verified}
    index = {d: i for i, d in enumerate(s.designs)}
    rows = []
    for d in [*(v.sphere for v in result.verified), *(d for d in s.designs if d not in verified)]:
        v, i = verified.get(d), index.get(d)
        status = ("baseline" if d == p.baseline else "verified") if v else "screened"
        regimes = (_regime_letters("APR" if f > 0.5 else "SMR" for f in v.apr) if v
                   else _regime_letters(s.regime[i]))
        worst_at = p.excitation[int(np.argmax(np.maximum(v.high, v.nominal)))] if v else None
        rows.append([status, d.material, d.clearance, d.radius, d.mass, d.k_H, d.cavity(), int(p.fits(d)),
                     s.worst[i] if i is not None and np.isfinite(s.worst[i]) else None,
                     s.switch[i] if i is not None else None, v.worst if v else None, worst_at, regimes])
    level_rows = []
    for v in result.verified:
        i = index.get(v.sphere)
        for k, a_base in enumerate(p.excitation):
            level_rows.append([v.sphere.material, v.sphere.clearance, v.sphere.radius, a_base, result.levels[k],
                               v.low[k], v.high[k], v.nominal[k], int(v.outside[k]), v.apr[k],
                               s.tip[i, k] if i is not None else None, result.no_absorber[k]])
    folder = result.folder
    files = [write_csv(folder / "design.csv", DESIGN_CSV.names, rows),
             write_csv(folder / "design-levels.csv", DESIGN_LEVELS_CSV.names, level_rows)]

    def verified_data(v: Verified) -> dict[str, Any]:
        return {**v.sphere.describe(), "worst_m": v.worst, "runs": v.runs, "low_m": v.low, "high_m": v.high,
                "nominal_m": v.nominal, "apr_fraction": v.apr, "monotonicity_failed_at_m":
                [a for a, o in zip(p.excitation, v.outside) if o]}

    best = result.recommendation
    data = {
        "settings": {**{k: v for k, v in dataclasses.asdict(p).items() if k != "baseline"},
                     "baseline": p.baseline and dataclasses.asdict(p.baseline)},
        "host": {"source": p.modal_file or "built-in rig", "omega_1_rad_per_s": mode.omega, "D_1": mode.D,
                 "phi_c": mode.phi_c, "phi_tip": mode.phi_tip, "participation": mode.participation,
                 "levels": result.levels},
        "screening": {"designs": len(s.designs), "fitting": int(np.isfinite(s.worst).sum()), "seconds": s.seconds,
                      "restitution": p.restitution},
        "verified": [verified_data(v) for v in result.verified],
        "recommendation": {**verified_data(best), "sentence": result.sentence(),
                           "reduction_vs_no_absorber": float(np.max(result.no_absorber)) / best.worst},
        "baseline": (None if result.baseline is None else
                     {**verified_data(result.baseline), "ratio_to_recommendation": result.baseline.worst / best.worst}),
        "no_absorber": {"D_1": min(p.D), "tip_m": result.no_absorber},
        "notes": ["the host's modes are taken as they are: the change of the host's mass by the cavity is neglected",
                  "k_H from Eq. 8 (sphere on the host's flat steel wall), scaled by the k_H factor interval",
                  "dry friction is not modelled in the design (it would break the similarity law)"],
    }
    files.append(write_text(folder / "design.json", dumps(data) + "\n"))
    files.append(write_design_netcdf(result, data))
    return files


def write_design_netcdf(result: DesignResult, data: Mapping[str, Any]) -> Any:
    """results.nc of a design (`uq.outputs.netcdf` conventions): the verified designs x operating levels (band, centre, APR
    fraction, slow-flow prediction) and every screened design's variables and predicted worst case, with units."""
    from pathlib import Path

    import xarray as xr

    from sim.common.files import atomic_path, dumps
    from uq.outputs.netcdf import ENGINE

    p, s = result.problem, result.screened
    v = result.verified
    index = {d: i for i, d in enumerate(s.designs)}
    nan_row = np.full(len(p.excitation), np.nan)

    def design_coords(spheres: Sequence[Sphere], dim: str) -> dict[str, Any]:
        return {f"{dim}_clearance": (dim, [x.clearance for x in spheres], {"units": "m", "long_name": "clearance g"}),
                f"{dim}_radius": (dim, [x.radius for x in spheres], {"units": "m", "long_name": "sphere radius R"}),
                f"{dim}_material": (dim, [x.material for x in spheres], {"long_name": "sphere material"}),
                f"{dim}_mass": (dim, [x.mass for x in spheres], {"units": "kg", "long_name": "sphere mass m_a"})}

    metres = {"units": "m"}
    ds = xr.Dataset(
        {"low": (("design", "level"), [x.low for x in v], {**metres, "long_name": "lowest resonant tip amplitude "
                                                                                "over the uncertainty corners"}),
         "high": (("design", "level"), [x.high for x in v], {**metres, "long_name": "highest resonant tip amplitude "
                                                                                  "over the uncertainty corners"}),
         "nominal": (("design", "level"), [x.nominal for x in v], {**metres, "long_name": "resonant tip amplitude at "
                                                                                        "the box's centre"}),
         "apr_fraction": (("design", "level"), [x.apr for x in v], {"units": "1", "long_name": "fraction of runs in "
                                                                                              "the APR regime"}),
         "predicted": (("design", "level"), [s.tip[index[x.sphere]] if x.sphere in index else nan_row for x in v],
                       {**metres, "long_name": "slow-flow resonant tip amplitude (worst over the D, tolerance ends)"}),
         "worst": ("design", [x.worst for x in v], {**metres, "long_name": "verified worst case"}),
         "no_absorber": ("level", result.no_absorber, {**metres, "long_name": "resonant tip amplitude without IES"}),
         "screened_worst": ("screened", np.where(np.isfinite(s.worst), s.worst, np.nan),
                            {**metres, "long_name": "slow-flow worst case (NaN: the cavity does not fit)"})},
        coords={"level": ("level", result.levels, {"units": "1", "long_name": "excitation level a_base/a_base*"}),
                "a_base": ("level", np.asarray(p.excitation), {**metres, "long_name": "operating base amplitude"}),
                **design_coords([x.sphere for x in v], "design"), **design_coords(s.designs, "screened")},
        attrs={"Conventions": "CF-1.10", "title": "ies-workbench design", "kind": "design",
               "recommendation": data["recommendation"]["sentence"], "settings": dumps(data["settings"])})
    path = Path(result.folder) / "results.nc"
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=ENGINE)
    return path


def design_table(result: DesignResult) -> str:
    """The printed table of the verified designs (best first), ending with the recommendation in words."""
    p = result.problem
    lines = [f"screened {len(result.screened.designs)} designs in {result.screened.seconds:.2f} s "
             f"({int(np.isfinite(result.screened.worst).sum())} fit the cavity); verified {len(result.verified)} by "
             f"{sum(v.runs for v in result.verified)} runs",
             f"{'design':<38} {'predicted':>10} {'worst':>9} {'regimes':>12}",
             f"{'':<38} {'mm':>10} {'mm':>9}"]
    index = {d: i for i, d in enumerate(result.screened.designs)}
    for v in result.verified:
        i = index.get(v.sphere)
        predicted = f"{result.screened.worst[i] * 1e3:.3g}" if i is not None and np.isfinite(result.screened.worst[i]) else "-"
        mark = " (baseline)" if v.sphere == p.baseline else ""
        lines.append(f"{v.sphere.label() + mark:<38} {predicted:>10} {v.worst * 1e3:>9.3g} "
                     f"{_regime_letters('APR' if f > 0.5 else 'SMR' for f in v.apr):>12}")
    failed = [v.sphere.label() for v in result.verified if v.outside.any()]
    if failed:
        lines.append(f"monotonicity check failed (the box's centre left the corners' band) for: {'; '.join(failed)}; "
                     "the worst case includes the centre")
    lines.append(f"no IES: {float(np.max(result.no_absorber)) * 1e3:.3g} mm at {micrometres(max(p.excitation))} um (D_1 = "
                 f"{min(p.D):g})")
    if result.baseline is not None and result.baseline is not result.recommendation:
        lines.append(f"baseline: {result.baseline.sphere.label()}, worst case {result.baseline.worst * 1e3:.3g} mm; "
                     f"the recommendation's is {result.baseline.worst / result.recommendation.worst:.2f}x lower")
    lines.append("the host's modes are taken as they are (the cavity's change of the host's mass is neglected)")
    lines.append("recommendation: " + result.sentence())
    return "\n".join(lines)
