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
from uq.design.problem import DesignProblem, Design, micrometres


@dataclass(frozen=True)
class Screened:
    """The screening of the grid: per design (`designs`, grid order) the worst case over the uncertainty ends of the
    predicted resonant tip amplitude (m) at each operating level (`tip`, shape designs x levels), its regime there
    (`regime`), the base amplitude of the predicted switch to the almost periodic response (`switch`, m) and the
    design's worst case over the levels (`worst`, m; inf for designs that do not fit)."""

    designs: list[Design]
    tip: np.ndarray
    regime: np.ndarray
    switch: np.ndarray
    worst: np.ndarray
    seconds: float


#: the rule by which a box point counts as almost periodic at a verified level (the margin's, and every operating
#: level's): any one of its runs almost periodic, not most of them. The conservative one: a switch met by one
#: repetition of three is a switch one tolerance or one seed away
APR_RULE = "any run"


@dataclass(frozen=True)
class Verified:
    """One verified design: per operating level the band of the objective over the box's corners (low, high; averaged
    over the repetitions, SI), the centre's value (nominal), the fraction of runs in the almost periodic regime, whether
    the centre left the corners' band beyond the repetition noise (monotonicity check); the runs; point_apr: per box
    point (corners, then the centre) and level (the operating ones, then the margin level) the share of its
    repetitions that are almost periodic; point_onset: per box point the base amplitude (m) of its first impacts
    (Eq. 7, mode 1: below it a response is linear and its "almost periodic" label means nothing); margin_high: the
    objective's highest value over the box at the margin level (SI); excitation: the base amplitudes (m) of those
    levels; prediction: the similarity law's (`uq.design.prediction.DesignPrediction`); round: the search round that
    verified it (0 = the first batch); worst_interval: the 95 % interval of the worst case of a repeat of this
    verification (`uq.design.uncertainty`; NaN where unknown); deciding: the (box point, operating level) cells that
    decide the worst case, most decisive first; point_runs: the runs per box point and level."""

    design: Design
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
    worst_interval: tuple[float, float] = (math.nan, math.nan)
    deciding: tuple[tuple[int, int], ...] = ()
    point_runs: np.ndarray | None = None

    @property
    def worst(self) -> float:
        """The worst case (SI): the corners' and the centre's highest value over the operating levels."""
        return float(np.max(np.maximum(self.high, self.nominal)))

    def deciding_runs(self) -> int:
        """The most runs any deciding cell holds (the problem's repetitions unless `uq.design.search.settle` added)."""
        if self.point_runs is None or not self.deciding:
            return 0
        return int(max(self.point_runs[i, k] for i, k in self.deciding))

    def apr_seen_at(self) -> float:
        """The lowest verified base amplitude (m) at or above its first impacts at which some point of the box has an
        almost periodic run (APR_RULE; inf: none, up to the margin level)."""
        if self.point_apr is None:
            return math.inf
        a = np.asarray(self.excitation)[None, :]
        onset = np.zeros((self.point_apr.shape[0], 1)) if self.point_onset is None else self.point_onset[:, None]
        hit = np.flatnonzero(((self.point_apr > 0.0) & (a >= onset)).any(axis=0))
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
        """A margin of at least `margin` at the box's worst corner, and no run of any point of the box almost periodic
        at any verified level (APR_RULE): never on the steep side of a switch anywhere in the box."""
        return self.margin(top) >= margin - 1e-12 and not math.isfinite(self.apr_seen_at())


