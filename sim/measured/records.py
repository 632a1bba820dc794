"""Measured records of the host: hammer-test time records and measured FRFs, as CSV with units in the header or as
universal file format (UFF) data sets 58, read and written with pyuff (the structural-dynamics ecosystem's reader).

CSV (UTF-8, one header line, one row per sample or frequency line, `#` lines are comments). Each header names its
column and its unit, as ``name_unit``, ``name [unit]`` or ``name (unit)``:

* time records (hammer tests): a time column (``time_s``; s or ms), one force column (``force_N``; N or kN) and one or
  more responses, each an acceleration (m/s^2 written ``m_s2`` or ``m/s^2``, mm/s^2, g), a velocity (m/s, mm/s) or a
  displacement (m, mm, um), e.g. ``time_s,force_N,accel_m_s2``. Uniform sampling.
* FRFs: a frequency column (``frequency_Hz``; Hz) and per response either ``NAME_real_UNIT`` and ``NAME_imag_UNIT``
  or ``NAME_mag_UNIT`` and ``NAME_phase_deg`` (or ``_rad``), UNIT one of m_N, mm_N (receptance), m_s_N (mobility),
  m_s2_N, g_N (accelerance); optionally ``NAME_coherence`` (-) and a comment line ``# window_decay_per_s = X``, the
  decay rate (1/s) an exponential window added to the poles, taken out again. ``ies identify``'s frf.csv is such a
  file.

UFF 58 (pyuff): function type 1 (time response) data sets make a time record, the force the one whose ordinate is a
force (specific data type 13), the responses those of acceleration (12), velocity (11) or displacement (8); function
type 4 (frequency response function) data sets of those responses per force make measured FRFs. Units, per axis of
each data set (`_uff_factor`): its axis units label where it names a unit of the CSV table below (s, ms, Hz, N, kN,
m/s^2, mm/s^2, g, m/s, mm/s, m, mm, um); else the file's units data set 164 (its factors to SI, raised to the axis's
length and force exponents); else SI. A label of no known unit in a file without a data set 164 is refused rather than
guessed. Data sets 151 (header) and 164 (units) may stand beside the data; any other kind is refused.

Every reader refuses with one line naming the file: a missing or unnamed column, a unit it does not know, a NaN, a
time or frequency axis that does not increase, a UFF data set of another kind.
"""
from __future__ import annotations

import io
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import read_text
from sim.measured.hammer import HammerRecord

#: unit spelling (lower case, "/" and "^" and "*" dropped) -> (quantity, factor to SI)
UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0), "ms": ("time", 1e-3),
    "n": ("force", 1.0), "kn": ("force", 1e3),
    "ms2": ("acceleration", 1.0), "m_s2": ("acceleration", 1.0), "mms2": ("acceleration", 1e-3),
    "mm_s2": ("acceleration", 1e-3), "g": ("acceleration", 9.80665),
    "m_s": ("velocity", 1.0), "mm_s": ("velocity", 1e-3),
    "m": ("displacement", 1.0), "mm": ("displacement", 1e-3), "um": ("displacement", 1e-6),
    "hz": ("frequency", 1.0), "khz": ("frequency", 1e3),
}
#: FRF units -> (quantity of the response, factor to SI per N)
FRF_UNITS: dict[str, tuple[str, float]] = {
    "m_n": ("displacement", 1.0), "mm_n": ("displacement", 1e-3), "m_s_n": ("velocity", 1.0),
    "m_s2_n": ("acceleration", 1.0), "g_n": ("acceleration", 9.80665),
}
KNOWN = "s, ms, N, kN, m_s2 (m/s^2), mm_s2, g, m_s, mm_s, m, mm, um, Hz"
#: UFF 58 ordinate specific data types
UFF_QUANTITY = {8: "displacement", 11: "velocity", 12: "acceleration"}
UFF_FORCE = 13
TO_DISPLACEMENT = {"acceleration": -2, "velocity": -1, "displacement": 0}


