"""A real single-node SLURM for the cluster tests (`_slurm.LocalSlurm`): started once per module in a temporary
folder, torn down after; skipped, with the reason, where the daemons cannot start (not installed, not root)."""
import os
from pathlib import Path

import pytest

from tests.cluster._slurm import LocalSlurm, SlurmUnavailable

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def slurm(tmp_path_factory):
    """The running controller and node daemon (LocalSlurm); skips the module's tests when they cannot start."""
    try:
        cluster = LocalSlurm(tmp_path_factory.mktemp("slurm")).start()
    except SlurmUnavailable as exc:
        pytest.skip(f"no test SLURM on this machine: {exc}")
    yield cluster
    cluster.stop()


@pytest.fixture
def on_slurm(slurm, tmp_path, monkeypatch):
    """The client side of `slurm` for one test: SLURM_CONF for sbatch/scancel, the workers importing this source
    tree (they start in the submitting process's folder, which need not be it), their logs in tmp_path/logs
    through Dask's jobqueue configuration (as a user's jobqueue.yaml would set it)."""
    import dask

    pytest.importorskip("dask_jobqueue")  # its defaults join Dask's configuration on import, before the set below
    monkeypatch.setenv("SLURM_CONF", slurm.env()["SLURM_CONF"])
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    (tmp_path / "logs").mkdir()
    with dask.config.set({"jobqueue.slurm.log-directory": str(tmp_path / "logs")}):
        yield slurm
