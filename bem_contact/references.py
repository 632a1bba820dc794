"""Independent references for the contact stage's tests and benchmarks (seed paper Sect. 4.1): closed-form
contact mechanics and plain quadrature, never our boundary-element code.

* `elliptical_hertz_force`: Hertz's elliptical contact of a gap x^2/(2 R1) + y^2/(2 R2) (Johnson 1985,
  Eqs. 4.39-4.41), through the complete elliptic integrals.
* `boussinesq_displacement`, `cerruti_displacements`: the half-space point-load solutions (Johnson 1985,
  Ch. 3) for the two bodies in contact, whose integrals over a rectangle are Love's and Cerruti's
  element coefficients (`bem_contact.influence`).
* `element_quadrature`: the integral of such a point-load solution over one square element by adaptive
  quadrature (scipy's QUADPACK), split at the singular point.

The hertz module (`bem_contact.hertz`) holds the circular Hertz and Mindlin formulas the library itself uses.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from bem_contact.materials import Material


def elliptical_hertz_force(delta: float, R1: float, R2: float, E_star: float) -> float:
    """Normal force (N) at indentation `delta` (m) of Hertz's elliptical contact of the gap
    x^2/(2 R1) + y^2/(2 R2) (R1 > R2, m) with contact modulus E* (Pa) (Johnson 1985, Eqs. 4.39-4.41)."""
    from scipy import optimize, special

    A, B = 1 / (2 * R1), 1 / (2 * R2)

    def ratio(m: float) -> float:  # B/A as a function of the eccentricity parameter m = e^2
        K, E = special.ellipk(m), special.ellipe(m)
        return (E / (1 - m) - K) / (K - E) - B / A

    m = optimize.brentq(ratio, 1e-12, 1 - 1e-12, xtol=1e-15)
    K, E = special.ellipk(m), special.ellipe(m)
    a = np.sqrt(delta * (K - E) / (K * m * A))
    b = a * np.sqrt(1 - m)
    p0 = delta * E_star / (K * b)
    return 2 / 3 * np.pi * a * b * p0


def boussinesq_displacement(x: float, y: float, E_star: float) -> float:
    """Normal approach (m) of two half-spaces at (x, y) (m) under a unit normal point load (N) at the origin:
    1/(pi E* r) (Boussinesq; Johnson 1985, Ch. 3; both bodies in E*, Pa)."""
    return 1.0 / (np.pi * E_star * np.hypot(x, y))


def cerruti_displacements(x: float, y: float, materials: Sequence[Material]) -> tuple[float, float, float]:
    """Relative tangential displacements (m) (u_xx, u_yy, u_xy) of the bodies `materials` at (x, y) (m) under a
    unit tangential point force (N) at the origin along x (u_xx, u_xy) or y (u_yy): per body
    (1/(2 pi G)) ((1 - nu)/r + nu x^2/r^3) and so on (Cerruti; Johnson 1985, Ch. 3), summed."""
    r = np.hypot(x, y)
    uxx = uyy = uxy = 0.0
    for m in materials:
        c = 1.0 / (2 * np.pi * m.G)
        uxx += c * ((1 - m.nu) / r + m.nu * x * x / r**3)
        uyy += c * ((1 - m.nu) / r + m.nu * y * y / r**3)
        uxy += c * m.nu * x * y / r**3
    return uxx, uyy, uxy


def element_quadrature(f: Callable[[float, float], float], X: float, Y: float, dx: float,
                       epsrel: float = 1e-11) -> float:
    """Integral of f(xi, eta) over the square element [X - dx/2, X + dx/2] x [Y - dx/2, Y + dx/2] (m), split at
    the singular point (0, 0) so that QUADPACK only ever meets it at a corner."""
    from scipy import integrate

    xs = sorted({X - dx / 2, X + dx / 2} | ({0.0} if abs(X) < dx / 2 else set()))
    ys = sorted({Y - dx / 2, Y + dx / 2} | ({0.0} if abs(Y) < dx / 2 else set()))
    total = 0.0
    for x0, x1 in zip(xs[:-1], xs[1:]):
        for y0, y1 in zip(ys[:-1], ys[1:]):
            value, _ = integrate.dblquad(lambda y, x: f(x, y), x0, x1, y0, y1, epsabs=0.0, epsrel=epsrel)
            total += value
    return total