@dataclass(frozen=True)
class MeasuredFrf:
    """Measured FRFs of displacement per force (m/N): frequencies_hz (Hz, increasing), frf[name] (complex) and the
    coherence[name] (-) where the file has it; source: the file; window_decay (1/s): the decay rate an exponential
    window added to every pole (a comment line ``# window_decay_per_s = X`` of the CSV, as `ies identify` writes it)."""

    frequencies_hz: np.ndarray
    frf: dict[str, np.ndarray]
    coherence: dict[str, np.ndarray]
    source: str
    window_decay: float = 0.0


def _split_header(name: str) -> tuple[str, str]:
    """(channel name, unit key) of a header cell: ``accel_m_s2``, ``accel [m/s^2]``, ``accel (m/s2)``."""
    text = name.strip()
    bracket = re.fullmatch(r"(.*?)\s*[\[(]\s*(.+?)\s*[\])]", text)
    if bracket:
        return bracket.group(1).strip(), _unit_key(bracket.group(2))
    for size in (3, 2, 1):  # the longest known unit at the end: accel_m_s2 before accel_m
        parts = text.split("_")
        if len(parts) > size:
            key = _unit_key("_".join(parts[-size:]))
            if key in UNITS or key in FRF_UNITS or key in ("deg", "rad"):
                return "_".join(parts[:-size]), key
    return text, ""


def _unit_key(unit: str) -> str:
    key = unit.strip().lower().replace("µ", "u").replace("μ", "u").replace("^", "").replace("²", "2").replace("*", "")
    key = key.replace("/", "_")
    return {"ms2": "m_s2", "mms2": "mm_s2", "ms": "ms"}.get(key, key)


def _table(path: Path, kind: str, example: str) -> tuple[list[str], np.ndarray]:
    """Header cells and the numbers (rows x columns) of a CSV, with one line for an empty file, a row of another
    length, a value that is not a number and a NaN."""
    text = read_text(path, kind, "CSV", f"; give the path of a CSV file such as '{example}'")
    lines = [line for line in io.StringIO(text).read().splitlines() if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise SimulationInputError(f"{path} is empty; a {kind} has a header line such as '{example}' and one row per sample")
    header = [cell.strip() for cell in lines[0].split(",")]
    if any(not cell for cell in header):
        raise SimulationInputError(f"{path}: column {header.index('') + 1} has no name; name every column with its unit, "
                                   f"e.g. '{example}'")
    if len(lines) < 9:
        raise SimulationInputError(f"{path}: {len(lines) - 1} data row(s); a {kind} needs at least 8")
    try:  # numpy's C reader first; the row by row reader below names a bad row
        data = np.loadtxt(io.StringIO("\n".join(lines[1:])), delimiter=",", ndmin=2)
        if data.shape[1] != len(header):
            raise ValueError
    except ValueError:
        data = _rows(path, header, lines)
    bad = np.argwhere(~np.isfinite(data))
    if bad.size:
        row, col = bad[0]
        raise SimulationInputError(f"{path}: column '{header[col]}' is {data[row, col]} at data row {row + 1}; every value "
                                   "must be a finite number (remove or interpolate it)")
    return header, data


def _rows(path: Path, header: list[str], lines: list[str]) -> np.ndarray:
    """The numbers of the data lines, row by row, naming the first row of another length or with a value that is not
    a number."""
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != len(header):
            raise SimulationInputError(f"{path}: row {number} has {len(cells)} values but the header names {len(header)}")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            raise SimulationInputError(f"{path}: row {number} has a value that is not a number ({line.strip()[:60]!r})") from None
    return np.array(rows, float).reshape(-1, len(header))


def _increasing(path: Path, axis: np.ndarray, name: str, what: str) -> None:
    step = np.diff(axis)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0])
        raise SimulationInputError(f"{path}: {name} must increase, but {float(axis[i + 1])!r} at data row {i + 2} follows "
                                   f"{float(axis[i])!r}; sort the {what} and remove repeated ones")


