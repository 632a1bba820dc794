"""Errors raised by studies and the command line."""


class StudyError(ValueError):
    """A study that cannot run as described (bad file, bounds, scheduler, output folder)."""


class ClusterUnavailable(RuntimeError):
    """A batch cluster gave no worker in time, or its workers keep dying (a resource failure: exit 3; the finished
    tasks are kept for --resume)."""
