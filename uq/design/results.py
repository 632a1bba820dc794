"""What a finished design is (the screening, the similarity predictions, the verified designs with their margins to
the switch, the recommendation) and what `ies design` writes and prints: design.csv, design-levels.csv, design.json,
results.nc and the table of the verified designs."""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
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
    """One verified design: per operating level the band of the objective over the box's corners (low, high; averaged
    over the repetitions, SI), the centre's value (nominal), the fraction of runs in the almost periodic regime, whether
    the centre left the corners' band beyond the repetition noise (monotonicity check); the runs; point_apr: per box
    point (corners, then the centre) and level (the operating ones, then the margin level) the share of its
    repetitions that are almost periodic; point_onset: per box point the base amplitude (m) of its first impacts
    (Eq. 7, mode 1: below it a response is linear and its "almost periodic" label means nothing); margin_high: the
    objective's highest value over the box at the margin level (SI); excitation: the base amplitudes (m) of those
    levels; prediction: the similarity law's (`uq.design.prediction.DesignPrediction`); round: the search round that verified it (0 = the first batch)."""

    sphere: Sphere
    low: np.ndarray
    high: np.ndarray
    nominal: np.ndarray
    apr: np.ndarray
    outside: np.ndarray
    runs: int
    point_apr: np.ndarray | None = None
    point_onset: np.ndarray | None = None
    margin_high: float = math.nan
    excitation: tuple[float, ...] = ()
    prediction: Any = None
    round: int = 0

    @property
    def worst(self) -> float:
        """The worst case (SI): the corners' and the centre's highest value over the operating levels."""
        return float(np.max(np.maximum(self.high, self.nominal)))

    def apr_seen_at(self) -> float:
        """The lowest verified base amplitude (m) at or above its first impacts at which some point of the box is mostly
        almost periodic (inf: none, up to the margin level)."""
        if self.point_apr is None:
            return math.inf
        a = np.asarray(self.excitation)[None, :]
        onset = np.zeros((self.point_apr.shape[0], 1)) if self.point_onset is None else self.point_onset[:, None]
        hit = np.flatnonzero(((self.point_apr >= 0.5) & (a >= onset)).any(axis=0))
        return float(self.excitation[hit[0]]) if hit.size else math.inf

    def switch_worst(self) -> float:
        """The switch's base amplitude (m) at the box's worst corner: the prediction's, or lower where a verified run
        was already almost periodic."""
        predicted = self.prediction.switch_worst if self.prediction is not None else math.inf
        return min(predicted, self.apr_seen_at())

    def switch_kind(self) -> str:
        """How switch_worst is known: "verified" (at most there), or the prediction's kind (found, above, below)."""
        if self.apr_seen_at() < (self.prediction.switch_worst if self.prediction is not None else math.inf):
            return "verified"
        return self.prediction.switch_worst_kind if self.prediction is not None else "above"

    def margin(self, top: float) -> float:
        """The margin (-) of the switch at the box's worst corner above the top of the operating range `top` (m)."""
        return self.switch_worst() / top - 1.0

    def admissible(self, top: float, margin: float) -> bool:
        """A margin of at least `margin` at the box's worst corner, and no point of the box almost periodic at any
        verified level: never on the steep side of a switch anywhere in the box."""
        return self.margin(top) >= margin - 1e-12 and not math.isfinite(self.apr_seen_at())


