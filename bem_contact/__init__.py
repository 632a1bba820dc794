"""Boundary-element contact of elastic half-spaces (seed paper, Sect. 4.1, Eq. 8, Fig. 3)."""
from bem_contact.errors import ContactInputError, ConvergenceError

__all__ = ["ContactInputError", "ConvergenceError"]
