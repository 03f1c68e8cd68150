"""The layering of ARCHITECTURE.md holds: imports point one way, no circles, no back-imports
of the package, no imports hidden in functions outside the command line."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "bistair"
LAYERS = {"errors": 0, "spec": 0, "hooks": 0, "core": 1, "codecs": 2, "io": 3, "geometry": 4,
          "sim": 5, "evaluation": 6, "acquire": 6.5, "app": 7}
# Commands import their jobs when they run (a fast --help and --version).
LAZY_OK = {"bistair.app.cli"}  # and every module under it


def _modules() -> dict[str, Path]:
    out = {}
    for path in SRC.rglob("*.py"):
        parts = ["bistair", *path.relative_to(SRC).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> tuple[set[str], set[str]]:
    """(module-level imports, function-level imports) of bistair modules."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top, local = set(), set()

    def resolve(node: ast.ImportFrom | ast.Import) -> list[str]:
        if isinstance(node, ast.Import):
            return [a.name for a in node.names if a.name.startswith("bistair")]
        base = node.module or ""
        if node.level:
            parts = package.split(".")
            parts = parts[:len(parts) - node.level + 1]
            base = ".".join(parts + ([base] if base else []))
        if not base.startswith("bistair"):
            return []
        found = []
        for alias in node.names:
            sub = f"{base}.{alias.name}"
            found.append(sub if sub in modules else base)
        return found

    for node in ast.walk(tree):
        if isinstance(node, ast.Import | ast.ImportFrom):
            parents = _parents(tree, node)
            if any(isinstance(p, ast.If) and "TYPE_CHECKING" in ast.unparse(p.test)
                   for p in parents):
                continue  # for annotations only, never imported at run time
            in_function = any(isinstance(p, ast.FunctionDef) for p in parents)
            (local if in_function else top).update(resolve(node))
    return top, local


def _parents(tree: ast.AST, target: ast.AST) -> list[ast.AST]:
    for node in ast.walk(tree):
        for child in ast.iter_child_nodes(node):
            if child is target:
                return [node, *_parents(tree, node)]
    return []


def _layer(name: str) -> int | None:
    parts = name.split(".")
    return LAYERS.get(parts[1]) if len(parts) > 1 else None


@pytest.fixture(scope="module")
def graph() -> dict[str, tuple[set[str], set[str]]]:
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def test_no_module_imports_the_package_back(graph):
    offenders = {name for name, (top, local) in graph.items()
                 if "bistair" in top | local and name not in ("bistair", "bistair.__main__")}
    assert not offenders


def test_imports_point_down_the_layers(graph):
    wrong = []
    for name, (top, _) in graph.items():
        own = _layer(name)
        for dep in top:
            if own is not None and _layer(dep) is not None and _layer(dep) > own:
                wrong.append(f"{name} -> {dep}")
    assert not wrong


def test_no_import_circles(graph):
    deps = {name: {d for d in top if d in graph and d != name} for name, (top, _) in graph.items()}
    state: dict[str, int] = {}
    cycles = []

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for dep in deps[node]:
            if state.get(dep) == 1:
                cycles.append(stack[stack.index(dep):] + [dep] if dep in stack else [node, dep])
            elif dep not in state:
                visit(dep, [*stack, dep])
        state[node] = 2

    for node in deps:
        if node not in state:
            visit(node, [node])
    assert not cycles


def test_no_imports_hidden_in_functions(graph):
    hidden = {name: sorted(local) for name, (_, local) in graph.items()
              if local and name not in LAZY_OK and not name.startswith("bistair.app.cli.")}
    assert not hidden
