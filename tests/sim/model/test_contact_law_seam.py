"""The contact-law seam: a law is defined once in `sim.model.contact_law` and every integrator compiles it. The toy
entry, defined here and registered by one line (`register`) inside the tests only, is a linear spring with
clearance and a constant of its own, f = k_lin delta for delta > 0 (k_lin in N/m, a row of
`sim.model.parameters.PARAMETERS` that the law carries: its option --k-lin, study key, JSON key and checks come with it;
its onset exponent 1 is what the exact integrator's step predictors are told). It is run end to end through a short
stepped-sine point (a wait and a hold of one period each at 0.99 omega_1, the sphere launched at 0.3 m/s: the
rattling is chaotic, and over four periods the exact integrator's 1e-11 per step already grow to 5e-7) by both
integrators and checked against scipy's DOP853 with events (`sim.integration.references.reference_run`, which
evaluates the law's force in Python), against its own single-impact reference (a half sine: restitution 1, duration
pi sqrt(m / k)), by the energy ledger's balance with the law's potential k delta^2 / 2, and through the real
commands: `ies sweep --contact-law linear-spring --k-lin ...` and an interval study that varies k_lin.

Files a law with a constant of its own touches: the file that defines it (here this test) and the registry line.

Compiling a new law into the integrators takes minutes (numba cannot cache kernels specialised on a law defined at
run time), so the tests that run it (the stepped-sine point, the single impact, `ies sweep` and the interval study) are
in the `long` set (`pytest -m long tests/sim/model/test_contact_law_seam.py`); the default run keeps stand-ins that
compile nothing: the registered toy law through `system_arrays` in the DOP853 reference against its single-impact
reference, its constant in the kernels' arrays, and the command line's refusal of an impossible constant.
"""
from __future__ import annotations

import json
import math

import numba
import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.common.units import Quantity
from sim.integration import exact, ode3
from sim.integration.energy import Ledger
from sim.integration.references import cantilever_like_model, reference_run
from sim.model import contact_law
from sim.model.contact_law import LAWS, ContactLaw, ImpactReference, Law, contact_law_of, register
from sim.model.parameters import PARAMETERS, CliOption, Feed, UncertainParameter
from sim.model.system import Impactor, ModalModel, a_base_star, system_arrays
from tests.support import interval_runs

K_SPRING = 4e6  # N/m: a contact of ~0.3 ms on the sphere, a few steps of ode3 at its paper step


@numba.njit(inline="always")
def spring_force(delta, rate, k, c):
    """k delta (N) for delta > 0."""
    return k * delta if delta > 0.0 else 0.0


@numba.njit(inline="always")
def spring_stiffness(delta, k):
    """k (N/m) in contact."""
    return k if delta > 0.0 else 0.0


def spring_potential(delta, k):
    """k delta^2 / 2 (J)."""
    return 0.5 * k * np.clip(np.asarray(delta, dtype=float), 0.0, None) ** 2


def spring_reference(m, v0, k, c):
    """A mass on a linear spring against a rigid wall: half a period of sqrt(k / m), elastic."""
    return ImpactReference(1.0, math.pi * math.sqrt(m / k))


#: the spring's own constant: a parameter row (units, bounds, plausible range, option, study key) that the law carries
K_LIN = UncertainParameter(
    "k_lin", "N/m", "stiffness k_lin of the linear spring", K_SPRING, (K_SPRING, K_SPRING), Feed(), "k_lin",
    quantity=Quantity("spring stiffness k_lin", "N/m", {"N/m": 1.0, "N/mm": 1e3, "kN/mm": 1e6}, (1e3, 1e10), "4kN/mm"),
    option=CliOption("--k-lin", "K", "stiffness of the linear-spring law in N/m, or with a unit: 4kN/mm"))

SPRING = Law("linear-spring", "a linear spring with clearance (test entry)", spring_force, spring_stiffness,
             spring_potential, spring_reference, constant=K_LIN, exponent=1.0)


