"""Orbit responses (sim.orbits.response: continuation in eta with its located bifurcations) against the stepped
sine where it settles on a periodic orbit, and against the slow flow's exact orbit where it loses stability."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from sim.model.contact_law import ContactLaw, restitution, xi_of_r_cont
from sim.model.system import Impactor
from sim.orbits.response import orbit_response
from sim.orbits.setting import OrbitSetting
from sim.orbits.shooting import solve_orbit
from sim.reduced.slow_flow import exact_orbit, periodic_orbits, slow_flow_model
from sim.stepped_sine.protocol import SteppedSine, run_sweep

from tests.sim.orbits._systems import one_mode


def test_where_the_stepped_sine_is_almost_periodic_it_is_on_a_stable_orbit(rig):
    """Mode 1 alone with the damped law (r_cont = 0.86, nominal k_H): the stepped sine (up from 0.94, 3 s wait, 2 s
    hold) is almost periodic at eta 0.96 and 0.965 with two impacts per period. The orbits found by continuation in
    eta from a stepped-sine start at 0.966 are stable there, and their amplitude is the stepped sine's per-period
    amplitude within 1 %. (They are asymmetric: the symmetric two-impact orbit has lost its stability below 0.96;
    this branch doubles its period near 0.969.)"""

    model, impactor = one_mode(rig), Impactor(contact_law=ContactLaw("hertz-damped", 0.86))
    sweep = run_sweep(model, impactor, 7.4, SteppedSine(eta_start=0.94, eta_stop=0.97, n_eta=7, wait=3.0, hold=2.0,
                                                        perturbation=0.0), seed=0, rep=0)
    response = orbit_response(OrbitSetting(model, impactor, 7.4, 0.966), "eta", (0.955, 0.966), start="simulation",
                              at=0.966, max_period=1, switches=0)
    branch = response.branches[0]
    etas = branch.values()
    for eta, mean, std in zip(sweep.eta[-3:-1], sweep.mean[-3:-1], sweep.std[-3:-1]):
        assert std / mean < 0.01
        nearest = branch.points[int(np.argmin(np.abs(etas - eta)))].orbit
        orbit = solve_orbit(replace(nearest.setting, eta=float(eta)), nearest.state, symmetric=False)
        assert orbit.stable and not orbit.symmetric and orbit.impacts_per_period == 2
        assert orbit.amplitude == pytest.approx(mean, rel=0.01)


def test_the_two_impact_orbit_loses_stability_where_the_slow_flow_says(rig):
    """The same host: continued in eta, the symmetric two-impact orbit loses its stability where the one-mode Newton
    model's exact orbit does (`sim.reduced.slow_flow.exact_orbit`, r = the law's restitution; its crossing bisected
    here to 1e-4 in eta), and the same way: the complex pair of the half map meets on the negative real axis and one
    real multiplier leaves through -1, a symmetry breaking (not a Neimark-Sacker point), located to |mu| within
    1e-4 of 1."""

    model, impactor = one_mode(rig), Impactor(contact_law=ContactLaw("hertz-damped", 0.86))
    r = restitution(float(xi_of_r_cont(0.86)))
    reference = slow_flow_model(model, impactor, r)

    def exact(eta: float):
        guess = sorted(periodic_orbits(reference, 7.4, eta), key=lambda o: -o.A_wall)[0]
        return exact_orbit(reference, 7.4, eta, guess)

    lo, hi = 0.955, 0.96
    assert exact(lo).stable and not exact(hi).stable
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if exact(mid).stable else (lo, mid)
    crossing = min(exact(hi).multipliers, key=lambda m: abs(m + 1.0))
    assert abs(crossing.imag) < 1e-12 and crossing.real < -1.0  # the reference: a real multiplier through -1
    response = orbit_response(OrbitSetting(model, impactor, 7.4, 0.95), "eta", (0.95, 0.97), switches=0,
                              searches=False, restitution=r)
    lost = [p for p in response.branches[0].points if p.note == "loses stability"]
    assert len(lost) == 1 and lost[0].label == "symmetry-breaking"
    assert lost[0].orbit.setting.eta == pytest.approx(0.5 * (lo + hi), abs=1e-3)  # the models differ by ~1 %
    assert lost[0].location_error < 1e-4
    assert abs(abs(min(lost[0].orbit.half_multipliers, key=lambda m: abs(m + 1.0))) ** 2 - 1.0) < 1e-4