def read_time_csv(path: str | os.PathLike) -> HammerRecord:
    """A hammer-test time record from CSV (module docstring), SI units."""
    path = Path(path)
    example = "time_s,force_N,accel_m_s2"
    header, data = _table(path, "time record", example)
    roles: dict[str, list[tuple[str, int, str, float]]] = {}
    for col, cell in enumerate(header):
        name, unit = _split_header(cell)
        if unit not in UNITS:
            raise SimulationInputError(f"{path}: column '{cell}' has no unit this reader knows; end its name with one of "
                                       f"{KNOWN}, e.g. '{example}'")
        quantity, factor = UNITS[unit]
        roles.setdefault(quantity, []).append((name or cell, col, quantity, factor))
    for need in ("time", "force"):
        if need not in roles:
            raise SimulationInputError(f"{path}: no {need} column (its unit names it: {'time_s' if need == 'time' else 'force_N'}); "
                                       f"the header is '{','.join(header)}', e.g. '{example}'")
        if len(roles[need]) > 1:
            raise SimulationInputError(f"{path}: {len(roles[need])} {need} columns; give one (a second force: one file per "
                                       "reference)")
    responses = [r for q in ("acceleration", "velocity", "displacement") for r in roles.get(q, [])]
    if not responses:
        raise SimulationInputError(f"{path}: no response column (an acceleration, velocity or displacement with its "
                                   f"unit, e.g. accel_m_s2)")
    _, tcol, _, tfac = roles["time"][0]
    t = data[:, tcol] * tfac
    _increasing(path, t, "time", "samples")
    dt = (t[-1] - t[0]) / (t.size - 1)
    off = np.abs(t - t[0] - dt * np.arange(t.size))
    if np.max(off) > 0.25 * dt:  # rounded time values stay within a quarter step of the uniform grid
        i = int(np.argmax(off))
        raise SimulationInputError(f"{path}: the time is not uniformly sampled (data row {i + 1} lies {off[i] / dt:.2g} "
                                   "steps off the uniform grid); resample to a uniform rate")
    _, fcol, _, ffac = roles["force"][0]
    return HammerRecord(1.0 / dt, data[:, fcol] * ffac,
                        {name: data[:, col] * fac for name, col, _, fac in responses},
                        {name: q for name, _, q, _ in responses}, str(path))


def read_frf_csv(path: str | os.PathLike) -> MeasuredFrf:
    """Measured FRFs from CSV (module docstring), turned into displacement per force (m/N)."""
    path = Path(path)
    example = "frequency_Hz,tip_real_m_N,tip_imag_m_N"
    header, data = _table(path, "FRF file", example)
    freq_cols = [c for c, cell in enumerate(header) if _split_header(cell)[1] in ("hz", "khz")]
    if len(freq_cols) != 1:
        raise SimulationInputError(f"{path}: needs one frequency column (frequency_Hz), found {len(freq_cols)}; e.g. '{example}'")
    f = data[:, freq_cols[0]] * UNITS[_split_header(header[freq_cols[0]])[1]][1]
    _increasing(path, f, "the frequency", "lines")
    parts: dict[str, dict[str, tuple[np.ndarray, str]]] = {}
    coherence: dict[str, np.ndarray] = {}
    for col, cell in enumerate(header):
        if col == freq_cols[0]:
            continue
        if cell.endswith("_coherence"):
            coherence[cell[: -len("_coherence")]] = data[:, col]
            continue
        name, unit = _split_header(cell)
        match = re.fullmatch(r"(.+)_(real|imag|mag|phase)", name)
        if not match or (unit not in FRF_UNITS and unit not in ("deg", "rad")):
            raise SimulationInputError(f"{path}: column '{cell}' is not an FRF part this reader knows; name it NAME_real_UNIT, "
                                       "NAME_imag_UNIT, NAME_mag_UNIT or NAME_phase_deg with UNIT one of m_N, mm_N, m_s_N, "
                                       "m_s2_N, g_N (or NAME_coherence)")
        parts.setdefault(match.group(1), {})[match.group(2)] = (data[:, col], unit)
    if not parts:
        raise SimulationInputError(f"{path}: no FRF columns; e.g. '{example}'")
    frf = {}
    omega = 2 * np.pi * f
    for name, got in parts.items():
        if {"real", "imag"} <= set(got):
            (re_, unit), (im_, unit2) = got["real"], got["imag"]
            value = re_ + 1j * im_
        elif {"mag", "phase"} <= set(got):
            (mag, unit), (phase, punit) = got["mag"], got["phase"]
            unit2 = unit
            value = mag * np.exp(1j * (np.radians(phase) if punit == "deg" else phase))
        else:
            raise SimulationInputError(f"{path}: response '{name}' has {', '.join(sorted(got))} but needs real and imag, "
                                       "or mag and phase")
        if unit != unit2 or unit not in FRF_UNITS:
            raise SimulationInputError(f"{path}: response '{name}': give both parts in one FRF unit (m_N, mm_N, m_s_N, "
                                       "m_s2_N, g_N)")
        quantity, factor = FRF_UNITS[unit]
        positive = omega > 0
        frf[name] = value[positive] * factor * (1j * omega[positive]) ** TO_DISPLACEMENT[quantity]
    positive = omega > 0
    return MeasuredFrf(f[positive], frf, {k: v[positive] for k, v in coherence.items() if k in frf}, str(path),
                       _window_decay(path))


