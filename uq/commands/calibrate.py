"""`ies calibrate`: the Hertzian spring constant k_H from a boundary-element force-indentation curve
(seed paper, Sect. 4.1, Eq. 8, Fig. 3c).

`ies calibrate --flat` presses the ideal sphere (R = 7.92 mm, brass) on the flat steel wall (Table 1),
computes the force at 20 indentations from 2 to 40 um, fits f = k_H delta^1.5 and compares with k_H*
of Eq. 8; the error bar comes from repeating the curve on a grid half as fine. The library
(`bem_contact.calibration.calibrate_k_H`) does the work; this module only chooses the gap map
(see `gap_source`), prints and plots.
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any, Callable

NAME = "calibrate"
HELP = "calibrate the Hertzian spring constant k_H by BEM contact (flat wall; Sect. 4.1, Eq. 8, Fig. 3c)"

SPHERE_RADIUS = 7.92e-3  # m, Sect. 2
DEFAULT_SIDE_MM = 2.5  # contact radius at 40 um is 0.56 mm: the domain holds it with room to spare


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from bem_contact.geometry import SHAPES
    from bem_contact.solvers import solver_names

    source = parser.add_argument_group("gap map (what is pressed on the wall)")
    source.add_argument("--flat", action="store_true", help="the ideal sphere on the flat wall (the default for now)")
    source.add_argument("--shape", choices=SHAPES, default="paraboloid",
                        help="sphere geometry on the flat wall: Hertz's paraboloid (default; Eq. 8 is exact for it) "
                             "or the exact spherical cap (k_H about 0.04 %% lower)")
    source.add_argument("--side-mm", type=float, default=DEFAULT_SIDE_MM, metavar="MM",
                        help=f"side of the square contact domain in mm (default {DEFAULT_SIDE_MM})")
    numerics = parser.add_argument_group("numerics")
    numerics.add_argument("--grid", type=int, default=256, metavar="N",
                          help="elements across the domain (default 256); the error bar uses N/2")
    numerics.add_argument("--solver", choices=solver_names(), default="auto",
                          help="contact solver (default auto = pk, Polonsky-Keer CG on the FFT operator; "
                               "al-jacobi, osqp, cvxpy are dense, for small grids)")
    numerics.add_argument("--delta-min-um", type=float, default=2.0, metavar="UM", help="smallest indentation in um (default 2)")
    numerics.add_argument("--delta-max-um", type=float, default=40.0, metavar="UM",
                          help="largest indentation in um (default 40, the largest in the paper's simulations)")
    numerics.add_argument("--points", type=int, default=20, help="indentations on the curve (default 20)")
    output = parser.add_argument_group("output")
    output.add_argument("--json", action="store_true", help="print one JSON object (SI units, k_H in N/m^1.5)")
    output.add_argument("--plot", metavar="FILE", help="write the force-indentation plot (Fig. 3c style), e.g. k_H.png")


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

    if not args.side_mm > 0:
        raise ContactInputError(f"--side-mm {args.side_mm} must be > 0 (default {DEFAULT_SIDE_MM})")
    side = args.side_mm * 1e-3
    return GapSource(
        gap_at=lambda n: sphere_gap(n, side, SPHERE_RADIUS, args.shape),
        label=f"flat wall, ideal sphere ({args.shape}) R = {SPHERE_RADIUS * 1e3:g} mm",
        facts={"geometry": "flat", "shape": args.shape, "R": SPHERE_RADIUS, "side": side},
    )


def gap_source(args: argparse.Namespace) -> GapSource:
    """Choose the gap map from the arguments. Scanned craters plug in here (a SCAN argument and its
    options); until then, with or without --flat, the flat wall is calibrated."""
    return flat_wall(args)


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
    result = calibrate_k_H(source.gap_at, args.grid, E_star, deltas, solver=args.solver, R=SPHERE_RADIUS)
    return result, source, E_star


def summary(result, source: GapSource, E_star: float) -> dict[str, Any]:
    """The JSON object of `ies calibrate --json` (SI units)."""
    data = result.summary()
    data.update(source.facts)
    data["E_star"] = E_star
    data["materials"] = {"wall": "steel, E = 207 GPa, nu = 0.3", "sphere": "brass, E = 102 GPa, nu = 0.3"}
    data["units"] = {"k_H": "N/m^1.5", "k_H_star": "N/m^1.5", "k_H_error": "N/m^1.5", "deltas": "m (from first touch)",
                     "forces": "N", "contact_areas": "m^2", "dx": "m", "side": "m", "R": "m", "E_star": "Pa",
                     "fit_residual": "1 (||f - k_H delta^1.5|| / ||f||)", "k_H_ratio": "1 (k_H / k_H*, Eq. 8)"}
    return data


def _text(data: dict[str, Any], label: str) -> str:
    to_mm = 1e3**1.5  # N/m^1.5 -> N/mm^1.5
    lines = [
        f"{label}, E* = {data['E_star'] / 1e9:.2f} GPa",
        f"grid {data['grid']}x{data['grid']} (dx = {data['dx'] * 1e6:.3g} um; error bar from {data['coarse_grid']}), "
        f"solver {data['solver']}, {len(data['deltas'])} indentations {data['deltas'][0] * 1e6:g}-{data['deltas'][-1] * 1e6:g} um",
        f"k_H      = {data['k_H'] / to_mm:.6g} N/mm^1.5  +- {data['k_H_error'] / to_mm:.2g} (numerical)",
        f"k_H*     = {data['k_H_star'] / to_mm:.6g} N/mm^1.5  (Eq. 8)",
        f"k_H/k_H* = {data['k_H_ratio']:.6f}  +- {data['k_H_error'] / data['k_H_star']:.1e}",
        f"fit residual ||f - k_H delta^1.5|| / ||f|| = {data['fit_residual']:.2e}",
    ]
    return "\n".join(lines)


def plot(data: dict[str, Any], label: str, path: str) -> None:
    """Force-indentation curve, the fit and Eq. 8 (Fig. 3c style), written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from uq.output import save_figure

    d = np.asarray(data["deltas"])
    fine = np.linspace(0.0, d[-1], 200)
    fig, ax = plt.subplots(figsize=(5.0, 3.8))
    ax.plot(d * 1e3, data["forces"], "o", ms=4, label="BEM")
    ax.plot(fine * 1e3, data["k_H"] * fine**1.5, "-", label=f"fit $k_H\\delta^{{1.5}}$, $k_H/k_H^*$ = {data['k_H_ratio']:.4f}")
    ax.plot(fine * 1e3, data["k_H_star"] * fine**1.5, "--", label="Hertz, Eq. 8")
    ax.set_xlabel("indentation $\\delta$ in mm")
    ax.set_ylabel("normal contact force $f_c$ in N")
    ax.set_title(label, fontsize=9)
    ax.legend()
    ax.grid(alpha=0.3)
    try:
        save_figure(fig, path)
    finally:
        plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from uq.output import dumps

    result, source, E_star = calibrate(args)
    data = summary(result, source, E_star)
    if args.plot:
        plot(data, source.label, args.plot)
    print(dumps(data) if args.json else _text(data, source.label))
    return 0
