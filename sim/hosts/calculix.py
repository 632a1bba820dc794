"""Modes from the seed paper's own FE tool, CalculiX (Sect. 3.1: ccx, C3D20 elements): read the nodal eigenvectors
of a *FREQUENCY step from the .frd result file, node sets and nodes from the .inp input deck, eigenvalues and
participation factors from the .dat output, and build the modal model of Eq. 7; also write a CalculiX job from a
solid model of sim/hosts/solid.py (for cross-checks, and for users who want to run ccx on the same mesh).

Conventions:
* Units: the job's own consistent units, converted to SI by `units`: "m-kg-s" (SI, the default; N, Pa) or
  "mm-t-s" (mm, tonne, s; N, MPa). Frequencies are taken as Hz (time in s). Mode values scale with the mass unit
  only (phi in 1/sqrt(t) = 1/sqrt(1000 kg)), participations phi^T M b likewise (sqrt(t)).
* Mass normalisation: ccx normalises eigenvectors to phi^T M phi = 1 and writes this generalised mass per mode
  in the .frd (record "1PGM"); the reader checks it is 1 (within 1e-6) and rescales otherwise.
* Participation phi^T M b: the x participation factors of the .dat ("PARTICIPATION FACTORS", ccx computes them
  with its own mass matrix as phi^T M r, r the unit x-translation of all nodes), because the .frd has no mass
  matrix; the .dat's effective modal mass must equal the factor squared (the same mass normalisation seen from
  the .dat). Without a .dat the participation is unknown and the reader stops with a message.
* Mode values: the mean x-displacement of the nodes of each node set (a single node gives its value; a patch of
  nodes on the wall gives their average).
* Mode selection: the x-bending modes are those whose x participation dominates (sim.hosts.solid.select_x_bending); or
  give the mode numbers.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import write_text
from sim.hosts.rig import damping_ratios, rig_host
from sim.model.system import ModalModel

UNITS = {"m-kg-s": (1.0, 1.0), "mm-t-s": (1e-3, 1e3)}  # (length in m, mass in kg) of one unit


def _read_text(path: Path, what: str) -> str:
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        raise SimulationInputError(f"{what} {path} not found; give the path of the CalculiX {what}") from None
    except IsADirectoryError:
        raise SimulationInputError(f"{path} is a folder, not a CalculiX {what}") from None


# ---------------------------------------------------------------------------------------------------------
# .inp: nodes and node sets


@dataclass(frozen=True)
class InpMesh:
    """Nodes of a CalculiX input deck: ids (n,), coordinates (n, 3) in the deck's length unit, and the node sets
    (upper-case name -> node ids), *INCLUDE files followed."""

    node_ids: np.ndarray
    coordinates: np.ndarray
    node_sets: dict[str, np.ndarray]

    def node_set(self, name: str) -> np.ndarray:
        """Node ids of the set `name` (case-insensitive, as CalculiX)."""
        key = name.upper()
        if key not in self.node_sets:
            known = ", ".join(sorted(self.node_sets)) or "none"
            raise SimulationInputError(f"node set {name!r} is not defined in the .inp (defined: {known})")
        return self.node_sets[key]


def _keyword_options(line: str) -> tuple[str, dict[str, str]]:
    parts = [p.strip() for p in line.split(",")]
    options = {}
    for p in parts[1:]:
        if p:
            key, _, value = p.partition("=")
            options[key.strip().upper()] = value.strip()
    return parts[0].upper(), options


def _deck_lines(path: Path, depth: int = 0) -> Iterable[str]:
    if depth > 10:
        raise SimulationInputError(f"{path}: *INCLUDE nested more than 10 deep")
    for raw in _read_text(path, ".inp file").splitlines():
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.upper().startswith("*INCLUDE"):
            target = _keyword_options(line)[1].get("INPUT")
            if not target:
                raise SimulationInputError(f"{path}: *INCLUDE without INPUT=FILE")
            yield from _deck_lines((path.parent / target).resolve(), depth + 1)
        else:
            yield line


def read_inp(path: str | os.PathLike) -> InpMesh:
    """Nodes (*NODE) and node sets (*NSET, with GENERATE; *ELSET and elements are skipped) of a CalculiX deck."""
    path = Path(path)
    ids, coords, sets = [], [], {}
    block, current = None, None
    for line in _deck_lines(path):
        if line.startswith("*"):
            keyword, options = _keyword_options(line)
            block = keyword
            if keyword == "*NODE":
                current = options.get("NSET", "").upper() or None
                if current:
                    sets.setdefault(current, [])
            elif keyword == "*NSET":
                current = options.get("NSET", "").upper()
                if not current:
                    raise SimulationInputError(f"{path}: *NSET without NSET=NAME")
                sets.setdefault(current, [])
                block = "*NSET GENERATE" if "GENERATE" in options else "*NSET"
            continue
        fields = [f.strip() for f in line.split(",") if f.strip()]
        try:
            if block == "*NODE":
                node = int(fields[0])
                xyz = [float(v) for v in fields[1:4]] + [0.0] * (3 - len(fields[1:4]))
                ids.append(node)
                coords.append(xyz)
                if current:
                    sets[current].append(node)
            elif block == "*NSET":
                for f in fields:
                    if f.lstrip("-").isdigit():
                        sets[current].append(int(f))
                    else:
                        sets[current].extend(sets.get(f.upper(), []))
            elif block == "*NSET GENERATE":
                a, b, step = (int(v) for v in (fields + ["1"])[:3])
                sets[current].extend(range(a, b + 1, step))
        except (ValueError, IndexError):
            raise SimulationInputError(f"{path}: cannot read the {block} line {line!r}") from None
    if not ids:
        raise SimulationInputError(f"{path}: no *NODE block; give the CalculiX input deck of the job")
    return InpMesh(np.array(ids), np.array(coords, float), {k: np.unique(v) for k, v in sets.items()})


# ---------------------------------------------------------------------------------------------------------
# Writing a job from a solid model

# C3D20 corner and mid-side nodes in CalculiX's order, as signs of (x, y, z) relative to the element centre
_C3D20_SIGNS = np.array([
    (-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1),
    (0, -1, -1), (1, 0, -1), (0, 1, -1), (-1, 0, -1), (0, -1, 1), (1, 0, 1), (0, 1, 1), (-1, 0, 1),
    (-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)])


def solid_nodes(solid) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes of a hex20 solid model (sim.hosts.solid.SolidMesh) as CalculiX sees them: coordinates (n, 3) in m (vertices,
    then edge mid-points), the 20 node indices of every element in C3D20 order (n_el, 20), and for every node its
    three global DOF numbers (n, 3) in the solid model."""
    if solid.element != "hex20":
        raise SimulationInputError("CalculiX jobs need the 20-node element (C3D20); build the solid model with "
                                   "element='hex20'")
    mesh, dofs = solid.mesh, solid.basis.dofs
    coords = np.vstack([mesh.p.T, mesh.p[:, mesh.edges].mean(axis=1).T])
    n_vertices = mesh.p.shape[1]
    candidates = np.vstack([mesh.t, n_vertices + mesh.t2e])  # (20, n_el) node indices of each element
    corners = mesh.p[:, mesh.t]  # (3, 8, n_el)
    centre = corners.mean(axis=1).T  # (n_el, 3)
    half = 0.5 * (corners.max(axis=1) - corners.min(axis=1)).T
    signs = np.rint((coords[candidates] - centre[None]) / half[None]).astype(int)  # (20, n_el, 3): -1, 0, 1
    codes = lambda s: (s[..., 0] + 1) * 9 + (s[..., 1] + 1) * 3 + (s[..., 2] + 1)  # noqa: E731
    lookup = codes(signs)  # (20, n_el)
    wanted = codes(_C3D20_SIGNS)  # (20,)
    order = np.argmax(lookup[None, :, :] == wanted[:, None, None], axis=1)  # (20 ccx, n_el) -> local position
    elements = np.take_along_axis(candidates, order, axis=0).T
    node_dofs = np.vstack([dofs.nodal_dofs.T, dofs.edge_dofs.T])
    return coords, elements, node_dofs


