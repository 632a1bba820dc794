"""Errors raised by studies and the command line."""


class StudyError(ValueError):
    """A study that cannot run as described (bad file, bounds, scheduler, output folder)."""
