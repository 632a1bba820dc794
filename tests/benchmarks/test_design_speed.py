"""Speed of `ies design`.

* The slow-flow kernel (`sim.reduced.slow_flow.screen`): 50 clearances x 10 sphere radii x 20 excitation levels.
  Target <= 2 s (median of 5 repeats after one untimed call; numpy only, no JIT). Latest: 0.03-0.04 s.
* The design's screening step (`uq.design.search.screen_designs`: the same grid for each end of the D interval and of the
  clearance tolerance, i.e. four slow-flow calls). Target <= 2 s. Latest: see `-s`.
* A design like the one a new user tried on an unseen host (the cantilever of `_cantilever.py`, 8 clearances, 6 levels,
  the box, 3 repetitions, default --candidates), the extra repetitions at the deciding cells included (`settle`):
  target <= 5 min on 2 cores after compilation.
* The README's worked example, run as written: target <= 5 min on 2 cores; its recommendation pinned (clearance within
  0.1 mm, worst case within 15 % and inside its 95 % interval's neighbourhood, its margin at least 20 %; the paper's
  0.58 mm switching inside the range).

Run: pytest -m benchmark tests/benchmarks/test_design_speed.py -s
"""
import os
import statistics
import time

import numpy as np
import pytest

from sim.model.materials import material, sphere_mass
from sim.reduced.slow_flow import host_mode, screen
from sim.hosts.rig import seed_rig_model

pytestmark = pytest.mark.benchmark
SCREENING_TARGET_S = 2.0
REPEATS = 5


def test_screening_50_clearances_10_radii_20_levels():
    host = host_mode(seed_rig_model())
    clearances = np.linspace(0.2e-3, 1.2e-3, 50)
    masses = sphere_mass(np.linspace(4e-3, 9e-3, 10), material("brass"))
    a_base = np.linspace(2e-6, 8e-6, 20)
    result = screen(host, clearances, masses, a_base, 0.86)  # untimed first call
    times = []
    for _ in range(REPEATS):
        started = time.perf_counter()
        result = screen(host, clearances, masses, a_base, 0.86)
        times.append(time.perf_counter() - started)
    median = statistics.median(times)
    print(f"\nscreening 50 x 10 x 20 designs: median {median:.3f} s over {REPEATS} (target {SCREENING_TARGET_S} s)")
    assert result.tip.shape == (50, 10, 20) and np.all(np.isfinite(result.tip)) and np.all(result.tip > 0)
    assert median <= SCREENING_TARGET_S


def test_the_design_screening_step_50_clearances_10_radii_20_levels():
    from uq.design.problem import DesignProblem, host_mode as design_host, host_model
    from uq.design.search import screen_designs

    problem = DesignProblem(excitation=tuple(np.linspace(2e-6, 8e-6, 20)),
                            clearances=tuple(np.linspace(0.2e-3, 1.2e-3, 50)),
                            radii=tuple(np.linspace(4e-3, 9e-3, 10)))
    mode = design_host(host_model(problem))
    screen_designs(problem, mode)  # untimed first call
    times = []
    for _ in range(REPEATS):
        started = time.perf_counter()
        screened = screen_designs(problem, mode)
        times.append(time.perf_counter() - started)
    median = statistics.median(times)
    print(f"\ndesign screening step (500 designs x 20 levels, 4 uncertainty ends): median {median:.3f} s "
          f"(target {SCREENING_TARGET_S} s)")
    assert screened.tip.shape == (500, 20) and median <= SCREENING_TARGET_S


#: the design of tests/benchmarks/test_design_brute_force.py (8 clearances, 6 levels, the box, 3 repetitions) on the
#: cantilever, with the default --candidates
TARGET_S = 5 * 60


def _cpu_seconds() -> float:
    """CPU seconds of this process and its finished children (the workers, once shut down)."""
    import resource

    return sum(resource.getrusage(who).ru_utime + resource.getrusage(who).ru_stime
               for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))