@pytest.fixture
def spring():
    """The toy law registered for one test by its one registry line, and removed after it (with its constant's row)."""
    saved = dict(LAWS), dict(PARAMETERS)
    register(SPRING)  # the registry line: the law and its constant's row of PARAMETERS
    yield SPRING
    for registry, before in zip((LAWS, PARAMETERS), saved):
        registry.clear()
        registry.update(before)


def spring_impactor(k: float = K_SPRING) -> Impactor:
    """The sphere with the toy law and its own constant k (N/m)."""
    return Impactor(contact_law=ContactLaw("linear-spring"), inputs=(("k_lin", k),))


def three_mode_system():
    model = cantilever_like_model(n_modes=3)
    return model, system_arrays(model, spring_impactor())


#: the sphere's speed at the start (m/s): the beam rings up over seconds at resonance, the sphere rattles at once
LAUNCH_SPEED = 0.3


def short_point(run_step, sys, model, **options):
    """A short stepped-sine point at eta = 0.99, level 7.4 a_base*: a period of wait, one of hold, from the beam at
    rest and the sphere at LAUNCH_SPEED; returns (y at the start and the end, the hold's amplitudes, impacts, its
    ledger, Omega, a_base)."""
    Omega = 0.99 * float(model.omega[0])
    a_base = 7.4 * a_base_star(model)
    y = np.zeros(2 * model.n_modes + 2)
    y[-1] = LAUNCH_SPEED
    y0 = y.copy()
    run_step(y, 1, Omega, a_base, sys, **options)
    ledger = Ledger()
    amplitudes, impacts = run_step(y, 1, Omega, a_base, sys, ledger=ledger, **options)
    return y0, y, amplitudes, impacts, ledger, Omega, a_base


def test_a_law_registered_in_a_test_reaches_the_command_line_choices(spring):
    law = contact_law_of("linear-spring", None)
    assert law.law is SPRING and law.r_cont == 1.0 and not law.dissipative
    with pytest.raises(SimulationInputError, match="takes no r_cont"):
        ContactLaw("linear-spring", 0.9)
    import argparse

    from sim.cli import add_system_arguments

    parser = argparse.ArgumentParser()
    add_system_arguments(parser)
    assert parser.parse_args(["--contact-law", "linear-spring"]).contact_law == "linear-spring"


def test_an_unknown_law_is_one_line():
    with pytest.raises(SimulationInputError, match="unknown contact law 'linear-spring'; choose one of hertz"):
        ContactLaw("linear-spring")


def immovable_wall(law_name: str = "linear-spring"):
    """A sphere against a wall that does not move (a 1e6 kg 'beam'), the impactor with the law `law_name`."""
    m_wall = 1e6
    phi = 1.0 / math.sqrt(m_wall)
    model = ModalModel(frequencies_hz=np.array([1e-3]), damping_ratios=np.array([1e-6]), phi_wall_left=np.array([phi]),
                       phi_wall_right=np.array([phi]), phi_tip=np.array([phi]), participation=np.array([0.0]),
                       source="immovable wall")
    impactor = spring_impactor() if law_name == "linear-spring" else Impactor(contact_law=ContactLaw(law_name))
    return model, impactor, system_arrays(model, impactor)


def test_the_toy_law_reaches_the_reference_and_meets_its_single_impact(spring):
    """The default run's stand-in for the compiled tests below: the registered toy law, carried by `system_arrays`
    like any law, drives the DOP853 reference (its force evaluated in Python): one impact on the immovable wall lasts
    half a period of the spring and rebounds with restitution 1, as the law's own reference says."""
    model, impactor, sys = immovable_wall()
    assert sys.law.force is spring_force
    v0 = 0.2
    y0 = np.array([0.0, 0.0, -sys.g + 1e-4 * v0, -v0])
    _, onsets, releases, rebounds = reference_run(y0, 1e-3, 2 * math.pi * 1000.0, 0.0, sys, rtol=1e-12)
    expected = SPRING.reference(impactor.mass, v0, K_SPRING, 0.0)
    assert onsets.size == 1 and releases.size == 1
    assert releases[0] - onsets[0] == pytest.approx(expected.duration, rel=1e-6)
    assert abs(rebounds[0]) / v0 == pytest.approx(expected.restitution, rel=1e-6)


