"""Subcommands of `ies`; every public module here is one subcommand (see `uq.cli`)."""
