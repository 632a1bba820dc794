"""Errors raised by the simulator."""


class SimulationInputError(ValueError):
    """A user mistake in model, parameters or protocol; the message says how to fix it."""


class SimulationDiverged(RuntimeError):
    """The time integration produced non-finite or exploding values."""
