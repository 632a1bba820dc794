"""Errors raised by the contact solvers: user input versus numerical failure."""


class ContactInputError(ValueError):
    """A user mistake (bad material, gap map, grid, indentation); the message says how to fix it."""


class ConvergenceError(RuntimeError):
    """A contact solver stopped without meeting its tolerance; never returned as a silent answer."""
