"""The contact stage: boundary-element contact of elastic half-spaces and the calibration of the Hertzian
spring constant k_H (seed paper Sect. 4.1, Eq. 8, Fig. 3).

Pipeline: scan file -> scans -> height map -> **bem_contact** -> k_H -> uq (sim for writing files).
Its command `ies calibrate` lives in `bem_contact.cli`; independent references for tests in
`bem_contact.references`.

Public names, each imported from its module on first use, so that `import bem_contact.errors` (done by the
`ies` front door) stays light (importing all of them takes 0.5-0.7 s more):
  materials:   Material, STEEL, BRASS (Table 1), contact_modulus (E*), tangential_modulus (G*), k_H_star (Eq. 8)
  geometry:    sphere_gap (ideal sphere or paraboloid on a flat wall)
  hertz:       hertz_force, hertz_radius, hertz_pressure, mindlin_tangential_stiffness (analytic references)
  influence:   normal_operator (Love/Boussinesq), TangentialOperator (Cerruti), ConvolutionOperator
  solvers:     solve_contact -> ContactResult, SOLVERS (by name)
  calibration: calibrate_k_H -> Calibration (force-indentation curve, k_H fit, grid-refinement error bar)
  tangential:  tangential_stiffness (stuck contact, Cerruti), checked against Mindlin k_t = 8 G* a
"""
from __future__ import annotations

import importlib
from typing import Any

from bem_contact.errors import ContactInputError, ConvergenceError

_MODULE_OF = {
    "Material": "materials", "STEEL": "materials", "BRASS": "materials", "contact_modulus": "materials",
    "tangential_modulus": "materials", "k_H_star": "materials",
    "sphere_gap": "geometry",
    "hertz_force": "hertz", "hertz_radius": "hertz", "hertz_pressure": "hertz",
    "hertz_indentation_from_force": "hertz", "mindlin_tangential_stiffness": "hertz",
    "ConvolutionOperator": "influence", "TangentialOperator": "influence", "normal_operator": "influence",
    "solve_contact": "solvers", "ContactResult": "solvers", "SOLVERS": "solvers",
    "calibrate_k_H": "calibration", "Calibration": "calibration", "force_curve": "calibration", "fit_k_H": "calibration",
    "tangential_stiffness": "tangential", "sphere_tangential_stiffness": "tangential",
}
__all__ = ["ContactInputError", "ConvergenceError", *_MODULE_OF]


def __getattr__(name: str) -> Any:
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_MODULE_OF[name]}"), name)