@dataclass
class DesignResult:
    """A finished design: the problem, the screening, the verified designs (best first: admissible ones by their worst
    case), the folder of its files, the operating levels a_base/a_base* and the structure without IES (m, at the host's
    D_1*); the objective, the similarity references (plain data), the search's rounds and why it stopped, the
    predictions of every design whose sphere has a law, the runs of the references, the host's first natural angular
    frequency (rad/s), how the ranking of the best two was settled (`uq.design.search.Settling`), the host's damping,
    wall and normalisation (`uq.design.search.host_summary`) and, where no verified design is admissible, the
    refusal in words."""

    problem: DesignProblem
    screened: Screened
    verified: list[Verified]
    folder: Any
    levels: np.ndarray
    no_absorber: np.ndarray
    files: list[Any]
    objective: Any = None
    similarity: list[dict[str, Any]] = field(default_factory=list)
    rounds: list[list[Design]] = field(default_factory=list)
    stop: str = ""
    predictions: Mapping[Design, Any] = field(default_factory=dict)
    reference_runs: int = 0
    omega_1: float = math.nan
    settling: Any = None
    host: Mapping[str, Any] = field(default_factory=dict)
    refusal: str | None = None

    def __post_init__(self) -> None:
        if self.objective is None:
            from uq.design.objectives import objective_named

            self.objective = objective_named(self.problem.objective)

    @property
    def top(self) -> float:
        return float(max(self.problem.excitation))

    @property
    def recommendation(self) -> Verified:
        """The best verified design (admissible unless `refusal`)."""
        return self.verified[0]

    @property
    def baseline(self) -> Verified | None:
        return next((v for v in self.verified if v.design == self.problem.baseline), None)

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

    def settling_text(self) -> str:
        """The ranking of the best two in words (`uq.design.search.Settling.text`)."""
        if self.settling is None:
            return ""
        return self.settling.text({v.design: v for v in self.verified}, self.objective.shown, self.objective.shown_in)

    def sentence(self) -> str:
        """The recommendation in words and units, with its interval, its margin to the switch and the jump there, and
        how its ranking against the runner-up was settled."""
        best, p, o = self.recommendation, self.problem, self.objective
        s = best.design
        lo, hi = min(p.excitation), max(p.excitation)
        ratio = float(np.max(self.no_absorber)) / best.worst if o.unit == "m" else math.nan
        versus = (f", {ratio:.1f}x below the structure without IES ({float(np.max(self.no_absorber)) * 1e3:.3g} mm)"
                  if math.isfinite(ratio) else "")
        w_lo, w_hi = best.worst_interval
        interval = (f" (95 % interval {o.shown(w_lo)}-{o.shown(w_hi)} {o.shown_in} over repeats of the verification)"
                    if math.isfinite(w_lo) else "")
        margin = best.margin(self.top)
        settled = self.settling_text()
        return (f"clearance {s.clearance * 1e3:.2f} mm, {s.material} sphere of radius {s.radius * 1e3:.2f} mm "
                f"({s.mass * 1e3:.1f} g) on {s.wall.name} walls: worst case {o.shown(best.worst)} {o.shown_in}{interval} "
                f"over {micrometres(lo)}-{micrometres(hi)} um{versus}; margin {margin:.0%} to the switch "
                f"({'at least' if best.switch_kind() == 'above' else 'predicted'}): {self.jump_text(best)}"
                + (f"; {settled}" if settled else ""))

    def check_command(self, v: Verified | None = None) -> str:
        """The `ies sweep` line that simulates a verified design (default the recommendation) at the cell deciding its
        worst case (the box point's D, g, k_H and the level as a base amplitude) with the design's protocol."""
        v = self.recommendation if v is None else v
        p, d = self.problem, v.design
        point, k = (v.deciding[0] if v.deciding else (len(p.corners(d)) - 1, int(np.argmax(v.nominal))))
        box = p.corners(d)[point]
        proto = p.protocol
        parts = ["ies sweep", f"--level {p.excitation[k] * 1e6:.6g}um", f"--radius {d.radius * 1e3:.6g}mm",
                 f"--material {d.material}", f"--wall-material {d.wall.name}", f"--g {box['g'] * 1e3:.6g}mm",
                 f"--D {box['D']:.6g}", f"--k-H {box['k_H']:.6g}",
                 f"--eta {proto['eta_start']:g}:{proto['eta_stop']:g}:{proto['n_eta']}", f"--wait {proto['wait']:g}",
                 f"--hold {proto['hold']:g}", f"--sequence {proto['sequence']}", f"--start {proto['start']}",
                 f"--repetition {proto['repetition']}", f"--integrator {proto['integrator']}",
                 f"--reps {p.repetitions}"]
        if p.modal_file:
            parts.insert(1, f"--model {p.modal_file}")
        return " ".join(parts)


