r"""The similarity law of the seed paper's Eqs. 2-7 as a predictor of the full model: the excitation at which a design
switches from strongly modulated (SMR) to almost periodic response (APR), and its resonant level on either side.

The law
-------
With Hertz's law F = k_H delta^1.5 (Eq. 4) the equations of motion (Eqs. 2-7) are invariant under g -> s g,
a_base -> s a_base, k_H -> s^-1/2 k_H: every displacement and force scales by s, time does not
(`tests/sim/integration/test_similarity.py` checks it on the simulator to round-off). For one host (its modes and
D_1) and one sphere mass m_a, the response normalised by a_noabs* at the *own* excitation level

    l = a_base / a_base*(g),   a_base*(g) = 2 D* g / |phi_c gamma|   (Sect. 5.3 with g* -> g)

therefore depends on g and k_H only through

    kappa = k_H g^(1/2)   (N/m),

and so does the switch, as a level l_s(kappa, D_1). Every clearance of a design grid, every k_H factor and every
clearance tolerance of the uncertainty box lies on this one family of curves. kappa enters only weakly: on the
built-in rig a factor 2 in g (1.41 in kappa) moves the switch by about half a level
(tests/benchmarks/test_slow_flow_switch.py).

The predictor
-------------
`reference_curves` simulates a few references, one per (kappa, D_1) pair spanning the kappas and dampings to be
predicted, on a grid of own levels with the full stepped-sine simulator, and bisects each reference's switch
bracket (last SMR level, first APR level] down to `resolution` levels. A level counts as APR when at least half of
its repetitions reach their resonant level almost periodically (the majority rule of
`sim.stepped_sine.landmarks.landmarks`, APR_SHARE). The switch is the first one from below
(`ReferenceCurve.bracket`): far above it the response can turn strongly modulated again for a few levels (seen at
17-18 a_base*(g) on the cantilever of the design benchmarks), which `landmarks`' rule "APR from there on" would take
for the switch. `SimilarityLaw` then predicts, for any (kappa, D_1):

* the switch level: the references' bracket midpoints, interpolated linearly in log kappa and in D_1 (clamped
  outside the references); a reference without a switch on its grid makes the prediction a bound ("above" its
  top level);
* the resonant level at any own level: each reference's curve on the predicted side of the switch (its SMR part
  below, its APR part above, each clamped to that part), interpolated the same way. Any scalar response per
  a_noabs* may stand for the resonant level (an amplitude in m / a_noabs*, an acceleration in m/s^2 / a_noabs*):
  under the law both scale with s.

The references' cost is independent of how many clearances a design grid has. The slow flow
(`sim.reduced.slow_flow`) stays the screening where it is right (the first impacts, the trends with the sphere
mass, the APR level within 5-13 %); its fold is only a lower bound of the switch.

Validity: tests/benchmarks/test_slow_flow_switch.py predicts each design's switch and SMR level from two references
at g/2 and 2 g (the design's own g never simulated for the prediction) and compares them with its own simulation, on
seven designs over three hosts (the rig, the sphere half and twice as heavy, twice the clearance, a cantilever, the
3D solid); its target and latest figures are in tests/benchmarks/README.md.

The cantilever is a uniform steel beam of another length, section and mass (tests/benchmarks/_cantilever.py: 55 Hz,
1.30 kg, m_a phi_c^2 = 5.2 % with the paper's sphere against the rig's 117 Hz, 1.57 kg, 3.5 %).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from sim.common.errors import SimulationInputError
from sim.stepped_sine.landmarks import APR_SHARE

#: the bracket width (levels) down to which `reference_curves` bisects each reference's switch
RESOLUTION = 0.25


def kappa(k_H: float, g: float) -> float:
    """kappa = k_H g^(1/2) (N/m): the one combination of k_H (N/m^1.5) and g (m) the normalised response depends on."""
    return float(k_H) * math.sqrt(float(g))


@dataclass(frozen=True)
class Outcome:
    """One simulated own level of a reference: the share of its repetitions that are APR at their resonant point,
    and the response per a_noabs* averaged over them."""

    apr: float
    value: float


@dataclass(frozen=True)
class Switch:
    """A predicted switch level (own level a_base/a_base*(g)): `kind` "found" (the midpoint of a bisected bracket,
    +- half its width), "above" (no switch up to `level`: a lower bound) or "below" (APR from `level` on: an upper
    bound)."""

    level: float
    kind: str = "found"
    width: float = 0.0

    @property
    def exists(self) -> bool:
        return self.kind != "above"


@dataclass(frozen=True)
class ReferenceCurve:
    """One reference of the law: kappa (N/m), D_1 (-), and per simulated own level (ascending) its Outcome."""

    kappa: float
    D: float
    levels: np.ndarray
    apr: np.ndarray
    value: np.ndarray

    @property
    def mostly_apr(self) -> np.ndarray:
        return self.apr >= APR_SHARE

    def bracket(self) -> tuple[float | None, float | None]:
        """(last SMR level, first APR level) of the first switch from below: the first APR level is the lowest mostly APR
        level above the lowest one that is not (None if there is none), the last SMR level the one below it (None if
        every level is APR). Mostly APR levels below the first SMR one (a rattle without a resonance, below the onset of
        impacts) do not count, and neither does whatever follows the first switch (on the rig and the cantilever a
        strongly modulated island far above it): a design must stay below the first."""
        apr = self.mostly_apr
        smr = np.flatnonzero(~apr)
        if not smr.size:
            return None, float(self.levels[0])
        later = np.flatnonzero(apr[smr[0]:])
        if not later.size:
            return float(self.levels[-1]), None
        first = smr[0] + later[0]
        return float(self.levels[first - 1]), float(self.levels[first])

    def switch(self) -> Switch:
        last, first = self.bracket()
        if first is None:
            return Switch(float(self.levels[-1]), "above")
        if last is None:
            return Switch(first, "below")
        return Switch(0.5 * (last + first), "found", first - last)

    def clear_sides(self) -> tuple[float, float]:
        """The response per a_noabs* at the highest level up to the switch bracket where no repetition is APR, and at
        the lowest from it where every repetition is (the bracket's own levels, where the repetitions split, would
        blur the jump); the bracket's levels where there are none."""
        last, first = self.bracket()
        if last is None or first is None:
            return math.nan, math.nan
        below = np.flatnonzero((self.levels <= last) & (self.apr == 0.0))
        above = np.flatnonzero((self.levels >= first) & (self.apr == 1.0))
        at_last = int(np.flatnonzero(self.levels == last)[0])
        at_first = int(np.flatnonzero(self.levels == first)[0])
        return (float(self.value[below[-1] if below.size else at_last]),
                float(self.value[above[0] if above.size else at_first]))

    def side_value(self, level: float, apr_side: bool) -> float:
        """The response per a_noabs* at `level` on one side of this reference's switch, interpolated linearly over that
        side's levels and clamped to them (the other side's levels are not used)."""
        last, first = self.bracket()
        if apr_side:
            keep = self.levels >= first if first is not None else np.zeros(self.levels.size, bool)
        else:
            keep = self.levels <= last if last is not None else np.zeros(self.levels.size, bool)
        if not keep.any():  # this reference has no such side: its nearest level stands in
            keep = np.ones(self.levels.size, bool)
        return float(np.interp(level, self.levels[keep], self.value[keep]))


