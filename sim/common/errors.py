"""Errors raised by the simulator."""


class SimulationInputError(ValueError):
    """A user mistake in model, parameters or protocol; the message says how to fix it."""


class SimulationDiverged(RuntimeError):
    """The time integration produced non-finite or exploding values."""


class ResourceFailure(RuntimeError):
    """The machine cannot do what was asked: a read-only or full disk, too little memory. Exit code 3; the
    message says what was kept (or that nothing was computed) and how to go on."""