#: what an objective's value is (its unit's suffix replaces `_m` for an objective in another unit, e.g.
#: `worst_m_per_s2`: `uq.design.objectives.Objective.suffix`)
_OBJ = "the objective's value"

DESIGN_JSON = OutputFile("design.json", "ies design", "The design's settings, host and result.", (
    Column("settings", "", "the design problem (SI units: excitation, clearances, radii in m; D, tolerance and k_H "
                           "factor intervals, damping_source: where D's comes from; wall: the cavity walls' material; "
                           "objective, margin, candidates, repetitions, restitution, protocol; apr_rule: when a box "
                           "point counts as almost periodic)"),
    Column("objective", "", "the objective's row: name, quantity, statistic, unit and key_suffix, the suffix of the "
                            "keys holding its values (_m for an amplitude; uq.design.objectives)"),
    Column("host", "", "the host's mode 1 as the slow flow uses it (omega_1 rad/s, D_1, phi_c, phi_tip, participation), "
                       "the operating levels a_base/a_base*, its nominal D_star, damping_interval and its source, "
                       "wall_material, and normalisation: the D_star and g_star_m every level and a/a_noabs* is "
                       "normalised by (Sect. 5)"),
    Column("screening", "", "designs screened, how many fit the cavity (fitting, fitting_text: which, and the "
                            "--block-width that takes all), seconds, the restitution r used"),
    Column("similarity", "", "per sphere the similarity law's references: kappa (N/m), D_1, their realisation "
                             "(clearance_m, k_H), own levels, APR share and value per a_noabs* per level, the bisected "
                             "switch (own level, kind, width), runs"),
    Column("search", "", "the verification rounds (designs per round, the first sized by --candidates), why the search "
                         "stopped, reference_runs, and settling: the runner-up, whether its interval still overlaps the "
                         "recommendation's, the most runs at a deciding cell and the budget, in words"),
    Column("verified", "", "every verified design: its variables (wall_material, mass_kg, k_H_N_per_m1p5 of Eq. 8), "
                           "worst_m and worst_interval_m [low, high] (the 95 % interval of a repeat of its verification, "
                           "uq.design.uncertainty), deciding (the cells deciding it: box point, a_base_m, runs), runs, per "
                           "level low_m, high_m, nominal_m, apr_fraction, the levels where the monotonicity check "
                           "failed; its prediction (predicted_worst_m, switch_worst_m and its kind and corner, "
                           "switch_nominal_m, jump_below_m, jump_above_m), the verified margin level's margin_high_m, "
                           "apr_seen_at_m, margin_worst, margin_nominal, admissible, round"),
    Column("recommendation", "", "the best admissible verified design (as in verified), its sentence, "
                                 "reduction_vs_no_absorber (-) and check_command: the ies sweep line that simulates it at "
                                 "its deciding cell, range_edge: where it lies on an edge of the grid (a larger or smaller clearance or "
                                 "radius was not tried; null inside); null when no verified design is admissible (see "
                                 "refusal)"),
    Column("refusal", "", "why no design is recommended (every verified design not admissible); null otherwise"),
    Column("baseline", "", "the baseline's verification and ratio_to_recommendation (-); null without --baseline"),
    Column("no_absorber", "", "the structure without IES: D_1 (the host's nominal D_1*) and tip_m (m) per level"),
    Column("notes", "", "what the design neglects"),
))


DESIGN_KEYS = DESIGN_JSON.names


