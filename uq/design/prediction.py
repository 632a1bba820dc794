"""The prediction stage of `ies design`: the similarity law of the full model (`sim.reduced.similarity`) for each
sphere of the grid, simulated through the study runner (cached, resumable, parallel), and what it predicts for each
design: the worst case of the objective, and the excitation at which the design switches from strongly modulated
to almost periodic response at the uncertainty box's worst corner and at its centre, with the size of the jump.

Per sphere (radius and material: its mass and Eq. 8's k_H), the references span kappa = f k_H (g + t)^(1/2) over every
fitting clearance g, clearance tolerance t and k_H factor f of the box (geometric, adjacent kappas at most
KAPPA_RATIO apart) at both ends of the D_1 interval, each simulated on own levels a_base/a_base*(g) from the lowest
operating level of the largest cavity to REACH times the margin level of the smallest one (geometric, LEVEL_RATIO
apart), its switch bisected to `sim.reduced.similarity.RESOLUTION` levels. A reference with kappa between two
corners is simulated at the k_H factor interpolated geometrically between the box's ends and the clearance that
gives its kappa: by the law any realisation is the same run.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from uq.design.objectives import Objective
from uq.design.problem import DesignProblem, Design

#: adjacent reference kappas at most this factor apart (the switch moves about one level per factor 2 on the rig)
KAPPA_RATIO = 2.5
#: adjacent own levels of a reference's grid at most this factor apart
LEVEL_RATIO = 1.2
#: the references reach this factor beyond the highest margin level (to place the switch of designs beyond it)
REACH = 1.25
#: the own-level range of the references is clipped to this (below: the linear response; above: only designs far
#: on the almost periodic side, whose prediction is then clamped)
LEVEL_FLOOR, LEVEL_CEILING = 0.25, 30.0
#: repetitions per reference level (at most the design's own)
REFERENCE_REPS = 2


@dataclass(frozen=True)
class Corner:
    """A point of the uncertainty box: D_1 (-), the tolerance added to the clearance (m), the factor on Eq. 8's k_H."""

    D: float
    tolerance: float
    k_H_factor: float

    def describe(self) -> dict[str, float]:
        return {"D_1": self.D, "clearance_tolerance_m": self.tolerance, "k_H_factor": self.k_H_factor}

    def label(self) -> str:
        return f"D_1 {self.D:g}, g + {self.tolerance * 1e3:.3g} mm, k_H x{self.k_H_factor:.3g}"


def corner_of(point: Mapping[str, float], sphere: Design) -> Corner:
    """A box point's task parameters (`DesignProblem.corners`: D, g, k_H in SI) as a Corner of `sphere`."""
    tolerance = round(float(point["g"]) - sphere.clearance, 12)  # to the picometre: no -1e-19 m from the subtraction
    return Corner(float(point["D"]), tolerance + 0.0, float(point["k_H"]) / sphere.k_H)


@dataclass(frozen=True)
class DesignPrediction:
    """What the similarity law predicts for one design.

    per_level: the objective's worst case over the box at each operating level (SI); worst: over the levels;
    switch_worst (m): the lowest base amplitude of the switch over the box's corners, at `worst_corner`; switch_nominal
    (m): at the box's centre; *_kind: "found", "above" (no switch up to it: a lower bound) or "below" (an upper bound);
    jump: the objective (SI) just below and just above the switch at the worst corner (NaN without one)."""

    design: Design
    per_level: np.ndarray
    switch_worst: float
    switch_worst_kind: str
    worst_corner: Corner
    switch_nominal: float
    switch_nominal_kind: str
    jump: tuple[float, float]

    @property
    def worst(self) -> float:
        return float(np.max(self.per_level))

    def margin(self, top: float) -> float:
        """(switch at the worst corner) / top - 1 (-), top the highest operating base amplitude (m)."""
        return self.switch_worst / top - 1.0


