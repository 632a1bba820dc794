"""Modal-model files: bring the modes of the host structure from any FE tool (seed paper Eq. 7).

Format (TOML, UTF-8): README.md, section "Your own structure", the one description for users (arrays of one value per
retained mode in ascending frequency order: frequencies_hz, damping_ratios, phi_wall_left, phi_wall_right, phi_tip,
participation; optional beam_mass_kg, phi_floor; an optional [host] table with damping_interval and wall_material, or
wall_E_Pa and wall_nu; an optional [shapes] table of mode values at named measurement points, NAME = [one per mode],
1/sqrt(kg), which `ies update` pairs measured modes by (MAC) where a test measured three or more of them; optional
[units] naming the units, "Hz", "1", "1/sqrt(kg)", "sqrt(kg)", and a free-form
[provenance] table, written by sim.hosts.solid and sim.hosts.calculix, that readers ignore). `format =
"ies-modal-model"`, `version = 1` and `source` are optional.

The optional keys are needed only by the damped contact law (beam_mass_kg) and by friction (phi_floor);
files without them load as before, and those laws then refuse the model with one line naming the key. Without a
[host] table the walls are steel and the damping interval is Table 2's relative one around damping_ratios[0]
(`sim.model.system.ModalModel.damping_box`; every command says so). damping_ratios[0] is the host's nominal D_1*: the
amplitudes are normalised by it (Sect. 5), so that the host alone peaks at a / a_noabs* = 1.

Signs follow sim/model/system.py: the wall directions w_l, w_r are both +x, so phi_wall_* are the x-components of
the mass-normalised modes (phi_j^T M phi_j = 1 kg^0). A mode's overall sign is free, but phi_wall_*, phi_tip,
phi_floor and participation of that mode must use the same sign.
"""
from __future__ import annotations

import math
import os
import tomllib
from pathlib import Path

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import read_text, write_text
from sim.model.system import ModalModel

FORMAT_NAME = "ies-modal-model"
FORMAT_VERSION = 1
ARRAY_KEYS = ("frequencies_hz", "damping_ratios", "phi_wall_left", "phi_wall_right", "phi_tip", "participation")
OPTIONAL_ARRAY_KEYS = ("phi_floor",)
BEAM_MASS_KEY = "beam_mass_kg"
#: the keys of the [host] table
HOST_KEYS = ("damping_interval", "wall_material", "wall_E_Pa", "wall_nu")
UNITS = {"frequencies_hz": "Hz", "damping_ratios": "1", "phi": "1/sqrt(kg)", "participation": "sqrt(kg)"}

_HEADER = """\
# ies modal model of the host structure without the sphere (seed paper Eq. 7); format described in
# sim/hosts/modal_file.py. One value per mode, ascending frequency. Mode values are mass-normalised x-values
# (1/sqrt(kg)) at the left/right cavity walls, the measurement point and (optional) the cavity floor;
# participation = phi^T M b (sqrt(kg)); beam_mass_kg (optional): the beam's free length without the block (kg).
"""


def _numbers(path: Path, key: str, value: object) -> np.ndarray:
    if not isinstance(value, list) or not value:
        raise SimulationInputError(f"{path}: '{key}' must be a non-empty array of numbers, e.g. {key} = [117.4, 886.0]")
    for item in value:
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            raise SimulationInputError(f"{path}: '{key}' contains the non-numeric value {item!r}; give plain numbers")
        if not math.isfinite(item):
            raise SimulationInputError(f"{path}: '{key}' contains {item!r}; every value must be finite")
    return np.array(value, dtype=float)


