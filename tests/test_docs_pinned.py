"""The documentation that names the commands and the issue tracker is pinned to the code:

* every `ies` command (the parser the front door builds from each stage's command table) is in the README's pipeline
  section and in the docstring of its stage's package and command module;
* no package carries an issue number (history lives in git and the tracker, not in the code's text).
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STAGES = ("bem_contact", "scans", "sim", "uq")


def stage_commands() -> dict[str, list[str]]:
    """Stage -> the names of the commands its command module registers (the front door's dispatch table)."""
    import argparse

    from uq.cli import STAGES as DISPATCH

    out = {}
    for module, handed in DISPATCH:
        sub = argparse.ArgumentParser().add_subparsers()
        module.add_commands(sub, **handed)
        out[module.__name__.split(".")[0]] = list(sub.choices)
    return out


def docstring(path: Path) -> str:
    return ast.get_docstring(ast.parse(path.read_text())) or ""


def test_every_command_is_in_the_front_doors_parser():
    from uq.cli import build_parser

    parser = build_parser()
    registered = next(a for a in parser._actions if a.dest == "command").choices
    assert set(registered) == {name for names in stage_commands().values() for name in names}


def test_the_readme_pipeline_names_every_command():
    text = (ROOT / "README.md").read_text()
    pipeline = text[text.index("## The pipeline"):text.index("## The commands")]
    missing = [name for names in stage_commands().values() for name in names if f"ies {name}" not in pipeline
               and not re.search(rf"`ies [^`]*\b{re.escape(name)}\b", pipeline)]
    assert not missing, f"README's pipeline section does not name: {missing}"


@pytest.mark.parametrize("stage, files", [
    ("bem_contact", ("bem_contact/__init__.py", "bem_contact/cli.py")),
    ("sim", ("sim/__init__.py", "sim/cli.py")),
    ("uq", ("uq/__init__.py", "uq/commands/__init__.py", "uq/cli.py")),
])
def test_package_docstrings_name_their_commands(stage, files):
    for file in files:
        text = docstring(ROOT / file)
        missing = [name for name in stage_commands()[stage] if not re.search(rf"(?<![\w-]){re.escape(name)}(?![\w-])", text)]
        assert not missing, f"{file}'s docstring does not name {missing}"


def test_no_issue_numbers_in_the_packages():
    pattern = re.compile(r"\bissues? \d+|\(issue\b|\bissue \"", re.IGNORECASE)
    found = [f"{path.relative_to(ROOT)}:{i}" for stage in STAGES for path in sorted((ROOT / stage).rglob("*.py"))
             for i, line in enumerate(path.read_text().splitlines(), 1) if pattern.search(line)]
    assert not found, f"issue numbers in the code's text: {found}"


def test_the_checks_can_fail():
    assert re.search(r"\bissues? \d+|\(issue\b", "see (issue 28)")
    assert not re.search(rf"(?<![\w-]){re.escape('fit')}(?![\w-])", "modal-fit")
