"""The kernel cache of `sim` follows edits of any kernel file (sim.integration.jit): in a copy of the package, a kernel of
exact.py calls a kernel of flight.py; a constant of flight.py is changed between two runs in fresh processes.
A control pair of modules compiled with plain numba.njit(cache=True) shows the stale result this prevents."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import sim
from sim.integration import jit

SIM_DIR = Path(sim.__file__).resolve().parent

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
    """Run `statement` in a fresh interpreter with `root` first on the path and the kernel cache in root/cache; its
    printed output."""
    code = f"import sys; sys.path.insert(0, {str(root)!r}); {statement}"
    env = {**os.environ, "IES_CACHE_DIR": str(root / "cache")}
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, timeout=600, env=env)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def _set_probe(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


@pytest.mark.slow
def test_an_edit_of_a_callee_file_reaches_the_cached_caller(tmp_path):
    shutil.copytree(SIM_DIR, tmp_path / "sim", ignore=shutil.ignore_patterns("__pycache__"))
    package = tmp_path / "sim" / "integration"
    (package / "flight.py").write_text((package / "flight.py").read_text() + PROBE_CALLEE.format(value=1.0))
    (package / "exact.py").write_text((package / "exact.py").read_text() + PROBE_CALLER)
    (tmp_path / "plain_callee.py").write_text(PLAIN_CALLEE.format(value=1.0))
    (tmp_path / "plain_caller.py").write_text(PLAIN_CALLER)
    run_sim = "from sim.integration import exact; print(exact.probe_caller())"
    run_plain = "import plain_caller; print(plain_caller.probe_caller())"

    assert _run(tmp_path, run_sim) == "1.0"
    assert _run(tmp_path, run_plain) == "1.0"
    cached = list((tmp_path / "cache").glob("sim-*/exact.probe_caller-*.nbi"))
    assert len(cached) == 1, "the caller was not cached: the scenario would not test the cache"
    assert _run(tmp_path, run_sim) == "1.0"  # loaded from the cache

    _set_probe(package / "flight.py", "PROBE = 1.0", "PROBE = 2.0")
    _set_probe(tmp_path / "plain_callee.py", "PROBE = 1.0", "PROBE = 2.0")
    assert _run(tmp_path, run_sim) == "2.0"
    assert len(list((tmp_path / "cache").glob("sim-*/exact.probe_caller-*.nbi"))) == 2  # a folder per version
    assert _run(tmp_path, run_plain) == "1.0", (
        "numba now follows edits of callee files by itself: sim.integration.jit's invalidation may no longer be needed")


@pytest.mark.slow
def test_an_edit_outside_the_kernels_is_a_new_code_version_that_compiles_nothing(tmp_path):
    """The simulator's kernels live in the folder of its code version (the hash `ies --version` prints): an edit of a
    file without kernels gives a new version and a new folder, which starts from the machine code of the same kernel
    sources (hard links), so the cached kernel is loaded, not compiled."""
    shutil.copytree(SIM_DIR, tmp_path / "sim", ignore=shutil.ignore_patterns("__pycache__"))
    package = tmp_path / "sim" / "integration"
    (package / "flight.py").write_text((package / "flight.py").read_text() + PROBE_CALLEE.format(value=1.0))
    (package / "exact.py").write_text((package / "exact.py").read_text() + PROBE_CALLER)
    run = ("from sim.integration import exact, jit; from sim.common.kernel_cache import code_version; "
           "value = exact.probe_caller(); print(value, sum(exact.probe_caller.stats.cache_hits.values()), "
           "jit.cache_folder().name, code_version())")
    value, hits, folder, version = _run(tmp_path, run).split()
    assert (value, hits, folder) == ("1.0", "0", f"sim-{version}")  # compiled into the folder of the code version
    cli = tmp_path / "sim" / "cli.py"
    cli.write_text(cli.read_text() + "\n# an edit outside the kernels\n")
    value, hits, edited, new_version = _run(tmp_path, run).split()
    assert (value, hits, edited) == ("1.0", "1", f"sim-{new_version}") and new_version != version
    first, second = (next((tmp_path / "cache" / name).glob("exact.probe_caller-*.nbi")) for name in (folder, edited))
    assert first.stat().st_ino == second.stat().st_ino  # one file on disk


def test_every_module_with_kernels_is_fingerprinted():
    """A kernel module missing from KERNEL_MODULES (or, for the inlined contact laws, FINGERPRINT_FILES) would not
    invalidate its callers' caches."""
    integration = SIM_DIR / "integration"
    with_kernels = {path.resolve() for path in SIM_DIR.rglob("*.py")
                    if re.search(r"^@(kernel|njit|numba\.njit)\b", path.read_text(), re.MULTILINE)}
    fingerprinted = {(integration / f"{stem}.py").resolve() for stem in jit.KERNEL_MODULES} | {
        path.resolve() for path in jit.FINGERPRINT_FILES}
    assert with_kernels <= fingerprinted
    assert all(path.is_file() for path in fingerprinted)
    assert SIM_DIR / "model" / "contact_law.py" in with_kernels
    assert "njit" not in "".join((integration / f"{stem}.py").read_text() for stem in jit.KERNEL_MODULES
                                 if stem != "jit")


def test_the_installed_numba_lies_in_the_supported_range():
    """pyproject.toml states the numba versions the kernels are tested with (they use the private `_nrt` option):
    a lower and an upper bound, and the installed numba inside them."""
    import tomllib

    import numba
    from packaging.requirements import Requirement
    from packaging.version import Version

    pyproject = tomllib.loads((SIM_DIR.parent / "pyproject.toml").read_text())
    (spec,) = [Requirement(r).specifier for r in pyproject["project"]["dependencies"] if Requirement(r).name == "numba"]
    assert {s.operator for s in spec} == {">=", "<"}
    assert Version(numba.__version__) in spec
    assert Version("0.58") not in spec and Version("99.0") not in spec
    assert jit.nrt_option_supported()  # the numbas of the range know the option


KERNELS_WITHOUT_COUNTS = '''import numpy as np

from sim.integration.jit import kernel


@kernel(refcounts=False)
def total(x):
    s = 0.0
    for v in x:
        s += v
    return s


@kernel(refcounts=False)
def twice(x):
    return 2.0 * total(x)
'''


def test_a_numba_that_refuses_the_nrt_option_still_compiles_the_kernels(tmp_path, monkeypatch, capsys):
    """numba's `_nrt` is private: a numba without it refuses such a kernel at its first call. Simulated by removing
    the option from numba's table; `kernel` then compiles with reference counts, and says so once."""
    import importlib

    import numba
    import numpy as np
    from numba.core.cpu import CPUTargetOptions

    owner = next(cls for cls in CPUTargetOptions.__mro__ if "_nrt" in vars(cls))
    monkeypatch.delattr(owner, "_nrt")
    with pytest.raises(KeyError, match="_nrt"):  # the refusal, as plain numba shows it
        numba.njit(_nrt=False)(lambda x: x + 1.0)(1.0)
    assert not jit.nrt_option_supported()
    monkeypatch.setattr(jit, "_fallback_said", False)
    (tmp_path / "nrt_probe_kernels.py").write_text(KERNELS_WITHOUT_COUNTS)
    monkeypatch.syspath_prepend(str(tmp_path))
    probe = importlib.import_module("nrt_probe_kernels")
    assert probe.twice(np.arange(4.0)) == 12.0
    err = capsys.readouterr().err
    assert err.count("does not take the option _nrt") == 1
