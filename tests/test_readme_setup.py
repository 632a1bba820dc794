"""The README's two set-up lines, as written, in order, in one folder of a temporary copy of this checkout (its tracked
and new files): the first (a non-editable install, then `ies reproduce all --quick`) must leave nothing in
site-packages beyond the install's own record and must compile nothing when this code's kernels are in the per-user
cache (this session compiled them; a reinstall of the same code costs 0 s); the second (an editable install with the
test extras, then the whole test suite) must pass over what the first left; then the installed `ies --version` and
`ies modes` work.

Minutes of work (two installs, the quick reproduction, a second run of the whole suite): not part of the default test
run (which keeps its 10 minutes); `.ci/run` runs it as a step of its own after the README's test command, with
IES_README_SETUP=1, as anyone can on demand; never inside its own nested test run.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
NESTED = "IES_README_SETUP_NESTED"
PACKAGES = ("bem_contact", "scans", "sim", "uq")

pytestmark = pytest.mark.skipif(
    not os.environ.get("IES_README_SETUP") or bool(os.environ.get(NESTED)),
    reason="minutes: runs with IES_README_SETUP=1 (a step of .ci/run of its own), not inside its own nested test run")


def setup_lines() -> list[str]:
    """The commands of the README's ``## Set up`` block, one per line."""
    section = README.read_text().split("## Set up", 1)[1]
    block = re.search(r"```bash\n(.*?)```", section, flags=re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def _copy_checkout(target: Path) -> None:
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                            capture_output=True, check=True).stdout.decode().split("\0")
    for name in filter(None, listed):
        source = ROOT / name
        if source.is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target / name)


def _run(line: str, folder: Path, env: dict, timeout: float) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-c", f"set -eo pipefail; {line}"], cwd=folder, env=env, capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def _unrecorded(venv: Path) -> list[str]:
    """Files in the installed packages' folders that the install's RECORD does not list (what `pip uninstall` would
    leave behind)."""
    (site,) = venv.glob("lib/python*/site-packages")
    (record,) = site.glob("ies_workbench-*.dist-info/RECORD")
    recorded = {line.split(",")[0] for line in record.read_text().splitlines()}
    found = [str(p.relative_to(site)) for package in PACKAGES for p in (site / package).rglob("*") if p.is_file()]
    return sorted(name for name in found if name not in recorded)


def test_the_readme_set_up_lines_in_sequence(tmp_path):
    first, second = setup_lines()
    assert first.startswith("python3.11 -m venv .venv") and "pip install . " in first and "ies reproduce" in first
    assert "pip install -e" in second and second.endswith("pytest -q")
    folder = tmp_path / "clone"
    _copy_checkout(folder)
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME")}
    here = Path(os.environ["VIRTUAL_ENV"]) / "bin" if os.environ.get("VIRTUAL_ENV") else None
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if here is None or Path(p) != here)
    env[NESTED] = "1"

    done = _run(first, folder, env, timeout=3600)
    assert done.returncode == 0, f"{first}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    assert "compiling" not in done.stderr, f"a reinstall of the same code compiled its kernels again:\n{done.stderr}"
    assert not _unrecorded(folder / ".venv"), f"written into site-packages: {_unrecorded(folder / '.venv')[:10]}"
    assert (folder / "ies-out" / "reproduce" / "index.md").is_file()

    done = _run(second, folder, env, timeout=3600)
    tail = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""
    assert done.returncode == 0, f"{second}\n{done.stdout[-5000:]}\n{done.stderr[-3000:]}"
    assert re.search(r"\d+ passed", tail) and "failed" not in tail and "error" not in tail, tail

    done = _run(". .venv/bin/activate && ies --version && ies modes", folder, env, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("ies-workbench 0.") and "simulator code" in lines[0]
    assert lines[1] == "modal model: built-in seed rig (sim.hosts.rig, Timoshenko beam, updated, variant joint-spring)"