def write_calculix_job(solid, path: str | os.PathLike, n_modes: int = 30,
                       node_sets: dict[str, Sequence[Sequence[float]]] | None = None) -> Path:
    """Write a CalculiX input deck of a hex20 solid model (sim.hosts.solid.SolidMesh): C3D20 elements, the clamped faces
    fixed, the material, a *FREQUENCY step for n_modes modes with nodal displacements (*NODE FILE U) and the
    .dat's participation factors, in SI units (m, kg, s). node_sets: name -> points (m); each point must be a
    node of the mesh (the solid model's grid contains the wall points and the measurement point)."""
    coords, elements, _ = solid_nodes(solid)
    from scipy.spatial import cKDTree

    tree = cKDTree(coords)
    scale = max(solid.geometry.free_length, solid.geometry.block_edge)
    lines = ["*HEADING", "ies-workbench solid model (sim.hosts.solid), SI units: m, kg, s", "*NODE, NSET=NALL"]
    lines += [f"{i + 1}, {x:.15g}, {y:.15g}, {z:.15g}" for i, (x, y, z) in enumerate(coords)]
    lines.append("*ELEMENT, TYPE=C3D20, ELSET=EALL")
    for e, nodes in enumerate(elements + 1):
        ids = [str(e + 1)] + [str(n) for n in nodes]
        lines += [", ".join(ids[:16]) + ",", ", ".join(ids[16:])]
    clamped = np.flatnonzero(solid.geometry.clamped(coords.T)) + 1
    sets = {"CLAMPED": clamped}
    for name, points in (node_sets or {}).items():
        dist, index = tree.query(np.atleast_2d(np.asarray(points, float)))
        if np.any(dist > 1e-9 * scale):
            raise SimulationInputError(f"node set {name}: a point is not a node of the mesh")
        sets[name.upper()] = index + 1
    for name, ids in sets.items():
        lines.append(f"*NSET, NSET={name}")
        lines += [", ".join(str(i) for i in ids[k:k + 16]) for k in range(0, len(ids), 16)]
    m = solid.material
    lines += ["*BOUNDARY", "CLAMPED, 1, 3", "*MATERIAL, NAME=STEEL", "*ELASTIC", f"{m.E:.10g}, {m.nu:.10g}",
              "*DENSITY", f"{m.rho:.10g}", "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL",
              "*STEP", "*FREQUENCY", f"{int(n_modes)}", "*NODE FILE", "U", "*END STEP"]
    return write_text(path, "\n".join(lines) + "\n")


