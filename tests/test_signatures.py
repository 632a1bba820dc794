"""Small signatures (issue 27, item 5): no function outside the numba kernels takes more than 8 positional
parameters, and no call outside them passes more than 8 positional arguments (a `Study` or a `SobolResult` is
built from named fields); a longer list of values is a dataclass with named fields or keyword-only parameters.

Functions decorated with the project's numba `kernel` (`sim.integration.jit.kernel`) or numba's `njit`/`jit` are
kernels: their argument lists are checked by the kernels' own test. `self` and `cls` of methods are not counted.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("scans", "bem_contact", "sim", "uq", "tests")
MAX_POSITIONAL = 8
KERNEL_DECORATORS = {"kernel", "njit", "jit", "cached_njit"}


def _decorator_name(node: ast.expr) -> str:
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def is_kernel(func: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    """True for a function decorated with `kernel`, `njit` or `jit` (bare, called or as numba.ATTR)."""
    return any(_decorator_name(d) in KERNEL_DECORATORS for d in func.decorator_list)


def positional_count(func: ast.FunctionDef | ast.AsyncFunctionDef, in_class: bool) -> int:
    """Positional(-or-keyword) parameters, without a method's leading self / cls; *args counts as one."""
    params = [*func.args.posonlyargs, *func.args.args]
    if in_class and params and params[0].arg in ("self", "cls"):
        params = params[1:]
    return len(params) + (1 if func.args.vararg is not None else 0)


def long_signatures(tree: ast.AST, where: str) -> list[str]:
    """'FILE:LINE name (N positional)' for every non-kernel function of `tree` with more than MAX_POSITIONAL."""
    found: list[str] = []

    def visit(node: ast.AST, in_class: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = positional_count(child, in_class)
                if n > MAX_POSITIONAL and not is_kernel(child):
                    found.append(f"{where}:{child.lineno} {child.name} ({n} positional)")
                visit(child, False)
            elif isinstance(child, ast.ClassDef):
                visit(child, True)
            else:
                visit(child, in_class)

    visit(tree, False)
    return found


def long_calls(tree: ast.AST, where: str, kernels: set[str]) -> list[str]:
    """'FILE:LINE callee (N positional)' for every call with more than MAX_POSITIONAL positional arguments, outside
    kernels and not to a kernel (a name in `kernels`): a dataclass or function built from a row of bare values."""
    found: list[str] = []

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)) and is_kernel(child):
                continue
            if isinstance(child, ast.Call) and len(child.args) > MAX_POSITIONAL:
                callee = _decorator_name(child.func)
                if callee not in kernels:
                    found.append(f"{where}:{child.lineno} {callee} ({len(child.args)} positional)")
            visit(child)

    visit(tree)
    return found


def kernel_names(tree: ast.AST) -> set[str]:
    """Names of the kernels defined in `tree`."""
    return {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and is_kernel(n)}


def _sources() -> list[Path]:
    return sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py") if "__pycache__" not in p.parts)


def test_no_long_positional_signatures_outside_kernels() -> None:
    offenders = []
    for path in _sources():
        offenders += long_signatures(ast.parse(path.read_text(encoding="utf-8")), str(path.relative_to(ROOT)))
    assert not offenders, (f"functions with more than {MAX_POSITIONAL} positional parameters (make the rest "
                           "keyword-only after *, or pass a dataclass): " + "; ".join(offenders))


def test_no_long_positional_calls_outside_kernels() -> None:
    trees = {path: ast.parse(path.read_text(encoding="utf-8")) for path in _sources()}
    kernels = set().union(*(kernel_names(tree) for tree in trees.values()))
    offenders = []
    for path, tree in trees.items():
        offenders += long_calls(tree, str(path.relative_to(ROOT)), kernels)
    assert not offenders, (f"calls with more than {MAX_POSITIONAL} positional arguments (name them): "
                           + "; ".join(offenders))


@pytest.mark.parametrize("source, expected", [
    ("def f(a, b, c, d, e, f, g, h, i): pass", ["x.py:1 f (9 positional)"]),
    ("def f(a, b, c, d, e, f, g, h, *, i): pass", []),
    ("def f(a, b, c, d, e, f, g, h, *rest): pass", ["x.py:1 f (9 positional)"]),
    ("class C:\n    def m(self, a, b, c, d, e, f, g, h): pass", []),
    ("class C:\n    def m(self, a, b, c, d, e, f, g, h, i): pass", ["x.py:2 m (9 positional)"]),
    ("@kernel(inline='always')\ndef k(a, b, c, d, e, f, g, h, i): pass", []),
    ("@numba.njit\ndef k(a, b, c, d, e, f, g, h, i): pass", []),
    ("def outer():\n    def inner(a, b, c, d, e, f, g, h, i): pass", ["x.py:2 inner (9 positional)"]),
])
def test_the_check_finds_long_signatures(source: str, expected: list[str]) -> None:
    """The rule itself: keyword-only parameters are free, kernels are skipped, nested functions are seen."""
    assert long_signatures(ast.parse(source), "x.py") == expected


@pytest.mark.parametrize("source, expected", [
    ("Study(1, 2, 3, 4, 5, 6, 7, 8, 9)", ["x.py:1 Study (9 positional)"]),
    ("Study(1, 2, 3, 4, 5, 6, 7, 8, i=9)", []),
    ("k(1, 2, 3, 4, 5, 6, 7, 8, 9)", []),  # a kernel's arguments: checked by the kernels' test
    ("@kernel\ndef f():\n    g(1, 2, 3, 4, 5, 6, 7, 8, 9)", []),
])
def test_the_check_finds_long_calls(source: str, expected: list[str]) -> None:
    assert long_calls(ast.parse(source), "x.py", {"k"}) == expected
