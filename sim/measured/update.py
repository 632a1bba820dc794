"""Model updating to measured modes, as Appendix A of the seed paper updates its model: the elastic modulus E (here a
stiffness scale, E / E_0) fitted to a chosen mode, the frequency errors per mode (Table A.1: 0.05 / 1.4 / 0.5 /
0.7 % after E went from 210 to 207 GPa to match mode 1), the measured damping ratios for the identified modes and a
stated default for the rest (the paper: 0.1 % for modes 5-9).

* Stiffness scale: the whole stiffness matrix times a scale (E, and any spring such as the built-in rig's joint
  spring, alike) multiplies every frequency by its square root at fixed mass, and leaves the mass-normalised mode
  shapes (hence phi at the walls, the tip, the floor and the participation phi^T M b) unchanged; for a model of one
  material without springs the scale is E / E_0. scale = (f_measured / f_model)^2 of the chosen mode (`fit_mode`, 1-based among the
  measured modes), or the least-squares scale of log f over every paired mode (fit_mode None). E = scale E_0 where
  E_0 is known (the built-in rig's updated E, the solid's material, or the user's).
* Pairing: each measured mode with one model mode (scipy's linear_sum_assignment on |ln(f_measured / f_model)|); a
  measured mode farther than `tolerance` (relative) from its model mode pairs with none, which is refused with one
  line: the measurement found a mode the model lacks (the clamping's secondary peak of Fig. A.1, a torsion or y-mode),
  or the model is far off. Where the test measured three or more points that the model file names in its [shapes]
  table (modes.csv's modal_constant_NAME_per_kg, A = phi_NAME phi_drive), the shapes pair first: the cost is
  1 - MAC + |ln(f_measured / f_model)| (MAC, the modal assurance criterion |a^T b|^2 / (a^T a b^T b) of the measured
  and the model's values at the common points), so that two modes close in frequency pair by their shapes; a pair
  with MAC below `MAC_MIN` is refused (the model's mode there is another mode).
* Damping: the paired modes take the measured damping ratios; the others `default_damping`. A damping interval of D_1
  the model carried (Table 2's for the rig) is dropped when it no longer contains the new D_1: the hammer's D_1 is a
  small-amplitude value, and `ies linearity` measures the interval over the response range.

The rig updated to Table A.1 (mode 1 fitted; tests/sim/measured/test_update.py), against the paper's E = 207 GPa and
errors 0.05 / 1.4 / 0.5 / 0.7 %:
* built-in beam, variant joint-spring (E = 215 GPa, its neck and joint spring already updated to Table A.1 and f9,
  `sim.hosts.rig`): scale 0.99995, E = 214.99 GPa, errors 0 / -1.05 / +0.28 / -0.38 %: E barely moves because the
  beam's geometry was fitted together with E; the errors are those of that fit, smaller than the paper's.
* variant effective-modulus (E = 240.8 GPa, neck in x and y fitted to f1..f4 exactly): scale 1, errors 0.
* the 3D solid (`ies update solid`: coarse mesh, the beam's neck, E_0 = 207 GPa): f1 = 111.8 Hz before, E =
  228.2 GPa after, errors 0 / -0.74 / +1.54 / +1.36 %: the paper's procedure on a 3D model, with errors of the paper's
  size; its E differs from 207 GPa because the neck of the paper's model is not published (E and the neck's
  stiffness trade off: f ~ sqrt(E) at fixed geometry).
* The paper's f1 error of 0.05 % after a fit to mode 1 is E rounded to 207 GPa (0.1 % in E is 0.05 % in f).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from sim.common.errors import SimulationInputError
from sim.common.files import read_text
from sim.model.system import ModalModel

#: the paper's damping of the modes not identified (Appendix A: D5..D9 = 0.1 %)
DEFAULT_DAMPING = 0.001
#: a measured mode pairs with a model mode within this relative frequency distance
PAIR_TOLERANCE = 0.15
#: the smallest MAC of a pair where shapes are measured (0.9 and above is the usual "same mode")
MAC_MIN = 0.6
#: the fewest common measurement points for pairing by MAC (two points cannot tell most modes apart)
MAC_POINTS = 3


@dataclass(frozen=True)
class MeasuredModes:
    """Measured natural frequencies (Hz) and damping ratios (-) of modes.csv (`ies identify`), its path, and the modal
    constants per response (name -> one per mode, 1/kg: phi_NAME phi_drive) where it has them."""

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    source: str
    constants: dict[str, np.ndarray] = field(default_factory=dict)


def read_modes(path: str | os.PathLike) -> MeasuredModes:
    """A modes.csv with the columns frequency_hz and damping_ratio (others ignored); one line for a missing column,
    a value that is not a positive number, or frequencies that do not increase."""
    path = Path(path)
    text = read_text(path, "measured modes file", "CSV", "; give the modes.csv that `ies identify` wrote")
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    header = [c.strip() for c in lines[0].split(",")] if lines else []
    missing = [c for c in ("frequency_hz", "damping_ratio") if c not in header]
    if missing:
        raise SimulationInputError(f"{path}: no column {' or '.join(missing)}; give the modes.csv of `ies identify` "
                                   "(columns mode, frequency_hz, damping_ratio, ...)")
    fi, di = header.index("frequency_hz"), header.index("damping_ratio")
    named = {m.group(1): i for i, c in enumerate(header) if (m := re.fullmatch(r"modal_constant_(.+)_per_kg", c))}
    f, d, a = [], [], []
    for number, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        try:
            f.append(float(cells[fi]))
            d.append(float(cells[di]))
            a.append([float(cells[i]) for i in named.values()])
        except (ValueError, IndexError):
            raise SimulationInputError(f"{path}: row {number} has no number in frequency_hz, damping_ratio or a "
                                       "modal_constant column") from None
    f, d = np.array(f), np.array(d)
    constants = {name: np.array([row[k] for row in a]) for k, name in enumerate(named)}
    if f.size == 0:
        raise SimulationInputError(f"{path}: no modes; identify at least one (`ies identify`)")
    if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) > 0)):
        raise SimulationInputError(f"{path}: frequency_hz must be positive and increase from row to row")
    if not (np.all(np.isfinite(d)) and np.all((d > 0) & (d < 1))):
        raise SimulationInputError(f"{path}: damping_ratio must lie in (0, 1), e.g. 0.0006 for 0.06 %")
    return MeasuredModes(f, d, str(path), constants)


@dataclass(frozen=True)
class Update:
    """The updated model and what the updating found: the pairing (model mode index of each measured mode), the
    stiffness scale (-), E (Pa, or None when E_0 is unknown), the model's frequencies before (Hz) and the relative
    frequency errors of the paired modes after (updated / measured - 1), and the damping source per mode."""

    model: ModalModel
    pairs: np.ndarray
    scale: float
    E: float | None
    before_hz: np.ndarray
    errors: np.ndarray
    damping_measured: np.ndarray
    note: str = ""
    mac: np.ndarray | None = None
    mac_points: tuple[str, ...] = ()


def mac_matrix(measured: np.ndarray, model: np.ndarray) -> np.ndarray:
    """The modal assurance criterion of every measured mode (rows of `measured`, values at the points) with every model
    mode (rows of `model`, the same points): |a^T b|^2 / (a^T a b^T b), 1 for proportional shapes, 0 for orthogonal."""
    num = np.abs(measured @ model.T) ** 2
    den = np.outer(np.sum(measured**2, axis=1), np.sum(model**2, axis=1))
    return np.divide(num, den, out=np.zeros_like(num), where=den > 0)  # a shape of zeros matches nothing


def pair_modes(measured_hz: np.ndarray, model_hz: np.ndarray, tolerance: float = PAIR_TOLERANCE,
               source: str = "modes.csv", mac: np.ndarray | None = None) -> np.ndarray:
    """The model mode (index) of each measured mode (module docstring), by frequency, or by shape and frequency where
    `mac` (measured x model modes, `mac_matrix`) is given; one line for a measured mode that pairs with none."""
    from scipy.optimize import linear_sum_assignment

    if measured_hz.size > model_hz.size:
        raise SimulationInputError(f"{source}: {measured_hz.size} measured modes but the model has {model_hz.size}; give "
                                   "the model more modes (--n-modes) or drop measured modes")
    cost = np.abs(np.log(measured_hz[:, None] / model_hz[None, :]))
    if mac is not None:
        cost = cost + (1.0 - mac)
    rows, cols = linear_sum_assignment(cost)
    pairs = cols[np.argsort(rows)]
    if mac is not None:
        for i, j in enumerate(pairs):
            if mac[i, j] < MAC_MIN:
                best = int(np.argmax(mac[i]))
                raise SimulationInputError(
                    f"{source}: the measured mode at {measured_hz[i]:.5g} Hz has no model mode of its shape (MAC "
                    f"{mac[i, j]:.2f} with the mode at {model_hz[j]:.5g} Hz, below {MAC_MIN:g}; its best, "
                    f"{mac[i, best]:.2f}, is the mode at {model_hz[best]:.5g} Hz); check the points' names and signs "
                    "in [shapes], or drop the mode")
    for i, j in enumerate(pairs):
        if abs(measured_hz[i] / model_hz[j] - 1) > tolerance:
            nearest = model_hz[int(np.argmin(np.abs(model_hz - measured_hz[i])))]
            raise SimulationInputError(
                f"{source}: the measured mode at {measured_hz[i]:.5g} Hz pairs with no model mode (nearest "
                f"{nearest:.5g} Hz, {100 * (measured_hz[i] / nearest - 1):+.1f} %, beyond {100 * tolerance:g} %); "
                "drop it from the file if the model lacks it, or widen --pair-tolerance")
    return pairs


def update_model(model: ModalModel, measured: MeasuredModes, *, fit_mode: int | None = 1, E_0: float | None = None,
                 default_damping: float = DEFAULT_DAMPING, tolerance: float = PAIR_TOLERANCE,
                 source: str = "", shapes: dict[str, np.ndarray] | None = None) -> Update:
    """The model updated to the measured modes (module docstring); `shapes`: the model's mode values at named points
    (a modal file's [shapes] table), for pairing by MAC where modes.csv has three or more of them."""
    if not 0 < default_damping < 1:
        raise SimulationInputError(f"--default-damping must lie in (0, 1), e.g. 0.001 for 0.1 %, got {default_damping!r}")
    points = tuple(name for name in measured.constants if name in (shapes or {}))
    mac = None
    if len(points) >= MAC_POINTS:
        mac = mac_matrix(np.column_stack([measured.constants[n] for n in points]),
                         np.column_stack([shapes[n] for n in points]))
    else:
        points = ()
    pairs = pair_modes(measured.frequencies_hz, model.frequencies_hz, tolerance, measured.source, mac)
    ratio = measured.frequencies_hz / model.frequencies_hz[pairs]
    if fit_mode is None:
        scale = float(np.exp(2 * np.mean(np.log(ratio))))
    else:
        if not 1 <= fit_mode <= ratio.size:
            raise SimulationInputError(f"--fit-mode {fit_mode}: {measured.source} has {ratio.size} measured mode(s); give "
                                       f"1..{ratio.size} or all")
        scale = float(ratio[fit_mode - 1] ** 2)
    frequencies = model.frequencies_hz * np.sqrt(scale)
    damping = np.full(model.n_modes, default_damping)
    damping[pairs] = measured.damping_ratios
    measured_mask = np.zeros(model.n_modes, bool)
    measured_mask[pairs] = True
    interval, note = model.damping_interval, ""
    if interval is not None and not interval[0] <= damping[0] <= interval[1]:
        interval = None
        note = (f"the model's damping interval of D_1 ({100 * model.damping_interval[0]:.4g}-"
                f"{100 * model.damping_interval[1]:.4g} %) does not hold the measured D_1 = {100 * damping[0]:.4g} % "
                "and was dropped; measure it with `ies linearity`")
    updated = replace(model, frequencies_hz=frequencies, damping_ratios=damping, damping_interval=interval,
                      nominal_damping=None, source=source or f"{model.source}, updated to {measured.source}")
    errors = updated.frequencies_hz[pairs] / measured.frequencies_hz - 1
    return Update(model=updated, pairs=pairs, scale=scale, E=None if E_0 is None else scale * E_0,
                  before_hz=model.frequencies_hz.copy(), errors=errors, damping_measured=measured_mask, note=note,
                  mac=None if mac is None else mac[np.arange(pairs.size), pairs], mac_points=points)


def model_frf(model: ModalModel, frequencies_hz: np.ndarray, window_decay: float = 0.0) -> np.ndarray:
    """Displacement per force at the tip of a tip hit (m/N) of a modal model: sum_j phi_tip,j^2 /
    (omega_j^2 - omega^2 + 2 i D_j omega_j omega) (Eq. 7 driven at the measurement point); with window_decay (1/s) as
    a measurement through an exponential window sees it (each D_j omega_j raised by window_decay)."""
    w = 2 * np.pi * np.asarray(frequencies_hz, float)[:, None]
    wj = model.omega[None, :]
    sigma = model.damping_ratios[None, :] * wj + window_decay
    return np.sum(model.phi_tip[None, :] ** 2 / (wj**2 - w**2 + 2j * sigma * w), axis=1)
