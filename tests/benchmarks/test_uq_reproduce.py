"""Wall time of the paper's studies (Figs. 5-8): quick (target <= 5 min each on 2 cores) and, with IES_FULL=1,
the full protocol of all four. Prints the times, the machine load
and the trend / band tables. Run: `pytest -m benchmark tests/benchmarks/test_uq_reproduce.py -s`."""
import os
import time

import pytest

from uq.cli import main


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.1f} (1 min), {five:.1f} (5 min) on {os.cpu_count()} cores"


@pytest.mark.benchmark
@pytest.mark.parametrize("figure", ["fig5", "fig6", "fig7", "fig8"])
def test_quick_reproduction_time(figure, tmp_path, capsys):
    before = _load()
    start = time.perf_counter()
    assert main(["reproduce", figure, "--quick", "--no-calibration", "--out", str(tmp_path), "--quiet"]) == 0
    seconds = time.perf_counter() - start
    out = capsys.readouterr().out
    with capsys.disabled():
        print(f"\n{figure} --quick: {seconds:.1f} s wall ({before} before, {_load()} after)\n{out}")
    assert seconds <= 300.0


@pytest.mark.benchmark
@pytest.mark.skipif(os.environ.get("IES_FULL") != "1", reason="full protocol takes long; set IES_FULL=1")
def test_full_reproduction_time(tmp_path, capsys):
    before = _load()
    start = time.perf_counter()
    assert main(["reproduce", "all", "--no-calibration", "--out", str(tmp_path), "--quiet"]) == 0
    seconds = time.perf_counter() - start
    out = capsys.readouterr().out
    with capsys.disabled():
        print(f"\nfigs. 5-8, full protocol: {seconds:.1f} s wall ({before} before, {_load()} after)\n{out}")
