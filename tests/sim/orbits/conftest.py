"""Shared systems of the orbit tests: the rig, its first mode alone with a Newton-like contact, and a stable
two-impact orbit of the rig with its higher modes damped (where Newton's method reaches it from the slow flow
directly, `sim.orbits.starts`)."""
from __future__ import annotations

import numpy as np
import pytest

from sim.hosts.rig import seed_rig_model
from sim.model.contact_law import ContactLaw
from sim.model.system import Impactor, ModalModel
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import solve_orbit
from sim.orbits.starts import slow_flow_candidates, slow_flow_state

#: The higher modes' damping factor at which the rig's two-impact orbit at 7.4 / 0.95 is stable.
DAMPED = 100.0


@pytest.fixture(scope="session")
def rig() -> ModalModel:
    return seed_rig_model(9)


def one_mode(rig: ModalModel) -> ModalModel:
    """The rig's mode 1 alone, with the beam mass set to the mode's mass at the walls 1/phi_c^2, so that the damped
    law's reduced mass (Eq. 10) is the one of the sphere against the mode: its restitution is then exactly
    `sim.model.contact_law.restitution(xi)`."""
    return ModalModel(frequencies_hz=rig.frequencies_hz[:1], damping_ratios=rig.damping_ratios[:1],
                      phi_wall_left=rig.phi_wall_left[:1], phi_wall_right=rig.phi_wall_right[:1],
                      phi_tip=rig.phi_tip[:1], participation=rig.participation[:1], source="rig mode 1",
                      beam_mass=float(1.0 / rig.phi_contact**2))


@pytest.fixture(scope="session")
def newton_like(rig) -> tuple[ModalModel, Impactor, float]:
    """(one-mode model, sphere with the damped law at r_cont = 0.8 and 100 k_H*, r_cont)."""
    r_cont = 0.8
    return one_mode(rig), Impactor(k_H=100 * Impactor().k_H, contact_law=ContactLaw("hertz-damped", r_cont)), r_cont


@pytest.fixture(scope="session")
def stable_rig_orbit(rig):
    """The rig's symmetric two-impact orbit at 7.4 / eta 0.95 with the higher modes' damping x DAMPED: stable."""
    setting = OrbitSetting(rig, Impactor(), 7.4, 0.95, higher_damping=DAMPED)
    orbit = solve_orbit(setting, slow_flow_state(setting, slow_flow_candidates(setting)[0]))
    assert orbit.stable and orbit.pattern == "RL"
    return orbit


@pytest.fixture(scope="session")
def nominal_rig_orbit(rig):
    """The nominal rig's symmetric two-impact orbit at 7.4 / eta 0.95 (`sim.orbits.starts.slow_flow_orbit`: from the
    slow flow through the higher modes' damping): unstable, a complex pair of multipliers |mu| ~ 12."""
    from sim.orbits.starts import slow_flow_orbit

    return slow_flow_orbit(OrbitSetting(rig, Impactor(), 7.4, 0.95))


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