# ---------------------------------------------------------------------------------------------------------
# .frd: eigenvectors; .dat: eigenvalues, participation factors, effective modal masses


@dataclass(frozen=True)
class FrdModes:
    """Eigenmodes of a .frd result file: mode numbers (n,), frequencies (n,) in cycles per time unit, generalised
    masses phi^T M phi (n,; NaN where the file has none), node ids (m,) and displacements (n, m, 3)."""

    mode_numbers: np.ndarray
    frequencies: np.ndarray
    generalized_mass: np.ndarray
    node_ids: np.ndarray
    displacements: np.ndarray


def read_frd(path: str | os.PathLike) -> FrdModes:
    """Nodal displacement eigenvectors (DISP blocks of *FREQUENCY steps, ASCII .frd, short or long format)."""
    path = Path(path)
    lines = _read_text(path, ".frd file").splitlines()
    if not any(line.startswith("    1C") or line.startswith("    2C") for line in lines[:50]):
        raise SimulationInputError(f"{path}: not a CalculiX .frd result file")
    numbers, freqs, masses, blocks = [], [], [], []
    mode, freq, mass, modal = None, None, math.nan, False
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("    1PMODE"):
            mode = int(line[10:].split()[0])
        elif line.startswith("    1PGM"):
            mass = float(line[8:].split()[0])
        elif line.startswith("  100C"):
            freq = float(line[12:24])
            modal = "MODAL" in line[63:73].upper() or line[56:58].strip() == "2"
            fmt = int(line[73:75]) if line[73:75].strip() else 0
            if modal and fmt == 2:
                raise SimulationInputError(f"{path}: binary .frd is not supported; let ccx write ASCII output "
                                           "(the default of *NODE FILE)")
            width = 10 if fmt == 1 else 5
        elif line.startswith(" -4") and line[3:].split()[0] == "DISP" and modal:
            i += 1
            while i < len(lines) and lines[i].startswith(" -5"):
                i += 1
            nodes, values = [], []
            while i < len(lines) and lines[i].startswith(" -1"):
                row = lines[i]
                try:
                    nodes.append(int(row[3:3 + width]))
                    start = 3 + width
                    values.append([float(row[start + 12 * k:start + 12 * (k + 1)]) for k in range(3)])
                except ValueError:
                    raise SimulationInputError(f"{path}: cannot read the displacement line {row.strip()!r}") from None
                i += 1
            numbers.append(mode if mode is not None else len(numbers) + 1)
            freqs.append(freq)
            masses.append(mass)
            blocks.append((np.array(nodes), np.array(values)))
            mode, mass, modal = None, math.nan, False
            continue
        i += 1
    if not blocks:
        raise SimulationInputError(f"{path}: no eigenvectors (DISP blocks of a *FREQUENCY step); add *NODE FILE with "
                                   "U to the frequency step and run ccx again")
    if len(set(numbers)) != len(numbers):
        raise SimulationInputError(f"{path}: mode numbers repeat (several *FREQUENCY steps); keep one frequency step")
    node_ids = blocks[0][0]
    if any(b[0].shape != node_ids.shape or np.any(b[0] != node_ids) for b in blocks):
        raise SimulationInputError(f"{path}: the modes' DISP blocks list different nodes")
    return FrdModes(np.array(numbers), np.array(freqs), np.array(masses), node_ids,
                    np.stack([b[1] for b in blocks]))