def _window_decay(path: Path) -> float:
    """The ``# window_decay_per_s = X`` comment of an FRF CSV (0 without one)."""
    for line in read_text(path, "FRF file", "CSV").splitlines():
        match = re.fullmatch(r"#\s*window_decay_per_s\s*=\s*(\S+)\s*", line.strip())
        if match:
            try:
                value = float(match.group(1))
            except ValueError:
                value = -1.0
            if not (value >= 0 and np.isfinite(value)):
                raise SimulationInputError(f"{path}: window_decay_per_s = {match.group(1)!r} must be a number >= 0 (1/s)")
            return value
    return 0.0


def _uff_sets(path: Path) -> list[dict]:
    import pyuff

    if not path.is_file():
        raise SimulationInputError(f"UFF file {path} not found; give the path of a .uff or .unv file")
    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions for malformed files
        raise SimulationInputError(f"{path}: not a readable UFF file ({str(exc).strip() or type(exc).__name__})") from None
    return [sets] if isinstance(sets, dict) else list(sets)


def read_uff(path: str | os.PathLike) -> HammerRecord | MeasuredFrf:
    """Time data or FRFs from the UFF 58 data sets of a file (module docstring), with one line for a data set of
    another kind."""
    path = Path(path)
    sets = _uff_sets(path)
    if not sets:
        raise SimulationInputError(f"{path}: no data sets; write time records or FRFs as UFF data sets 58")
    units = [s for s in sets if s.get("type") == 164]
    sets = [s for s in sets if s.get("type") not in (151, 164)]
    if len(units) > 1:
        raise SimulationInputError(f"{path}: {len(units)} units data sets (164); keep one")
    if not sets:
        raise SimulationInputError(f"{path}: no data sets 58; write time records or FRFs as UFF data sets 58")
    kinds = {(s.get("type"), s.get("func_type")) for s in sets}
    wrong = [k for k in kinds if k not in ((58, 1), (58, 4))]
    if wrong or len(kinds) != 1:
        described = ", ".join(f"type {t} function {ft}" if ft is not None else f"type {t}" for t, ft in sorted(kinds, key=str))
        raise SimulationInputError(f"{path}: holds UFF data sets of {described}; ies reads data sets 58 of time responses "
                                   "(function type 1) or of FRFs (function type 4), one kind per file")
    unit = units[0] if units else None
    if kinds == {(58, 1)}:
        return _uff_time(path, sets, unit)
    return _uff_frf(path, sets, unit)