@pytest.mark.long  # compiles the toy law into the integrator: minutes (see the module docstring)
@pytest.mark.parametrize("integrator", ["exact", "ode3"])
def test_the_toy_law_runs_a_stepped_sine_point_like_scipy(spring, integrator):
    model, sys = three_mode_system()
    run_step, options = (exact.run_step, {}) if integrator == "exact" else (ode3.run_step, {"dt_scale": 0.05})
    y0, y, amplitudes, impacts, ledger, Omega, a_base = short_point(run_step, sys, model, **options)
    T = 2 * math.pi / Omega
    pieces: list = []
    y_ref, onsets, _, _ = reference_run(y0, 2 * T, Omega, a_base, sys, rtol=1e-12, pieces=pieces)
    assert onsets.size >= 3 and impacts.sum() == np.count_nonzero(onsets > T) > 0  # contacts in the wait and the hold
    n = model.n_modes
    scale = np.concatenate([np.abs(y_ref[:n]).max() * np.ones(n), np.abs(y_ref[n:2 * n]).max() * np.ones(n),
                            [sys.g, np.abs(y_ref[-1])]])
    error = float(np.max(np.abs(y - y_ref) / scale))
    # exact: 7e-9 measured; ode3 at a twentieth of the paper's step: 4e-3 (the force's kink at the onsets costs
    # ode3 its order; at the paper's step 0.6)
    tolerance = 1e-6 if integrator == "exact" else 1e-2
    assert error < tolerance, f"{integrator}: largest relative deviation from DOP853 {error:.2e}"
    # the point's measure: |c_1| of the tip over the hold, c_1 = (2/T) int q_tip e^{-i Omega t} dt (Sect. 5)
    t = np.linspace(T, 2 * T, 40001)
    q = np.empty_like(t)
    for start, stop, dense in pieces:
        inside = (t >= start) & (t <= stop)
        if inside.any():
            q[inside] = sys.phi_tip @ dense(t[inside])[:model.n_modes]
    c_1 = 2.0 / T * np.trapezoid(q * np.exp(-1j * Omega * t), t)
    assert amplitudes[0] == pytest.approx(abs(c_1), rel=1e-5 if integrator == "exact" else 1e-2)
    # the energy balance closes with the law's potential (its stored energy) and no contact dissipation
    assert np.all(ledger.contact == 0.0)
    assert abs(ledger.balance_error) < (1e-7 if integrator == "exact" else 1e-3)


@pytest.mark.long  # compiles the toy law into the exact integrator: minutes (see the module docstring)
def test_the_toy_law_meets_its_single_impact_reference(spring):
    """One impact on a wall that does not move (a 1e6 kg 'beam'): the exact integrator's impact log against the
    law's reference (half a period of the spring, restitution 1)."""
    model, impactor, sys = immovable_wall()
    v0 = 0.2
    y = np.zeros(4)
    y[2] = -sys.g + 1e-4 * v0
    y[3] = -v0
    ledger = Ledger()
    exact.run_step(y, 1, 2 * math.pi * 1000.0, 0.0, sys, ledger=ledger)
    assert ledger.impacts.size == 1
    expected = SPRING.reference(impactor.mass, v0, K_SPRING, 0.0)
    hit = ledger.impacts[0]
    assert hit["duration"] == pytest.approx(expected.duration, rel=1e-6)
    assert -hit["sphere_after"] / hit["sphere_before"] == pytest.approx(expected.restitution, rel=1e-6)


