"""Small signatures for the numba kernels (issue 27, item 5): every function of `sim` decorated with the project's
`kernel` (`sim.integration.jit`) takes at most 8 arguments; larger sets travel as records or named tuples
(`sim.integration.flight`). Found by reading the sources (ast), so a new kernel is checked without being listed."""
import ast
from pathlib import Path

import sim

SIM_DIR = Path(sim.__file__).resolve().parent
MAX_ARGUMENTS = 8


def _is_kernel(decorator: ast.expr) -> bool:
    """`@kernel`, `@kernel(...)`, `@jit.kernel` or `@jit.kernel(...)`."""
    target = decorator.func if isinstance(decorator, ast.Call) else decorator
    return (isinstance(target, ast.Name) and target.id == "kernel") or (
        isinstance(target, ast.Attribute) and target.attr == "kernel")


def kernels(root: Path = SIM_DIR) -> list[tuple[str, int]]:
    """(file:function, number of arguments) of every kernel in the sources under root (`sim`)."""
    found = []
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and any(map(_is_kernel, node.decorator_list)):
                a = node.args
                count = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (
                    a.kwarg is not None)
                found.append((f"{path.relative_to(root)}:{node.name}", count))
    return found


def test_the_kernels_are_found():
    names = {name for name, _ in kernels()}
    # the integrators' kernels, among them the five that took 9-11 arguments
    for expected in ("integration/ode3.py:_stage", "integration/ode3.py:_friction_step", "integration/ode3.py:_bs_step",
                     "integration/dopri5.py:_stage", "integration/exact.py:_fly", "integration/exact.py:_advance",
                     "integration/collocation.py:contact", "integration/flight.py:closing_at"):
        assert expected in names
    assert len(names) > 60


def test_no_kernel_takes_more_than_eight_arguments():
    wide = [f"{name} takes {count}" for name, count in kernels() if count > MAX_ARGUMENTS]
    assert not wide, "pack arguments into records or named tuples:\n" + "\n".join(wide)


def test_the_search_sees_every_decorator_form_and_argument_kind(tmp_path):
    """The check itself, on a module of its own: kernels with 9 arguments (one keyword-only, one *args) are caught,
    a plain function is not a kernel."""
    (tmp_path / "wide.py").write_text(
        "@kernel(inline='always')\ndef wide(a, b, c, d, e, f, g, h, *, i):\n    return a\n\n\n"
        "@jit.kernel\ndef star(a, b, c, d, e, f, g, h, *rest):\n    return a\n\n\n"
        "def plain(a, b, c, d, e, f, g, h, i):\n    return a\n")
    assert kernels(tmp_path) == [("wide.py:wide", 9), ("wide.py:star", 9)]