DESIGN_CSV = OutputFile("design.csv", "ies design", "One row per evaluated design (verified first, best first; then the "
                        "screened ones). Empty cells: not known for that design (not verified, or no similarity law for "
                        "its sphere).", (
    Column("status", "-", "verified, baseline (verified) or screened"),
    Column("material", "-", "sphere material (sim.model.materials)"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("mass_kg", "kg", "sphere mass m_a (sim.model.sphere: the paper's sphere Table 1's 17.7 g)"),
    Column("k_H_N_per_m1p5", "N/m^1.5", "Eq. 8's k_H* of the sphere on the walls (both bodies' E and nu)"),
    Column("wall_material", "-", "the cavity walls' material (the host's, or --wall-material)"),
    Column("cavity_m", "m", "cavity width 2R + 2g"),
    Column("fits", "-", "1 if the cavity leaves walls of the minimum thickness"),
    Column("screened_worst_m", "m", "slow flow: worst case of the tip amplitude over levels and the D, tolerance ends"),
    Column("screened_switch_m", "m", "slow flow: base amplitude of its fold (a lower bound of the switch)"),
    Column("predicted_worst_m", "SI", f"similarity law: {_OBJ}, worst case over levels and the box"),
    Column("worst_m", "SI", f"verified: {_OBJ}, worst case over levels, the box's corners and centre (mean of the "
                            "repetitions)"),
    Column("worst_interval_low_m", "SI", "low end of the 95 % interval of the worst case of a repeat of the "
                                         "verification (uq.design.uncertainty)"),
    Column("worst_interval_high_m", "SI", "high end of that interval"),
    Column("worst_a_base_m", "m", "base amplitude a_base where the verified worst case occurs"),
    Column("deciding_runs", "-", "the most runs at a cell deciding the worst case (the repetitions, more where the "
                                 "ranking needed them)"),
    Column("regimes", "-", ("per operating level: A (almost periodic in most runs), S (strongly modulated), L (no impacts "
                      "predicted); verified designs from the runs, screened ones from the slow flow")),
    Column("objective", "-", "the objective's name (uq.design.objectives)"),
    Column("unit", "-", "the objective's unit"),
    Column("switch_worst_m", "m", "base amplitude of the switch to the almost periodic response at the box's worst "
                                  "corner: predicted, or lower where a verified run was already almost periodic"),
    Column("switch_kind", "-", "found (bisected), above (none up to it: a lower bound), below (an upper bound) or "
                               "verified (a verified run was almost periodic there)"),
    Column("switch_nominal_m", "m", "predicted base amplitude of the switch at the box's centre"),
    Column("margin_worst", "-", "switch_worst_m over the top of the operating range, minus 1"),
    Column("margin_nominal", "-", "switch_nominal_m over the top of the operating range, minus 1"),
    Column("admissible", "-", "1 if margin_worst >= --margin and no verified run of the box is almost periodic, else 0"),
    Column("jump_below_m", "SI", f"similarity law: {_OBJ} just below the switch at the worst corner"),
    Column("jump_above_m", "SI", f"similarity law: {_OBJ} just above it"),
    Column("round", "-", "search round that verified the design (0: the first batch)"),
))


DESIGN_LEVELS_CSV = OutputFile("design-levels.csv", "ies design", "One row per verified design and level: the operating "
                               "levels, then the margin level. Empty cells: not computed at that level.", (
    Column("material", "-", "sphere material"),
    Column("clearance_m", "m", "clearance g"),
    Column("radius_m", "m", "sphere radius R"),
    Column("a_base_m", "m", "base amplitude"),
    Column("level", "-", "a_base / a_base* (a_base* of the host's nominal D_1* and the paper's g*)"),
    Column("role", "-", "operating (a level of --excitation) or margin (the top times 1 + --margin, the margin check)"),
    Column("low_m", "SI", f"lowest {_OBJ} over the box's corners (mean of the repetitions)"),
    Column("high_m", "SI", f"highest {_OBJ} over the corners (at the margin level: over the whole box)"),
    Column("nominal_m", "SI", f"{_OBJ} at the box's centre"),
    Column("outside", "-", "1 if the centre left the corners' band beyond 2 standard errors (monotonicity check failed)"),
    Column("apr_fraction", "-", "fraction of runs in the almost periodic regime"),
    Column("apr_points", "-", "points of the box (corners and centre) with an almost periodic run (the margin rule)"),
    Column("runs", "-", "runs at this level over the box (more at the cells deciding the worst case)"),
    Column("screened_m", "m", "slow flow: the tip amplitude (worst over the D and tolerance ends)"),
    Column("predicted_m", "SI", f"similarity law: {_OBJ} (worst over the box)"),
    Column("no_absorber_m", "m", "the structure without IES at the host's nominal D_1*"),
))


#: the columns and keys holding the objective's values: `_m` becomes the objective's suffix
OBJECTIVE_KEYS = ("predicted_worst_m", "worst_m", "worst_interval_m", "worst_interval_low_m", "worst_interval_high_m",
                  "jump_below_m", "jump_above_m", "low_m", "high_m", "nominal_m", "predicted_m", "margin_high_m")


def _key(name: str, objective: Any) -> str:
    """The output name of a column or key: its objective's suffix for the objective's values."""
    return name[: -len("_m")] + objective.suffix if name in OBJECTIVE_KEYS else name


def _keys(data: Mapping[str, Any], objective: Any) -> dict[str, Any]:
    return {_key(k, objective): v for k, v in data.items()}


def _regime_letters(values: Sequence[Any]) -> str:
    return "".join({"APR": "A", "SMR": "S", "linear": "L"}.get(str(v), "?") for v in values)


def _cell(value: Any) -> Any:
    """A CSV cell: empty for a value not known (None, NaN)."""
    if value is None or (isinstance(value, (float, np.floating)) and not math.isfinite(value)):
        return ""
    return value


def verified_row(result: DesignResult, v: Verified) -> dict[str, Any]:
    """The prediction-and-margin fields of a verified design (design.csv, design.json; `_m` keys of the objective's
    values, renamed by `_key`)."""
    p, top = v.prediction, result.top
    return {"predicted_worst_m": p.worst if p is not None else None, "switch_worst_m": v.switch_worst(),
            "switch_kind": v.switch_kind(),
            "switch_worst_corner": p.worst_corner.describe() if p is not None else None,
            "switch_nominal_m": p.switch_nominal if p is not None else None,
            "margin_worst": v.margin(top),
            "margin_nominal": p.switch_nominal / top - 1.0 if p is not None else None,
            "jump_below_m": p.jump[0] if p is not None else None, "jump_above_m": p.jump[1] if p is not None else None,
            "margin_high_m": v.margin_high,
            "apr_seen_at_m": v.apr_seen_at() if math.isfinite(v.apr_seen_at()) else None,
            "admissible": v.admissible(top, result.problem.margin), "round": v.round}


def write_design(result: DesignResult, mode: Any) -> list[Any]:
    """design.csv, design-levels.csv, design.json and results.nc (all written atomically)."""
    from sim.common.files import write_csv, write_json

    p, s, o = result.problem, result.screened, result.objective
    verified = {v.design: v for v in result.verified}
    index = {d: i for i, d in enumerate(s.designs)}
    top = result.top
    rows = []
    for d in [*(v.design for v in result.verified), *(d for d in s.designs if d not in verified)]:
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
        interval = v.worst_interval if v else (None, None)
        rows.append([_cell(x) for x in (
            status, d.material, d.clearance, d.radius, d.mass, d.k_H, d.wall.name, d.cavity(), int(p.fits(d)),
            s.worst[i] if i is not None and np.isfinite(s.worst[i]) else None,
            s.switch[i] if i is not None else None, prediction.worst if prediction is not None else None,
            v.worst if v else None, interval[0], interval[1], worst_at, v.deciding_runs() if v else None, regimes,
            o.name, o.unit, switch, kind, prediction.switch_nominal if prediction is not None else None,
            switch / top - 1.0 if switch is not None else None,
            prediction.switch_nominal / top - 1.0 if prediction is not None else None, admissible,
            prediction.jump[0] if prediction is not None else None,
            prediction.jump[1] if prediction is not None else None, v.round if v else None)])
    level_rows = []
    for v in result.verified:
        i = index.get(v.design)
        predicted = v.prediction.per_level if v.prediction is not None else np.full(len(p.excitation), np.nan)
        n_apr = (v.point_apr > 0).sum(axis=0) if v.point_apr is not None else np.zeros(len(p.excitation) + 1, int)
        runs = (v.point_runs.sum(axis=0) if v.point_runs is not None else np.full(len(p.excitation) + 1, None))
        for k, a_base in enumerate(p.excitation):
            level_rows.append([_cell(x) for x in (
                v.design.material, v.design.clearance, v.design.radius, a_base, result.levels[k], "operating",
                v.low[k], v.high[k], v.nominal[k], int(v.outside[k]), v.apr[k], int(n_apr[k]), runs[k],
                s.tip[i, k] if i is not None else None, predicted[k], result.no_absorber[k])])
        if v.excitation:
            a_m = v.excitation[-1]
            level_rows.append([_cell(x) for x in (
                v.design.material, v.design.clearance, v.design.radius, a_m, result.levels[-1] * a_m / max(p.excitation),
                "margin", None, v.margin_high, None, None, None, int(n_apr[-1]), runs[-1], None, None, None)])
    folder = result.folder
    files = [write_csv(folder / "design.csv", [_key(n, o) for n in DESIGN_CSV.names], rows),
             write_csv(folder / "design-levels.csv", [_key(n, o) for n in DESIGN_LEVELS_CSV.names], level_rows)]

    def verified_data(v: Verified) -> dict[str, Any]:
        boxes = p.corners(v.design)
        deciding = [{"point": boxes[i], "a_base_m": p.excitation[k],
                     "runs": int(v.point_runs[i, k]) if v.point_runs is not None else None} for i, k in v.deciding]
        return _keys({**v.design.describe(), "worst_m": v.worst, "worst_interval_m": list(v.worst_interval),
                      "deciding": deciding, "runs": v.runs, "low_m": v.low, "high_m": v.high, "nominal_m": v.nominal,
                      "apr_fraction": v.apr, "monotonicity_failed_at_m": [a for a, out in zip(p.excitation, v.outside)
                                                                          if out],
                      **verified_row(result, v)}, o)

    best = result.recommendation
    settling = result.settling
    data = {
        "settings": {**{k: v for k, v in dataclasses.asdict(p).items() if k not in ("baseline", "wall")},
                     "wall": p.wall.describe(), "apr_rule": APR_RULE,
                     "baseline": p.baseline and p.baseline.describe()},
        "objective": o.describe(),
        "host": {"source": p.modal_file or "built-in rig", "omega_1_rad_per_s": mode.omega, "D_1": mode.D,
                 "phi_c": mode.phi_c, "phi_tip": mode.phi_tip, "participation": mode.participation,
                 "levels": result.levels, **result.host},
        "screening": {"designs": len(s.designs), "fitting": int(np.isfinite(s.worst).sum()),
                      "fitting_text": p.fitting_text(), "seconds": s.seconds, "restitution": p.restitution},
        "similarity": result.similarity,
        "search": {"rounds": [[d.describe() for d in r] for r in result.rounds], "stop": result.stop,
                   "reference_runs": result.reference_runs,
                   "settling": None if settling is None else {
                       "runner_up": settling.runner_up and settling.runner_up.describe(), "overlap": settling.overlap,
                       "most_runs": settling.most_runs, "budget": settling.budget, "text": result.settling_text()}},
        "verified": [verified_data(v) for v in result.verified],
        "recommendation": (None if result.refusal is not None else
                           {**verified_data(best), "sentence": result.sentence(),
                            "reduction_vs_no_absorber": (float(np.max(result.no_absorber)) / best.worst
                                                         if o.unit == "m" else None),
                            "check_command": result.check_command(),
                            "range_edge": p.edge_text(best.design) or None}),
        "refusal": result.refusal,
        "baseline": (None if result.baseline is None else
                     {**verified_data(result.baseline), "ratio_to_recommendation": result.baseline.worst / best.worst}),
        "no_absorber": {"D_1": result.host.get("D_star", mode.D), "tip_m": result.no_absorber},
        "notes": ["the host's modes are taken as they are: the change of the host's mass by the cavity is neglected",
                  f"k_H from Eq. 8 (sphere on the host's flat {p.wall.name} wall, both bodies' E and nu), scaled by the "
                  "k_H factor interval",
                  "dry friction is not modelled in the design (it would break the similarity law)",
                  "switch and prediction: the similarity law of the full model (sim.reduced.similarity), its "
                  "references simulated with the design's protocol",
                  f"a box point counts as almost periodic at a level when {APR_RULE} of it is (the conservative rule)"],
    }
    files.append(write_json(folder / "design.json", data))
    files.append(write_design_netcdf(result, data))
    return files


def write_design_netcdf(result: DesignResult, data: Mapping[str, Any]) -> Any:
    """results.nc of a design (`uq.outputs.netcdf` conventions): the verified designs x operating levels (band, centre,
    APR fraction, the slow flow's and the similarity law's predictions), their worst cases with intervals, switches and
    margins, and the screened grid's slow-flow worst case, with units."""
    from pathlib import Path

    import xarray as xr

    from sim.common.files import atomic_path, dumps
    from uq.outputs.netcdf import ENGINE

    p, s, o = result.problem, result.screened, result.objective
    v = result.verified
    index = {d: i for i, d in enumerate(s.designs)}
    nan_row = np.full(len(p.excitation), np.nan)

    def design_coords(designs: Sequence[Design], dim: str) -> dict[str, Any]:
        return {f"{dim}_clearance": (dim, [x.clearance for x in designs], {"units": "m", "long_name": "clearance g"}),
                f"{dim}_radius": (dim, [x.radius for x in designs], {"units": "m", "long_name": "sphere radius R"}),
                f"{dim}_material": (dim, [x.material for x in designs], {"long_name": "sphere material"}),
                f"{dim}_mass": (dim, [x.mass for x in designs], {"units": "kg", "long_name": "sphere mass m_a"})}

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
         "screened": (("design", "level"), [s.tip[index[x.design]] if x.design in index else nan_row for x in v],
                      {**metres, "long_name": "slow-flow resonant tip amplitude (worst over the D, tolerance ends)"}),
         "predicted": (("design", "level"), [x.prediction.per_level if x.prediction is not None else nan_row
                                             for x in v],
                       {**unit, "long_name": f"similarity law's {o.quantity} (worst over the box)"}),
         "worst": ("design", [x.worst for x in v], {**unit, "long_name": "verified worst case"}),
         "worst_interval_low": ("design", [x.worst_interval[0] for x in v],
                                {**unit, "long_name": "low end of the 95 % interval of a repeat's worst case"}),
         "worst_interval_high": ("design", [x.worst_interval[1] for x in v],
                                 {**unit, "long_name": "high end of the 95 % interval of a repeat's worst case"}),
         "switch_worst": ("design", [x.switch_worst() for x in v],
                          {**metres, "long_name": "base amplitude of the switch at the box's worst corner"}),
         "margin_worst": ("design", [x.margin(top) for x in v],
                          {"units": "1", "long_name": "margin of the switch above the top of the operating range"}),
         "admissible": ("design", [int(x.admissible(top, p.margin)) for x in v],
                        {"units": "1", "long_name": "1 if the margin holds and no run of the box is almost periodic"}),
         "no_absorber": ("level", result.no_absorber, {**metres, "long_name": "resonant tip amplitude without IES at "
                                                                              "the host's nominal D_1*"}),
         "screened_worst": ("screened", np.where(np.isfinite(s.worst), s.worst, np.nan),
                            {**metres, "long_name": "slow-flow worst case (NaN: the cavity does not fit)"})},
        coords={"level": ("level", result.levels, {"units": "1", "long_name": "excitation level a_base/a_base*"}),
                "a_base": ("level", np.asarray(p.excitation), {**metres, "long_name": "operating base amplitude"}),
                **design_coords([x.design for x in v], "design"), **design_coords(s.designs, "screened")},
        attrs={"Conventions": "CF-1.10", "title": "ies-workbench design", "kind": "design",
               "recommendation": (data["recommendation"] or {}).get("sentence", data["refusal"] or ""),
               "settings": dumps(data["settings"]), "objective": dumps(data["objective"])})
    path = Path(result.folder) / "results.nc"
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine=ENGINE)
    return path