@dataclass(frozen=True)
class DatModes:
    """From a .dat file of a *FREQUENCY step: mode numbers (n,), frequencies (cycles per time unit), participation
    factors (n, 3) and effective modal masses (n, 3) for the x, y, z translations (NaN where absent)."""

    mode_numbers: np.ndarray
    frequencies: np.ndarray
    participation: np.ndarray
    effective_mass: np.ndarray


def _dat_table(lines: list[str], title: str, columns: int) -> dict[int, list[float]]:
    out: dict[int, list[float]] = {}
    spaced = " ".join(title)
    for k, line in enumerate(lines):
        if line.strip() == spaced:
            for row in lines[k + 1:]:
                fields = row.split()
                if not fields:
                    continue
                if fields[0].isdigit() and len(fields) >= columns + 1:
                    try:
                        out[int(fields[0])] = [float(v) for v in fields[1:columns + 1]]
                    except ValueError:
                        break
                elif out and not fields[0].isdigit():
                    break
    return out


def read_dat(path: str | os.PathLike) -> DatModes:
    """Eigenvalue output, participation factors and effective modal masses of a .dat file."""
    path = Path(path)
    lines = _read_text(path, ".dat file").splitlines()
    eigen = _dat_table(lines, "EIGENVALUE OUTPUT", 4)
    if not eigen:
        raise SimulationInputError(f"{path}: no eigenvalue output; give the .dat of a *FREQUENCY step")
    numbers = np.array(sorted(eigen))
    part = _dat_table(lines, "PARTICIPATION FACTORS", 6)
    mass = _dat_table(lines, "EFFECTIVE MODAL MASS", 6)
    pick = lambda table: np.array([table.get(n, [math.nan] * 6)[:3] for n in numbers])  # noqa: E731
    return DatModes(numbers, np.array([eigen[n][2] for n in numbers]), pick(part), pick(mass))


