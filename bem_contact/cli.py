"""The contact stage's word of the `ies` command line: `calibrate`, the Hertzian spring constant k_H from a
boundary-element force-indentation curve (seed paper, Sect. 4.1, Eq. 8, Fig. 3).

`ies calibrate [SCAN]` reads a scanned crater (or, with --imprint, its resin imprint, as in the paper),
levels it on the flat wall, places the sphere above the crater and calibrates k_H on the gap map
sphere - wall; it also reports the crater metrics and the clearance interval of Sect. 4.1. With no
SCAN it uses the shipped paper-like crater (`scans/data/paper_crater.ply`).
`ies calibrate --flat` presses the ideal sphere (R = 7.92 mm, brass) on the flat steel wall (Table 1).
`ies calibrate --tangential [--normal-force N]` gives instead the tangential stiffness k_t of the stuck sphere on
the flat (Appendix C, Cattaneo-Mindlin; default N = the sphere's weight m_a g) by BEM and Mindlin's 8 G* a,
beside the paper's 22 kN/mm and the normal force Mindlin's formula would need for it.
Both compute the force at 20 indentations from 2 to 40 um, fit f = k_H delta^1.5 and compare with k_H*
of Eq. 8; the error bar comes from repeating the curve on a grid half as fine. The indentation is
measured from the first touch; on a scan, from the first touch on the wall denoised by a second-order
Gaussian filter (--denoise, default 90 um; 0 = the raw scan, whose noise peaks bias k_H low; see
`scans.contact`). The libraries (`scans`, `bem_contact.calibration.calibrate_k_H`) do the work; this
module only chooses the gap map (see `gap_source`), prints and plots.

`add_commands(subparsers)` registers the command with the front door (`uq.cli`); `calibrate_default`
gives `ies reproduce` the calibration in process. The scans stage is imported here because reading a scan
and pressing on it is the pipeline's arrow scans -> bem_contact. Heavy imports stay inside the functions,
so that `ies --help` stays fast.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from typing import Any, Callable

from sim.options import figure_file

HELP = "calibrate the Hertzian spring constant k_H by BEM contact on a scanned crater or the flat wall (Sect. 4.1, Eq. 8, Fig. 3)"

SPHERE_RADIUS = 7.92e-3  # m, Sect. 2
SPHERE_WEIGHT = 0.0177 * 9.81  # N, m_a g: the normal load of Appendix C
K_T_PAPER = 22e6  # N/m, Appendix C: "stiffness 22 kN/mm"
DEFAULT_GRID = 256
DEFAULT_TANGENTIAL_GRID = 96  # BEM k_t within 0.1 % of Mindlin's at the weight
DEFAULT_SIDE_MM = 2.5  # contact radius at 40 um is 0.56 mm: the domain holds it with room to spare
PAPER_FLATTENING_MM = 0.02  # Sect. 4.1: sphere diameter 15.80 mm in the flattened regions, 15.84 nominal
PAPER_CLEARANCE_MM = 0.58  # Sect. 4.1: (17 - 15.84) / 2
DEFAULT_DENOISE_UM = 90.0  # = scans.contact.DEFAULT_DENOISE (not imported here: `ies --help` stays light)
NOISY_RAW = 0.1e-6  # m: raw-scan noise beyond which k_H is biased by more than about half a percent


def add_commands(subparsers: Any) -> None:
    """Register `calibrate` on the front door's subparsers (argparse)."""
    parser = subparsers.add_parser("calibrate", help=HELP, description=HELP)
    add_arguments(parser)
    parser.set_defaults(_run=run)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of `ies calibrate`."""
    from bem_contact.geometry import SHAPES
    from bem_contact.solvers import solver_names

    source = parser.add_argument_group("gap map (what is pressed on the wall)")
    source.add_argument("scan", nargs="?", metavar="SCAN",
                        help="scanned wall or imprint: STL, PLY, OBJ, OFF mesh, XYZ/CSV points, NPY/NPZ height map "
                             "(default: the shipped paper-like crater)")
    source.add_argument("--flat", action="store_true", help="the ideal sphere on the flat wall instead of a scan")
    source.add_argument("--tangential", action="store_true",
                        help="the tangential stiffness k_t of the sphere stuck on the flat wall (Appendix C, "
                             "Cattaneo-Mindlin) instead of k_H: BEM and 8 G* a, beside the paper's 22 kN/mm")
    source.add_argument("--normal-force", dest="normal_force", type=float, default=None, metavar="N",
                        help=f"--tangential: normal load in N (default the sphere's weight m_a g = {SPHERE_WEIGHT:.4g} N)")
    source.add_argument("--shape", choices=SHAPES, default="paraboloid",
                        help="sphere geometry on the flat wall: Hertz's paraboloid (default; Eq. 8 is exact for it) "
                             "or the exact spherical cap (k_H about 0.04 %% lower)")
    source.add_argument("--side-mm", type=float, default=None, metavar="MM",
                        help=f"side of the square contact domain in mm (flat wall: default {DEFAULT_SIDE_MM}; "
                             "scan: default automatic, holding every point that can touch at the largest indentation)")
    scan = parser.add_argument_group("scan (Sect. 4.1)")
    scan.add_argument("--units", default="mm", metavar="UNIT", help="length unit of the scan file: m, cm, mm, um, in (default mm)")
    scan.add_argument("--imprint", action="store_true", help="the scan is a resin imprint (cast) of the crater: invert it")
    scan.add_argument("--pixel-size", type=float, default=None, metavar="SIZE",
                      help="pixel size of a bare .npy height map, in --units (.npz files carry their own)")
    scan.add_argument("--flattening", type=float, default=PAPER_FLATTENING_MM, metavar="MM",
                      help=f"sphere flattening per side in mm, added to the clearance bound (default {PAPER_FLATTENING_MM}, "
                           "15.84 -> 15.80 mm in the paper)")
    scan.add_argument("--sphere", choices=("ideal", "flattened"), default="ideal",
                      help="sphere in the BEM: ideal (default, as the paper's Fig. 3c) or flattened (cap of --flattening cut off)")
    scan.add_argument("--placement", choices=("centroid", "deepest"), default="centroid",
                      help="sphere axis above the crater's depth-weighted centroid (default) or its deepest point")
    scan.add_argument("--denoise", type=float, default=DEFAULT_DENOISE_UM, metavar="UM",
                      help=f"width (standard deviation, um) of the second-order Gaussian filter that removes scanner noise "
                           f"before the BEM and so fixes the indentation reference (first touch) on the crater, not on a "
                           f"noise peak; exact for quadratic surfaces (default {DEFAULT_DENOISE_UM:g}; 0 = the raw scan, "
                           "k_H low by about 6 %% per um of noise)")
    scan.add_argument("--smooth", type=float, default=0.0, metavar="UM",
                      help="extra plain Gaussian filter (standard deviation, um) of the wall; rounds the crater "
                           "(default 0: none)")
    scan.add_argument("--clearance", type=float, default=PAPER_CLEARANCE_MM, metavar="MM",
                      help=f"nominal clearance in mm (default {PAPER_CLEARANCE_MM} = (17 - 15.84) / 2)")
    numerics = parser.add_argument_group("numerics")
    numerics.add_argument("--grid", type=int, default=None, metavar="N",
                          help=f"elements across the domain (default {DEFAULT_GRID}; the error bar uses N/2; "
                               f"--tangential: {DEFAULT_TANGENTIAL_GRID} across 4 contact radii)")
    numerics.add_argument("--solver", choices=solver_names(), default="auto",
                          help="contact solver (default auto = pk, Polonsky-Keer CG on the FFT operator; "
                               "al-jacobi, osqp, cvxpy are dense, for small grids)")
    numerics.add_argument("--delta-min-um", type=float, default=2.0, metavar="UM", help="smallest indentation in um (default 2)")
    numerics.add_argument("--delta-max-um", type=float, default=40.0, metavar="UM",
                          help="largest indentation in um (default 40, the largest in the paper's simulations)")
    numerics.add_argument("--points", type=int, default=20, help="indentations on the curve (default 20)")
    output = parser.add_argument_group("output")
    output.add_argument("--json", action="store_true", help="print one JSON object (SI units, k_H in N/m^1.5)")
    output.add_argument("--plot", type=figure_file, metavar="FILE", help="write the force-indentation plot (Fig. 3c style; for a scan beside the levelled crater map, Fig. 3b), e.g. k_H.png")


@dataclass(frozen=True)
class GapSource:
    """What is calibrated: gap_at(n) -> (gap map (m), dx (m)) on n elements across, a label and its facts."""

    gap_at: Callable[[int], Any]
    label: str
    facts: dict[str, Any]


def flat_wall(args: argparse.Namespace) -> GapSource:
    """The ideal sphere (Sect. 2: R = 7.92 mm) on the nominally flat cavity wall."""
    from bem_contact.errors import ContactInputError
    from bem_contact.geometry import sphere_gap

    side_mm = DEFAULT_SIDE_MM if args.side_mm is None else args.side_mm
    if not side_mm > 0:
        raise ContactInputError(f"--side-mm {side_mm} must be > 0 (default {DEFAULT_SIDE_MM})")
    side = side_mm * 1e-3
    return GapSource(
        gap_at=lambda n: sphere_gap(n, side, SPHERE_RADIUS, args.shape),
        label=f"flat wall, ideal sphere ({args.shape}) R = {SPHERE_RADIUS * 1e3:g} mm",
        facts={"geometry": "flat", "shape": args.shape, "R": SPHERE_RADIUS, "side": side,
               "indentation_reference": "first touch of the ideal sphere on the flat wall"},
    )


def scanned_wall(args: argparse.Namespace) -> GapSource:
    """The sphere above a scanned crater (Sect. 4.1, Fig. 3b): read, level, measure, place the sphere.

    Everything that can be wrong with the scan is checked here, before any BEM work or file output.
    """
    import math

    from scans import (PAPER_CRATER, ScanError, Sphere, clearance_bounds, crater_metrics, example_path,
                       level_scan, read_scan, scan_contact)

    for name in ("flattening", "clearance", "smooth", "denoise"):
        value = getattr(args, name)
        if not (math.isfinite(value) and value >= 0):
            raise ScanError(f"--{name} {value} must be a finite number >= 0")
    if args.pixel_size is not None and not (math.isfinite(args.pixel_size) and args.pixel_size > 0):
        raise ScanError(f"--pixel-size {args.pixel_size} must be > 0 (in --units)")
    path = args.scan if args.scan is not None else example_path("crater")
    scan = read_scan(path, units=args.units, pixel_size=args.pixel_size)
    surface = level_scan(scan, imprint=args.imprint)
    metrics = crater_metrics(surface)
    unit_warning = crater_units_check(metrics.diameter, metrics.depth, args.units, scan.source)
    flattening = args.flattening * 1e-3
    sphere = Sphere(SPHERE_RADIUS, flattening if args.sphere == "flattened" else 0.0)
    side = None if args.side_mm is None else args.side_mm * 1e-3
    contact = scan_contact(surface, sphere, placement=args.placement, delta_max=args.delta_max_um * 1e-6, side=side,
                           smoothing=args.smooth * 1e-6, denoise=args.denoise * 1e-6)
    clearance_min, clearance_max = clearance_bounds(metrics.depth, flattening, args.clearance * 1e-3)
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
        "clearance_nominal": args.clearance * 1e-3,
        "flattening": flattening,
        "clearance_min": clearance_min,
        "clearance_max": clearance_max,
        "warnings": list(metrics.warnings) + _noise_warnings(contact.denoise, metrics) + unit_warning,
    }
    if args.scan is None:
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


def gap_source(args: argparse.Namespace) -> GapSource:
    """Choose the gap map from the arguments: --flat, or a scan (SCAN, default the shipped crater)."""
    from scans import ScanError

    if args.flat:
        if args.scan is not None:
            raise ScanError("give either a SCAN file or --flat, not both")
        return flat_wall(args)
    return scanned_wall(args)


def calibrate(args: argparse.Namespace):
    """Run the calibration the arguments describe; returns (Calibration, GapSource, E* in Pa)."""
    import numpy as np

    from bem_contact.calibration import calibrate_k_H
    from bem_contact.errors import ContactInputError
    from bem_contact.materials import BRASS, STEEL, contact_modulus

    if args.points < 2:
        raise ContactInputError(f"--points {args.points}: need at least 2 indentations for a fit")
    if not 0 < args.delta_min_um < args.delta_max_um:
        raise ContactInputError(
            f"indentations must satisfy 0 < --delta-min-um < --delta-max-um (got {args.delta_min_um}, {args.delta_max_um})"
        )
    source = gap_source(args)
    E_star = contact_modulus(STEEL, BRASS)
    deltas = np.round(np.linspace(args.delta_min_um, args.delta_max_um, args.points) * 1e-6, 13)  # m, no float noise
    from tqdm import tqdm

    # progress on stderr for long runs (fine grids); silent when stderr is not a terminal
    with tqdm(total=2 * len(deltas), desc="contact solves", unit="solve", leave=False, disable=not sys.stderr.isatty()) as bar:
        grid = DEFAULT_GRID if args.grid is None else args.grid
        result = calibrate_k_H(source.gap_at, grid, E_star, deltas, solver=args.solver, R=SPHERE_RADIUS, on_solve=bar.update)
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


def _text(data: dict[str, Any], label: str) -> str:
    import math

    to_mm = 1e3**1.5  # N/m^1.5 -> N/mm^1.5
    lines = [
        f"{label}, E* = {data['E_star'] / 1e9:.2f} GPa",
        f"grid {data['grid']}x{data['grid']} (dx = {data['dx'] * 1e6:.3g} um; error bar from {data['coarse_grid']}), "
        f"solver {data['solver']}, {len(data['deltas'])} indentations {data['deltas'][0] * 1e6:g}-{data['deltas'][-1] * 1e6:g} um",
        f"k_H      = {data['k_H'] / to_mm:.6g} N/mm^1.5  +- {data['k_H_error'] / to_mm:.2g} (numerical)",
        f"k_H*     = {data['k_H_star'] / to_mm:.6g} N/mm^1.5  (Eq. 8)",
        f"k_H/k_H* = {data['k_H_ratio']:.6f}  +- {data['k_H_error'] / data['k_H_star']:.1e}",
        f"fit residual ||f - k_H delta^1.5|| / ||f|| = {data['fit_residual']:.2e}",
        f"indentation delta from the {data['indentation_reference']}",
    ]
    if data.get("geometry") == "scan":
        from scans.io import unit_scale

        um, unit = 1e6, unit_scale(data["units_in_file"])
        decimals = max(0, round(-math.log10(1e-6 / unit)))  # to the micrometre
        lines[:0] = [
            f"scan {data['scan']}: {data['scan_kind']}, {data['scan_points']} points, read in {data['units_in_file']}"
            + (", imprint inverted" if data["imprint"] else ""),
            f"levelled on the flat wall ({100 * data['flat_fraction']:.0f} % of the scan): tilt {data['wall_tilt_deg']:.2f} deg, "
            f"noise {data['noise'] * um:.3g} um, {data['spikes_removed']} spike(s) removed",
            f"crater: depth {data['crater_depth'] * um:.2f} um, rim {data['rim_height'] * um:.2f} um, "
            f"diameter {data['crater_diameter'] * 1e3:.3f} mm",
            f"sphere axis on the crater's {'deepest point' if data['placement'] == 'deepest' else 'depth-weighted centroid'}, through ("
            + ", ".join(f"{round(v / unit, decimals) + 0.0:.{decimals}f}" for v in data["sphere_axis_point"]) + f") {data['units_in_file']} in the scan's frame; "
            f"domain {data['side'] * 1e3:.3f} mm; holes: {data['holes'][str(data['grid'])]}",
        ]
        lines += [
            f"clearance: {data['clearance_min'] * 1e3:.3f} to {data['clearance_max'] * 1e3:.3f} mm "
            f"(nominal {data['clearance_nominal'] * 1e3:g} + crater {data['crater_depth'] * 1e3:.4f} "
            f"+ flattening {data['flattening'] * 1e3:g} mm, Sect. 4.1)",
        ]
        lines += [f"warning: {w}" for w in data["warnings"]]
    return "\n".join(lines)


def plot(data: dict[str, Any], label: str, path: str) -> None:
    """Force-indentation curve, the fit and Eq. 8 (Fig. 3c style), written atomically."""
    import numpy as np

    from sim.files import plot_to

    d = np.asarray(data["deltas"])
    fine = np.linspace(0.0, d[-1], 200)
    with plot_to(path, figsize=(5.0, 3.8)) as (fig, ax):
        ax.plot(d * 1e3, data["forces"], "o", ms=4, label="BEM")
        ax.plot(fine * 1e3, data["k_H"] * fine**1.5, "-", label=f"fit $k_H\\delta^{{1.5}}$, $k_H/k_H^*$ = {data['k_H_ratio']:.4f}")
        ax.plot(fine * 1e3, data["k_H_star"] * fine**1.5, "--", label="Hertz, Eq. 8")
        ax.set_xlabel("indentation $\\delta$ in mm")
        ax.set_ylabel("normal contact force $f_c$ in N")
        ax.set_title(label, fontsize=9)
        ax.legend()
        ax.grid(alpha=0.3)


def scan_plot(data: dict[str, Any], source: GapSource, path: str) -> None:
    """Levelled crater map beside the force-indentation curve, its fit and Eq. 8 (Fig. 3b, 3c), atomically."""
    from scans.figures import calibration_figure
    from sim.files import save_figure

    fig = calibration_figure(source.facts["_contact"], source.facts["_metrics"], data["deltas"], data["forces"],
                             data["k_H"], data["k_H_star"])
    save_figure(fig, path)


def tangential(args: argparse.Namespace) -> dict[str, Any]:
    """`ies calibrate --tangential`: k_t of the sphere stuck on the flat wall (Appendix C) by BEM and by Mindlin's
    8 G* a, the paper's value and the normal force (N) for which 8 G* a would equal it (k_t grows as N^(1/3)).
    Plain data in SI units (the JSON object)."""
    import math

    from bem_contact.errors import ContactInputError
    from bem_contact.materials import BRASS, STEEL
    from bem_contact.tangential import sphere_tangential_stiffness

    if args.scan is not None or args.plot:
        raise ContactInputError("--tangential is the ideal sphere on the flat wall: drop the SCAN file and --plot")
    force = SPHERE_WEIGHT if args.normal_force is None else args.normal_force
    if not (math.isfinite(force) and force > 0):
        raise ContactInputError(f"--normal-force {force} must be a finite number of newtons > 0 (the weight: {SPHERE_WEIGHT:.4g})")
    grid = DEFAULT_TANGENTIAL_GRID if args.grid is None else args.grid
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


def _tangential_text(data: dict[str, Any]) -> str:
    kn_mm = 1e-6  # N/m -> kN/mm
    return "\n".join([
        f"sphere R = {SPHERE_RADIUS * 1e3:g} mm (brass) stuck on the flat steel wall, normal force "
        f"{data['normal_force']:.4g} N ({data['normal_force'] / data['weight']:.3g} x the weight m_a g)",
        f"contact radius a = {data['contact_radius'] * 1e6:.2f} um (Hertz)",
        f"k_t = {data['k_t'] * kn_mm:.4g} kN/mm (BEM, grid {data['grid']})   "
        f"8 G* a = {data['k_t_mindlin'] * kn_mm:.4g} kN/mm (Mindlin)",
        f"paper (Appendix C): {data['k_t_paper'] * kn_mm:g} kN/mm = {data['paper_over_mindlin']:.3g} x Mindlin's; "
        f"8 G* a reaches it at a normal force of {data['normal_force_for_paper']:.4g} N "
        f"({data['normal_force_for_paper'] / data['weight']:.0f} x the weight)",
    ])


def run(args: argparse.Namespace) -> int:
    """`ies calibrate`: calibrate, print the summary (text or JSON), plot on request."""
    from pathlib import Path

    from sim.files import check_writable, dumps, report_written, write_or_fallback

    if args.normal_force is not None and not args.tangential:
        from bem_contact.errors import ContactInputError

        raise ContactInputError("--normal-force belongs to --tangential")
    if args.tangential:
        data = tangential(args)
        print(dumps(data) if args.json else _tangential_text(data))
        return 0
    if args.plot:
        check_writable(args.plot, "--plot")  # before the contact solves
    result, source, E_star = calibrate(args)
    data = summary(result, source, E_star)
    print(dumps(data) if args.json else _text(data, source.label), flush=True)  # first: a refused figure loses nothing
    if args.plot:
        target = Path(args.plot)

        def draw(folder: Path) -> None:
            path = target if folder == target.parent else folder / target.name
            if data.get("geometry") == "scan":
                scan_plot(data, source, path)
            else:
                plot(data, source.label, path)

        write_or_fallback(draw, target.parent, "calibrate")
    report_written([args.plot] if args.plot else [], json_mode=args.json)
    return 0


def calibrate_default() -> dict[str, Any]:
    """`ies calibrate --json` with every default (the shipped paper-like crater, Sect. 4.1), in process: the
    JSON object as plain data (SI units; k_H in N/m^1.5). Raises the stages' errors as `ies calibrate` does."""
    from sim.files import to_jsonable

    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return to_jsonable(summary(*calibrate(parser.parse_args([]))))