def _uff_factor(path: Path, s: dict, axis: str, quantity: str, units: dict | None) -> float:
    """The factor to SI of one axis ("abscissa", "ordinate", "orddenom") of a data set 58 holding `quantity` (module
    docstring): its units label if it names a known unit of that quantity, else the units data set 164 (SI = value /
    (length^len_exp force^force_exp)), else 1 (SI); one line for a label of another quantity or of no known unit."""
    label = str(s.get(f"{axis}_axis_units_lab", "") or "").strip()
    if label and label.upper() != "NONE":
        known = UNITS.get(_unit_key(label))
        if known is not None:
            if known[0] != quantity:
                raise SimulationInputError(f"{path}: data set '{_uff_name(s, 0)}' labels its {axis} '{label}' ({known[0]}) "
                                           f"where {quantity} belongs; fix the data set's units label")
            return known[1]
        if units is None:
            raise SimulationInputError(f"{path}: data set '{_uff_name(s, 0)}' labels its {axis} '{label}', a unit ies "
                                       f"does not know, and the file has no units data set 164; give one of {KNOWN} as "
                                       "the label or add a data set 164")
    if units is None:
        return 1.0
    length, force = float(units["length"]), float(units["force"])
    exponents = (float(s.get(f"{axis}_len_unit_exp", 0) or 0), float(s.get(f"{axis}_force_unit_exp", 0) or 0))
    return 1.0 / (length ** exponents[0] * force ** exponents[1])


def _uff_name(s: dict, index: int) -> str:
    """A response's name: its entity name (what `write_uff_frf` writes), else node and direction."""
    name = str(s.get("rsp_ent_name", "") or "").strip()
    if name and name.upper() != "NONE":
        return name
    node, direction = s.get("rsp_node"), s.get("rsp_dir")
    return f"node{node}_dir{direction}" if node is not None else f"response{index + 1}"


def _uff_time(path: Path, sets: list[dict], units: dict | None = None) -> HammerRecord:
    forces = [s for s in sets if s.get("ordinate_spec_data_type") == UFF_FORCE]
    responses = [s for s in sets if s.get("ordinate_spec_data_type") in UFF_QUANTITY]
    if len(forces) != 1 or not responses:
        raise SimulationInputError(f"{path}: a hammer record needs one force data set (ordinate type 13) and at least one "
                                   f"response (8, 11, 12); found {len(forces)} force(s) and {len(responses)} response(s)")
    x = np.asarray(forces[0]["x"], float) * _uff_factor(path, forces[0], "abscissa", "time", units)
    _increasing(path, x, "the time", "samples")
    out, quantities = {}, {}
    for i, s in enumerate(responses):
        quantity = UFF_QUANTITY[s["ordinate_spec_data_type"]]
        values = np.asarray(s["data"], float) * _uff_factor(path, s, "ordinate", quantity, units)
        if values.size != x.size:
            raise SimulationInputError(f"{path}: response data set {i + 1} has {values.size} samples but the force {x.size}")
        name = _uff_name(s, i)
        out[name], quantities[name] = values, quantity
    force = np.asarray(forces[0]["data"], float) * _uff_factor(path, forces[0], "ordinate", "force", units)
    for name, values in [("force", force), *out.items()]:
        if not np.all(np.isfinite(values)):
            raise SimulationInputError(f"{path}: the {name} data set holds NaN or infinite values; remove or interpolate them")
    return HammerRecord(1.0 / float(np.mean(np.diff(x))), force, out, quantities, str(path))


def _uff_frf(path: Path, sets: list[dict], units: dict | None = None) -> MeasuredFrf:
    frf, f0 = {}, None
    for i, s in enumerate(sets):
        quantity = UFF_QUANTITY.get(s.get("ordinate_spec_data_type"))
        if quantity is None or s.get("orddenom_spec_data_type", UFF_FORCE) != UFF_FORCE:
            raise SimulationInputError(f"{path}: FRF data set {i + 1} is not a displacement, velocity or acceleration per "
                                       "force (ordinate types 8, 11, 12 over 13)")
        f = np.asarray(s["x"], float) * _uff_factor(path, s, "abscissa", "frequency", units)
        _increasing(path, f, "the frequency", "lines")
        if f0 is not None and (f.size != f0.size or not np.allclose(f, f0)):
            raise SimulationInputError(f"{path}: the FRF data sets have different frequency axes; give one axis")
        f0 = f
        values = np.asarray(s["data"], complex) * (_uff_factor(path, s, "ordinate", quantity, units)
                                                   / _uff_factor(path, s, "orddenom", "force", units))
        if not np.all(np.isfinite(values)):
            raise SimulationInputError(f"{path}: FRF data set {i + 1} holds NaN or infinite values")
        positive = f > 0
        frf[_uff_name(s, i)] = values[positive] * (2j * np.pi * f[positive]) ** TO_DISPLACEMENT[quantity]
    return MeasuredFrf(f0[f0 > 0], frf, {}, str(path))


