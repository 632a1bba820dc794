"""Fidelity of the rig model: the physically motivated variants of the host and impactor model whose effect on the
paper's Fig. 6 landmarks (`sim.stepped_sine.landmarks`) is studied (uq/studies/fidelity/README.md): a rolling sphere,
the damping of the higher modes, the 3D solid's variants (neck, update, contact point, Hertz patch).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.common.errors import SimulationInputError
from sim.hosts.solid import NECK_UPDATED_GEOMETRY, UPDATED_SOLID_GEOMETRY, SolidGeometry


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
