"""The kernel cache (sim.common.kernel_cache): outside the installed package, per user, keyed by the code; a copy of
the same sources elsewhere (a reinstall) loads the machine code without compiling; a read-only package folder
gets nothing written into it; `ies cache` shows the folder and empties it."""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sim.common import kernel_cache
from uq.cli import main

PACKAGE = '''
from sim.common.kernel_cache import cached_njit


@cached_njit
def triple(x):
    return 3.0 * x
'''
def _stats(where: Path, env: dict) -> tuple[bool, Path]:
    """(whether the kernel was loaded from the cache, the cache folder numba used) in a fresh process."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import probe_pkg.kernels as k; k.triple(2.0); "
            "print(sum(k.triple.stats.cache_hits.values()), sum(k.triple.stats.cache_misses.values())); "
            "print(k.triple.stats.cache_path)")
    done = subprocess.run([sys.executable, "-c", code, str(where)], capture_output=True, text=True, env=env, cwd=where,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    counts, path = done.stdout.splitlines()
    hits, misses = map(int, counts.split())
    assert hits + misses == 1
    return hits == 1, Path(path)


def _package(root: Path) -> Path:
    (root / "probe_pkg").mkdir(parents=True)
    (root / "probe_pkg" / "__init__.py").write_text("")
    (root / "probe_pkg" / "kernels.py").write_text(PACKAGE)
    return root


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")}


@pytest.fixture
def env(tmp_path):
    environment = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", kernel_cache.SETTING)}
    repo = Path(__file__).resolve().parents[3]
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, (str(repo), environment.get("PYTHONPATH"))))
    environment["PYTHONDONTWRITEBYTECODE"] = "1"
    environment["XDG_CACHE_HOME"] = str(tmp_path / "xdg")
    return environment


def test_the_cache_lives_in_the_users_cache_folder_and_a_copy_of_the_same_code_compiles_nothing(tmp_path, env):
    first = _package(tmp_path / "install-1")
    before = _files(first)
    loaded, folder = _stats(first, env)
    assert not loaded
    assert folder.parent == tmp_path / "xdg" / "ies-workbench" and folder.name.startswith("probe_pkg-")
    assert any(folder.glob("kernels.triple-*.nbi")) and any(folder.glob("kernels.triple-*.nbc"))
    assert _files(first) == before, "something was written into the package's folder"
    assert _stats(first, env) == (True, folder)

    # a reinstall: the same sources at another place, with new modification times
    second = tmp_path / "install-2"
    shutil.copytree(first, second)
    os.utime(second / "probe_pkg" / "kernels.py", (time.time() + 100, time.time() + 100))
    assert _stats(second, env) == (True, folder)

    # an edit: a new folder, compiled afresh
    source = second / "probe_pkg" / "kernels.py"
    source.write_text(source.read_text().replace("3.0", "4.0"))
    loaded, edited = _stats(second, env)
    assert not loaded and edited != folder and edited.parent == folder.parent


def test_the_settings_move_the_cache(tmp_path, env):
    package = _package(tmp_path / "pkg")
    _, folder = _stats(package, {**env, "NUMBA_CACHE_DIR": str(tmp_path / "numba")})
    assert folder.parent == tmp_path / "numba" / "ies-workbench"
    _, folder = _stats(package, {**env, "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
                                 kernel_cache.SETTING: str(tmp_path / "ies")})
    assert folder.parent == tmp_path / "ies"


def test_a_cache_folder_that_cannot_be_written_falls_back_to_the_temporary_folder(tmp_path, env):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    package = _package(tmp_path / "pkg")
    (tmp_path / "tmp").mkdir()
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import probe_pkg.kernels as k; print(k.triple(2.0)); "
            "print(k.triple.stats.cache_path)")
    done = subprocess.run([sys.executable, "-c", code, str(package)], capture_output=True, text=True, cwd=package,
                          env={**env, kernel_cache.SETTING: str(blocker / "cache"), "TMPDIR": str(tmp_path / "tmp")})
    assert done.returncode == 0, done.stderr
    value, folder = done.stdout.splitlines()
    assert value == "6.0" and Path(folder).parent.parent == tmp_path / "tmp"
    assert done.stderr.count("cannot be written") == 1 and str(blocker / "cache") in done.stderr


def test_a_folder_unused_for_a_month_is_pruned_when_a_new_version_is_made(tmp_path, monkeypatch):
    monkeypatch.setenv(kernel_cache.SETTING, str(tmp_path))
    old, recent = tmp_path / f"probe-{'a' * 16}", tmp_path / f"probe-{'b' * 16}"
    for folder in (old, recent):
        folder.mkdir()
        (folder / "k.f-1.py311.nbi").write_text("x")
        (folder / kernel_cache.LAST_USED).touch()
    month_ago = time.time() - (kernel_cache.PRUNE_AFTER_DAYS + 1) * 86400
    os.utime(old / kernel_cache.LAST_USED, (month_ago, month_ago))
    kernel_cache.version_folder.cache_clear()
    made = kernel_cache.version_folder("probe", "c" * 64)
    assert made == tmp_path / f"probe-{'c' * 16}" and made.is_dir()
    assert not old.exists() and recent.exists()
    kernel_cache.version_folder.cache_clear()


def test_ies_cache_shows_the_folder_and_empties_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(kernel_cache.SETTING, str(tmp_path / "cache"))
    folder = tmp_path / "cache" / f"sim-{'d' * 16}"
    folder.mkdir(parents=True)
    (folder / "exact._advance-575.py311.nbi").write_bytes(b"x" * 1000)
    (folder / "exact._advance-575.py311.1.nbc").write_bytes(b"x" * 2_000_000)
    stranger = tmp_path / "cache" / "notes.txt"  # not ours: never deleted
    stranger.write_text("keep")
    assert main(["cache"]) == 0
    out = capsys.readouterr().out
    assert f"kernel cache: {tmp_path / 'cache'} (IES_CACHE_DIR)" in out
    assert f"sim-{'d' * 16}" in out and "2.0 MB" in out and "another version" in out
    assert "`ies cache --clear` empties it" in out
    assert main(["cache", "--clear"]) == 0
    assert "removed 1 code version(s), 2.0 MB" in capsys.readouterr().out
    assert not folder.exists() and stranger.read_text() == "keep"
    assert main(["cache", "--json"]) == 0
    assert '"total_bytes": 0' in capsys.readouterr().out
