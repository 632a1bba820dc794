"""Cold compilation of every kernel `ies reproduce all --quick` uses (issue 25 item 1): the warm-up of each study's
model (integrator and contact law, with and without the energy ledger) in a fresh process with an empty numba cache
folder (NUMBA_CACHE_DIR), as on a first run on a new machine.

Target: <= 90 s wall on 2 quiet cores. Latest: see `-s` (the machine's load average is printed beside it).

Run: pytest -m benchmark tests/benchmarks/test_cold_compile.py -s
"""
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.benchmark
ROOT = Path(__file__).resolve().parents[2]
TARGET_S = 90.0
WARM_ALL = """
from sim.integration.integrators import warm_up_all
from uq.outputs.paper_figures import PAPER_FIGURES, figures_of_all
from uq.methods import load_study
models = [load_study(PAPER_FIGURES[figure].study_file(True)).make_model() for figure in figures_of_all()]
warm_up_all(pair for model in models for pair in model.kernel_variants())
"""


def test_cold_compilation_of_reproduce_all_quick(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", WARM_ALL], cwd=ROOT, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - started
    assert done.returncode == 0, done.stderr[-2000:]
    print(f"\ncold compilation for reproduce all --quick: {seconds:.0f} s (target {TARGET_S:.0f} s; load average "
          f"{os.getloadavg()[0]:.1f})\n{done.stderr}")
    assert seconds <= TARGET_S
