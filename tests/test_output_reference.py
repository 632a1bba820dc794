"""The output reference uq/OUTPUTS.md is what `uq.output_reference` generates from the column tables beside the
writers, and those tables cover what the writers write."""
from __future__ import annotations

import dataclasses

import numpy as np

from sim.common.outputs import Column, OutputFile, describe, header
from uq.output_reference import PAGE, SECTIONS, render

UNITS = {"", "-", "m", "m/s", "m/s^2", "N", "W", "s", "Hz", "J", "SI", "a/a_noabs*", "a_base/a_base*", "(a/a_noabs*)^2",
         "-, s", "-, Hz, -, s", "-, , Hz", "a_base/a_base*, -", "kg", "N/m^1.5"}


def documented(output: OutputFile) -> set[str]:
    """Every name a table documents (a row may document several, "a, b")."""
    return {name.strip() for column in output.columns for name in column.name.split(",")}


def test_the_page_is_generated_from_the_code():
    assert PAGE.read_text() == render(), "uq/OUTPUTS.md is stale: run `python -m uq.output_reference`"


def test_every_table_has_units_and_meanings():
    for _, outputs in SECTIONS:
        for output in outputs:
            assert len(output.names) == len(set(output.names)), output.file
            for column in output.columns:
                assert column.unit in UNITS and column.meaning.strip(), (output.file, column)


def test_a_table_renders_as_markdown_and_expands_its_placeholders():
    table = OutputFile("x.csv", "ies x", "A note.", (Column("a", "m", "first"), Column("<p>", "", "the p's")))
    text = describe(table)
    assert text.splitlines()[0] == "### `x.csv` (ies x)" and "| `a` | m | first |" in text and "A note." in text
    assert header(table, p=["b", "c"]) == ["a", "b", "c"]


def test_the_scattering_columns_are_the_simulators_measures():
    from sim.stepped_sine.measures import SCATTERING_MEASURES
    from sim.stepped_sine.tables import OVERVIEW_COLUMNS, SCATTERING_COLUMNS, SWEEP_COLUMNS

    assert [c.replace("input_power_W", "input_power") for c in SCATTERING_COLUMNS] == list(SCATTERING_MEASURES)
    assert SWEEP_COLUMNS[-len(SCATTERING_COLUMNS):] == OVERVIEW_COLUMNS[-len(SCATTERING_COLUMNS):] == SCATTERING_COLUMNS


def test_sweep_json_documents_every_key_of_a_sweep_result():
    """SweepResult.to_dict's keys (and the keys `ies sweep` adds) are all in the sweep.json table."""
    from sim.stepped_sine.measures import SCATTERING_MEASURES
    from sim.stepped_sine.protocol import SteppedSine, SweepResult
    from sim.stepped_sine.tables import SWEEP_CSV, SWEEP_JSON

    values = {}
    for f in dataclasses.fields(SweepResult):
        if f.name == "protocol":
            values[f.name] = SteppedSine()
        elif f.name == "scattering":
            values[f.name] = {name: np.zeros(1) for name in SCATTERING_MEASURES}
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            values[f.name] = {"str": "APR", "list[str]": ["APR"], "float": 0.0, "int": 1}.get(str(f.type), np.zeros(1))
    keys = set(SweepResult(**values).to_dict())
    added_by_ies_sweep = {"seed", "reps", "model", "impactor", "D1"}
    names = documented(SWEEP_JSON) | set(SWEEP_CSV.names)  # sweep.json has the arrays of sweep.csv
    assert keys | added_by_ies_sweep <= names, (keys | added_by_ies_sweep) - names


def test_trace_json_and_csv_follow_the_writer():
    from sim.analysis.trace import COLUMNS, TRACE_CSV, TRACE_JSON, UNITS

    assert COLUMNS == TRACE_CSV.names and set(UNITS) == set(COLUMNS)
    assert {"fs", "impacts", "impacts_source", "columns", "units"} <= documented(TRACE_JSON)


def test_compare_and_band_tables_are_the_headers_written():
    from uq.outputs.compare import COMPARE_COLUMNS, PAPER_ROW
    from uq.methods import kinds

    assert set(PAPER_ROW) == set(COMPARE_COLUMNS)
    written = {t.file.file for methods in kinds().values() for m in methods for t in m.tables}
    assert {"points.csv", "bands.csv", "sobol.csv", "variance.csv", "surrogate.csv", "sweeps.csv"} <= written