def test_the_registered_laws_give_their_own_references():
    """The laws of the registry: Hertz's contact time (Johnson, Sect. 11.4) and the damped law's restitution at
    r_cont,diss = 1 (elastic)."""
    m, v0, k = 0.0327, 0.3, 8.9e9
    hertz = contact_law.HERTZ.reference(m, v0, k, 0.0)
    assert hertz.restitution == 1.0
    assert hertz.duration == pytest.approx(2.9432 * (5 * m * v0**2 / (4 * k)) ** 0.4 / v0)
    assert contact_law.HERTZ_DAMPED.reference(m, v0, k, 0.0).restitution == 1.0
    assert contact_law_of(None, 0.9).law is contact_law.HERTZ_DAMPED
    assert contact_law_of("hertz-damped", 1.0).law is contact_law.HERTZ  # r_cont = 1: the elastic law, bit for bit


def test_the_law_gives_its_constant_to_the_kernels_and_its_predictor_its_exponent(spring):
    """The spring's k is the kernels' k (`SystemArrays.k_H`), not Hertz's k_H; the law's exponent and its contact time
    (pi sqrt(m / k) = pi delta_max / v0 for p = 1, the closed form Law derives) are the predictors' inputs."""
    model = cantilever_like_model(n_modes=3)
    sys = system_arrays(model, spring_impactor(2.5e6))
    assert sys.k_H == 2.5e6 and sys.law is SPRING
    assert SPRING.exponent == 1.0 and SPRING.duration_factor == pytest.approx(math.pi, rel=1e-14)
    assert contact_law.HERTZ.duration_factor == 2.9432  # Johnson's rounded value, stated by the Hertz law
    assert system_arrays(model, Impactor()).k_H == Impactor().k_H  # the Hertz laws keep k_H


def test_an_impossible_constant_is_refused_before_anything_runs(spring, capsys):
    """The stand-in of the next test in the default run: the constant's option refuses a negative value with the
    row's one line, before any kernel is compiled."""
    from uq.cli import main

    assert main(["sweep", "--level", "7.4", "--eta", "0.99", "--contact-law", "linear-spring", "--k-lin", "-1"]) == 2
    assert "argument --k-lin: k_lin must be a positive number, got -1.0" in capsys.readouterr().err


@pytest.mark.long  # compiles the toy law into the exact integrator: minutes (see the module docstring)
def test_the_toy_law_and_its_constant_through_ies_sweep(spring, model_file, capsys):
    """`ies sweep` takes the law and its constant's option (with a unit), reports the constant in its JSON, and
    refuses an impossible value with the row's one line."""
    from uq.cli import main

    argv = ["sweep", "--level", "7.4", "--eta", "0.99", "--wait", "0.02", "--hold", "0.05", "--reps", "1",
            "--model", model_file, "--contact-law", "linear-spring", "--json"]
    assert main([*argv, "--k-lin", "2kN/mm"]) == 0
    soft = json.loads(capsys.readouterr().out)
    assert soft["impactor"]["contact_law"] == "linear-spring" and soft["impactor"]["k_lin_N_per_m"] == 2e6
    assert main([*argv, "--k-lin", "8e6"]) == 0
    stiff = json.loads(capsys.readouterr().out)
    assert stiff["impactor"]["k_lin_N_per_m"] == 8e6
    assert soft["mean"] != stiff["mean"]  # the constant reaches the kernels: another spring, another response
    assert main([*argv, "--k-lin", "-1"]) == 2
    assert "argument --k-lin: k_lin must be a positive number, got -1.0" in capsys.readouterr().err


@pytest.mark.long  # compiles the toy law into the exact integrator: minutes (see the module docstring)
def test_a_study_varies_the_laws_constant(spring, model_file, tmp_path):
    """An interval study lists the constant under its study key and runs it end to end (`ies interval`)."""
    _, runs = interval_runs(tmp_path, f"contact_law = 'linear-spring'\nmodal_model = '{model_file}'\n"
                                      "[parameters.k_lin]\nmin = '2kN/mm'\nmax = '8kN/mm'\n")
    assert {float(r["k_lin_N_per_m"]) for r in runs} == {2e6, K_SPRING, 8e6}  # its ends and its nominal value
    assert len({r["mean"] for r in runs}) > 1