def _weights(x: float, nodes: Sequence[float]) -> list[tuple[int, float]]:
    """Linear interpolation weights of x over ascending `nodes`, clamped at the ends."""
    nodes = list(nodes)
    if len(nodes) == 1 or x <= nodes[0]:
        return [(0, 1.0)]
    if x >= nodes[-1]:
        return [(len(nodes) - 1, 1.0)]
    k = int(np.searchsorted(nodes, x)) - 1
    t = (x - nodes[k]) / (nodes[k + 1] - nodes[k])
    return [(k, 1.0 - t), (k + 1, t)]


@dataclass(frozen=True)
class SimilarityLaw:
    """The references of one host and sphere (`reference_curves`), and the predictions they give by the law."""

    curves: tuple[ReferenceCurve, ...]
    dampings: tuple[float, ...] = field(init=False)

    def __post_init__(self) -> None:
        if not self.curves:
            raise SimulationInputError("similarity law: no reference curves")
        object.__setattr__(self, "dampings", tuple(sorted({c.D for c in self.curves})))

    def _blend(self, k: float, D: float) -> list[tuple[ReferenceCurve, float]]:
        """(reference, weight): linear in log kappa within each damping, then linear in D_1 (clamped)."""
        out: list[tuple[ReferenceCurve, float]] = []
        for j, wD in _weights(D, self.dampings):
            same = sorted((c for c in self.curves if c.D == self.dampings[j]), key=lambda c: c.kappa)
            for i, wk in _weights(math.log(k), [math.log(c.kappa) for c in same]):
                out.append((same[i], wD * wk))
        return [(c, w) for c, w in out if w > 0.0]

    def switch(self, k: float, D: float) -> Switch:
        """The predicted switch level (own level) at kappa `k` (N/m) and damping `D`."""
        parts = [(c.switch(), w) for c, w in self._blend(k, D)]
        level = sum(s.level * w for s, w in parts)
        kinds = {s.kind for s, _ in parts}
        kind = "above" if "above" in kinds else ("below" if kinds == {"below"} else "found")
        return Switch(level, kind, max(s.width for s, _ in parts))

    def value(self, k: float, D: float, level: float) -> float:
        """The predicted response per a_noabs* at own level `level`, kappa `k`, damping `D`: on the side of the predicted
        switch where `level` lies."""
        return float(self.values(k, D, [level])[0])

    def values(self, k: float, D: float, levels: Sequence[float]) -> np.ndarray:
        """`value` at each of `levels`, the switch and the blend found once."""
        s, blend = self.switch(k, D), self._blend(k, D)
        return np.array([sum(c.side_value(x, s.kind != "above" and x >= s.level) * w for c, w in blend)
                         for x in levels], dtype=float)

    def is_apr(self, k: float, D: float, level: float) -> bool:
        """True where `level` lies at or above the predicted switch."""
        s = self.switch(k, D)
        return s.kind != "above" and level >= s.level

    def jump(self, k: float, D: float) -> tuple[float, float]:
        """The response per a_noabs* on either side of the predicted switch (NaN without a switch): each reference's
        nearest levels where all its repetitions agree (`ReferenceCurve.clear_sides`), blended."""
        s = self.switch(k, D)
        if s.kind != "found":
            return math.nan, math.nan
        parts = [(c.clear_sides(), w) for c, w in self._blend(k, D)]
        return sum(b * w for (b, _), w in parts), sum(a * w for (_, a), w in parts)