def write_uff_frf(path: str | os.PathLike, frequencies_hz: np.ndarray, frf: dict[str, np.ndarray],
                  quantity: str = "displacement") -> Path:
    """Write FRFs (name -> complex values per force, in SI units of `quantity` per N) as UFF 58 data sets of function
    type 4 (pyuff), one per response (response node = its position + 1, direction +x; reference node 1, +x),
    atomically."""
    import pyuff

    from sim.common.files import atomic_path

    codes = {v: k for k, v in UFF_QUANTITY.items()}
    with atomic_path(path) as tmp:
        tmp.unlink()
        uff = pyuff.UFF(str(tmp))
        for i, (name, values) in enumerate(frf.items()):
            uff.write_sets(pyuff.prepare_58(
                func_type=4, rsp_node=i + 1, rsp_dir=1, ref_node=1, ref_dir=1, rsp_ent_name=name[:10], ref_ent_name="force",
                id1=f"FRF {name}", data=np.asarray(values, complex), x=np.asarray(frequencies_hz, float),
                abscissa_spacing=1, abscissa_spec_data_type=18, ordinate_spec_data_type=codes[quantity],
                orddenom_spec_data_type=UFF_FORCE), mode="add")
    return Path(path)


def write_uff_time(path: str | os.PathLike, record: HammerRecord) -> Path:
    """Write a hammer record as UFF 58 data sets of function type 1 (pyuff): the force (node 1) and each response
    (nodes 2, 3, ...), atomically."""
    import pyuff

    from sim.common.files import atomic_path

    codes = {v: k for k, v in UFF_QUANTITY.items()}
    x = np.arange(record.force.size) / record.fs
    channels = [("force", record.force, UFF_FORCE)] + [(n, v, codes[record.quantities[n]]) for n, v in record.responses.items()]
    with atomic_path(path) as tmp:
        tmp.unlink()
        uff = pyuff.UFF(str(tmp))
        for i, (name, values, code) in enumerate(channels):
            uff.write_sets(pyuff.prepare_58(
                func_type=1, rsp_node=i + 1, rsp_dir=1, ref_node=1, ref_dir=1, rsp_ent_name=name[:10], ref_ent_name="force",
                id1=f"time {name}", data=np.asarray(values, float), x=x, abscissa_spacing=1, abscissa_spec_data_type=17,
                ordinate_spec_data_type=code, orddenom_spec_data_type=0), mode="add")
    return Path(path)


def read_hammer_inputs(paths: list[str]) -> tuple[list[HammerRecord], list[MeasuredFrf]]:
    """The inputs of `ies identify`: time records (CSV with a time column, UFF time data) or measured FRFs (CSV with a
    frequency column, UFF FRF data), by their content; one kind for all files."""
    records, frfs = [], []
    for p in paths:
        path = Path(p)
        if path.suffix.lower() in (".uff", ".unv"):
            got = read_uff(path)
        else:
            text_head = read_text(path, "record", "CSV", "; give a time record or FRF CSV, or a .uff file")
            first = next((line for line in text_head.splitlines() if line.strip() and not line.startswith("#")), "")
            units = [_split_header(cell)[1] for cell in first.split(",")]
            got = read_frf_csv(path) if any(u in ("hz", "khz") for u in units) else read_time_csv(path)
        (records if isinstance(got, HammerRecord) else frfs).append(got)
    if records and frfs:
        raise SimulationInputError(f"{paths[0]} ...: give either time records or measured FRFs, not both")
    return records, frfs
