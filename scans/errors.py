"""Errors raised while reading and preparing scans."""


class ScanError(ValueError):
    """A scan that cannot be used (missing, corrupt, implausible); the message says what to do."""