def _run_design(argv, out):
    """`ies design` in this process with one worker per core: (printed text, wall seconds, CPU seconds of this process
    and the workers). On the shared machine the wall time depends on the others' load; CPU seconds / cores is what
    the same design takes on quiet cores (plus the workers' start)."""
    import contextlib
    import io
    import os

    from joblib.externals.loky import get_reusable_executor

    from uq.cli import main

    printed = io.StringIO()
    get_reusable_executor().shutdown(wait=True)
    cpu, started = _cpu_seconds(), time.perf_counter()
    with contextlib.redirect_stdout(printed):
        assert main(["design", *argv, "--out", str(out), "--quiet", "--no-figures",
                     "--jobs", str(os.cpu_count() or 1)]) == 0
    seconds = time.perf_counter() - started
    get_reusable_executor().shutdown(wait=True)  # the workers' CPU time counts once they are reaped
    return printed.getvalue(), seconds, _cpu_seconds() - cpu


def _report(name, printed, seconds, cpu, out):
    import json
    import os

    data = json.loads((out / "design.json").read_text())
    runs = sum(v["runs"] for v in data["verified"]) + data["search"]["reference_runs"]
    cores = os.cpu_count() or 1
    print(f"\n{printed}\n{name}: {seconds:.0f} s wall on {cores} cores at load average {os.getloadavg()[0]:.1f}, "
          f"{cpu:.0f} CPU s ({cpu / cores:.0f} s on {cores} quiet cores), {len(data['verified'])} designs verified in "
          f"{len(data['search']['rounds'])} rounds, {runs} runs in all ({data['search']['reference_runs']} for the "
          f"similarity references; target {TARGET_S} s)")
    return data


def test_a_design_of_8_clearances_and_6_levels_on_an_unseen_host_within_5_minutes(tmp_path):
    from sim.integration.integrators import warm_up
    from tests.benchmarks._cantilever import save_cantilever
    from tests.benchmarks.test_design_brute_force import design_arguments

    warm_up("exact")  # compilation is not part of the design's time
    argv = design_arguments(save_cantilever(tmp_path / "cantilever.toml"))
    printed, seconds, cpu = _run_design(argv, tmp_path / "unseen")
    _report("8 clearances, 6 levels on the cantilever", printed, seconds, cpu, tmp_path / "unseen")
    assert min(seconds, cpu / (os.cpu_count() or 1)) <= TARGET_S


def readme_design_example() -> list[str]:
    """The arguments of the README's worked example (the line `ies design --excitation 0.66um:6.6um:...`)."""
    import shlex
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    line = next(line for line in readme.splitlines() if line.strip().startswith("ies design --excitation 0.66um"))
    return [a for a in shlex.split(line.strip())[2:] if a]


def test_the_readme_worked_example_within_5_minutes_and_its_recommendation_pinned(tmp_path):
    from sim.integration.integrators import warm_up

    argv = readme_design_example()
    argv = [a for i, a in enumerate(argv) if a != "--out" and (i == 0 or argv[i - 1] != "--out")]
    warm_up("exact")
    printed, seconds, cpu = _run_design(argv, tmp_path / "example")
    data = _report("worked example", printed, seconds, cpu, tmp_path / "example")
    best, paper = data["recommendation"], data["baseline"]
    # pinned (README): 1.4 mm, worst case 0.296 mm (15 %: chaotic runs; 95 % interval 0.244-0.328 mm), margin 35 % to
    # the switch at 8.9 um; the paper's 0.58 mm switches inside the range (3.4 um)
    assert best["material"] == "brass" and best["radius_m"] == pytest.approx(7.92e-3)
    assert best["clearance_m"] == pytest.approx(1.4e-3, abs=0.1e-3)
    assert best["worst_m"] == pytest.approx(0.296e-3, rel=0.15)
    low, high = best["worst_interval_m"]
    assert low < best["worst_m"] < high
    assert best["admissible"] and best["margin_worst"] >= 0.2
    assert not paper["admissible"] and paper["switch_worst_m"] < max(data["settings"]["excitation"])
    assert min(seconds, cpu / (os.cpu_count() or 1)) <= TARGET_S
