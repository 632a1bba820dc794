"""What every output file holds, in one shared format: a table of its columns (CSV) or keys (JSON), each with
its unit and meaning, kept beside the code that writes the file (e.g. `sim.stepped_sine.tables.SWEEP_CSV`).

The user's output reference (`uq/OUTPUTS.md`) is generated from these tables (`uq.output_reference`), and a
test regenerates it and fails when page and code drift. Units: "-" for a dimensionless number, "a/a_noabs*"
for an amplitude normalised by the linear resonant amplitude (Sect. 5), "a_base/a_base*" for an excitation
level (Sect. 5.3), SI units otherwise; "" where a column holds text.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Column:
    """One CSV column or JSON key: its name, unit (module docstring) and what it holds."""

    name: str
    unit: str
    meaning: str


@dataclass(frozen=True)
class OutputFile:
    """One output file: its name, the command that writes it, a note for the whole file, its columns or keys."""

    file: str
    written_by: str
    note: str
    columns: tuple[Column, ...]

    @property
    def names(self) -> tuple[str, ...]:
        """The column (key) names in their order."""
        return tuple(c.name for c in self.columns)


def describe(output: OutputFile) -> str:
    """The file as a Markdown section: a heading with its writer, its note and a table name | unit | meaning."""
    lines = [f"### `{output.file}` ({output.written_by})", ""]
    if output.note:
        lines += [output.note, ""]
    lines += ["| name | unit | meaning |", "| --- | --- | --- |"]
    lines += [f"| `{c.name}` | {c.unit} | {c.meaning} |" for c in output.columns]
    return "\n".join(lines)


def header(output: OutputFile, **expand: list[str] | tuple[str, ...]) -> list[str]:
    """The file's CSV header: its column names, each placeholder "<name>" replaced by the names `expand[name]`
    gives (e.g. the parameters of a study for "<parameters>")."""
    names: list[str] = []
    for name in output.names:
        if name.startswith("<") and name.endswith(">"):
            names.extend(expand[name[1:-1]])
        else:
            names.append(name)
    return names
