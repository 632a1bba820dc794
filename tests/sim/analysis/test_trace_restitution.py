"""The modal coefficient of restitution (Eq. D.1) computed from a saved trace alone (`sim.analysis.signals.trace_restitution`:
the sampled displacements and contact forces of `ies trace`) against the simulator's own value from its exact impact
records (`sim.stepped_sine.measures.scattering_measures`), at a_base/a_base* = 7.4 in the almost periodic (eta 0.976, reached
by a down-sweep) and the strongly modulated (0.99) response."""
import numpy as np
import pytest

from sim.stepped_sine.measures import scattering_measures
from sim.stepped_sine.protocol import SteppedSine
from sim.hosts.rig import seed_rig_model
from sim.analysis.signals import trace_restitution
from sim.model.system import CLEARANCE_NOMINAL, SPHERE_MASS, Impactor
from sim.analysis.trace import record_trace


@pytest.mark.parametrize("eta, protocol", [
    (0.976, SteppedSine(eta_start=0.976, eta_stop=0.99, n_eta=5, sequence="down")),
    (0.99, SteppedSine(eta_start=0.99, eta_stop=0.99, n_eta=1)),
])
def test_restitution_from_the_samples_matches_the_simulators(eta, protocol):
    """Within 1 %: the samples (19.5 us apart) place onset and release by the free flight's straight line and the
    fundamental by a DFT of the period's samples, where the simulator has exact times and integrals."""
    trace = record_trace(seed_rig_model(9), Impactor(), 7.4, protocol)
    simulator = scattering_measures(trace.ledger)
    f = trace.Omega / (2 * np.pi)
    r_tip, n = trace_restitution(trace.signal, f, trace.a_base, CLEARANCE_NOMINAL, SPHERE_MASS, "tip")
    r_wall, _ = trace_restitution(trace.signal, f, trace.a_base, CLEARANCE_NOMINAL, SPHERE_MASS, "wall")
    print(f"\neta {eta}: {n} impacts; r tip {r_tip:.4f} (simulator {simulator.restitution:.4f}), wall {r_wall:.4f} "
          f"({simulator.restitution_wall:.4f})")
    assert n >= 50
    assert r_tip == pytest.approx(simulator.restitution, rel=0.01)
    assert r_wall == pytest.approx(simulator.restitution_wall, rel=0.01)
    assert r_tip < 0.95  # the 9-mode rig scatters: r below 1