def design_table(result: DesignResult) -> str:
    """The printed table of the verified designs (best first) with their predictions, worst cases with intervals and
    margins, ending with the recommendation in words (or the refusal) and the ies sweep line that checks it."""
    p, o = result.problem, result.objective
    top = result.top
    runs = sum(v.runs for v in result.verified)
    host = result.host.get("normalisation", {}).get("text", "")
    lines = [f"screened {len(result.screened.designs)} designs in {result.screened.seconds:.2f} s; "
             f"{p.fitting_text()}",
             p.box_text() + (f"; levels and amplitudes {host}" if host else ""),
             f"similarity references {result.reference_runs} runs; verified {len(result.verified)} designs in "
             f"{len(result.rounds)} round(s) by {runs} runs ({result.stop})",
             f"{'design':<38} {'predicted':>9} {'worst':>8} {'95 % interval':>15} {'switch':>8} {'margin':>7} "
             f"{'regimes':>9}",
             f"{'':<38} {o.shown_in:>9} {o.shown_in:>8} {o.shown_in:>15} {'um':>8} {'':>7}"]
    for v in result.verified:
        predicted = o.shown(v.prediction.worst) if v.prediction is not None else "-"
        mark = " (baseline)" if v.design == p.baseline else ""
        flag = "" if v.admissible(top, p.margin) else " x"
        switch = micrometres(v.switch_worst()) if math.isfinite(v.switch_worst()) else "-"
        if v.switch_kind() == "above":
            switch = ">" + switch
        lo, hi = v.worst_interval
        interval = f"{o.shown(lo)}-{o.shown(hi)}" if math.isfinite(lo) else "-"
        lines.append(f"{v.design.label() + mark:<38} {predicted:>9} {o.shown(v.worst):>8} {interval:>15} {switch:>8} "
                     f"{v.margin(top):>6.0%}{flag:<2}"
                     f"{_regime_letters('APR' if f > 0.5 else 'SMR' for f in v.apr):>9}")
    lines.append(f"predicted: the similarity law; 95 % interval: of the worst case of a repeat of the verification "
                 f"(other seeds); switch: at the box's worst corner (similarity law; lower where a verified run was almost "
                 f"periodic); x: margin below {p.margin:.0%} or a verified run almost periodic ({APR_RULE}: not "
                 "admissible)")
    failed = [v.design.label() for v in result.verified if v.outside.any()]
    if failed:
        lines.append(f"monotonicity check failed (the box's centre left the corners' band) for: {'; '.join(failed)}; "
                     "the worst case includes the centre")
    D_star = result.host.get("D_star")
    lines.append(f"no IES: {float(np.max(result.no_absorber)) * 1e3:.3g} mm at {micrometres(max(p.excitation))} um"
                 + (f" (the host's D_1* = {100 * D_star:.4g} %)" if D_star is not None else ""))
    if result.refusal is not None:
        return "\n".join(lines)
    if result.baseline is not None and result.baseline is not result.recommendation:
        lines.append(f"baseline: {result.baseline.design.label()}, worst case {o.shown(result.baseline.worst)} "
                     f"{o.shown_in}, margin {result.baseline.margin(top):.0%}; the recommendation's worst case is "
                     f"{result.baseline.worst / result.recommendation.worst:.2f}x lower")
    lines.append("the host's modes are taken as they are (the cavity's change of the host's mass is neglected)")
    lines.append("recommendation: " + result.sentence())
    edge = p.edge_text(result.recommendation.design)
    if edge:
        lines.append(edge)
    lines.append("check it: " + result.check_command())
    return "\n".join(lines)
