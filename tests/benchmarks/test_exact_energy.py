"""Energy conservation of the exact integrator at its defaults (within 1e-6 over 1000 impacts without damping
or excitation), next to a looser fall-back tolerance (rtol 1e-10) and to every
contact by Dormand-Prince at rtol 1e-7.

Run: pytest -m benchmark tests/benchmarks/test_exact_energy.py -s
"""
import pytest

from sim.integration.references import ringing_energy_drift

pytestmark = pytest.mark.benchmark


def test_energy_over_1000_impacts_at_the_defaults():
    rows = {"defaults (collocation, fall-backs at rtol 1e-11)": {},
            "fall-backs at rtol 1e-10": {"rtol": 1e-10},
            "Dormand-Prince contacts at rtol 1e-7": {"contacts": "dopri5", "rtol": 1e-7}}
    print()
    drifts = {}
    for label, options in rows.items():
        drift, impacts, stats = ringing_energy_drift(**options)
        drifts[label] = drift
        print(f"  {label:50s}: relative energy change {drift:.1e} over {impacts} impacts "
              f"({stats['collocation_fallbacks']} of {stats['contacts']} contacts fell back)")
    assert drifts["defaults (collocation, fall-backs at rtol 1e-11)"] < 1e-6
