"""Fused element loops of the Polonsky-Keer iteration (numba): one pass over the grid per stage
instead of a dozen numpy temporaries. Arrays are 2-D float64, C-contiguous, of one shape."""
from __future__ import annotations

import numpy as np

from sim.common.kernel_cache import cached_njit


@cached_njit
def contact_mean(h: np.ndarray, u: np.ndarray, p: np.ndarray) -> float:
    """Mean of h + u over the loaded elements (the approach read off the solution, load control)."""
    total = 0.0
    count = 0
    for i in range(h.shape[0]):
        for j in range(h.shape[1]):
            if p[i, j] > 0.0:
                total += h[i, j] + u[i, j]
                count += 1
    return total / count if count else 0.0


@cached_njit
def gap_and_residual(h: np.ndarray, u: np.ndarray, p: np.ndarray, delta: float, kii: float, g: np.ndarray):
    """g = h + u - delta (written into g); returns (max |min(p kii, g)|, sum of g^2 over the contact)."""
    worst = 0.0
    G = 0.0
    for i in range(h.shape[0]):
        for j in range(h.shape[1]):
            gij = h[i, j] + u[i, j] - delta
            g[i, j] = gij
            m = min(p[i, j] * kii, gij)
            if abs(m) > worst:
                worst = abs(m)
            if p[i, j] > 0.0:
                G += gij * gij
    return worst, G


@cached_njit
def conjugate_direction(g: np.ndarray, p: np.ndarray, t: np.ndarray, beta: float) -> None:
    """t = g + beta t on the contact, 0 elsewhere (in place; beta = 0 restarts)."""
    for i in range(g.shape[0]):
        for j in range(g.shape[1]):
            t[i, j] = g[i, j] + beta * t[i, j] if p[i, j] > 0.0 else 0.0


@cached_njit
def step_sums(Kt: np.ndarray, t: np.ndarray, g: np.ndarray, p: np.ndarray):
    """Sums over the contact: (Kt.t, g.t, sum t, sum Kt, count)."""
    rt = 0.0
    gt = 0.0
    st = 0.0
    sk = 0.0
    count = 0
    for i in range(t.shape[0]):
        for j in range(t.shape[1]):
            if p[i, j] > 0.0:
                rt += Kt[i, j] * t[i, j]
                gt += g[i, j] * t[i, j]
                st += t[i, j]
                sk += Kt[i, j]
                count += 1
    return rt, gt, st, sk, count


@cached_njit
def update_pressure(p: np.ndarray, t: np.ndarray, g: np.ndarray, tau: float, tau_overlap: float):
    """p <- max(p - tau t, 0); elements that stay unloaded but penetrate (g < 0) get -tau_overlap g.

    Returns (number clipped, number newly loaded by overlap, sum p)."""
    clipped = 0
    overlap = 0
    total = 0.0
    for i in range(p.shape[0]):
        for j in range(p.shape[1]):
            value = p[i, j] - tau * t[i, j]
            if value < 0.0:
                value = 0.0
                clipped += 1
            if value == 0.0 and g[i, j] < 0.0:
                value = -tau_overlap * g[i, j]
                overlap += 1
            p[i, j] = value
            total += value
    return clipped, overlap, total


@cached_njit
def linear_update(u: np.ndarray, Kt: np.ndarray, tau: float, scale: float) -> None:
    """u <- scale (u - tau Kt), the exact displacement after a step without clipping."""
    for i in range(u.shape[0]):
        for j in range(u.shape[1]):
            u[i, j] = scale * (u[i, j] - tau * Kt[i, j])