@dataclass
class DesignResult:
    """A finished design: the problem, the screening, the verified designs (best first: admissible ones by their worst
    case), the folder of its files, the operating levels a_base/a_base* and the structure without IES (m); the objective,
    the similarity references (plain data), the search's rounds and why it stopped, the predictions of every design
    whose sphere has a law, the runs of the references and the host's first natural angular frequency (rad/s)."""

    problem: DesignProblem
    screened: Screened
    verified: list[Verified]
    folder: Any
    levels: np.ndarray
    no_absorber: np.ndarray
    files: list[Any]
    objective: Any = None
    similarity: list[dict[str, Any]] = field(default_factory=list)
    rounds: list[list[Sphere]] = field(default_factory=list)
    stop: str = ""
    predictions: Mapping[Sphere, Any] = field(default_factory=dict)
    reference_runs: int = 0
    omega_1: float = math.nan

    def __post_init__(self) -> None:
        if self.objective is None:
            from uq.design.objectives import objective_named

            self.objective = objective_named(self.problem.objective)

    @property
    def top(self) -> float:
        return float(max(self.problem.excitation))

    @property
    def recommendation(self) -> Verified:
        return self.verified[0]

    @property
    def baseline(self) -> Verified | None:
        return next((v for v in self.verified if v.sphere == self.problem.baseline), None)

    def jump_text(self, v: Verified) -> str:
        """Where the design's amplitude jumps and by how much, in words."""
        p, o = v.prediction, self.objective
        if v.switch_kind() == "verified":
            return f"a verified run of its box is almost periodic at {micrometres(v.apr_seen_at())} um"
        if p is None:
            return "no prediction"
        if p.switch_worst_kind != "found":
            return f"no switch predicted up to {micrometres(p.switch_worst)} um (the references' top)"
        below, above = p.jump
        corner = p.worst_corner.label()
        return (f"it switches at {micrometres(p.switch_worst)} um at the box's worst corner ({corner}), where its "
                f"{o.quantity} jumps {above / below:.1f}x ({o.shown(below)} -> {o.shown(above)} {o.shown_in}); "
                f"at {micrometres(p.switch_nominal)} um at the box's centre")

    def sentence(self) -> str:
        """The recommendation in words and units, with its margin to the switch and the jump there."""
        best, p, o = self.recommendation, self.problem, self.objective
        s = best.sphere
        lo, hi = min(p.excitation), max(p.excitation)
        ratio = float(np.max(self.no_absorber)) / best.worst if o.unit == "m" else math.nan
        versus = (f", {ratio:.1f}x below the structure without IES ({float(np.max(self.no_absorber)) * 1e3:.3g} mm)"
                  if math.isfinite(ratio) else "")
        margin = best.margin(self.top)
        return (f"clearance {s.clearance * 1e3:.2f} mm, {s.material} sphere of radius {s.radius * 1e3:.2f} mm "
                f"({s.mass * 1e3:.1f} g): worst case {o.shown(best.worst)} {o.shown_in} over "
                f"{micrometres(lo)}-{micrometres(hi)} um{versus}; margin {margin:.0%} to the switch "
                f"({'at least' if best.switch_kind() == 'above' else 'predicted'}): {self.jump_text(best)}")


