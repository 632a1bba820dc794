"""Shared systems of the orbit tests: the rig, its first mode alone with a Newton-like contact, and a stable
two-impact orbit of the rig with its higher modes damped (where Newton's method reaches it from the slow flow
directly, `sim.orbits.starts`)."""
from __future__ import annotations

import pytest

from sim.hosts.rig import seed_rig_model
from sim.model.contact_law import ContactLaw
from sim.model.system import Impactor, ModalModel
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import solve_orbit
from sim.orbits.starts import slow_flow_candidates, slow_flow_state

from tests.sim.orbits._systems import DAMPED, one_mode


@pytest.fixture(scope="session")
def rig() -> ModalModel:
    return seed_rig_model(9)


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
