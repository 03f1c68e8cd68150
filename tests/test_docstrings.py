"""Every public function of core/, codecs/, io/ and geometry/ has numpydoc sections.

Parameters (when it takes any), Returns (when it returns something), Raises (when it raises
itself) and Examples with a doctest (run by ``--doctest-modules``). Public: a module-level
function whose name does not start with an underscore, in a module whose name does not.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src" / "bistair"
PACKAGES = ("core", "codecs", "io", "geometry")


def _public_functions() -> list[tuple[str, ast.FunctionDef]]:
    found = []
    for package in PACKAGES:
        for path in sorted((SRC / package).rglob("*.py")):
            if path.stem.startswith("_") and path.stem != "__init__":
                continue
            tree = ast.parse(path.read_text())
            for node in tree.body:
                if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
                    found.append((f"{path.relative_to(SRC)}:{node.name}", node))
    return found


FUNCTIONS = _public_functions()


def _raises(node: ast.FunctionDef) -> bool:
    """The function raises an exception itself (not in a nested function)."""
    stack = list(node.body)
    while stack:
        item = stack.pop()
        if isinstance(item, ast.Raise) and item.exc is not None:
            return True
        if not isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            stack.extend(ast.iter_child_nodes(item))
    return False


def missing_sections(node: ast.FunctionDef) -> list[str]:
    """The numpydoc sections a function's docstring lacks."""
    doc = ast.get_docstring(node) or ""
    args = [a for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs
            if a.arg not in ("self", "cls")]
    needed = []
    if args or node.args.vararg or node.args.kwarg:
        needed.append("Parameters")
    returns = node.returns is not None and ast.unparse(node.returns) not in ("None", "NoReturn")
    if returns:
        needed.append("Yields" if "Iterator" in ast.unparse(node.returns) else "Returns")
    if _raises(node):
        needed.append("Raises")
    needed.append("Examples")
    lacking = [name for name in needed if f"{name}\n{'-' * len(name)}" not in doc]
    if "Examples" not in lacking and ">>>" not in doc:
        lacking.append("Examples (a doctest)")
    return lacking


def test_there_are_public_functions_to_check() -> None:
    assert len(FUNCTIONS) > 100


@pytest.mark.parametrize("node", [n for _, n in FUNCTIONS], ids=[name for name, _ in FUNCTIONS])
def test_numpydoc_sections(node: ast.FunctionDef) -> None:
    assert not missing_sections(node)
