"""The seed paper's nominal values of the sphere and its contact (Table 1, Sects. 2, 4.1, Table 2).

Every other module takes them from here (`sim.model.system` re-exports them for its callers)."""
from __future__ import annotations

SPHERE_MASS = 0.0177  # kg, Table 1
CLEARANCE_NOMINAL = 0.58e-3  # m, Sect. 2
K_H_NOMINAL = 282e3 * 1e3**1.5  # N/m^1.5  (282e3 N/mm^1.5, Eq. 8)
D1_NOMINAL = 0.00085  # Table 2
