"""Reading and writing scanned surfaces: one reader per format, units converted to metres at the edge.

Supported (Sect. 4.1: the paper scanned a resin imprint of the crater with a 3D surface scanner):

* triangle meshes through trimesh: STL (binary and ASCII), PLY, OBJ, OFF;
* point clouds: XYZ / CSV / TXT with three numeric columns (x, y, z), an optional header line;
* height maps: ``.npz`` with ``height`` (2-D array, rows along y) and ``pixel_size`` (scalar or (dx, dy)),
  or ``.npy`` holding either an (N, 3) point array or a 2-D height map (then ``pixel_size`` is required).
  NaN pixels of a height map are missing data (holes); NaN coordinates anywhere else are an error.

Every reader returns a :class:`Scan` in metres; any corruption is reported as one-line :class:`ScanError`.
"""
from __future__ import annotations

import io
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scans.errors import ScanError
from sim.common.files import write_bytes

#: length units a scan file may be written in, as metres per unit
UNITS: dict[str, float] = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "in": 0.0254}
MESH_SUFFIXES = {".stl": "stl", ".ply": "ply", ".obj": "obj", ".off": "off"}
POINT_SUFFIXES = {".xyz", ".csv", ".txt", ".asc", ".pts"}
ARRAY_SUFFIXES = {".npy", ".npz"}
#: the names under which a .npz file may hold its height map
HEIGHT_KEYS = ("height", "heights", "z", "h")
SUPPORTED = sorted(set(MESH_SUFFIXES) | POINT_SUFFIXES | ARRAY_SUFFIXES)

#: lateral size (m) of a plausible scanned patch of a cavity wall: from 0.1 mm to 1 m
PLAUSIBLE_EXTENT = (1e-4, 1.0)
_TYPICAL_EXTENT = (0.5e-3, 50e-3)  # a crater patch: 0.5 mm to 50 mm
_PREFERENCE = ("mm", "m", "um", "in", "cm")


@dataclass(frozen=True)
class Scan:
    """A scanned surface in metres, in the scanner's own frame.

    vertices: (N, 3) coordinates (m); faces: (M, 3) vertex indices of triangles, or None for a point
    cloud; kind: "mesh", "points" or "heightmap"; source: file name (or a description); units: the unit
    the file was read in. For meshes, triangle winding gives the outward side of the scanned body.
    """

    vertices: np.ndarray
    faces: np.ndarray | None
    kind: str
    source: str
    units: str = "m"

    @property
    def extent(self) -> float:
        """Largest side (m) of the axis-aligned bounding box."""
        return float(np.ptp(self.vertices, axis=0).max())


def unit_scale(units: str) -> float:
    """Metres per `units` (one of :data:`UNITS`)."""
    try:
        return UNITS[units]
    except KeyError:
        raise ScanError(f"unknown unit {units!r}; use one of {', '.join(UNITS)}") from None


def check_units(raw_extent: float, units: str, source: str = "scan") -> None:
    """Refuse a scan whose size is implausible in `units` and suggest the unit that fits.

    raw_extent: the largest bounding-box side in the file's own numbers.
    """
    extent = raw_extent * unit_scale(units)
    lo, hi = PLAUSIBLE_EXTENT
    if lo <= extent <= hi:
        return
    # suggest the first unit, in the order scanners use them, that makes it a typical crater patch
    best = next((u for u in _PREFERENCE if _TYPICAL_EXTENT[0] <= raw_extent * UNITS[u] <= _TYPICAL_EXTENT[1]), None)
    hint = f"the file looks like it is in {best}: use --units {best}" if best else "check the file"
    raise ScanError(
        f"{source}: size {raw_extent:.4g} {units} is implausible for a scanned wall patch "
        f"(expected {lo * 1e3:g} mm to {hi:g} m); {hint}"
    )


