"""The calibration `ies calibrate` performs, as library functions usable from Python (seed paper, Sect. 4.1, Eq. 8,
Fig. 3; Appendix C for k_t).

`CalibrationSettings` holds every choice of the command (its defaults are the command's); `gap_source` builds what
is pressed on the wall: the ideal sphere on the flat wall (`flat_wall`) or the sphere above a scanned crater
(`scanned_wall`: read, level, measure, place the sphere; every scan problem is found before any BEM work);
`calibrate` computes the force-indentation curve and fits k_H (`bem_contact.calibration.calibrate_k_H`); `summary` is
the JSON object of `ies calibrate --json`, and `calibrate_default` that object for the shipped paper-like crater
with every default, which `ies reproduce` uses as the upper bound of k_H. `tangential` gives k_t of the stuck sphere.

The scans stage is imported here because reading a scan and pressing on it is the pipeline's arrow
scans -> bem_contact. Heavy imports stay inside the functions (`ies --help` reads the defaults from here); the paper's
sphere, clearance and k_t come from the one vocabulary, `sim.model.parameters`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from sim.model.parameters import (CLEARANCE_NOMINAL, GRAVITY, K_T_PAPER, SPHERE_FLATTENING, SPHERE_MASS,  # noqa: F401
                                  SPHERE_RADIUS)

SPHERE_WEIGHT = SPHERE_MASS * GRAVITY  # N, m_a g: the normal load of Appendix C
DEFAULT_GRID = 256
DEFAULT_TANGENTIAL_GRID = 96  # BEM k_t within 0.1 % of Mindlin's at the weight
DEFAULT_SIDE_MM = 2.5  # contact radius at 40 um is 0.56 mm: the domain holds it with room to spare
PAPER_FLATTENING_MM = SPHERE_FLATTENING * 1e3  # Sect. 4.1: sphere diameter 15.80 mm in the flattened regions, 15.84 nominal
PAPER_CLEARANCE_MM = CLEARANCE_NOMINAL * 1e3  # Sect. 4.1: (17 - 15.84) / 2
DEFAULT_DENOISE_UM = 90.0  # = scans.contact.DEFAULT_DENOISE (not imported here: `ies --help` stays light)
NOISY_RAW = 0.1e-6  # m: raw-scan noise beyond which k_H is biased by more than about half a percent


@dataclass(frozen=True, kw_only=True)
class CalibrationSettings:
    """Every choice of a k_H calibration, with the defaults of `ies calibrate` (lengths in the units named).

    scan: scan file (None: the shipped paper-like crater); flat: the ideal sphere on the flat wall instead;
    shape: "paraboloid" or "sphere" (flat wall); side_mm: side of the square contact domain (mm; None: automatic
    for a scan, DEFAULT_SIDE_MM on the flat wall); units, imprint, pixel_size: how to read the scan; flattening:
    sphere flattening per side (mm); sphere: "ideal" or "flattened" in the BEM; placement: "centroid" or "deepest";
    denoise, smooth: filter widths (um); clearance: nominal clearance (mm); grid: elements across (None:
    DEFAULT_GRID); solver: contact solver name; delta_min_um, delta_max_um, points: the indentations of the curve.
    """

    scan: str | None = None
    flat: bool = False
    shape: str = "paraboloid"
    side_mm: float | None = None
    units: str = "mm"
    imprint: bool = False
    pixel_size: float | None = None
    flattening: float = PAPER_FLATTENING_MM
    sphere: str = "ideal"
    placement: str = "centroid"
    denoise: float = DEFAULT_DENOISE_UM
    smooth: float = 0.0
    clearance: float = PAPER_CLEARANCE_MM
    grid: int | None = None
    solver: str = "auto"
    delta_min_um: float = 2.0
    delta_max_um: float = 40.0
    points: int = 20


@dataclass(frozen=True)
class GapSource:
    """What is calibrated: gap_at(n) -> (gap map (m), dx (m)) on n elements across, a label and its facts."""

    gap_at: Callable[[int], Any]
    label: str
    facts: dict[str, Any]


def flat_wall(settings: CalibrationSettings) -> GapSource:
    """The ideal sphere (Sect. 2: R = 7.92 mm) on the nominally flat cavity wall."""
    from bem_contact.errors import ContactInputError
    from bem_contact.geometry import sphere_gap

    side_mm = DEFAULT_SIDE_MM if settings.side_mm is None else settings.side_mm
    if not side_mm > 0:
        raise ContactInputError(f"--side-mm {side_mm} must be > 0 (default {DEFAULT_SIDE_MM})")
    side = side_mm * 1e-3
    return GapSource(
        gap_at=lambda n: sphere_gap(n, side, SPHERE_RADIUS, settings.shape),
        label=f"flat wall, ideal sphere ({settings.shape}) R = {SPHERE_RADIUS * 1e3:g} mm",
        facts={"geometry": "flat", "shape": settings.shape, "R": SPHERE_RADIUS, "side": side,
               "indentation_reference": "first touch of the ideal sphere on the flat wall"},
    )


def scanned_wall(settings: CalibrationSettings) -> GapSource:
    """The sphere above a scanned crater (Sect. 4.1, Fig. 3b): read, level, measure, place the sphere.

    Everything that can be wrong with the scan is checked here, before any BEM work or file output.
    """
    import math

    from scans import (PAPER_CRATER, ScanError, Sphere, clearance_bounds, crater_metrics, example_path,
                       level_scan, read_scan, scan_contact)

    for name in ("flattening", "clearance", "smooth", "denoise"):
        value = getattr(settings, name)
        if not (math.isfinite(value) and value >= 0):
            raise ScanError(f"--{name} {value} must be a finite number >= 0")
    if settings.pixel_size is not None and not (math.isfinite(settings.pixel_size) and settings.pixel_size > 0):
        raise ScanError(f"--pixel-size {settings.pixel_size} must be > 0 (in --units)")
    path = settings.scan if settings.scan is not None else example_path("crater")
    scan = read_scan(path, units=settings.units, pixel_size=settings.pixel_size)
    surface = level_scan(scan, imprint=settings.imprint)
    metrics = crater_metrics(surface)
    unit_warning = crater_units_check(metrics.diameter, metrics.depth, settings.units, scan.source)
    flattening = settings.flattening * 1e-3
    sphere = Sphere(SPHERE_RADIUS, flattening if settings.sphere == "flattened" else 0.0)
    side = None if settings.side_mm is None else settings.side_mm * 1e-3
    contact = scan_contact(surface, sphere, placement=settings.placement, delta_max=settings.delta_max_um * 1e-6, side=side,
                           smoothing=settings.smooth * 1e-6, denoise=settings.denoise * 1e-6)
    clearance_min, clearance_max = clearance_bounds(metrics.depth, flattening, settings.clearance * 1e-3)
    facts: dict[str, Any] = {
        "geometry": "scan",
        "scan": str(path),
        "scan_kind": scan.kind,
        "scan_points": len(scan.vertices),
        "units_in_file": scan.units,
        "imprint": surface.imprint,
        "sphere": sphere.describe(),
        "R": SPHERE_RADIUS,
        "sphere_flattening_in_bem": sphere.flattening,
        "placement": contact.placement,
        "sphere_axis_point": surface.to_scanner(*contact.centre),
        "sphere_axis_direction": surface.axes[2],
        "side": contact.side,
        "smoothing": contact.smoothing,
        "denoise": contact.denoise,
        "indentation_reference": _reference(contact.denoise, contact.smoothing),
        "wall_tilt_deg": surface.tilt_deg(),
        "noise": metrics.noise,
        "spikes_removed": surface.spikes,
        "flat_fraction": surface.flat_fraction,
        "crater_depth": metrics.depth,
        "rim_height": metrics.rim_height,
        "crater_diameter": metrics.diameter,
        "clearance_nominal": settings.clearance * 1e-3,
        "flattening": flattening,
        "clearance_min": clearance_min,
        "clearance_max": clearance_max,
        "warnings": list(metrics.warnings) + _noise_warnings(contact.denoise, metrics) + unit_warning,
    }
    if settings.scan is None:
        facts["scan_note"] = (f"shipped example: synthetic crater {PAPER_CRATER.depth * 1e6:g} um deep, "
                              f"{PAPER_CRATER.pileup * 1e6:g} um pile-up (scans.examples)")

    def gap_at(n: int):
        gap, dx = contact.gap_at(n)
        facts.setdefault("holes", {})[str(n)] = contact.holes[n].describe()
        return gap, dx

    label = f"{scan.source}{' (imprint, inverted)' if surface.imprint else ''}, {sphere.describe()}"
    facts["_contact"], facts["_metrics"] = contact, metrics  # for the plot; not in the JSON
    return GapSource(gap_at=gap_at, label=label, facts=facts)


#: a crater deeper than this (m) is implausible: the paper's is about 20 um deep (Sect. 4.1, the sphere flattened by
#: 0.02 mm), and 0.1 mm would already widen the 0.58 mm clearance by a sixth (the paper-like crater read in cm: 0.12 mm)
MAX_CRATER_DEPTH = 0.1e-3


def crater_units_check(diameter: float, depth: float, units: str, source: str) -> list[str]:
    """Whether a crater of `diameter` and `depth` (m, as read in `units`) can be the sphere's (R = 7.92 mm, Sect. 2):
    wider than the sphere is refused (ScanError: the units are wrong), deeper than MAX_CRATER_DEPTH is one warning
    (returned as a list of lines); each names the unit that would fit."""
    from scans import ScanError
    from scans.io import UNITS

    def fits(unit: str) -> bool:
        scale = UNITS[unit] / UNITS[units]
        return diameter * scale <= 2.0 * SPHERE_RADIUS and depth * scale <= MAX_CRATER_DEPTH

    if diameter <= 0 or depth <= 0 or units not in UNITS or fits(units):
        return []
    better = next((u for u in ("mm", "um", "cm", "m", "in") if fits(u)), None)
    hint = f"; the file looks like it is in {better}: use --units {better}" if better else "; check --units"
    what = f"{source}: read in {units}, the crater is {diameter * 1e3:.3g} mm across and {depth * 1e6:.3g} um deep"
    if diameter > 2.0 * SPHERE_RADIUS:
        raise ScanError(f"{what}: wider than the {2e3 * SPHERE_RADIUS:.2f} mm sphere that made it{hint}")
    return [f"{what}: deeper than {MAX_CRATER_DEPTH * 1e3:g} mm, implausible for impacts of the sphere{hint}"]


def _reference(denoise: float, smoothing: float) -> str:
    """Which indentation reference the curve uses (text and JSON)."""
    if denoise > 0:
        text = (f"first touch on the wall denoised by a second-order Gaussian filter of {denoise * 1e6:g} um "
                "(exact for quadratic surfaces; --denoise 0 for the raw scan)")
    else:
        text = "first touch on the raw scan (noise peaks included; k_H low by about 6 % per um of noise)"
    return text + (f", then smoothed over {smoothing * 1e6:g} um" if smoothing else "")


def _noise_warnings(denoise: float, metrics) -> list[str]:
    """Warnings about scanner noise (raw scan) or a denoising filter wide against the crater."""
    warnings = []
    if denoise == 0 and metrics.noise > NOISY_RAW:
        warnings.append(f"scanner noise {metrics.noise * 1e6:.2g} um on the raw scan (--denoise 0): the first touch moves onto "
                        "noise peaks and k_H comes out low (paper-like crater: -0.6 % at 0.1 um, -3.4 % at 0.5 um); "
                        f"drop --denoise 0 (default {DEFAULT_DENOISE_UM:g} um)")
    if denoise > 0 and metrics.diameter > 0 and denoise > metrics.diameter / 8:
        warnings.append(f"the denoising filter ({denoise * 1e6:g} um) is wide against the crater ({metrics.diameter * 1e3:.3g} mm "
                        "across) and may flatten it; use a smaller --denoise (about diameter / 16)")
    return warnings


def gap_source(settings: CalibrationSettings) -> GapSource:
    """Choose the gap map from the settings: the flat wall (`flat`), or a scan (`scan`, default the shipped crater)."""
    from scans import ScanError

    if settings.flat:
        if settings.scan is not None:
            raise ScanError("give either a SCAN file or --flat, not both")
        return flat_wall(settings)
    return scanned_wall(settings)


def calibrate(settings: CalibrationSettings) -> tuple[Any, GapSource, float]:
    """Run the calibration the settings describe (Sect. 4.1, Eq. 8, Fig. 3c): the force-indentation curve of the gap
    map at `points` indentations from `delta_min_um` to `delta_max_um` (um), on `grid` and grid / 2 for the error bar,
    fit f = k_H delta^1.5 (`bem_contact.calibration.calibrate_k_H`). Returns (Calibration, GapSource, E* in Pa)."""
    import numpy as np

    from bem_contact.calibration import calibrate_k_H
    from bem_contact.errors import ContactInputError
    from bem_contact.materials import BRASS, STEEL, contact_modulus

    if settings.points < 2:
        raise ContactInputError(f"--points {settings.points}: need at least 2 indentations for a fit")
    if not 0 < settings.delta_min_um < settings.delta_max_um:
        raise ContactInputError(
            f"indentations must satisfy 0 < --delta-min-um < --delta-max-um (got {settings.delta_min_um}, {settings.delta_max_um})"
        )
    source = gap_source(settings)
    E_star = contact_modulus(STEEL, BRASS)
    deltas = np.round(np.linspace(settings.delta_min_um, settings.delta_max_um, settings.points) * 1e-6, 13)  # m, no float noise
    from sim.common.progress import progress

    # progress on stderr: a bar on a terminal, plain lines in a log when it takes long (fine grids)
    with progress(2 * len(deltas), "contact solves", "solve", leave=False) as bar:
        grid = DEFAULT_GRID if settings.grid is None else settings.grid
        result = calibrate_k_H(source.gap_at, grid, E_star, deltas, solver=settings.solver, R=SPHERE_RADIUS, on_solve=bar.update)
    return result, source, E_star


def summary(result, source: GapSource, E_star: float) -> dict[str, Any]:
    """The JSON object of `ies calibrate --json` (SI units)."""
    data = result.summary()
    data.update({k: v for k, v in source.facts.items() if not k.startswith("_")})
    data["E_star"] = E_star
    data["materials"] = {"wall": "steel, E = 207 GPa, nu = 0.3", "sphere": "brass, E = 102 GPa, nu = 0.3"}
    data["units"] = {"k_H": "N/m^1.5", "k_H_star": "N/m^1.5", "k_H_error": "N/m^1.5", "deltas": "m (from first touch)",
                     "forces": "N", "contact_areas": "m^2", "dx": "m", "side": "m", "R": "m", "E_star": "Pa",
                     "fit_residual": "1 (||f - k_H delta^1.5|| / ||f||)", "k_H_ratio": "1 (k_H / k_H*, Eq. 8)"}
    if data.get("geometry") == "scan":
        data["holes_in_contact_zone"] = holes_in_contact_zone(data, source.facts["_contact"].holes.get(data["grid"]))
        if data["holes_in_contact_zone"]:
            data["warnings"] = [*data["warnings"], data["holes_in_contact_zone"]]
        data["units"].update({k: "m" for k in ("crater_depth", "rim_height", "crater_diameter", "clearance_min",
                                                "clearance_max", "clearance_nominal", "flattening", "noise",
                                                "sphere_flattening_in_bem", "sphere_axis_point", "smoothing",
                                                "denoise")})
        data["units"].update({"wall_tilt_deg": "deg", "flat_fraction": "1", "sphere_axis_direction": "1 (unit normal)"})
    return data


def holes_in_contact_zone(data: dict[str, Any], holes: Any) -> str | None:
    """A warning when a filled hole of the scan (`scans.raster.HoleReport`) lies inside the contact zone at the
    largest indentation (radius sqrt(A / pi) from the largest contact area A, m^2), where k_H then rests on
    interpolated heights; None otherwise."""
    import math

    if holes is None or len(data.get("contact_areas", ())) == 0:
        return None
    radius = math.sqrt(float(data["contact_areas"][-1]) / math.pi)
    if not holes.nearest <= radius:
        return None
    return (f"a filled hole lies inside the contact zone: its nearest node is {holes.nearest * 1e6:.0f} um from the "
            f"sphere's axis, the contact radius at {data['deltas'][-1] * 1e6:g} um indentation is {radius * 1e6:.0f} um; "
            "k_H rests on interpolated heights there: rescan the crater without the dropout, or compare with the "
            "hole elsewhere")


def tangential(normal_force: float | None = None, grid: int | None = None) -> dict[str, Any]:
    """k_t of the sphere stuck on the flat wall (Appendix C, `ies calibrate --tangential`) by BEM and by Mindlin's
    8 G* a at `normal_force` (N; default the sphere's weight m_a g) on `grid` elements across (default
    DEFAULT_TANGENTIAL_GRID), the paper's value and the normal force (N) for which 8 G* a would equal it (k_t grows
    as N^(1/3)). Plain data in SI units (the JSON object)."""
    import math

    from bem_contact.errors import ContactInputError
    from bem_contact.materials import BRASS, STEEL
    from bem_contact.tangential import sphere_tangential_stiffness

    force = SPHERE_WEIGHT if normal_force is None else normal_force
    if not (math.isfinite(force) and force > 0):
        raise ContactInputError(f"--normal-force {force} must be a finite number of newtons > 0 (the weight: {SPHERE_WEIGHT:.4g})")
    grid = DEFAULT_TANGENTIAL_GRID if grid is None else grid
    if grid < 8:
        raise ContactInputError(f"--grid {grid}: need at least 8 elements across the domain")
    check = sphere_tangential_stiffness(force, SPHERE_RADIUS, BRASS, STEEL, grid=grid)
    return {"k_t": check.k_t, "k_t_mindlin": check.k_t_mindlin, "contact_radius": check.contact_radius,
            "normal_force": check.normal_force, "grid": check.grid, "k_t_paper": K_T_PAPER,
            "paper_over_mindlin": K_T_PAPER / check.k_t_mindlin,
            "normal_force_for_paper": force * (K_T_PAPER / check.k_t_mindlin) ** 3,
            "weight": SPHERE_WEIGHT, "R": SPHERE_RADIUS,
            "materials": {"wall": "steel, E = 207 GPa, nu = 0.3", "sphere": "brass, E = 102 GPa, nu = 0.3"},
            "units": {"k_t": "N/m", "k_t_mindlin": "N/m (8 G* a)", "k_t_paper": "N/m", "contact_radius": "m",
                      "normal_force": "N", "normal_force_for_paper": "N", "weight": "N (m_a g)", "R": "m"}}


def calibrate_default() -> dict[str, Any]:
    """`ies calibrate --json` with every default (the shipped paper-like crater, Sect. 4.1), in process: the
    JSON object as plain data (SI units; k_H in N/m^1.5). Raises the stages' errors as `ies calibrate` does."""
    from sim.common.files import to_jsonable

    return to_jsonable(summary(*calibrate(CalibrationSettings())))
