"""Boundary-element contact of elastic half-spaces (seed paper, Sect. 4.1, Eq. 8, Fig. 3).

Public API:
  materials: Material, STEEL, BRASS (Table 1), contact_modulus (E*), tangential_modulus (G*), k_H_star (Eq. 8)
  geometry: sphere_gap (ideal sphere/paraboloid on a flat wall)
  influence: normal_operator (Love/Boussinesq), TangentialOperator (Cerruti), ConvolutionOperator
  solvers: solve_contact -> ContactResult, SOLVERS (by name)
  calibration: calibrate_k_H -> Calibration (force-indentation curve, k_H fit, error bar)
  tangential: tangential_stiffness (stuck contact, Cerruti) vs Mindlin k_t = 8 G* a
"""
from bem_contact.errors import ContactInputError, ConvergenceError
from bem_contact.geometry import sphere_gap
from bem_contact.hertz import hertz_force, hertz_pressure, hertz_radius, mindlin_tangential_stiffness
from bem_contact.influence import ConvolutionOperator, TangentialOperator, normal_operator
from bem_contact.materials import BRASS, STEEL, Material, contact_modulus, k_H_star, tangential_modulus
from bem_contact.solvers import SOLVERS, ContactResult, solve_contact

__all__ = [
    "BRASS", "STEEL", "SOLVERS", "ContactInputError", "ContactResult", "ConvergenceError", "ConvolutionOperator",
    "Material", "TangentialOperator", "contact_modulus", "hertz_force", "hertz_pressure", "hertz_radius",
    "k_H_star", "mindlin_tangential_stiffness", "normal_operator", "solve_contact", "sphere_gap", "tangential_modulus",
]
