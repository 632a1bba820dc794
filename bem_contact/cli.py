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
`scans.contact`). The libraries do the work (`bem_contact.pipeline`: the gap map, the run, the JSON object;
`bem_contact.calibration.calibrate_k_H`: the fit); this module only reads the options, prints and plots.

`--json` prints one object in SI units (also `calibration.json` of `ies reproduce`): k_H, k_H_star (Eq. 8),
k_H_ratio, k_H_error (N/m^1.5, |k_H(N) - k_H(N/2)|), fit_residual, crater_depth, rim_height, crater_diameter,
clearance_min, clearance_max (m), grid, solver, sphere, placement, holes, holes_in_contact_zone (a warning when a
filled hole lies where the sphere touches, else null), warnings, the curve and its settings;
with --tangential k_t and k_t_mindlin (N/m), contact_radius (m), normal_force and normal_force_for_paper (N).

`add_commands(subparsers)` registers the command with the front door (`uq.cli`), which hands
`bem_contact.pipeline.calibrate_default` to `ies reproduce`. Heavy imports stay inside the functions, so that
`ies --help` stays fast.
"""
from __future__ import annotations

import argparse
import dataclasses
from typing import Any

from bem_contact.pipeline import (DEFAULT_DENOISE_UM, DEFAULT_GRID, DEFAULT_SIDE_MM, DEFAULT_TANGENTIAL_GRID,
                                  PAPER_CLEARANCE_MM, PAPER_FLATTENING_MM, SPHERE_RADIUS, SPHERE_WEIGHT,
                                  CalibrationSettings, GapSource, calibrate, summary,
                                  tangential)
from sim.common.options import figure_file

HELP = "calibrate the Hertzian spring constant k_H by BEM contact on a scanned crater or the flat wall (Sect. 4.1, Eq. 8, Fig. 3)"

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

    from sim.common.figure_style import legend_beside
    from sim.common.files import plot_to

    d = np.asarray(data["deltas"])
    fine = np.linspace(0.0, d[-1], 200)
    with plot_to(path, figsize=(7.5, 3.8)) as (fig, ax):
        ax.plot(d * 1e6, data["forces"], "o", ms=4, label="BEM")
        ax.plot(fine * 1e6, data["k_H"] * fine**1.5, "-", label=f"fit $k_H\\delta^{{1.5}}$, $k_H/k_H^*$ = {data['k_H_ratio']:.4f}")
        ax.plot(fine * 1e6, data["k_H_star"] * fine**1.5, "--", label="Hertz, Eq. 8 ($k_H^*$)")
        ax.set_xlabel("indentation $\\delta$ ($\\mu$m)")
        ax.set_ylabel("normal contact force $f_c$ (N)")
        ax.set_title(label, fontsize=9)
        ax.grid(alpha=0.3)
        legend_beside(ax)


def scan_plot(data: dict[str, Any], source: GapSource, path: str) -> None:
    """Levelled crater map beside the force-indentation curve, its fit and Eq. 8 (Fig. 3b, 3c), atomically."""
    from scans.figures import calibration_figure
    from sim.common.files import save_figure

    fig = calibration_figure(source.facts["_contact"], source.facts["_metrics"], data["deltas"], data["forces"],
                             data["k_H"], data["k_H_star"])
    save_figure(fig, path)


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


def settings_of(args: argparse.Namespace) -> CalibrationSettings:
    """The `bem_contact.pipeline.CalibrationSettings` of the command's options."""
    return CalibrationSettings(**{f.name: getattr(args, f.name) for f in dataclasses.fields(CalibrationSettings)})


def run(args: argparse.Namespace) -> int:
    """`ies calibrate`: calibrate, print the summary (text or JSON), plot on request."""
    from pathlib import Path

    from sim.common.files import check_writable, dumps, report_written, write_or_fallback

    if args.normal_force is not None and not args.tangential:
        from bem_contact.errors import ContactInputError

        raise ContactInputError("--normal-force belongs to --tangential")
    if args.tangential:
        if args.scan is not None or args.plot:
            from bem_contact.errors import ContactInputError

            raise ContactInputError("--tangential is the ideal sphere on the flat wall: drop the SCAN file and --plot")
        data = tangential(args.normal_force, args.grid)
        print(dumps(data) if args.json else _tangential_text(data))
        return 0
    if args.plot:
        check_writable(args.plot, "--plot")  # before the contact solves
    result, source, E_star = calibrate(settings_of(args))
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
