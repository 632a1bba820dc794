"""The kernel cache of `sim` follows edits of any kernel file (sim.integration.jit): in a copy of the package, a kernel of
exact.py calls a kernel of flight.py; a constant of flight.py is changed between two runs in fresh processes.
A control pair of modules compiled with plain numba.njit(cache=True) shows the stale result this prevents."""
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim
from sim.integration import jit

SIM_DIR = Path(sim.__file__).resolve().parent
KERNEL_DIR = SIM_DIR / "integration"

PROBE_CALLEE = '''

PROBE = {value}


@kernel
def probe():
    return PROBE
'''
PROBE_CALLER = '''

@kernel
def probe_caller():
    return flight.probe() + 0.0
'''
PLAIN_CALLEE = '''from numba import njit

PROBE = {value}


@njit(cache=True)
def probe():
    return PROBE
'''
PLAIN_CALLER = '''from numba import njit

import plain_callee


@njit(cache=True)
def probe_caller():
    return plain_callee.probe() + 0.0
'''


def _run(root: Path, statement: str) -> str:
    """Run `statement` in a fresh interpreter with `root` first on the path; its printed output."""
    code = f"import sys; sys.path.insert(0, {str(root)!r}); {statement}"
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def _set_probe(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


@pytest.mark.slow
def test_an_edit_of_a_callee_file_reaches_the_cached_caller(tmp_path):
    package = tmp_path / "sim"
    shutil.copytree(SIM_DIR, package, ignore=shutil.ignore_patterns("__pycache__"))
    kernels = package / "integration"
    (kernels / "flight.py").write_text((kernels / "flight.py").read_text() + PROBE_CALLEE.format(value=1.0))
    (kernels / "exact.py").write_text((kernels / "exact.py").read_text() + PROBE_CALLER)
    (tmp_path / "plain_callee.py").write_text(PLAIN_CALLEE.format(value=1.0))
    (tmp_path / "plain_caller.py").write_text(PLAIN_CALLER)
    run_sim = "from sim.integration import exact; print(exact.probe_caller())"
    run_plain = "import plain_caller; print(plain_caller.probe_caller())"

    assert _run(tmp_path, run_sim) == "1.0"
    assert _run(tmp_path, run_plain) == "1.0"
    cached = list((kernels / "__pycache__").glob("exact.probe_caller-*.nbi"))
    assert cached, "the caller was not cached: the scenario would not test the cache"
    assert _run(tmp_path, run_sim) == "1.0"  # loaded from the cache

    _set_probe(kernels / "flight.py", "PROBE = 1.0", "PROBE = 2.0")
    _set_probe(tmp_path / "plain_callee.py", "PROBE = 1.0", "PROBE = 2.0")
    assert _run(tmp_path, run_sim) == "2.0"
    assert _run(tmp_path, run_plain) == "1.0", (
        "numba now follows edits of callee files by itself: sim.integration.jit's invalidation may no longer be needed")


def test_every_module_with_kernels_is_fingerprinted():
    """A kernel module missing from KERNEL_MODULES would not invalidate its callers' caches."""
    with_kernels = {path.relative_to(SIM_DIR).with_suffix("").as_posix() for path in SIM_DIR.rglob("*.py")
                    if re.search(r"^@(kernel|njit|numba\.njit)\b", path.read_text(), re.MULTILINE)}
    assert with_kernels <= {f"integration/{stem}" for stem in jit.KERNEL_MODULES}  # all kernels live in one folder
    assert all((KERNEL_DIR / f"{stem}.py").is_file() for stem in jit.KERNEL_MODULES)
    assert "njit" not in "".join((KERNEL_DIR / f"{stem}.py").read_text() for stem in jit.KERNEL_MODULES if stem != "jit")


def test_a_folder_that_cannot_be_written_is_left_alone(tmp_path):
    """Where numba cannot cache (here: the folder would be below a file) nothing is deleted and nothing raises."""
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert jit.discard_stale_kernels(blocker / "cache") is False


def test_a_stale_fingerprint_discards_only_the_kernel_modules_caches(tmp_path):
    kept = tmp_path / "other.f-1.py311.nbi"
    stale = [tmp_path / "exact._advance-10.py311.nbi", tmp_path / "exact._advance-10.py311.1.nbc"]
    for path in [kept, *stale]:
        path.write_text("x")
    (tmp_path / jit.FINGERPRINT_FILE).write_text("an older fingerprint")
    assert jit.discard_stale_kernels(tmp_path) is True
    assert kept.exists() and not any(path.exists() for path in stale)
    assert (tmp_path / jit.FINGERPRINT_FILE).read_text() == jit.fingerprint()
    stale[0].write_text("x")
    assert jit.discard_stale_kernels(tmp_path) is False and stale[0].exists()
