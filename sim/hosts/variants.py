"""Fidelity of the rig model: the landmarks of the paper's Fig. 6 (Sect. 5.3, Appendices B, D) measured on an
overview of resonant levels, and the physically motivated variants of the host and impactor model whose effect on
them is studied (uq/studies/fidelity/README.md).

Landmarks of the paper (Sect. 5.3, Fig. 6, Appendix B):
* the switch from strongly modulated (SMR) to almost periodic response (APR), and with it the optimum, at
  a_base/a_base* ~ 6.7, where the resonant mean (max) level is 1/20 (1/10) of a^noabs*;
* at 7.4 the resonant level is reached in the APR near eta = 0.976, with about two significant impacts per
  period; the measured APR tip amplitudes 0.58-0.95 mm are 0.14-0.19 a^noabs* by Eq. B.1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from sim.common.errors import SimulationInputError
from sim.stepped_sine.measures import PAPER_APR_ETA, PAPER_APR_LEVEL, PAPER_OPTIMUM_LEVEL, REGIME_CV_THRESHOLD
from sim.hosts.solid import NECK_UPDATED_GEOMETRY, UPDATED_SOLID_GEOMETRY, SolidGeometry


@dataclass(frozen=True)
class Landmarks:
    """The Fig. 6 landmarks of one overview (Sect. 5.3).

    levels (a_base/a_base*, ascending); resonant_mean, resonant_max (/ a^noabs*, averaged over the repetition
    samples) with the samples' range *_lo, *_hi; regime of the averaged response at the resonant mean;
    apr_samples: share of the repetition samples whose own resonant point is APR (cv <= threshold, with impacts).
    The switch: first_apr is the lowest level from which most samples (at least half) of every level are APR (None
    if the highest level is not), last_smr the highest level below it where most are not (None if there is none).
    optimum_level: the level of the lowest resonant
    mean, with reduction_mean = 1/resonant_mean and reduction_max = 1/resonant_max there; impacts_at_apr_eta:
    contact onsets per period at the grid point nearest PAPER_APR_ETA for each level (NaN off the grid).
    """

    levels: np.ndarray
    resonant_mean: np.ndarray
    resonant_mean_lo: np.ndarray
    resonant_mean_hi: np.ndarray
    resonant_max: np.ndarray
    resonant_max_lo: np.ndarray
    resonant_max_hi: np.ndarray
    regime: tuple[str, ...]
    apr_samples: np.ndarray
    impacts_at_apr_eta: np.ndarray
    first_apr: float | None
    last_smr: float | None
    optimum_level: float
    reduction_mean: float
    reduction_max: float

    def at(self, level: float, key: str = "resonant_mean") -> float:
        """A per-level quantity at `level` (NaN when the overview does not have it)."""
        hit = np.flatnonzero(np.isclose(self.levels, level))
        return float(getattr(self, key)[hit[0]]) if hit.size else float("nan")

    def summary(self) -> dict:
        """Plain data: the switch, the optimum, and the APR levels and impacts at 7.4 and 9."""
        return {
            "last_smr": self.last_smr, "first_apr": self.first_apr, "optimum_level": self.optimum_level,
            "reduction_mean": self.reduction_mean, "reduction_max": self.reduction_max,
            **{f"{key}_{level:g}": self.at(level, key) for level in (7.4, 9.0)
               for key in ("resonant_mean", "resonant_mean_lo", "resonant_mean_hi", "impacts_at_apr_eta")},
        }


def landmarks(results: Sequence) -> Landmarks:
    """Landmarks (Sect. 5.3) of an overview: one `sim.stepped_sine.protocol.SweepResult` per excitation level, any order."""
    results = sorted(results, key=lambda r: r.level)
    levels = np.array([r.level for r in results])
    mean = np.array([r.resonant_mean for r in results])
    mx = np.array([r.resonant_max for r in results])
    regime = tuple(r.regime for r in results)
    apr_samples = []
    impacts = []
    for r in results:
        rows, at_peak = np.arange(r.mean_samples.shape[0]), np.argmax(r.mean_samples, axis=1)
        apr = (r.cv_samples[rows, at_peak] <= REGIME_CV_THRESHOLD) & (r.impacts_samples[rows, at_peak] > 0)
        apr_samples.append(float(np.mean(apr)))
        k = int(np.argmin(np.abs(r.eta - PAPER_APR_ETA)))
        impacts.append(float(r.impacts_per_period[k]) if abs(r.eta[k] - PAPER_APR_ETA) < 1e-9 else float("nan"))
    mostly_apr = np.array(apr_samples) >= 0.5
    tail = np.flatnonzero(np.cumprod(mostly_apr[::-1])[::-1])  # indices of the mostly-APR levels at the top
    first_apr = float(levels[tail[0]]) if tail.size else None
    below = np.flatnonzero(~mostly_apr[: tail[0] if tail.size else levels.size])
    last_smr = float(levels[below[-1]]) if below.size else None
    best = int(np.argmin(mean))
    return Landmarks(
        levels=levels, resonant_mean=mean, resonant_max=mx,
        resonant_mean_lo=np.array([r.resonant_mean_samples.min() for r in results]),
        resonant_mean_hi=np.array([r.resonant_mean_samples.max() for r in results]),
        resonant_max_lo=np.array([r.resonant_max_samples.min() for r in results]),
        resonant_max_hi=np.array([r.resonant_max_samples.max() for r in results]),
        regime=regime, apr_samples=np.array(apr_samples), impacts_at_apr_eta=np.array(impacts),
        first_apr=first_apr, last_smr=last_smr, optimum_level=float(levels[best]),
        reduction_mean=1.0 / float(mean[best]), reduction_max=1.0 / float(mx[best]))


def switch_line(summary: dict) -> str:
    """One line on the switch to the almost periodic response of `Landmarks.summary()` next to the paper's."""
    last, first = summary["last_smr"], summary["first_apr"]
    if first is None:
        where = "no switch to APR: most repetition samples are not APR at the highest level"
    elif last is None:
        where = f"APR from the lowest level ({first:g}) on"
    else:
        where = f"switch from SMR to APR between a_base/a_base* = {last:g} and {first:g}"
    at_7_4 = summary.get("resonant_mean_7.4")  # NaN (None in JSON) when 7.4 is not among the levels
    level = "" if at_7_4 is None or math.isnan(at_7_4) else f"; resonant mean level at 7.4: {at_7_4:.3f}"
    return (f"{where} (by the majority of repetition samples){level}; the paper: switch and optimum at "
            f"{PAPER_OPTIMUM_LEVEL:g}, APR level at 7.4 {PAPER_APR_LEVEL[0]:g}-{PAPER_APR_LEVEL[1]:g} (Appendix B)")


