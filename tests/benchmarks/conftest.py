"""Shared pieces of the benchmarks: the source tree of an earlier git revision, for same-run A/B timings."""
import io
import subprocess
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def tree_at(tmp_path_factory):
    """tree_at(REV): the files of git revision REV extracted into a temporary folder (its path)."""
    def extract(rev: str) -> Path:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], check=True, capture_output=True).stdout
        target = tmp_path_factory.mktemp("tree")
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            tar.extractall(target)
        return target
    return extract
