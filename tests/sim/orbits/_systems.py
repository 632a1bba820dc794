"""Systems and measurements the orbit tests share (the fixtures in conftest.py build on them)."""
from __future__ import annotations

import numpy as np

from sim.model.system import ModalModel
from sim.orbits.setting import OrbitSetting

#: The higher modes' damping factor at which the rig's two-impact orbit at 7.4 / 0.95 is stable.
DAMPED = 100.0


def one_mode(rig: ModalModel) -> ModalModel:
    """The rig's mode 1 alone, with the beam mass set to the mode's mass at the walls 1/phi_c^2, so that the damped
    law's reduced mass (Eq. 10) is the one of the sphere against the mode: its restitution is then exactly
    `sim.model.contact_law.restitution(xi)`."""
    return ModalModel(frequencies_hz=rig.frequencies_hz[:1], damping_ratios=rig.damping_ratios[:1],
                      phi_wall_left=rig.phi_wall_left[:1], phi_wall_right=rig.phi_wall_right[:1],
                      phi_tip=rig.phi_tip[:1], participation=rig.participation[:1], source="rig mode 1",
                      beam_mass=float(1.0 / rig.phi_contact**2))


def departure_rate(setting: OrbitSetting, y: np.ndarray, basis: np.ndarray, periods: int,
                   epsilon: float = 1e-10) -> float:
    """The per-period growth factor of a perturbation of the orbit through y started as epsilon times the first
    column of `basis` (scaled units; the dominant eigenvector, or the real and imaginary parts of a complex one), by
    the exact integrator period by period against the unperturbed run: the geometric mean over `periods` of the
    growth of its coordinates in `basis` (least squares), in which the linearised map is |mu| times a rotation."""
    from sim.integration.exact import run_step

    sys = setting.system()
    scale = setting.scales()
    a, b = y.copy(), y + epsilon * basis[:, 0] * scale
    start = np.linalg.lstsq(basis, (b - a) / scale, rcond=None)[0]
    for _ in range(periods):
        run_step(a, 1, setting.Omega, setting.a_base, sys)
        run_step(b, 1, setting.Omega, setting.a_base, sys)
    end = np.linalg.lstsq(basis, (b - a) / scale, rcond=None)[0]
    return float((np.linalg.norm(end) / np.linalg.norm(start)) ** (1.0 / periods))