def read_scan(path: str | os.PathLike, units: str = "mm", pixel_size: float | None = None) -> Scan:
    """Read a scan file (format from its suffix) and return it in metres.

    units: the file's length unit (scanner files are usually mm); the size is sanity-checked.
    pixel_size: pixel pitch of a bare ``.npy`` height map, in `units`.
    """
    path = Path(path)
    scale = unit_scale(units)
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED:
        raise ScanError(f"{path.name}: unknown scan format {suffix or '(no suffix)'!r}; use one of {' '.join(SUPPORTED)}")
    if not path.exists():
        raise ScanError(f"{path}: no such file")
    if path.is_dir():
        raise ScanError(f"{path}: is a folder, not a scan file")
    if path.stat().st_size == 0:
        raise ScanError(f"{path.name}: the file is empty")
    if suffix in MESH_SUFFIXES:
        vertices, faces, kind = _read_mesh(path, MESH_SUFFIXES[suffix])
    elif suffix in POINT_SUFFIXES:
        vertices, faces, kind = _read_points_text(path), None, "points"
    else:
        vertices, faces, kind = _read_array(path, pixel_size)
    vertices = np.asarray(vertices, dtype=float)
    if kind != "heightmap" and not np.isfinite(vertices).all():
        bad = int((~np.isfinite(vertices).all(axis=1)).sum())
        raise ScanError(f"{path.name}: {bad} point(s) with NaN or infinite coordinates; remove them and export again")
    finite = vertices[np.isfinite(vertices).all(axis=1)]
    if len(finite) < 3 or np.ptp(finite, axis=0).max() == 0.0:
        raise ScanError(f"{path.name}: fewer than 3 distinct points; the scan is empty or truncated")
    raw_extent = float(np.ptp(finite, axis=0).max())
    check_units(raw_extent, units, path.name)
    return Scan(vertices * scale, faces, kind, path.name, units)


