"""Pictures of a scan calibration: the levelled crater and the force-indentation curve (Fig. 3b, 3c).

Built on `matplotlib.figure.Figure` (no pyplot, no GUI back end); save with `sim.common.files.save_figure`.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from scans.contact import ScanContact
from scans.metrics import CraterMetrics


def calibration_figure(
    contact: ScanContact,
    metrics: CraterMetrics,
    deltas: np.ndarray,
    forces: np.ndarray,
    k_H: float,
    k_H_star: float,
    title: str = "",
) -> Any:
    """Two panels: (a) levelled wall height (µm) with the sphere's axis and the BEM domain, as Fig. 3b;
    (b) force (N) against indentation (µm): BEM points, the fit k_H delta^1.5 and Eq. 8's flat wall
    k_H* delta^1.5, as Fig. 3c. deltas in m, forces in N, k_H and k_H_star in N/m^1.5.
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Rectangle

    surface = contact.surface
    fig = Figure(figsize=(11.5, 4.6), layout="constrained")
    ax_map, ax_curve = fig.subplots(1, 2)
    ny, nx = surface.overview.shape
    extent_mm = [1e3 * (surface.x0 - 0.5 * surface.pitch), 1e3 * (surface.x0 + (nx - 0.5) * surface.pitch),
                 1e3 * (surface.y0 - 0.5 * surface.pitch), 1e3 * (surface.y0 + (ny - 0.5) * surface.pitch)]
    heights = surface.overview * 1e6
    limit = float(np.nanmax(np.abs(heights))) or 1.0
    image = ax_map.imshow(heights, origin="lower", extent=extent_mm, cmap="RdBu_r", vmin=-limit, vmax=limit)
    fig.colorbar(image, ax=ax_map, label=r"levelled wall height ($\mu$m); crater < 0, rim > 0")
    cx, cy = (1e3 * c for c in contact.centre)
    half = 0.5e3 * contact.side
    ax_map.add_patch(Rectangle((cx - half, cy - half), 2 * half, 2 * half, fill=False, color="k", lw=1.0, ls="--",
                               label=f"BEM domain {contact.side * 1e3:.2f} mm"))
    if metrics.diameter > 0:
        ax_map.add_patch(Circle((cx, cy), 0.5e3 * metrics.diameter, fill=False, color="0.3", lw=0.8,
                                label=f"crater diameter {metrics.diameter * 1e3:.2f} mm"))
    ax_map.plot([cx], [cy], "k+", ms=10, label=f"sphere axis ({contact.placement})")
    ax_map.set_xlabel("x (mm)")
    ax_map.set_ylabel("y (mm)")
    ax_map.set_title(f"(a) {surface.source}\ndepth {metrics.depth * 1e6:.2f} $\\mu$m, rim {metrics.rim_height * 1e6:.2f} $\\mu$m",
                     fontsize=9)
    ax_map.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=8, frameon=False)  # off the map

    d_um = np.asarray(deltas) * 1e6
    fine = np.linspace(0.0, float(np.max(deltas)), 200)
    ax_curve.plot(d_um, np.asarray(forces), "o", ms=4, label="BEM, scanned wall")
    ax_curve.plot(fine * 1e6, k_H * fine**1.5, "-", label=f"fit: $k_H$ = {k_H / k_H_star:.3f} $k_H^*$")
    ax_curve.plot(fine * 1e6, k_H_star * fine**1.5, "--", color="0.4", label="flat wall, Eq. 8 ($k_H^*$)")
    ax_curve.set_xlabel(r"indentation ($\mu$m)")
    ax_curve.set_ylabel("normal force (N)")
    ax_curve.set_title("(b) " + contact.sphere.describe().replace(" with ", "\nwith "), fontsize=9)
    ax_curve.grid(alpha=0.3)
    ax_curve.legend(loc="upper left", fontsize=8)
    if title:
        fig.suptitle(title)
    return fig