# ---------------------------------------------------------------------------------------------------------
# The modal model from a CalculiX job

MASS_NORMALISATION_TOLERANCE = 1e-6


@dataclass(frozen=True)
class CalculixResult:
    """A modal model read from CalculiX output (model: Eq. 7 inputs in SI units) with its provenance (plain data
    for the modal file's [provenance] table) and the lines `ies modes --from-calculix` prints."""

    model: ModalModel
    provenance: dict
    report: list[str]


def calculix_modal_model(frd: str | os.PathLike, inp: str | os.PathLike, wall_left: str, wall_right: str,
                         tip: str, *, dat: str | os.PathLike | None = None, units: str = "m-kg-s", n_modes: int = 9,
                         modes: Sequence[int] | None = None, floor: str | None = None,
                         beam_mass: float | None = None) -> CalculixResult:
    """Modal model (Sect. 3.1, Eq. 7) from a CalculiX *FREQUENCY job: eigenvectors from `frd`, node sets from
    `inp`, frequencies and participation factors from `dat` (default: the .dat beside the .frd).

    wall_left, wall_right, tip: names of node sets in the .inp; each mode value is the mean x-displacement of the
    set's nodes. units: "m-kg-s" or "mm-t-s" (the job's consistent units). The first n_modes x-bending modes are
    selected by their participation (sim.hosts.solid.select_x_bending), or the given 1-based mode numbers `modes`.
    Damping per sim.hosts.rig.damping_ratios. floor: the node set of the cavity floor under the sphere (its mean
    x-values are the model's phi_floor, Appendix C); beam_mass: the beam's free length without the block (kg, Eq.
    10; a .frd has no masses). Raises SimulationInputError (one line) for missing files, a .frd without
    eigenvectors, unknown node sets, node sets with nodes missing from the .frd, a .dat that does not belong to
    the .frd or eigenvectors that are not mass-normalised.
    """
    from sim.hosts.solid import select_x_bending

    if units not in UNITS:
        raise SimulationInputError(f"unknown units {units!r}; choose one of {', '.join(UNITS)}")
    length_unit, mass_unit = UNITS[units]
    frd, inp = Path(frd), Path(inp)
    dat = Path(dat) if dat is not None else frd.with_suffix(".dat")
    deck = read_inp(inp)
    named = [("wall_left", wall_left), ("wall_right", wall_right), ("tip", tip)] + ([("floor", floor)] if floor else [])
    sets = {role: deck.node_set(name) for role, name in named}
    if beam_mass is not None and not (math.isfinite(beam_mass) and beam_mass > 0):
        raise SimulationInputError(f"--beam-mass must be a positive mass in kg, got {beam_mass!r}")
    for role, ids in sets.items():
        if ids.size == 0:
            raise SimulationInputError(f"node set for {role.replace('_', ' ')} is empty in {inp}")
    result = read_frd(frd)
    if not dat.is_file():
        raise SimulationInputError(f"{dat} not found: the participation phi^T M b comes from the .dat of the job "
                                   "(ccx writes JOB.dat beside JOB.frd); give its path")
    table = read_dat(dat)
    common = np.intersect1d(result.mode_numbers, table.mode_numbers)
    if common.size != result.mode_numbers.size:
        raise SimulationInputError(f"{dat} lists modes {table.mode_numbers.min()}..{table.mode_numbers.max()} but "
                                   f"{frd} has {result.mode_numbers.size} modes; give the .dat of the same job")
    rows = np.searchsorted(table.mode_numbers, result.mode_numbers)
    if not np.allclose(table.frequencies[rows], result.frequencies, rtol=1e-5):
        raise SimulationInputError(f"the frequencies in {dat} and {frd} differ; give the .dat and .frd of the same job")
    participation = table.participation[rows]
    if np.isnan(participation).any():
        raise SimulationInputError(f"{dat}: participation factors missing for some modes; give the .dat of a "
                                   "*FREQUENCY step")
    gm = result.generalized_mass
    scale = 1.0 / np.sqrt(np.nan_to_num(gm, nan=1.0))
    checks = []
    if not np.isnan(gm).all():
        checks.append(f"phi^T M phi from the .frd: max |GM - 1| = {np.nanmax(np.abs(gm - 1.0)):.1e}")
    effective = table.effective_mass[rows, 0]
    if not np.isnan(effective).any():
        mismatch = np.abs(effective - participation[:, 0] ** 2) / np.maximum(participation[:, 0] ** 2, 1e-300)
        relevant = participation[:, 0] ** 2 > 1e-9 * np.max(participation[:, 0] ** 2)
        worst = float(mismatch[relevant].max(initial=0.0))
        if worst > 1e-4:
            raise SimulationInputError(f"{dat}: effective modal mass differs from the participation factor squared by "
                                       f"{worst:.1e}: the eigenvectors are not mass-normalised")
        checks.append(f"effective modal mass = participation^2 in the .dat within {worst:.1e}")
    if not np.isnan(gm).all() and np.nanmax(np.abs(gm - 1.0)) > MASS_NORMALISATION_TOLERANCE:
        checks.append("eigenvectors rescaled to phi^T M phi = 1")

    if modes is not None:
        wanted = np.array([int(m) for m in modes])
        missing = sorted(set(wanted) - set(result.mode_numbers.tolist()))
        if missing:
            raise SimulationInputError(f"mode(s) {', '.join(map(str, missing))} are not in {frd}")
        chosen, rejected = np.searchsorted(result.mode_numbers, wanted), []
    else:
        chosen, rejected = select_x_bending(participation, None, n_modes)
        if chosen.size < n_modes:
            raise SimulationInputError(f"{frd}: only {chosen.size} x-bending modes among its "
                                       f"{result.mode_numbers.size}; ask ccx for more modes (*FREQUENCY) or give fewer")
    position = {node: k for k, node in enumerate(result.node_ids)}
    values = {}
    for role, ids in sets.items():
        missing = [n for n in ids if n not in position]
        if missing:
            raise SimulationInputError(f"node set for {role.replace('_', ' ')}: node {missing[0]} has no displacement "
                                       f"in {frd}")
        index = np.array([position[n] for n in ids])
        values[role] = result.displacements[chosen][:, index, 0].mean(axis=1) * scale[chosen] / math.sqrt(mass_unit)
    sign = np.where(values["wall_left"] + values["wall_right"] < 0, -1.0, 1.0)
    gamma = participation[chosen, 0] * scale[chosen] * math.sqrt(mass_unit) * sign
    model = ModalModel(
        frequencies_hz=result.frequencies[chosen], damping_ratios=damping_ratios(chosen.size),
        phi_wall_left=values["wall_left"] * sign, phi_wall_right=values["wall_right"] * sign,
        phi_tip=values["tip"] * sign, participation=gamma, source=f"CalculiX job {frd.name} (sim.hosts.calculix)",
        phi_floor=values["floor"] * sign if floor else None, beam_mass=beam_mass, **rig_host(walls=False))
    coords = {node: xyz for node, xyz in zip(deck.node_ids, deck.coordinates * length_unit)}
    provenance = {
        "model": "CalculiX eigenvectors (sim.hosts.calculix)", "frd": str(frd), "inp": str(inp), "dat": str(dat),
        "units": units, "node_sets": dict(named),
        "node_set_sizes": {role: int(ids.size) for role, ids in sets.items()},
        "node_set_centres_m": {role: np.mean([coords[n] for n in ids if n in coords], axis=0).tolist()
                               for role, ids in sets.items()},
        "selected_modes": result.mode_numbers[chosen].tolist(), "rejected_modes": rejected,
        "mass_normalisation": checks,
    }
    report = [f"CalculiX job {frd}: {result.mode_numbers.size} modes, x-bending modes "
              f"{', '.join(map(str, result.mode_numbers[chosen]))}"] + checks
    return CalculixResult(model, provenance, report)