def load_modal_model(path: str | os.PathLike) -> ModalModel:
    """Read a modal-model file (format in this module's docstring) into a ModalModel.

    Raises SimulationInputError with one line naming the file and the problem for a missing or unreadable
    file, invalid TOML, a missing key, a non-numeric entry (also in the optional phi_floor, beam_mass_kg),
    arrays of different lengths, frequencies that are not positive and strictly ascending, damping ratios
    outside (0, 1) or a beam mass that is not positive.
    """
    path = Path(path)
    text = read_text(path, "modal file", "TOML", "; give the path of a .toml modal-model file")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SimulationInputError(f"{path}: not valid TOML ({exc})") from None
    if "format" in data and data["format"] != FORMAT_NAME:
        raise SimulationInputError(f"{path}: format is {data['format']!r}, expected {FORMAT_NAME!r}")
    if "version" in data and data["version"] != FORMAT_VERSION:
        raise SimulationInputError(f"{path}: version {data['version']!r} is not supported; this reader knows version {FORMAT_VERSION}")
    missing = [key for key in ARRAY_KEYS if key not in data]
    if missing:
        raise SimulationInputError(f"{path}: missing key(s) {', '.join(missing)}; a modal file needs {', '.join(ARRAY_KEYS)}")
    units = data.get("units", {})
    if not isinstance(units, dict):
        raise SimulationInputError(f"{path}: 'units' must be a table, e.g. [units] frequencies_hz = \"Hz\"")
    for key, unit in units.items():
        if key in UNITS and unit != UNITS[key]:
            raise SimulationInputError(f"{path}: units.{key} is {unit!r} but must be {UNITS[key]!r}; convert the values")
    arrays = {key: _numbers(path, key, data[key]) for key in ARRAY_KEYS + OPTIONAL_ARRAY_KEYS if key in data}
    lengths = {key: a.size for key, a in arrays.items()}
    n = lengths["frequencies_hz"]
    wrong = [f"{key} has {size}" for key, size in lengths.items() if size != n]
    if wrong:
        raise SimulationInputError(f"{path}: arrays must all have {n} values (one per mode) but {'; '.join(wrong)}")
    source = data.get("source", str(path))
    beam_mass = data.get(BEAM_MASS_KEY)
    if beam_mass is not None and (isinstance(beam_mass, bool) or not isinstance(beam_mass, (int, float))):
        raise SimulationInputError(f"{path}: '{BEAM_MASS_KEY}' must be a number (kg), e.g. {BEAM_MASS_KEY} = 1.573")
    try:
        return ModalModel(**arrays, source=str(source), beam_mass=beam_mass, **host_table(data.get("host", {})))
    except SimulationInputError as exc:
        raise SimulationInputError(f"{path}: {exc}") from None


def host_table(table: object) -> dict:
    """The `ModalModel` fields of a [host] table (damping_interval, wall; format in the module docstring); one
    `SimulationInputError` line (without the file's name) for an unknown key or a value of the wrong kind."""
    from sim.model.materials import wall_material

    if not isinstance(table, dict):
        raise SimulationInputError("'host' must be a table, e.g. [host] wall_material = \"steel\"")
    unknown = sorted(set(table) - set(HOST_KEYS))
    if unknown:
        raise SimulationInputError(f"unknown key(s) {', '.join(unknown)} in [host]; known: {', '.join(HOST_KEYS)}")
    fields: dict = {}
    if "damping_interval" in table:
        interval = table["damping_interval"]
        if (not isinstance(interval, list) or len(interval) != 2
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in interval)):
            raise SimulationInputError(f"[host] damping_interval must be two damping ratios [low, high], e.g. "
                                       f"[0.00075, 0.0009], got {interval!r}")
        fields["damping_interval"] = tuple(float(v) for v in interval)
    own = [key for key in ("wall_E_Pa", "wall_nu") if key in table]
    if "wall_material" in table and own:
        raise SimulationInputError("[host] give wall_material or wall_E_Pa and wall_nu, not both")
    if "wall_material" in table:
        if not isinstance(table["wall_material"], str):
            raise SimulationInputError(f"[host] wall_material must be a name such as \"aluminium\" or \"E=70GPa,nu=0.33\", "
                                       f"got {table['wall_material']!r}")
        fields["wall"] = wall_material(table["wall_material"])
    elif own:
        if len(own) == 1:
            raise SimulationInputError(f"[host] has {own[0]} but not {({'wall_E_Pa', 'wall_nu'} - set(own)).pop()}; Eq. 8 "
                                       "needs the wall's E (Pa) and nu")
        E, nu = table["wall_E_Pa"], table["wall_nu"]
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in (E, nu)):
            raise SimulationInputError("[host] wall_E_Pa and wall_nu must be numbers (Pa and -)")
        fields["wall"] = wall_material(f"E={float(E)!r},nu={float(nu)!r}")
    return fields


