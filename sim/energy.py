"""Mechanical energy of the coupled system (Sect. 5.5) for energy-balance checks.

Without base excitation the relative coordinates of `sim.system` are absolute, and with no damping the
total energy

    E = sum_j (s_j'^2 + w_j^2 s_j^2) / 2  +  m_a u_a'^2 / 2  +  (2/5) k_H (<delta_l>^2.5 + <-delta_r>^2.5)

(modes with mass-normalised shapes, sphere, Hertz potential of Eq. 4) is conserved through impacts.
"""
from __future__ import annotations

import numpy as np

from sim.system import SystemArrays


def energy_parts(states: np.ndarray, sys: SystemArrays) -> dict[str, np.ndarray]:
    """Energies in J of each state row y = [s, s', u_a, u_a']: 'modes', 'sphere', 'contact' and 'total'."""
    y = np.atleast_2d(np.asarray(states, dtype=float))
    n = sys.omega.size
    s, v, u, w = y[:, :n], y[:, n:2 * n], y[:, 2 * n], y[:, 2 * n + 1]
    modes = 0.5 * np.sum(v**2 + (sys.omega * s) ** 2, axis=1)
    sphere = 0.5 * sys.m_a * w**2
    delta_l = s @ sys.phi_l - u - sys.g
    delta_r = s @ sys.phi_r - u + sys.g
    contact = 0.4 * sys.k_H * (np.clip(delta_l, 0.0, None) ** 2.5 + np.clip(-delta_r, 0.0, None) ** 2.5)
    return {"modes": modes, "sphere": sphere, "contact": contact, "total": modes + sphere + contact}