#: one request of `reference_curves`' evaluate: (reference index, own level)
Request = tuple[int, float]


def reference_curves(evaluate: Callable[[list[Request]], Sequence[Outcome]], references: Sequence[tuple[float, float]],
                     levels: Sequence[float], *, resolution: float = RESOLUTION) -> SimilarityLaw:
    """Simulate the references (kappa in N/m, D_1) on the own levels `levels`, then bisect each one's switch bracket down
    to `resolution` levels. The grid is simulated in two passes: every other level first, then, per reference, the
    levels below its first APR level (above it only the coarse levels are needed: designs there are on the almost
    periodic side, and those runs are the slowest). `evaluate` runs a batch of requests (reference index, own level)
    and returns their Outcomes in order; every batch holds all references that need a level, so that a parallel
    evaluate keeps its workers busy."""
    grid = sorted({float(x) for x in levels})
    if not references or not grid or any(x <= 0 or not math.isfinite(x) for x in grid):
        raise SimulationInputError("similarity law: give at least one reference and positive own levels")
    if not resolution > 0:
        raise SimulationInputError(f"similarity law: the resolution must be > 0 levels, got {resolution!r}")
    data: list[dict[float, Outcome]] = [{} for _ in references]
    coarse = sorted({*grid[::2], grid[-1]})
    batch: list[Request] = [(i, x) for i in range(len(references)) for x in coarse]
    filled = False
    curves: list[ReferenceCurve] = []
    while batch:
        for (i, x), outcome in zip(batch, evaluate(batch), strict=True):
            data[i][x] = outcome
        curves = [_curve(k, D, data[i]) for i, (k, D) in enumerate(references)]
        batch = []
        if not filled:
            filled = True
            for i, curve in enumerate(curves):
                first = curve.bracket()[1]
                batch += [(i, x) for x in grid if x not in data[i] and (first is None or x < first)]
            if batch:
                continue
        for i, curve in enumerate(curves):
            last, first = curve.bracket()
            if last is not None and first is not None and first - last > resolution * (1 + 1e-9):
                middle = 0.5 * (last + first)
                if middle not in data[i]:
                    batch.append((i, middle))
    return SimilarityLaw(tuple(curves))