@dataclass(frozen=True)
class SphereLaw:
    """The similarity law of one sphere on the host, with the realisation (g, k_H, D) of each reference and the runs it
    took."""

    law: Any
    realisations: tuple[tuple[float, float, float], ...]
    runs: int


class Predictor:
    """The similarity laws of the spheres a design needs, built on demand through `run` (a function from a list of
    `uq.problem.tasks.Task` to their records, the study runner's cache), and their predictions per design."""

    def __init__(self, problem: DesignProblem, objective: Objective, rig: Any,
                 run: Callable[[list[Any]], Mapping[Any, Any]]) -> None:
        from sim.model.system import Nominal, a_base_star

        self.problem, self.objective, self.rig, self._run = problem, objective, rig, run
        self.laws: dict[tuple[float, str], SphereLaw] = {}
        self._predicted: dict[Design, DesignPrediction] = {}  # a law never changes once built
        self._a_star = lambda g: a_base_star(rig, Nominal.of(rig, g))  # a_base*(g) (m), Sect. 5.3 with g* -> g
        self._a_star_nominal = a_base_star(rig)

    @property
    def runs(self) -> int:
        return sum(s.runs for s in self.laws.values())

    def reps(self) -> int:
        return min(REFERENCE_REPS, self.problem.repetitions)

    def plan(self, sphere: Design) -> tuple[list[tuple[float, float]], list[tuple[float, float, float]], list[float]]:
        """The references (kappa, D), their realisations (g, k_H, D) and the own levels of the law of `sphere`'s radius
        and material (its clearance does not matter)."""
        from sim.reduced.similarity import kappa, own_levels, reference_kappas

        p = self.problem
        gs = [g for g in p.clearances if p.fits(sphere.moved("clearance", g))] or list(p.clearances)
        t_lo, t_hi = min(p.clearance_tolerance), max(p.clearance_tolerance)
        f_lo, f_hi = min(p.k_H_factor), max(p.k_H_factor)
        k_lo, k_hi = kappa(f_lo * sphere.k_H, min(gs) + t_lo), kappa(f_hi * sphere.k_H, max(gs) + t_hi)
        kappas = reference_kappas(k_lo, k_hi, KAPPA_RATIO)
        references, realisations = [], []
        for k in kappas:
            share = 0.0 if k_hi <= k_lo * (1 + 1e-12) else math.log(k / k_lo) / math.log(k_hi / k_lo)
            k_H = sphere.k_H * f_lo * (f_hi / f_lo) ** share
            for D in sorted(set(p.D)):
                references.append((k, D))
                realisations.append(((k / k_H) ** 2, k_H, D))
        top = p.margin_level() * REACH
        low = min(p.excitation) / self._a_star(max(gs) + t_hi)
        high = top / self._a_star(min(gs) + t_lo)
        low = min(max(low, LEVEL_FLOOR), LEVEL_CEILING)
        high = min(max(high, low), LEVEL_CEILING)
        return references, realisations, own_levels(low, high, LEVEL_RATIO)

    def ensure(self, spheres: Sequence[Design]) -> None:
        """Build the law of every sphere (radius, material) among `spheres` that has none yet."""
        from sim.reduced.similarity import reference_curves

        for sphere in spheres:
            key = (sphere.radius, sphere.material)
            if key in self.laws:
                continue
            references, realisations, levels = self.plan(sphere)
            counted = [0]
            evaluate = self._evaluator(realisations, sphere.mass, counted)
            law = reference_curves(evaluate, references, levels)
            self.laws[key] = SphereLaw(law, tuple(realisations), counted[0])

    def _evaluator(self, realisations: Sequence[tuple[float, float, float]], mass: float,
                   counted: list[int]) -> Callable[[list[tuple[int, float]]], list[Any]]:
        """The references' outcomes at own levels: the share of almost periodic runs and the objective per a_noabs*.
        Below a reference's first impacts, own level D_1 / D_1* (Eq. 7, mode 1: the linear wall amplitude at resonance
        reaches g at a_base = 2 D_1 g / (phi_c phi^T M b), a_base*(g) at D_1*), the response is linear and its almost
        periodic label (a cv below 0.1) means nothing: it counts as no switch, as in `Verified.apr_seen_at` (a
        reference of the rig at own level 0.51 had one such run, and the law put the switch there)."""
        from sim.reduced.similarity import Outcome
        from uq.problem.tasks import Task

        reps = self.reps()
        omega_1 = float(self.rig.omega[0])

        def evaluate(batch: list[tuple[int, float]]) -> list[Outcome]:
            tasks = {}
            for i, own in batch:
                g, k_H, D = realisations[i]
                level = own * self._a_star(g) / self._a_star_nominal
                tasks[(i, own)] = [Task.make({"D": D, "g": g, "k_H": k_H, "m_a": mass}, level, rep) for rep in range(reps)]
            records = self._run([t for ts in tasks.values() for t in ts])
            counted[0] += sum(len(ts) for ts in tasks.values())
            out = []
            for request in batch:
                runs = [records[t] for t in tasks[request]]
                i, own = request
                linear = own < realisations[i][2] / self.rig.D_star  # below its first impacts (`first_impacts`)
                apr = [0.0 if linear else r["outputs"].get("apr", 0.0) for r in runs if not r.get("error")]
                values = [self.objective.of_run(r, omega_1) / r["trace"]["a_noabs"] for r in runs
                          if not r.get("error") and "trace" in r]
                values = [v for v in values if math.isfinite(v)]
                out.append(Outcome(float(np.mean(apr)) if apr else 0.0, float(np.mean(values)) if values else math.nan))
            return out

        return evaluate

    def predict(self, sphere: Design) -> DesignPrediction | None:
        """The prediction for one design (None when its sphere has no law yet)."""
        from sim.model.system import a_noabs_star
        from sim.reduced.similarity import kappa

        if sphere in self._predicted:
            return self._predicted[sphere]
        entry = self.laws.get((sphere.radius, sphere.material))
        if entry is None:
            return None
        law, p = entry.law, self.problem
        a = np.asarray(p.excitation, dtype=float)
        scale = np.array([a_noabs_star(self.rig, x) for x in a])  # objective per a_noabs* -> SI
        per_level = np.full(a.size, -np.inf)
        switches = []
        for point in p.corners(sphere):  # the box's corners, then its centre (built from the parameter rows)
            g, D = float(point["g"]), float(point["D"])
            k = kappa(float(point["k_H"]), g)
            own = a / self._a_star(g)
            values = law.values(k, D, own) * scale
            per_level = np.maximum(per_level, values)
            s = law.switch(k, D)
            switches.append((s.level * self._a_star(g), s.kind, corner_of(point, sphere), k))
        corner_switches = switches[:-1]
        a_s, kind, worst_corner, k_w = min(corner_switches, key=lambda x: x[0])
        below, above = law.jump(k_w, worst_corner.D)
        at_switch = a_noabs_star(self.rig, a_s)
        nominal = switches[-1]
        prediction = DesignPrediction(sphere, per_level, float(a_s), kind, worst_corner, float(nominal[0]), nominal[1],
                                      (below * at_switch, above * at_switch))
        self._predicted[sphere] = prediction
        return prediction

    def describe(self) -> list[dict[str, Any]]:
        """Each sphere's references as plain data (design.json "similarity")."""
        out = []
        for (R, material), entry in self.laws.items():
            curves = []
            for curve, (g, k_H, D) in zip(entry.law.curves, entry.realisations):
                s = curve.switch()
                curves.append({"kappa_N_per_m": curve.kappa, "D_1": curve.D, "clearance_m": g, "k_H_N_per_m1p5": k_H,
                               "own_levels": curve.levels, "apr_share": curve.apr, "value_per_a_noabs": curve.value,
                               "switch_own_level": s.level, "switch_kind": s.kind, "switch_width": s.width})
            out.append({"radius_m": R, "material": material, "runs": entry.runs, "repetitions": self.reps(),
                        "references": curves})
        return out