def rolling_mass_factor(sphere_radius: float, support_half_width: float = 0.0) -> float:
    """Effective mass in x of a rolling sphere over its mass m_a (-), for the variant "the IES rolls" (Sect. 3.1
    assumes it slides without friction).

    A sphere (radius R, I = 2/5 m R^2) rolling along x on two rails at y = +-b (the groove's edges, b = half the
    groove width; b = 0 is a flat floor) touches them h = sqrt(R^2 - b^2) below its centre; no slip there means
    spin omega = v / h about y, so T = 1/2 m v^2 + 1/2 I omega^2 = 1/2 m v^2 (1 + 2 R^2 / (5 h^2)).
    Flat floor: 7/5; the rig's groove (R = 7.92 mm, b = 4 mm, h = 6.84 mm): 1.537.
    Rolling needs a tangential force of (factor - 1) m a at the rails, while friction gives at most mu m g there:
    at the accelerations of an impact (many thousand g) the sphere slides and keeps its spin, so the factor bounds
    the effect of rolling rather than describing the impacts.
    """
    if not (sphere_radius > 0 and 0 <= support_half_width < sphere_radius):
        raise SimulationInputError("rolling_mass_factor needs 0 <= support_half_width < sphere_radius (m)")
    h2 = sphere_radius**2 - support_half_width**2
    return 1.0 + 0.4 * sphere_radius**2 / h2


def with_higher_mode_damping(model, damping: float, first_mode: int = 5):
    """Copy of a ModalModel with the damping ratio of modes first_mode.. (1-based) set to `damping` (-); the paper
    sets D5..D9 = 0.1 % (Appendix A)."""
    from dataclasses import replace

    from sim.model.system import check_open_unit

    d = model.damping_ratios.copy()
    d[first_mode - 1:] = check_open_unit(damping, "damping of the higher modes")
    return replace(model, damping_ratios=d)