def _curve(k: float, D: float, points: Mapping[float, Outcome]) -> ReferenceCurve:
    levels = np.array(sorted(points))
    return ReferenceCurve(float(k), float(D), levels, np.array([points[x].apr for x in levels]),
                          np.array([points[x].value for x in levels]))


def reference_kappas(low: float, high: float, ratio: float = 2.5) -> list[float]:
    """Reference kappas from `low` to `high` (N/m), geometric, adjacent ones at most `ratio` apart (one when they are
    within 5 % of each other)."""
    if not (0 < low <= high and math.isfinite(high)):
        raise SimulationInputError(f"similarity law: need 0 < kappa_low <= kappa_high, got {low!r}, {high!r}")
    if high <= 1.05 * low:
        return [math.sqrt(low * high)]
    n = max(2, 1 + math.ceil(math.log(high / low) / math.log(ratio)))
    return [float(x) for x in np.geomspace(low, high, n)]


def own_levels(low: float, high: float, ratio: float = 1.2) -> list[float]:
    """A geometric grid of own levels from `low` to `high` with adjacent levels at most `ratio` apart, rounded to
    0.01 (the levels of a reference's grid)."""
    if not (0 < low <= high and math.isfinite(high)):
        raise SimulationInputError(f"similarity law: need 0 < low <= high levels, got {low!r}, {high!r}")
    n = max(2, 1 + math.ceil(math.log(high / low) / math.log(ratio))) if high > low else 1
    return sorted({round(float(x), 2) for x in np.geomspace(low, high, n)})


def simulate_levels(model, m_a: float, realise: Callable[[int], tuple[float, float, float]], protocol, *, reps: int,
                    seed: int, output: str = "mean") -> Callable[[list[Request]], list[Outcome]]:
    """An `evaluate` for `reference_curves` by direct stepped-sine sweeps (`sim.stepped_sine.protocol.sweep`): reference
    i is simulated as the design `realise(i)` = (g in m, k_H in N/m^1.5, D_1) with sphere mass m_a (kg) on `model`, its
    levels own levels (a_base*(g) of its own clearance); the value is the sweep's resonant `output` ("mean" or "max",
    / a_noabs*), the APR share that of its repetition samples (`sim.stepped_sine.landmarks.landmarks`)."""
    from sim.stepped_sine.landmarks import landmarks
    from sim.model.system import Impactor, Nominal
    from sim.stepped_sine.protocol import sweep

    def evaluate(batch: list[Request]) -> list[Outcome]:
        out = []
        for i, level in batch:
            g, k_H, D = realise(i)
            result = sweep(model.with_damping(D), Impactor(mass=m_a, clearance=g, k_H=k_H), float(level), protocol,
                           reps=reps, seed=seed, nominal=Nominal.of(model, g), progress=False)
            marks = landmarks([result])
            out.append(Outcome(float(marks.apr_samples[0]), float(getattr(result, f"resonant_{output}"))))
        return out

    return evaluate


__all__ = ["APR_SHARE", "RESOLUTION", "Outcome", "ReferenceCurve", "Request", "SimilarityLaw", "Switch", "kappa",
           "own_levels", "reference_curves", "reference_kappas", "simulate_levels"]
