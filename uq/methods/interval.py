"""Interval (vertex) propagation with a monotonicity check (seed paper, Sect. 5.4, Figs. 7 and 8).

The paper takes only the interval limits of D, g and k_H and *assumes* that the resonant response level
is monotone in each parameter, so that the band of the response is spanned by the corners of the box.
Here the assumption is checked: interior samples are evaluated too. Where an interior value leaves the
corner envelope (by more than the repetition noise allows), or a one-parameter sequence is not monotone,
the location is flagged and the band is widened to the envelope of *all* evaluated points.

Designs (points in the parameter box; each point is a dict of parameter values in SI units):
* individual variation (Fig. 7): one parameter along its axis (min, interior points, max), the others
  nominal;
* joint variation (Fig. 8): all 2^k corners of the varied parameters plus interior points (the centre
  and a scrambled Sobol' sample); the residual band of Fig. 8 is the joint design of the space with k_H
  fixed at its best estimate (`ParameterSpace.fix`).

The evaluation of the points is left to the caller (`uq.problem.study` runs the simulator through `uq.engine.runner`);
`propagate` does it for a plain function, which is how the layer is tested on analytic functions.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np

from uq.errors import StudyError
from uq.problem.space import ParameterSpace


@dataclass(frozen=True)
class DesignPoint:
    """One point of an interval design: its parameter values (SI), its role and a short label."""

    values: Mapping[str, float]
    role: str  # "corner" (interval limit) or "interior"
    label: str

    def key(self) -> tuple:
        """Hashable identity of the parameter values (points shared by designs are evaluated once)."""
        return tuple(sorted((k, float(v)) for k, v in self.values.items()))


@dataclass(frozen=True)
class Design:
    """Points of one band: `kind` is "axis" (ordered along one parameter) or "box" (corners + interior)."""

    name: str
    kind: str
    points: tuple[DesignPoint, ...]
    parameter: str | None = None  # the varied parameter of an axis design


def axis_design(space: ParameterSpace, name: str, n_interior: int = 1) -> Design:
    """Individual variation of `name` (Fig. 7): min, `n_interior` equispaced interior points, max.

    The nominal value is added as an interior point when it lies strictly inside the interval (D in
    Table 2). The others stay nominal. Points are ordered by the value of `name`.
    """
    if n_interior < 0:
        raise StudyError(f"interior points must be >= 0, got {n_interior}")
    p = space[name]
    if not p.varied:
        raise StudyError(f"parameter '{name}' is not varied (min = max = {p.min:g}); widen its interval")
    ts = [0.0, *np.linspace(0.0, 1.0, n_interior + 2)[1:-1].tolist(), 1.0]
    values = sorted({float(p.at(t)) for t in ts} | ({p.nominal} if p.min < p.nominal < p.max else set()))
    base = space.nominal()
    points = []
    for v in values:
        role = "corner" if v in (p.min, p.max) else "interior"
        points.append(DesignPoint({**base, name: v}, role, f"{name}={v:.6g}"))
    return Design(f"individual:{name}", "axis", tuple(points), parameter=name)


def box_design(space: ParameterSpace, n_interior: int = 4, *, name: str = "joint", seed: int = 0) -> Design:
    """Joint variation (Fig. 8): the 2^k corners of the varied parameters, the centre,
    `n_interior - 1` further interior points from a scrambled Sobol' sequence (seeded) and, when
    n_interior >= 1, the nominal point unless it is a corner."""
    varied = space.varied
    if not varied:
        raise StudyError("no parameter is varied; widen at least one interval")
    if n_interior < 0:
        raise StudyError(f"interior points must be >= 0, got {n_interior}")
    points = []
    for corner in itertools.product((0.0, 1.0), repeat=len(varied)):
        vals = space.point(corner)
        label = ",".join(f"{p.name}={'max' if t else 'min'}" for p, t in zip(varied, corner))
        points.append(DesignPoint(vals, "corner", label))
    interior = []
    if n_interior >= 1:
        interior.append(np.full(len(varied), 0.5))
    if n_interior >= 2:
        from scipy.stats import qmc

        m = int(np.ceil(np.log2(n_interior - 1))) if n_interior > 2 else 0
        sample = qmc.Sobol(d=len(varied), scramble=True, seed=seed).random_base2(m)[: n_interior - 1]
        interior.extend(0.05 + 0.9 * sample)  # strictly inside, away from the faces
    for i, t in enumerate(interior):
        vals = space.point(t)
        points.append(DesignPoint(vals, "interior", f"interior{i}"))
    nominal = DesignPoint(space.nominal(), "interior", "nominal")
    if n_interior >= 1 and all(nominal.key() != p.key() for p in points):
        points.append(nominal)  # inside the closed box too: monotonicity puts it within the corner band
    return Design(name, "box", tuple(points))


@dataclass
class Band:
    """Band of a response (one value per output column, e.g. per excitation level).

    lower/upper: the corner band, widened to the envelope of all evaluated points where the check failed;
    corner_lower/corner_upper: the paper's vertex band (interval limits only);
    flagged: where monotonicity failed beyond the noise tolerance; violation: by how much (NaN where untested);
    tested: where the check could be made (False where the values have no noise estimate, e.g. one repetition
    of a chaotic response: a difference cannot be judged against an unknown noise).
    """

    design: str
    lower: np.ndarray
    upper: np.ndarray
    corner_lower: np.ndarray
    corner_upper: np.ndarray
    flagged: np.ndarray
    violation: np.ndarray
    tested: np.ndarray
    notes: list[str] = field(default_factory=list)

    @property
    def monotone(self) -> bool:
        """No significant violation where the check was made."""
        return not bool(np.any(self.flagged))

    @property
    def fully_tested(self) -> bool:
        return bool(np.all(self.tested))


def _as_2d(values: np.ndarray | Sequence) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    return arr[:, None] if arr.ndim == 1 else arr


def band(design: Design, values: np.ndarray, noise: np.ndarray | None = None, *, z: float = 2.0,
         output_labels: Sequence[str] | None = None, pool: bool = True) -> Band:
    """Band of `values` (n_points x n_outputs, rows in `design.points` order) with the monotonicity check.

    `noise` (same shape) is the standard error of each value (repetition noise of a chaotic response;
    zero for a deterministic function, None = all zero; NaN = unknown, e.g. one repetition); two values differ
    significantly when their difference exceeds z * sqrt(se_a^2 + se_b^2). Box designs: an interior value
    outside the corner envelope is a violation. Axis designs: the sequence along the axis must be monotone
    (all steps >= -tol or all <= +tol). Non-finite values are refused (catch failed runs before). A column
    whose noise is unknown is not tested (`Band.tested`): its band is the corner band, and a note says so.
    pool: use the RMS standard error of the design's points with a noise estimate (per output column) for
    every point: a chaotic response scatters alike at nearby parameters, and the standard error of 2-5
    repetitions of one point is itself too uncertain to judge by.
    """
    y = _as_2d(values)
    if y.shape[0] != len(design.points):
        raise StudyError(f"design '{design.name}' has {len(design.points)} points but {y.shape[0]} values were given")
    if not np.all(np.isfinite(y)):
        raise StudyError(f"design '{design.name}': some values are NaN or infinite; report failed runs before banding")
    se = np.zeros_like(y) if noise is None else _as_2d(noise)
    if se.shape != y.shape:
        raise StudyError(f"noise has shape {se.shape} but values have shape {y.shape}")
    if pool:
        known = np.isfinite(se)
        mean_square = np.sum(np.where(known, se, 0.0) ** 2, axis=0) / np.maximum(known.sum(axis=0), 1)
        se = np.broadcast_to(np.where(known.any(axis=0), np.sqrt(mean_square), np.nan), se.shape)
    tested = np.isfinite(se).all(axis=0)
    se = np.nan_to_num(se, nan=0.0)
    corner = np.array([p.role == "corner" for p in design.points])
    labels = output_labels or [str(j) for j in range(y.shape[1])]
    corner_lo, corner_hi = y[corner].min(axis=0), y[corner].max(axis=0)
    violation = np.zeros(y.shape[1])
    notes: list[str] = []
    if design.kind == "box":
        idx_lo, idx_hi = np.where(corner)[0][y[corner].argmin(axis=0)], np.where(corner)[0][y[corner].argmax(axis=0)]
        for i in np.where(~corner)[0]:
            cols = np.arange(y.shape[1])
            tol_lo = z * np.hypot(se[i], se[idx_lo, cols])
            tol_hi = z * np.hypot(se[i], se[idx_hi, cols])
            excess = np.maximum(corner_lo - tol_lo - y[i], y[i] - corner_hi - tol_hi)
            violation = np.maximum(violation, np.maximum(excess, 0.0))
            for j in np.where((excess > 0) & tested)[0]:
                notes.append(f"{design.name}: {design.points[i].label} gives {y[i, j]:.4g} outside the corner band "
                             f"[{corner_lo[j]:.4g}, {corner_hi[j]:.4g}] at {labels[j]} -> band widened")
    elif design.kind == "axis":
        steps = np.diff(y, axis=0)
        tol = z * np.hypot(se[1:], se[:-1])
        down = np.maximum(-steps - tol, 0.0).max(axis=0)  # worst significant decrease
        up = np.maximum(steps - tol, 0.0).max(axis=0)  # worst significant increase
        violation = np.minimum(up, down)  # both directions significant -> not monotone
        for j in np.where((violation > 0) & tested)[0]:
            notes.append(f"{design.name}: response is not monotone in {design.parameter} at {labels[j]} "
                         f"(rises by {up[j]:.4g} and falls by {down[j]:.4g} beyond the noise) -> band widened")
    else:
        raise StudyError(f"unknown design kind '{design.kind}'")
    if not tested.all():
        where = ", ".join(labels[j] for j in np.where(~tested)[0])
        notes.append(f"{design.name}: monotonicity could not be tested at {where}: no noise estimate (one "
                     "repetition per point); run repetitions >= 2")
    flagged = (violation > 0) & tested
    violation = np.where(tested, violation, np.nan)
    lower = np.where(flagged, np.minimum(corner_lo, y.min(axis=0)), corner_lo)
    upper = np.where(flagged, np.maximum(corner_hi, y.max(axis=0)), corner_hi)
    return Band(design=design.name, lower=lower, upper=upper, corner_lower=corner_lo, corner_upper=corner_hi,
                flagged=flagged, violation=violation, tested=tested, notes=notes)


def propagate(func: Callable[[Mapping[str, float]], float | np.ndarray], design: Design, *,
              z: float = 2.0) -> Band:
    """Evaluate a deterministic function at every design point and band it (no noise)."""
    values = np.array([np.atleast_1d(np.asarray(func(p.values), dtype=float)) for p in design.points])
    return band(design, values, None, z=z)
