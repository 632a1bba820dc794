"""The rig as a 3D solid model (sim/hosts/solid.py): cost, mesh convergence and comparison with the Timoshenko beam model.

Run with `pytest -m benchmark tests/benchmarks/test_solid_rig.py -s` (about 5 min on the shared 2-core machine).
Targets: a coarse rig model solves in under 3 minutes and 4 GB; coarse and medium meshes agree within
0.5 % in f1..f9 and the contact values. The comparison with sim.hosts.rig.seed_rig_model() (frequencies, wall values at
the contact height, 2 mm higher and at the wall's top edge, tip values, participation, masses) is printed.
"""
import json
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("skfem")

from sim.hosts.rig import F_MEASURED_HZ, rig_modes, seed_rig_model, variant_parameters  # noqa: E402
from sim.hosts.solid import MESH_LEVELS, SolidGeometry, solid_mesh, solid_modal_model, solve_solid_modes  # noqa: E402
from sim.model.system import SPHERE_MASS  # noqa: E402

CHILD = """
import json, resource, time
start = time.perf_counter()
from sim.hosts.solid import solid_rig_model
result = solid_rig_model("coarse", convergence=False)
print(json.dumps({"seconds": time.perf_counter() - start, "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
                  "free_dofs": result.provenance["free_dofs"], "elements": result.provenance["elements"]}))
"""


def row(label, values, fmt="{:>9.4f}"):
    return f"{label:<34}" + " ".join(fmt.format(v) for v in values)


@pytest.mark.benchmark
def test_coarse_rig_time_and_memory():
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True)
    data = json.loads(out.stdout.strip().splitlines()[-1])
    print(f"\ncoarse rig model ({1e3 * MESH_LEVELS['coarse']:g} mm, {data['elements']} hex20 elements, "
          f"{data['free_dofs']} free DOFs): {data['seconds']:.0f} s including imports, peak RSS {data['peak_rss_gb']:.2f} GB")
    assert data["seconds"] < 180 and data["peak_rss_gb"] < 4.0


@pytest.mark.benchmark
def test_rig_convergence_and_comparison_with_the_beam_model():
    g = SolidGeometry()
    heights = {"contact": g.contact_height, "+2 mm": g.contact_height + 0.002, "top edge": g.free_length}
    results = {}
    for level in ("coarse", "medium"):
        start = time.perf_counter()
        modes = solve_solid_modes(solid_mesh(g, element_size=MESH_LEVELS[level]))
        model = solid_modal_model(modes)
        walls = {name: np.mean(modes.wall_values(height=z), axis=0) for name, z in heights.items()}
        results[level] = (modes, model, walls, time.perf_counter() - start)
    coarse, medium = results["coarse"][1], results["medium"][1]
    df = medium.frequencies_hz / coarse.frequencies_hz - 1
    dw = medium.phi_wall_left / coarse.phi_wall_left - 1
    modes, model, walls, seconds = results["medium"]
    E = modes.solid.material.E
    beam = seed_rig_model()
    rig = rig_modes(variant_parameters())
    beam_E = rig.params.E
    print(f"\nsolid model, medium mesh ({1e3 * MESH_LEVELS['medium']:g} mm, {modes.solid.n_free} free DOFs, {seconds:.0f} s), "
          f"E = {E / 1e9:g} GPa, clamp {g.clamp}; beam model: sim.hosts.rig, E = {beam_E / 1e9:g} GPa, joint spring")
    print(row("mode", range(1, 10), "{:>9d}"))
    print(row("f solid (Hz)", model.frequencies_hz, "{:>9.1f}"))
    print(row("f solid at the beam's E (Hz)", model.frequencies_hz * np.sqrt(beam_E / E), "{:>9.1f}"))
    print(row("f beam (Hz)", beam.frequencies_hz, "{:>9.1f}"))
    print(row("f solid(E beam)/beam - 1 (%)", 100 * (model.frequencies_hz * np.sqrt(beam_E / E) / beam.frequencies_hz - 1),
              "{:>9.2f}"))
    print(row("E for measured f1..f4 (GPa)", E * (np.array(F_MEASURED_HZ) / model.frequencies_hz[:4]) ** 2 / 1e9, "{:>9.1f}"))
    print(row("phi_c solid, contact height", walls["contact"]))
    print(row("phi_c beam", beam.phi_wall_left))
    print(row("  solid / beam", walls["contact"] / beam.phi_wall_left))
    print(row("phi solid 2 mm higher / contact", walls["+2 mm"] / walls["contact"]))
    print(row("phi solid 2 mm higher / beam", walls["+2 mm"] / beam.phi_wall_left))
    print(row("phi solid top edge / beam", walls["top edge"] / beam.phi_wall_left))
    print(row("phi_tip solid (outer face)", model.phi_tip))
    axis = modes.values_at(np.array([0.0, 0.0, g.measurement_height]))[0] * np.sign(modes.wall_values()[0])
    print(row("phi_tip solid (axis)", axis))
    print(row("phi_tip beam", beam.phi_tip))
    print(row("participation solid", model.participation))
    print(row("participation beam", beam.participation))
    print(f"m_a phi_c1^2: solid {100 * SPHERE_MASS * walls['contact'][0] ** 2:.2f} %, beam "
          f"{100 * SPHERE_MASS * beam.phi_wall_left[0] ** 2:.2f} % (paper 3.6 %); phi_tip/phi_c: solid "
          f"{model.phi_tip[0] / model.phi_wall_left[0]:.4f}, beam {beam.phi_tip[0] / beam.phi_wall_left[0]:.4f} (paper 0.96)")
    print(f"beam mass (free length): solid {modes.solid.material.rho * g.beam_volume:.3f} kg, beam model "
          f"{rig.beam_mass:.3f} kg (paper ca. 1.8 kg); solid with block {modes.solid.total_mass:.3f} kg; "
          f"sum of participation^2 of the 9 modes: solid {np.sum(model.participation ** 2):.3f} kg, beam "
          f"{np.sum(beam.participation ** 2):.3f} kg")
    print(row("coarse->medium change f (%)", 100 * df, "{:>9.3f}"))
    print(row("coarse->medium change phi_c (%)", 100 * dw, "{:>9.3f}"))
    assert np.max(np.abs(df)) < 5e-3 and np.max(np.abs(dw)) < 5e-3
