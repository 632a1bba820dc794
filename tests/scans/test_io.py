"""Readers: every format gives the same surface, bad files give one ScanError, corrupted bytes never crash."""
from __future__ import annotations

import zlib

import numpy as np
import pytest

from scans import ScanError, check_units, crater_metrics, level_scan, read_scan, synthetic_scan, write_scan
from scans.io import SUPPORTED

# a small crater scan (m) used for all round trips: 2.4 mm patch, 40 um triangles
SMALL = dict(side=3.0e-3, triangle=40e-6, seed=5)


@pytest.fixture(scope="module")
def small_scan():
    return synthetic_scan(**SMALL)


@pytest.fixture(scope="module")
def reference_depth(small_scan):
    return crater_metrics(level_scan(small_scan)).depth


@pytest.mark.parametrize("suffix", [".stl", ".ply", ".obj", ".off", ".xyz", ".csv"])
def test_every_format_round_trips_to_the_same_crater(tmp_path, small_scan, reference_depth, suffix):
    path = write_scan(tmp_path / f"scan{suffix}", small_scan.vertices, small_scan.faces if suffix not in (".xyz", ".csv") else None)
    scan = read_scan(path, units="mm")
    # STL stores float32: 2e-7 relative of a 1.5 mm coordinate is 0.3 nm
    assert scan.vertices.shape[1] == 3 and len(scan.vertices) == len(small_scan.vertices)
    depth = crater_metrics(level_scan(scan)).depth
    assert depth == pytest.approx(reference_depth, abs=0.05e-6)


def test_ascii_stl_reads_like_binary(tmp_path, small_scan):
    import trimesh

    mesh = trimesh.Trimesh(small_scan.vertices * 1e3, small_scan.faces, process=False)
    (tmp_path / "a.stl").write_text(mesh.export(file_type="stl_ascii"))
    (tmp_path / "b.stl").write_bytes(mesh.export(file_type="stl"))
    a, b = read_scan(tmp_path / "a.stl"), read_scan(tmp_path / "b.stl")
    np.testing.assert_allclose(np.sort(a.vertices, axis=0), np.sort(b.vertices, axis=0), atol=1e-9)
    assert a.kind == b.kind == "mesh"


def test_height_maps_npz_and_npy(tmp_path, reference_depth):
    from scans.synthetic import PAPER_CRATER

    pitch = 20e-6
    ticks = np.arange(-75, 76) * pitch
    height = PAPER_CRATER.height(ticks[None, :], ticks[:, None])  # rows along y
    np.savez(tmp_path / "map.npz", height=height * 1e3, pixel_size=pitch * 1e3)
    np.save(tmp_path / "map.npy", height * 1e3)
    a = read_scan(tmp_path / "map.npz")
    b = read_scan(tmp_path / "map.npy", pixel_size=pitch * 1e3)
    assert a.kind == b.kind == "heightmap"
    for scan in (a, b):
        assert crater_metrics(level_scan(scan)).depth == pytest.approx(PAPER_CRATER.depth, abs=0.05e-6)
    with pytest.raises(ScanError, match="pixel size"):
        read_scan(tmp_path / "map.npy")


def test_npy_point_array_and_nan_pixels_are_holes(tmp_path, small_scan):
    np.save(tmp_path / "points.npy", small_scan.vertices * 1e3)
    assert read_scan(tmp_path / "points.npy").kind == "points"
    height = np.zeros((50, 60))
    height[20:23, 30:33] = np.nan
    np.savez(tmp_path / "holes.npz", height=height, pixel_size=0.05)
    scan = read_scan(tmp_path / "holes.npz")
    assert len(scan.vertices) == 50 * 60 - 9 and np.isfinite(scan.vertices).all()


def test_units_m_and_mm_give_the_same_scan(tmp_path, small_scan):
    mm = write_scan(tmp_path / "mm.ply", small_scan.vertices, small_scan.faces, units="mm")
    m = write_scan(tmp_path / "m.ply", small_scan.vertices, small_scan.faces, units="m")
    # PLY stores float32: equal to 1e-7 relative, i.e. to 0.2 nm here
    np.testing.assert_allclose(read_scan(mm, units="mm").vertices, read_scan(m, units="m").vertices, rtol=3e-7, atol=1e-12)