# Hertz contact radius a = sqrt(R delta_max) (m) of the strongest impact at a_base/a_base* = 7.4 near the optimum
# (`ies trace --level 7.4 --eta 0.96:0.976:9 --periods 20`, built-in rig: approach speeds 0.17-1.16 m/s, median
# 0.65): energy 1/2 m v^2 = 2/5 k_H delta^2.5 with the sphere's mass m_a = 17.7 g (an upper bound: the wall's own
# effective mass lowers delta), nominal k_H = 282e3 N/mm^1.5, R = 7.92 mm: delta_max = 25.6 um (impact time
# 2.94 delta/v = 65 us, as the trace's 62-70 us), a = 0.45 mm.
HERTZ_PATCH_RADIUS = 0.00045


@dataclass(frozen=True)
class SolidVariant:
    """A variant of the 3D solid host model (sim.hosts.solid): its geometry, where on the inner wall faces the contact
    acts (contact_offset m above the sphere centre, on the faces' centre line; the wall values averaged over a
    disc of patch_radius m there, 0 = the point), and why it is studied."""

    geometry: SolidGeometry
    contact_offset: float
    justification: str
    patch_radius: float = 0.0

    def wall_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The left and right contact points (m)."""
        z = self.geometry.contact_height + self.contact_offset
        return self.geometry.wall_point("left", z), self.geometry.wall_point("right", z)


SOLID_VARIANTS: dict[str, SolidVariant] = {
    "beam-neck": SolidVariant(SolidGeometry(), 0.0, "the beam model's updated neck (146 x 11.98 mm, y) in the solid "
                              "model at E = 207 GPa: f1 = 111.8 Hz against 117.4 Hz measured"),
    "updated": SolidVariant(UPDATED_SOLID_GEOMETRY, 0.0, "neck and free length updated to f1..f4 of Table A.1 at "
                            "E = 207 GPa (Appendix A; sim.hosts.solid.UPDATED_SOLID_GEOMETRY); contact at the sphere centre"),
    "updated-400": SolidVariant(NECK_UPDATED_GEOMETRY, 0.0, "the neck alone updated, free length 400 mm: f2..f4 "
                                "2.7-4.1 % low; contact at the sphere centre"),
    "updated-contact+2mm": SolidVariant(UPDATED_SOLID_GEOMETRY, 0.002, "sensitivity: the contact 2 mm above the "
                                        "sphere centre (no geometric reason: the sphere rests on the groove's edges)"),
    "updated-contact+4mm": SolidVariant(UPDATED_SOLID_GEOMETRY, 0.004, "sensitivity: the contact 4 mm above the "
                                        "sphere centre (no geometric reason: the sphere rests on the groove's edges)"),
    "updated-hertz-patch": SolidVariant(UPDATED_SOLID_GEOMETRY, 0.0, "the wall values averaged over the Hertz "
                                        "contact disc a = sqrt(R delta_max) = 0.45 mm of the strongest impact at "
                                        "7.4 (approach speed 1.16 m/s, nominal k_H, the sphere's mass; "
                                        "uq/studies/fidelity/README.md)", HERTZ_PATCH_RADIUS),
    "updated-patch-3mm": SolidVariant(UPDATED_SOLID_GEOMETRY, 0.0, "sensitivity: the wall values averaged over a "
                                      "3 mm disc (6.7 times the Hertz radius; no physical reason)", 0.003),
}


def solid_variant_model(name: str, mesh: str | float = "medium", convergence: bool = True, n_modes: int = 9):
    """The modal model of a SOLID_VARIANTS entry (Sect. 3.1, Eq. 7) by sim.hosts.solid.solid_rig_model on the quarter
    model (same modes as the full one), with the variant's name and justification in the provenance. Returns a
    sim.hosts.solid.SolidResult; medium mesh: about 20 s with the convergence partner."""
    from dataclasses import replace

    from sim.hosts.solid import solid_rig_model

    if name not in SOLID_VARIANTS:
        raise SimulationInputError(f"unknown solid variant {name!r}; choose one of {', '.join(SOLID_VARIANTS)}")
    variant = SOLID_VARIANTS[name]
    result = solid_rig_model(mesh, variant.geometry, n_modes=n_modes, patch_radius=variant.patch_radius,
                             wall_points=variant.wall_points(), convergence=convergence, symmetry="quarter")
    provenance = dict(result.provenance, variant=name, justification=variant.justification,
                      contact_offset_m=variant.contact_offset, patch_radius_m=variant.patch_radius)
    model = replace(result.model, source=f"{result.model.source}, variant {name}")
    return replace(result, model=model, provenance=provenance)