def check_stl(path: Path) -> None:
    """Refuse a binary STL whose size does not match the triangle count in its header (a truncated download or
    copy), naming both; an ASCII STL (text starting with ``solid`` and holding ``facet``) is left to the reader.

    Binary STL: an 80-byte header, a uint32 triangle count N, then N records of 50 bytes: 84 + 50 N bytes."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if head.lstrip().lower().startswith(b"solid") and b"facet" in head.lower():
        return
    if size < 84:
        raise ScanError(f"{path.name}: {size} bytes is too short for a binary STL (84-byte header) and it is not an "
                        "ASCII STL; the file is truncated")
    n = int(np.frombuffer(head[80:84], dtype="<u4")[0])
    if size != 84 + 50 * n:
        whole = (size - 84) // 50
        raise ScanError(f"{path.name}: truncated or damaged binary STL: its header announces {n} triangles "
                        f"({84 + 50 * n} bytes) but the file has {size} bytes ({whole} whole triangles); export or "
                        "copy it again")


def _read_mesh(path: Path, file_type: str) -> tuple[np.ndarray, np.ndarray | None, str]:
    import trimesh

    if file_type == "stl":
        check_stl(path)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")  # corrupt numbers are caught below, not warned about
            loaded = trimesh.load(str(path), file_type=file_type, process=True)
    except Exception as exc:  # trimesh raises many kinds on corrupt files
        raise ScanError(f"{path.name}: cannot read as {file_type.upper()} ({_short(exc)}); the file is corrupt or truncated") from None
    if isinstance(loaded, trimesh.Scene):
        geometries = [g for g in loaded.geometry.values() if len(getattr(g, "vertices", ())) > 0]
        if not geometries:
            raise ScanError(f"{path.name}: no geometry found; the file is empty or truncated")
        loaded = trimesh.util.concatenate(geometries) if len(geometries) > 1 else geometries[0]
    vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=float)
    faces = getattr(loaded, "faces", None)
    if vertices.ndim != 2 or vertices.shape[0] == 0:
        raise ScanError(f"{path.name}: no vertices found; the file is empty or truncated")
    if faces is None or len(faces) == 0:
        return vertices, None, "points"  # e.g. a PLY point cloud
    faces = np.asarray(faces, dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or faces.min() < 0 or faces.max() >= len(vertices):
        raise ScanError(f"{path.name}: malformed triangle list; the file is corrupt")
    return vertices, faces, "mesh"


def _read_points_text(path: Path) -> np.ndarray:
    try:
        text = path.read_bytes().decode("utf-8-sig")  # without the byte-order mark spreadsheets write
    except UnicodeDecodeError:
        raise ScanError(f"{path.name}: not a text point cloud (binary bytes found); expected x y z columns") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith(("#", "//", "%"))]
    if not lines:
        raise ScanError(f"{path.name}: no points found; the file is empty")
    delimiter = "," if "," in lines[min(1, len(lines) - 1)] else (";" if ";" in lines[min(1, len(lines) - 1)] else None)
    header = 0
    try:
        [float(v) for v in _split(lines[0], delimiter)[:3]]
    except ValueError:
        header = 1  # a column-name line
    try:
        data = np.loadtxt(io.StringIO("\n".join(lines[header:])), delimiter=delimiter, usecols=(0, 1, 2), ndmin=2)
    except (ValueError, IndexError) as exc:
        raise ScanError(f"{path.name}: expected three numeric columns x y z ({_short(exc)})") from None
    return data


def _split(line: str, delimiter: str | None) -> list[str]:
    return [v for v in line.split(delimiter)] if delimiter else line.split()


def _read_array(path: Path, pixel_size: float | None) -> tuple[np.ndarray, np.ndarray | None, str]:
    try:
        loaded = np.load(path, allow_pickle=False)
        if isinstance(loaded, np.lib.npyio.NpzFile):
            with loaded:
                arrays = {k: loaded[k] for k in loaded.files}
        else:
            arrays = {"height": loaded}
    except Exception as exc:  # numpy raises ValueError, OSError, EOFError, TokenError, BadZipFile, ... on corrupt files
        raise ScanError(f"{path.name}: cannot read as {path.suffix} array ({_short(exc)}); the file is corrupt or truncated") from None
    height = next((arrays[k] for k in HEIGHT_KEYS if k in arrays), None)
    if height is None:  # an array under another name may be anything (a mask, a colour channel): never guessed
        raise ScanError(f"{path.name}: no 'height' array (found {', '.join(arrays) or 'nothing'}; a height map is read "
                       f"only under {', '.join(HEIGHT_KEYS)}); save with np.savez(f, height=..., pixel_size=...)")
    height = np.asarray(height)
    if not np.issubdtype(height.dtype, np.number):
        raise ScanError(f"{path.name}: the array is not numeric")
    height = height.astype(float)
    if height.ndim == 2 and height.shape[1] == 3 and path.suffix.lower() == ".npy" and pixel_size is None:
        return height, None, "points"
    if height.ndim != 2 or min(height.shape) < 2:
        raise ScanError(f"{path.name}: expected a 2-D height map or an (N, 3) point array, got shape {height.shape}")
    size = next((arrays[k] for k in ("pixel_size", "dx", "pixel") if k in arrays), pixel_size)
    if size is None:
        raise ScanError(f"{path.name}: a height map needs its pixel size: save as .npz with pixel_size, or pass --pixel-size")
    size = np.atleast_1d(np.asarray(size, dtype=float)).ravel()
    if size.size not in (1, 2) or not np.isfinite(size).all() or (size <= 0).any():
        raise ScanError(f"{path.name}: pixel size must be one or two positive numbers, got {size.tolist()}")
    dx, dy = (size[0], size[0]) if size.size == 1 else (size[0], size[1])
    if np.isinf(height).any():
        raise ScanError(f"{path.name}: infinite heights; mark missing pixels as NaN instead")
    if not np.isfinite(height).any():
        raise ScanError(f"{path.name}: every pixel is NaN; the height map is empty")
    return heightmap_to_mesh(height, dx, dy)


def heightmap_to_mesh(height: np.ndarray, dx: float, dy: float) -> tuple[np.ndarray, np.ndarray, str]:
    """Two triangles per pixel quad; quads touching a NaN pixel are left out (holes)."""
    ny, nx = height.shape
    yy, xx = np.meshgrid(np.arange(ny) * dy, np.arange(nx) * dx, indexing="ij")
    vertices = np.column_stack([xx.ravel(), yy.ravel(), height.ravel()])
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    finite = np.isfinite(height.ravel())
    faces = faces[finite[faces].all(axis=1)]
    used = np.unique(faces)
    if used.size < 3:
        raise ScanError("the height map has fewer than one complete pixel quad of valid heights")
    remap = np.full(nx * ny, -1)
    remap[used] = np.arange(used.size)
    return vertices[used], remap[faces], "heightmap"


def write_scan(path: str | os.PathLike, vertices: np.ndarray, faces: np.ndarray | None, units: str = "mm") -> Path:
    """Write a surface (vertices in m) as a mesh (STL/PLY/OBJ/OFF) or point cloud (XYZ/CSV), atomically."""
    path = Path(path)
    suffix = path.suffix.lower()
    coords = np.asarray(vertices, float) / unit_scale(units)
    if suffix in MESH_SUFFIXES:
        import trimesh

        if faces is None:
            raise ScanError(f"{path.name}: a mesh format needs triangles; write points as .xyz or .csv")
        mesh = trimesh.Trimesh(coords, np.asarray(faces), process=False)
        data = mesh.export(file_type=MESH_SUFFIXES[suffix])
        payload = data if isinstance(data, bytes) else data.encode()
    elif suffix in POINT_SUFFIXES:
        sep = "," if suffix == ".csv" else " "
        header = "x,y,z\n" if suffix == ".csv" else ""
        payload = (header + "\n".join(sep.join(f"{v:.9g}" for v in row) for row in coords) + "\n").encode()
    else:
        raise ScanError(f"{path.name}: cannot write format {suffix!r}; use one of {' '.join(sorted(MESH_SUFFIXES) + sorted(POINT_SUFFIXES))}")
    return write_bytes(path, payload)


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return text[:120]