def host_document(model: ModalModel) -> dict:
    """The [host] table of a model (what `host_table` reads back): its damping interval and wall, where it has them."""
    from sim.model.materials import WALL_MATERIALS

    doc: dict = {}
    if model.damping_interval is not None:
        doc["damping_interval"] = [float(v) for v in model.damping_interval]
    if model.wall is not None:
        if WALL_MATERIALS.get(model.wall.name) == model.wall:
            doc["wall_material"] = model.wall.name
        else:
            doc.update(wall_E_Pa=model.wall.E, wall_nu=model.wall.nu)
    return doc


def modal_model_document(model: ModalModel, provenance: dict | None = None,
                         shapes: dict[str, np.ndarray] | None = None) -> dict:
    """The file content of a model as plain data (what save_modal_model writes), with optional [shapes] (`load_shapes`)
    and [provenance] tables (plain TOML data: strings, numbers, booleans, lists and tables)."""
    doc: dict = {"format": FORMAT_NAME, "version": FORMAT_VERSION, "source": model.source}
    for key in ARRAY_KEYS:
        doc[key] = [float(v) for v in getattr(model, key)]
    if model.phi_floor is not None:
        doc["phi_floor"] = [float(v) for v in model.phi_floor]
    if model.beam_mass is not None:
        doc[BEAM_MASS_KEY] = model.beam_mass
    if host := host_document(model):
        doc["host"] = host
    if shapes:
        doc["shapes"] = {name: [float(v) for v in values] for name, values in shapes.items()}
    doc["units"] = dict(UNITS)
    if provenance:
        doc["provenance"] = provenance
    return doc


def load_shapes(path: str | os.PathLike, n_modes: int) -> dict[str, np.ndarray]:
    """The [shapes] table of a modal-model file (module docstring; {} when it has none): point name -> the mode values
    there (1/sqrt(kg), one per mode); one line for a table of another form. Call load_modal_model first."""
    path = Path(path)
    table = tomllib.loads(path.read_text(encoding="utf-8")).get("shapes", {})
    if not isinstance(table, dict):
        raise SimulationInputError(f"{path}: 'shapes' must be a table of points, e.g. [shapes] tip = [1.36, 1.18]")
    shapes = {str(name): _numbers(path, f"shapes.{name}", values) for name, values in table.items()}
    wrong = [f"{name} has {v.size}" for name, v in shapes.items() if v.size != n_modes]
    if wrong:
        raise SimulationInputError(f"{path}: [shapes] needs {n_modes} values per point (one per mode) but "
                                   f"{'; '.join(wrong)}")
    return shapes


def load_provenance(path: str | os.PathLike) -> dict:
    """The [provenance] table of a modal-model file ({} when it has none); call load_modal_model first to check
    the file."""
    return dict(tomllib.loads(Path(path).read_text(encoding="utf-8")).get("provenance", {}))


def save_modal_model(model: ModalModel, path: str | os.PathLike, provenance: dict | None = None,
                     shapes: dict[str, np.ndarray] | None = None) -> Path:
    """Write `model` (and optional [shapes] and [provenance] tables) as a modal-model file (format in this module's
    docstring), atomically (`sim.common.files`)."""
    import tomli_w

    try:
        return write_text(path, _HEADER + tomli_w.dumps(modal_model_document(model, provenance, shapes)))
    except (FileNotFoundError, IsADirectoryError) as exc:  # a missing folder, or a folder named as the file
        raise SimulationInputError(exc.strerror) from None
