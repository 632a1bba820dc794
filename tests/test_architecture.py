"""The pipeline's import rules, read from the source with `ast`:

* the stages import each other only along the pipeline: sim stands alone; scans may use sim (its file
  writer); bem_contact may use scans and sim; uq may use sim;
* the one exception is the `ies` front door, uq.cli, whose dispatch table imports every stage's commands
  and error classes;
* nothing imports uq apart from uq itself (sim and scans above all);
* the modules' top-level imports form no cycle.

Imports inside functions count for the rules (they run too); only top-level imports can make a cycle at
import time. `import a.b.c` also runs the packages a and a.b (their __init__), so it counts as importing them.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STAGES = ("bem_contact", "scans", "sim", "uq")
#: stage -> the other stages it may import
ALLOWED = {"sim": set(), "scans": {"sim"}, "bem_contact": {"scans", "sim"}, "uq": {"sim"}}
FRONT_DOOR = "uq.cli"


def project_modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the four stages (a package by its __init__.py)."""
    found = {}
    for stage in STAGES:
        for path in sorted((ROOT / stage).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imported_names(source: str, module: str, is_package: bool, *, top_level_only: bool) -> set[str]:
    """Dotted names a module's import statements name (each `from X import y` as X.y and X); relative imports
    resolved against `module`. With top_level_only, imports inside functions and lambdas are left out."""
    package = module if is_package else module.rpartition(".")[0]
    names: set[str] = set()

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inside = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if not (top_level_only and inside):
                if isinstance(child, ast.Import):
                    names.update(alias.name for alias in child.names)
                elif isinstance(child, ast.ImportFrom):
                    base = child.module or ""
                    if child.level:
                        anchor = package.split(".")[: len(package.split(".")) - child.level + 1]
                        base = ".".join([*anchor, *([base] if base else [])])
                    names.add(base)
                    names.update(f"{base}.{alias.name}" for alias in child.names)
            visit(child, inside)

    visit(ast.parse(source), False)
    return names


def resolve(names: set[str], modules: dict[str, Path]) -> set[str]:
    """The project modules that importing `names` runs: each name's module and its parent packages."""
    resolved = set()
    for name in names:
        parts = name.split(".")
        resolved.update(".".join(parts[:i]) for i in range(1, len(parts) + 1) if ".".join(parts[:i]) in modules)
    return resolved


def import_graph(modules: dict[str, Path], *, top_level_only: bool) -> dict[str, set[str]]:
    """Module -> the project modules it imports, leaving out itself and its own parent packages (Python has
    imported those before it, so they are no edge of a cycle)."""
    graph = {}
    for name, path in modules.items():
        names = imported_names(path.read_text(), name, path.name == "__init__.py", top_level_only=top_level_only)
        parents = {name.rsplit(".", i)[0] for i in range(name.count(".") + 1)}
        graph[name] = resolve(names, modules) - parents
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the directed graph as a list of nodes (first = last), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: finished
    path: list[str] = []

    def walk(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (cycle := walk(nxt)):
                return cycle
        state[node] = 2
        path.pop()
        return None

    for start in sorted(graph):
        if start not in state and (cycle := walk(start)):
            return cycle
    return None


@pytest.fixture(scope="module")
def modules() -> dict[str, Path]:
    return project_modules()


def test_stages_import_each_other_only_along_the_pipeline(modules):
    wrong = []
    for name, targets in import_graph(modules, top_level_only=False).items():
        stage = name.split(".")[0]
        allowed = set(STAGES) if name == FRONT_DOOR else ALLOWED[stage] | {stage}
        wrong += [f"{name} imports {t}" for t in sorted(targets) if t.split(".")[0] not in allowed]
    assert not wrong, "\n".join(wrong)


def test_the_front_door_is_the_one_uq_module_that_sees_the_contact_stages(modules):
    graph = import_graph(modules, top_level_only=False)
    reaching = sorted(name for name, targets in graph.items()
                      if name.startswith("uq") and {t.split(".")[0] for t in targets} & {"scans", "bem_contact"})
    assert reaching == [FRONT_DOOR]
    assert not [name for name, targets in graph.items()
                if not name.startswith("uq") and any(t.split(".")[0] == "uq" for t in targets)]


def test_no_import_cycles_at_module_level(modules):
    assert find_cycle(import_graph(modules, top_level_only=True)) is None


def test_the_walk_sees_every_kind_of_import():
    """The checks above can fail: imports in functions, relative and aliased imports are all seen."""
    source = ("import uq.cli as front\nfrom .common import files\nfrom ..scans import io\n"
              "def later():\n    from bem_contact.solvers import solve_contact\n")
    every = imported_names(source, "sim.cli", False, top_level_only=False)
    assert {"uq.cli", "sim.common.files", "scans.io", "bem_contact.solvers"} <= every
    top = imported_names(source, "sim.cli", False, top_level_only=True)
    assert "bem_contact.solvers" not in top and "uq.cli" in top
    modules = {"uq": ROOT, "uq.cli": ROOT, "sim": ROOT, "sim.common.files": ROOT}
    assert resolve({"uq.cli", "sim.common.files.write_text", "numpy"}, modules) == {"uq", "uq.cli", "sim", "sim.common.files"}
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


#: Inside `sim`, the simulator's parts as a pipeline: the shared layer; the coupled system and the paper's vocabulary;
#: the host models; the integrators; the stepped-sine protocol, its measures and the paper's landmarks; signal
#: analysis; the host as measured (hammer and shaker tests to its modes and damping interval); the reduced
#: (slow-flow) model; the periodic orbits of the full model (they start from the slow flow's); figures. A part may import the parts before it, none after it. `sim` itself (its lazy public names) and `sim.cli`
#: (the commands) may import every part.
SIM_PIPELINE = ("common", "model", "hosts", "integration", "stepped_sine", "analysis", "measured", "reduced", "orbits",
                "plots")
#: sub-package -> the sub-packages it may import (besides itself): those before it in SIM_PIPELINE
SIM_LAYERS: dict[str, set[str]] = {part: set(SIM_PIPELINE[:i]) for i, part in enumerate(SIM_PIPELINE)}
#: The written-down exceptions: (importing module, the part after it that it may also import), each with its reason
#: in a comment. None at present: `ies trace` hands its figure's drawing function to `sim.analysis.trace.write_trace`,
#: and the paper's Fig. 6 landmarks are measured in `sim.stepped_sine.landmarks`, not among the host models.
SIM_EXCEPTIONS: set[tuple[str, str]] = set()


def sim_part(module: str) -> str | None:
    """The sub-package of `sim` a module belongs to (None for `sim` itself and `sim.cli`)."""
    parts = module.split(".")
    return parts[1] if parts[0] == "sim" and len(parts) > 1 and parts[1] != "cli" else None


def test_sim_parts_import_each_other_only_as_written_down(modules):
    assert {sim_part(m) for m in modules if sim_part(m)} <= set(SIM_LAYERS), "a new part of sim: add it to SIM_LAYERS"
    wrong = []
    for name, targets in import_graph(modules, top_level_only=False).items():
        part = sim_part(name)
        if part is None:
            continue
        for target in sorted(targets):
            other = sim_part(target)
            if target.startswith("sim") and (other is None and target != "sim" or other and other != part
                                             and other not in SIM_LAYERS[part]) and (name, other) not in SIM_EXCEPTIONS:
                wrong.append(f"{name} imports {target}")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles_between_modules_even_inside_functions(modules):
    """Also the imports made inside functions: a cycle there is a tangle even when it cannot fail at import time."""
    graph = import_graph(modules, top_level_only=False)
    for name, part in SIM_EXCEPTIONS:
        graph[name] = {t for t in graph[name] if sim_part(t) != part}
    graph = {name: {t for t in targets if t not in ("sim", "uq")} for name, targets in graph.items()}
    assert find_cycle(graph) is None


#: Inside `uq`: part -> the parts it may import (besides itself and `uq.errors`, which every part may use). The
#: problem (study files, spaces, models, the method contract) imports no method, figure or engine; outputs (tables,
#: NetCDF, figures) read what a problem is; the methods are a problem's sampling and analysis and write outputs; the
#: engine runs a study with its method; the design runs its own search through the engine; the commands see all.
#: `uq` itself (its lazy public names), `uq.cli` (the front door) and `uq.output_reference` (the page generated from
#: every table) may import every part.
UQ_LAYERS: dict[str, set[str]] = {
    "problem": set(),
    "outputs": {"problem"},
    "methods": {"problem", "outputs"},
    "engine": {"problem", "methods", "outputs"},
    "design": {"problem", "outputs", "engine"},
    "commands": {"problem", "methods", "engine", "outputs", "design"},
}
#: the written-down exceptions: (importing module, the part it may also import) with the reason (none yet)
UQ_EXCEPTIONS: set[tuple[str, str]] = set()
UQ_SHARED = ("uq", "uq.errors")


def uq_part(module: str) -> str | None:
    """The sub-package of `uq` a module (or the sub-package itself) belongs to; None for `uq`'s own modules: cli,
    errors, output_reference."""
    parts = module.split(".")
    return parts[1] if parts[0] == "uq" and (len(parts) > 2 or len(parts) == 2 and parts[1] in UQ_LAYERS) else None


def test_uq_parts_import_each_other_only_as_written_down(modules):
    parts = {uq_part(m) for m in modules if uq_part(m)}
    assert parts <= set(UQ_LAYERS), f"a new part of uq: add it to UQ_LAYERS ({parts - set(UQ_LAYERS)})"
    wrong = []
    for name, targets in import_graph(modules, top_level_only=False).items():
        part = uq_part(name)
        if part is None:
            continue
        for target in sorted(targets):
            other = uq_part(target)
            if not target.startswith("uq") or target in UQ_SHARED or other == part:
                continue
            if (other is None or other not in UQ_LAYERS[part]) and (name, other) not in UQ_EXCEPTIONS:
                wrong.append(f"{name} imports {target}")
    assert not wrong, "\n".join(wrong)


def test_the_study_reader_imports_no_method_figure_or_engine(modules):
    """The reader of study files stays light: what it reads is declared by the methods handed to it."""
    graph = import_graph(modules, top_level_only=False)
    assert {t for t in graph["uq.problem.study"] if t.startswith("uq")} <= {"uq", "uq.errors", "uq.problem",
                                                                             "uq.problem.cluster_settings",
                                                                             "uq.problem.models", "uq.problem.space"}