@pytest.mark.parametrize("stated, actual", [("mm", "m"), ("m", "mm"), ("mm", "um")])
def test_implausible_units_are_refused_with_the_right_suggestion(tmp_path, small_scan, stated, actual):
    path = write_scan(tmp_path / "scan.ply", small_scan.vertices, small_scan.faces, units=actual)
    with pytest.raises(ScanError, match=f"use --units {actual}$"):
        read_scan(path, units=stated)


def test_check_units_accepts_plausible_and_rejects_unknown():
    check_units(4.0, "mm")
    with pytest.raises(ScanError, match="unknown unit"):
        check_units(4.0, "furlong")


def test_bad_files_are_one_line_scan_errors(tmp_path, small_scan):
    cases = {}
    cases["missing"] = tmp_path / "nope.stl"
    (tmp_path / "scan.step").write_text("solid")
    cases["unknown format"] = tmp_path / "scan.step"
    (tmp_path / "empty.ply").write_bytes(b"")
    cases["empty"] = tmp_path / "empty.ply"
    full = write_scan(tmp_path / "full.stl", small_scan.vertices, small_scan.faces).read_bytes()
    (tmp_path / "trunc.stl").write_bytes(full[: len(full) // 3])
    cases["truncated"] = tmp_path / "trunc.stl"
    bad = small_scan.vertices.copy()
    bad[7, 2] = np.nan
    cases["nan"] = write_scan(tmp_path / "nan.xyz", bad, None)
    (tmp_path / "two.csv").write_text("x,y\n1,2\n3,4\n")
    cases["two columns"] = tmp_path / "two.csv"
    for what, path in cases.items():
        with pytest.raises(ScanError) as info:
            read_scan(path)
        message = str(info.value)
        assert "\n" not in message and len(message) < 300, what


def _corruptions(payload: bytes, rng: np.random.Generator):
    """Truncations, byte flips, inserted garbage and pure noise of a valid file."""
    n = len(payload)
    yield payload[: rng.integers(1, max(n // 4, 2))]
    yield payload[: n - rng.integers(1, max(n // 10, 2))]
    for count in (1, 16, 512):
        data = bytearray(payload)
        where = rng.integers(0, n, count)
        data_arr = np.frombuffer(bytes(data), np.uint8).copy()
        data_arr[where] = rng.integers(0, 256, count)
        yield data_arr.tobytes()
    cut = int(rng.integers(0, n))
    yield payload[:cut] + rng.bytes(200) + payload[cut:]
    yield rng.bytes(int(rng.integers(1, 4096)))
    yield payload[:84] + rng.bytes(500)  # a header followed by garbage


@pytest.mark.parametrize("suffix", SUPPORTED)
def test_fuzz_corrupted_bytes_never_escape_as_other_errors(tmp_path, small_scan, suffix):
    """Every reader either returns a finite scan or raises ScanError, whatever the bytes."""
    rng = np.random.default_rng(zlib.crc32(suffix.encode()))
    source = tmp_path / f"good{suffix}"
    if suffix in (".npy",):
        np.save(source, small_scan.vertices * 1e3)
    elif suffix == ".npz":
        np.savez(source, height=np.zeros((40, 40)), pixel_size=0.05)
    elif suffix in (".txt", ".asc", ".pts"):
        write_scan(source.with_suffix(".xyz"), small_scan.vertices, None).rename(source)
    else:
        write_scan(source, small_scan.vertices, None if suffix in (".xyz", ".csv") else small_scan.faces)
    payload = source.read_bytes()
    corruptions = [c for _ in range(4) for c in _corruptions(payload, rng)]
    for k, corrupted in enumerate(corruptions):
        path = tmp_path / f"bad{k}{suffix}"
        path.write_bytes(corrupted)
        try:
            scan = read_scan(path)
        except ScanError as exc:
            assert "\n" not in str(exc)
        else:
            assert np.isfinite(scan.vertices).all() and len(scan.vertices) >= 3
            if scan.faces is not None:
                assert scan.faces.min() >= 0 and scan.faces.max() < len(scan.vertices)