DESIGN_JSON = OutputFile("design.json", "ies design", "The design's settings, host and result.", (
    Column("settings", "", "the design problem (SI units: excitation, clearances, radii in m; D, tolerance and k_H "
                           "factor intervals; objective, margin, candidates, repetitions, restitution, protocol)"),
    Column("objective", "", "the objective's row: name, quantity, statistic, unit (uq.design.objectives)"),
    Column("host", "", "the host's mode 1 as the slow flow uses it (omega_1 rad/s, D_1, phi_c, phi_tip, participation) "
                       "and the operating levels a_base/a_base*"),
    Column("screening", "", "designs screened, how many fit the cavity, seconds, the restitution r used"),
    Column("similarity", "", "per sphere the similarity law's references: kappa (N/m), D_1, their realisation "
                             "(clearance_m, k_H), own levels, APR share and value per a_noabs* per level, the bisected "
                             "switch (own level, kind, width), runs"),
    Column("search", "", "the verification rounds (designs per round, the first sized by --candidates) and why the "
                         "search stopped"),
    Column("verified", "", "every verified design: its variables, worst (objective unit; worst_m in m for an amplitude), "
                           "runs, per level low, high, nominal (and *_m), apr_fraction, the levels where the "
                           "monotonicity check failed; its prediction (predicted_worst, switch_worst_m and its kind and "
                           "corner, switch_nominal_m, jump_below, jump_above), the verified margin level's "
                           "margin_high, apr_seen_at_m, margin_worst, admissible, round"),
    Column("recommendation", "", "the best admissible verified design (as in verified), its sentence and "
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
    Column("predicted_worst_m", "m", "slow-flow worst case of the tip amplitude over levels and the D, tolerance ends"),
    Column("predicted_switch_m", "m", "slow-flow base amplitude of its fold (a lower bound of the switch)"),
    Column("worst_m", "m", "verified worst case over levels, uncertainty corners and the nominal point, for an objective "
                           "in m (empty if screened)"),
    Column("worst_level_m", "m", "base amplitude a_base where the verified worst case occurs"),
    Column("regimes", "-", ("per operating level: A (almost periodic in most runs), S (strongly modulated), L (no impacts "
                      "predicted); verified designs from the runs, screened ones from the slow flow")),
    Column("objective", "-", "the objective's name (uq.design.objectives)"),
    Column("unit", "-", "the objective's unit"),
    Column("worst", "SI", "verified worst case of the objective, in its unit (column unit; empty if not verified)"),
    Column("similarity_worst", "SI", "the similarity law's predicted worst case (empty without a law for the "
                                                 "sphere)"),
    Column("switch_worst_m", "m", "base amplitude of the switch to the almost periodic response at the box's worst "
                                  "corner: predicted, or lower where a verified run was already almost periodic"),
    Column("switch_kind", "-", "found (bisected), above (none up to it: a lower bound), below (an upper bound) or "
                               "verified (a verified run was almost periodic there)"),
    Column("switch_nominal_m", "m", "predicted base amplitude of the switch at the box's centre"),
    Column("margin_worst", "-", "switch_worst_m over the top of the operating range, minus 1"),
    Column("margin_nominal", "-", "switch_nominal_m over the top of the operating range, minus 1"),
    Column("admissible", "-", "1 if margin_worst >= --margin and no verified run of the box is almost periodic (empty if "
                              "not verified)"),
    Column("jump_below", "SI", "predicted objective just below the switch at the worst corner"),
    Column("jump_above", "SI", "predicted objective just above it"),
    Column("round", "-", "search round that verified the design (0: the first batch; empty if not verified)"),
))


DESIGN_LEVELS_CSV = OutputFile("design-levels.csv", "ies design", "One row per verified design and level: the operating "
                               "levels, then the margin level.", (
    Column("material", "-", "sphere material"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("a_base_m", "m", "operating base amplitude"),
    Column("level", "-", "a_base / a_base* (a_base* of the paper's nominal D*, g*)"),
    Column("low_m", "m", "lowest resonant tip amplitude over the uncertainty corners (mean of the repetitions; objectives "
                         "in m)"),
    Column("high_m", "m", "highest resonant tip amplitude over the uncertainty corners"),
    Column("nominal_m", "m", "resonant tip amplitude at the box's centre"),
    Column("outside", "-", "1 if the centre left the corners' band beyond 2 standard errors (monotonicity check failed)"),
    Column("apr_fraction", "-", "fraction of runs in the almost periodic regime"),
    Column("predicted_m", "m", "slow-flow prediction of the tip amplitude (worst over the D and tolerance ends)"),
    Column("no_absorber_m", "m", "the structure without IES at the lower end of D"),
    Column("role", "-", "operating (a level of --excitation) or margin (the top times 1 + --margin, the margin check)"),
    Column("low", "SI", "lowest objective over the corners (mean of the repetitions)"),
    Column("high", "SI", "highest objective over the corners (at the margin level: over the whole box)"),
    Column("nominal", "SI", "objective at the box's centre"),
    Column("similarity", "SI", "the similarity law's prediction (worst over the box)"),
    Column("apr_points", "-", "points of the box (corners and centre) almost periodic in most of their runs"),
))


def _regime_letters(values: Sequence[Any]) -> str:
    return "".join({"APR": "A", "SMR": "S", "linear": "L"}.get(str(v), "?") for v in values)


def _metres(result: DesignResult, value: Any) -> Any:
    """A value for a *_m column: itself for an objective in m, else empty."""
    return value if result.objective.unit == "m" else None


def verified_row(result: DesignResult, v: Verified) -> dict[str, Any]:
    """The prediction-and-margin fields of a verified design (design.csv, design.json)."""
    p, top = v.prediction, result.top
    return {"predicted_worst": p.worst if p is not None else None, "switch_worst_m": v.switch_worst(),
            "switch_kind": v.switch_kind(),
            "switch_worst_corner": p.worst_corner.describe() if p is not None else None,
            "switch_nominal_m": p.switch_nominal if p is not None else None,
            "margin_worst": v.margin(top),
            "margin_nominal": p.switch_nominal / top - 1.0 if p is not None else None,
            "jump_below": p.jump[0] if p is not None else None, "jump_above": p.jump[1] if p is not None else None,
            "margin_high": v.margin_high, "apr_seen_at_m": v.apr_seen_at() if math.isfinite(v.apr_seen_at()) else None,
            "admissible": v.admissible(top, result.problem.margin), "round": v.round}


def write_design(result: DesignResult, mode: Any) -> list[Any]:
    """design.csv, design-levels.csv, design.json and results.nc (all written atomically)."""
    from sim.common.files import dumps, write_csv, write_text

    p, s, o = result.problem, result.screened, result.objective
    verified = {v.sphere: v for v in result.verified}
    index = {d: i for i, d in enumerate(s.designs)}
    top = result.top
    rows = []
    for d in [*(v.sphere for v in result.verified), *(d for d in s.designs if d not in verified)]:
        v, i = verified.get(d), index.get(d)
        status = ("baseline" if d == p.baseline else "verified") if v else "screened"
        regimes = (_regime_letters("APR" if f > 0.5 else "SMR" for f in v.apr) if v
                   else _regime_letters(s.regime[i]))
        worst_at = p.excitation[int(np.argmax(np.maximum(v.high, v.nominal)))] if v else None
        prediction = v.prediction if v else result.predictions.get(d)
        if v:
            extra = verified_row(result, v)
            switch, kind, admissible = extra["switch_worst_m"], extra["switch_kind"], int(extra["admissible"])
        elif prediction is not None:
            switch, kind, admissible = prediction.switch_worst, prediction.switch_worst_kind, None
        else:
            switch, kind, admissible = None, None, None
        rows.append([status, d.material, d.clearance, d.radius, d.mass, d.k_H, d.cavity(), int(p.fits(d)),
                     s.worst[i] if i is not None and np.isfinite(s.worst[i]) else None,
                     s.switch[i] if i is not None else None, _metres(result, v.worst) if v else None, worst_at, regimes,
                     o.name, o.unit, v.worst if v else None, prediction.worst if prediction is not None else None,
                     switch, kind, prediction.switch_nominal if prediction is not None else None,
                     switch / top - 1.0 if switch is not None else None,
                     prediction.switch_nominal / top - 1.0 if prediction is not None else None, admissible,
                     prediction.jump[0] if prediction is not None else None,
                     prediction.jump[1] if prediction is not None else None, v.round if v else None])
    level_rows = []
    for v in result.verified:
        i = index.get(v.sphere)
        predicted = v.prediction.per_level if v.prediction is not None else np.full(len(p.excitation), np.nan)
        n_apr = (v.point_apr >= 0.5).sum(axis=0) if v.point_apr is not None else np.zeros(len(p.excitation) + 1, int)
        for k, a_base in enumerate(p.excitation):
            level_rows.append([v.sphere.material, v.sphere.clearance, v.sphere.radius, a_base, result.levels[k],
                               _metres(result, v.low[k]), _metres(result, v.high[k]), _metres(result, v.nominal[k]),
                               int(v.outside[k]), v.apr[k], s.tip[i, k] if i is not None else None,
                               result.no_absorber[k], "operating", v.low[k], v.high[k], v.nominal[k], predicted[k],
                               int(n_apr[k])])
        if v.excitation:
            a_m = v.excitation[-1]
            level_rows.append([v.sphere.material, v.sphere.clearance, v.sphere.radius, a_m,
                               result.levels[-1] * a_m / max(p.excitation), None, _metres(result, v.margin_high), None,
                               None, None, None, None, "margin", None, v.margin_high, None, None, int(n_apr[-1])])
    folder = result.folder
    files = [write_csv(folder / "design.csv", DESIGN_CSV.names, rows),
             write_csv(folder / "design-levels.csv", DESIGN_LEVELS_CSV.names, level_rows)]

    def verified_data(v: Verified) -> dict[str, Any]:
        return {**v.sphere.describe(), "worst": v.worst, "worst_m": _metres(result, v.worst), "runs": v.runs,
                "low": v.low, "high": v.high, "nominal": v.nominal, "low_m": _metres(result, v.low),
                "high_m": _metres(result, v.high), "nominal_m": _metres(result, v.nominal), "apr_fraction": v.apr,
                "monotonicity_failed_at_m": [a for a, out in zip(p.excitation, v.outside) if out],
                **verified_row(result, v)}

    best = result.recommendation
    data = {
        "settings": {**{k: v for k, v in dataclasses.asdict(p).items() if k != "baseline"},
                     "baseline": p.baseline and dataclasses.asdict(p.baseline)},
        "objective": o.describe(),
        "host": {"source": p.modal_file or "built-in rig", "omega_1_rad_per_s": mode.omega, "D_1": mode.D,
                 "phi_c": mode.phi_c, "phi_tip": mode.phi_tip, "participation": mode.participation,
                 "levels": result.levels},
        "screening": {"designs": len(s.designs), "fitting": int(np.isfinite(s.worst).sum()), "seconds": s.seconds,
                      "restitution": p.restitution},
        "similarity": result.similarity,
        "search": {"rounds": [[d.describe() for d in r] for r in result.rounds], "stop": result.stop,
                   "reference_runs": result.reference_runs},
        "verified": [verified_data(v) for v in result.verified],
        "recommendation": {**verified_data(best), "sentence": result.sentence(),
                           "reduction_vs_no_absorber": (float(np.max(result.no_absorber)) / best.worst
                                                        if o.unit == "m" else None)},
        "baseline": (None if result.baseline is None else
                     {**verified_data(result.baseline), "ratio_to_recommendation": result.baseline.worst / best.worst}),
        "no_absorber": {"D_1": min(p.D), "tip_m": result.no_absorber},
        "notes": ["the host's modes are taken as they are: the change of the host's mass by the cavity is neglected",
                  "k_H from Eq. 8 (sphere on the host's flat steel wall), scaled by the k_H factor interval",
                  "dry friction is not modelled in the design (it would break the similarity law)",
                  "switch and prediction: the similarity law of the full model (sim.reduced.similarity), its "
                  "references simulated with the design's protocol"],
    }
    files.append(write_text(folder / "design.json", dumps(data) + "\n"))
    files.append(write_design_netcdf(result, data))
    return files


def write_design_netcdf(result: DesignResult, data: Mapping[str, Any]) -> Any:
    """results.nc of a design (`uq.outputs.netcdf` conventions): the verified designs x operating levels (band, centre,
    APR fraction, the slow flow's and the similarity law's predictions), their switches and margins, and the screened
    grid's predicted worst case, with units."""
    from pathlib import Path

    import xarray as xr

    from sim.common.files import atomic_path, dumps
    from uq.outputs.netcdf import ENGINE

    p, s, o = result.problem, result.screened, result.objective
    v = result.verified
    index = {d: i for i, d in enumerate(s.designs)}
    nan_row = np.full(len(p.excitation), np.nan)

    def design_coords(spheres: Sequence[Sphere], dim: str) -> dict[str, Any]:
        return {f"{dim}_clearance": (dim, [x.clearance for x in spheres], {"units": "m", "long_name": "clearance g"}),
                f"{dim}_radius": (dim, [x.radius for x in spheres], {"units": "m", "long_name": "sphere radius R"}),
                f"{dim}_material": (dim, [x.material for x in spheres], {"long_name": "sphere material"}),
                f"{dim}_mass": (dim, [x.mass for x in spheres], {"units": "kg", "long_name": "sphere mass m_a"})}

    metres = {"units": "m"}
    unit = {"units": o.unit}
    top = result.top
    ds = xr.Dataset(
        {"low": (("design", "level"), [x.low for x in v], {**unit, "long_name": f"lowest {o.quantity} over the "
                                                                               "uncertainty corners"}),
         "high": (("design", "level"), [x.high for x in v], {**unit, "long_name": f"highest {o.quantity} over the "
                                                                                  "uncertainty corners"}),
         "nominal": (("design", "level"), [x.nominal for x in v], {**unit, "long_name": f"{o.quantity} at the box's "
                                                                                        "centre"}),
         "apr_fraction": (("design", "level"), [x.apr for x in v], {"units": "1", "long_name": "fraction of runs in "
                                                                                              "the APR regime"}),
         "predicted": (("design", "level"), [s.tip[index[x.sphere]] if x.sphere in index else nan_row for x in v],
                       {**metres, "long_name": "slow-flow resonant tip amplitude (worst over the D, tolerance ends)"}),
         "similarity": (("design", "level"), [x.prediction.per_level if x.prediction is not None else nan_row
                                              for x in v],
                        {**unit, "long_name": f"similarity law's {o.quantity} (worst over the box)"}),
         "worst": ("design", [x.worst for x in v], {**unit, "long_name": "verified worst case"}),
         "switch_worst": ("design", [x.switch_worst() for x in v],
                          {**metres, "long_name": "base amplitude of the switch at the box's worst corner"}),
         "margin_worst": ("design", [x.margin(top) for x in v],
                          {"units": "1", "long_name": "margin of the switch above the top of the operating range"}),
         "admissible": ("design", [int(x.admissible(top, p.margin)) for x in v],
                        {"units": "1", "long_name": "1 if the margin holds and no run of the box is almost periodic"}),
         "no_absorber": ("level", result.no_absorber, {**metres, "long_name": "resonant tip amplitude without IES"}),
         "screened_worst": ("screened", np.where(np.isfinite(s.worst), s.worst, np.nan),
                            {**metres, "long_name": "slow-flow worst case (NaN: the cavity does not fit)"})},
        coords={"level": ("level", result.levels, {"units": "1", "long_name": "excitation level a_base/a_base*"}),
                "a_base": ("level", np.asarray(p.excitation), {**metres, "long_name": "operating base amplitude"}),
                **design_coords([x.sphere for x in v], "design"), **design_coords(s.designs, "screened")},
        attrs={"Conventions": "CF-1.10", "title": "ies-workbench design", "kind": "design",
               "recommendation": data["recommendation"]["sentence"], "settings": dumps(data["settings"]),
               "objective": dumps(data["objective"])})
    path = Path(result.folder) / "results.nc"
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=ENGINE)
    return path


def design_table(result: DesignResult) -> str:
    """The printed table of the verified designs (best first) with their predictions and margins, ending with the
    recommendation in words."""
    p, o = result.problem, result.objective
    top = result.top
    runs = sum(v.runs for v in result.verified)
    lines = [f"screened {len(result.screened.designs)} designs in {result.screened.seconds:.2f} s "
             f"({int(np.isfinite(result.screened.worst).sum())} fit the cavity); similarity references "
             f"{result.reference_runs} runs; verified {len(result.verified)} designs in {len(result.rounds)} round(s) by "
             f"{runs} runs ({result.stop})",
             f"{'design':<38} {'predicted':>9} {'worst':>8} {'switch':>8} {'margin':>7} {'regimes':>10}",
             f"{'':<38} {o.shown_in:>9} {o.shown_in:>8} {'um':>8} {'':>7}"]
    for v in result.verified:
        predicted = o.shown(v.prediction.worst) if v.prediction is not None else "-"
        mark = " (baseline)" if v.sphere == p.baseline else ""
        flag = "" if v.admissible(top, p.margin) else " x"
        switch = micrometres(v.switch_worst()) if math.isfinite(v.switch_worst()) else "-"
        if v.switch_kind() == "above":
            switch = ">" + switch
        lines.append(f"{v.sphere.label() + mark:<38} {predicted:>9} {o.shown(v.worst):>8} {switch:>8} "
                     f"{v.margin(top):>6.0%}{flag:<2}"
                     f"{_regime_letters('APR' if f > 0.5 else 'SMR' for f in v.apr):>9}")
    lines.append(f"switch: at the box's worst corner (similarity law; lower where a verified run was almost periodic); "
                 f"x: margin below {p.margin:.0%} or a verified run almost periodic (not admissible)")
    failed = [v.sphere.label() for v in result.verified if v.outside.any()]
    if failed:
        lines.append(f"monotonicity check failed (the box's centre left the corners' band) for: {'; '.join(failed)}; "
                     "the worst case includes the centre")
    lines.append(f"no IES: {float(np.max(result.no_absorber)) * 1e3:.3g} mm at {micrometres(max(p.excitation))} um (D_1 = "
                 f"{min(p.D):g})")
    if result.baseline is not None and result.baseline is not result.recommendation:
        lines.append(f"baseline: {result.baseline.sphere.label()}, worst case {o.shown(result.baseline.worst)} "
                     f"{o.shown_in}, margin {result.baseline.margin(top):.0%}; the recommendation's worst case is "
                     f"{result.baseline.worst / result.recommendation.worst:.2f}x lower")
    lines.append("the host's modes are taken as they are (the cavity's change of the host's mass is neglected)")
    lines.append("recommendation: " + result.sentence())
    return "\n".join(lines)
