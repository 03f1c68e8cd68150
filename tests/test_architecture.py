"""The layering of ARCHITECTURE.md holds: imports point one way, no circles, no back-imports
of the package, no imports hidden in functions outside the command line. And its doors: no
``_name`` imported from another file, and a ``*_jit`` twin imported only by its face (see
:func:`twin_importers`), in every package but those listed in ``NOT_YET_HELD``."""

from __future__ import annotations

import ast
import io
import tokenize
import warnings
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


# Packages a door rule does not hold in yet: the rules it skips there, the date it was
# listed and the move that takes it off (issue 35: their private imports and twins are that
# move's). A package that breaks a rule no more is warned of: take it off.
NOT_YET_HELD: dict[str, tuple[tuple[str, ...], str, str]] = {}


def _in(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def _held(name: str, rule_name: str) -> bool:
    return not any(_in(name, p) and rule_name in rules
                   for p, (rules, _, _) in NOT_YET_HELD.items())


def _import_froms(path: Path, name: str, modules) -> list[tuple[str, ast.ImportFrom]]:
    """Each ``from bistair... import ...`` of a module (at any depth), with the module it
    names."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            if base.startswith("bistair"):
                out.append((base, node))
    return out


def private_imports(name: str, path: Path, modules) -> list[str]:
    """``module: name`` for each ``_name`` (not ``__dunder__``) the module imports from
    another bistair file."""
    return [f"{base}: {alias.name}" for base, node in _import_froms(path, name, modules)
            for alias in node.names
            if alias.name.startswith("_") and not alias.name.startswith("__")]


def twin_importers(name: str, path: Path, modules) -> list[str]:
    """The ``*_jit`` modules that ``name`` imports but may not. A twin ``P.X_jit`` may be
    imported by its face ``P.X``, by a module of ``P`` whose name starts with ``X``
    (``graycode_alone`` for ``graycode_jit``), by a face whose twin it is a part of
    (``regions`` for ``regions_labels_jit``) and by another twin."""
    own_package, _, own = name.rpartition(".")
    if path.name == "__init__.py":
        own_package, own = name, "__init__"
    if own.endswith("_jit"):
        return []
    wrong = []
    for base, node in _import_froms(path, name, modules):
        targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base
                   for a in node.names]
        for target in targets:
            package, _, twin = target.rpartition(".")
            if not twin.endswith("_jit"):
                continue
            concept = twin[:-len("_jit")]
            if package == own_package and (own.startswith(concept)
                                           or concept.startswith(own + "_")):
                continue
            wrong.append(target)
    return sorted(set(wrong))


def _offences(rule) -> dict[str, list[str]]:
    modules = _modules()
    found = {name: rule(name, path, modules) for name, path in sorted(modules.items())}
    return {name: hits for name, hits in found.items() if hits}


def _not_yet_held_report(rule_name: str, offences: dict[str, list[str]]) -> None:
    """Print the packages the rule does not hold in yet and what they still break; warn of
    one that breaks nothing (take it off ``NOT_YET_HELD``)."""
    for package, (rules, date, move) in NOT_YET_HELD.items():
        if rule_name not in rules:
            continue
        mine = {n: h for n, h in offences.items() if _in(n, package)}
        count = sum(len(h) for h in mine.values())
        print(f"{rule_name}: not yet held in {package} (listed {date}; {move}): {count} "
              f"in {len(mine)} files")
        if not mine:
            warnings.warn(f"{package} breaks no '{rule_name}' rule now: take it off "
                          "NOT_YET_HELD", stacklevel=2)


def test_no_private_name_is_imported_from_another_file():
    offences = _offences(private_imports)
    _not_yet_held_report("private imports", offences)
    assert not {n: h for n, h in offences.items() if _held(n, "private imports")}


def test_a_twin_is_imported_only_by_its_face():
    offences = _offences(twin_importers)
    _not_yet_held_report("twin imports", offences)
    assert not {n: h for n, h in offences.items() if _held(n, "twin imports")}


#: What a compiled twin may import besides other twins and core/jit.py: the install's
#: kernel build (app/kernels.py) imports the twins in an environment without scipy or
#: OpenCV, so a twin that imports a face (which does) fails to build its kernels.
TWIN_LIBRARIES = {"__future__", "math", "numpy", "numba", "typing", "dataclasses"}
#: The package's modules a twin may import besides twins (the standard library and NumPy
#: alone: the compile options and the memory the row bands fit in).
TWIN_HELPERS = {"bistair.core.jit", "bistair.core.memory"}


def twin_outside_imports(path: Path, root: Path = SRC) -> list[str]:
    """The imports of a ``*_jit.py`` module (of the package at ``root``) that are neither a
    twin, one of :data:`TWIN_HELPERS` nor one of :data:`TWIN_LIBRARIES`."""
    tree = ast.parse(path.read_text())
    package = path.relative_to(root.parent).with_suffix("").parts[:-1]
    found = []
    for node in tree.body:
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] not in TWIN_LIBRARIES]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                if (node.module or "").split(".")[0] not in TWIN_LIBRARIES:
                    found.append(node.module or "")
                continue
            base = list(package[:len(package) - node.level + 1])
            target = ".".join(base + (node.module or "").split("."))
            if not (target.endswith("_jit") or target in TWIN_HELPERS):
                found.append(target)
    return found


def test_a_twin_imports_only_twins_and_numerical_libraries(tmp_path):
    offences = {str(p.relative_to(SRC)): twin_outside_imports(p) for p in SRC.rglob("*_jit.py")}
    assert len(offences) > 20
    assert not {k: v for k, v in offences.items() if v}
    planted = tmp_path / "bistair" / "geometry" / "planted_jit.py"
    planted.parent.mkdir(parents=True)
    planted.write_text("import numpy as np\nfrom .stereo import rectify\n"
                       "from .stereo_jit import resample_wrapped\nimport cv2\n")
    assert twin_outside_imports(planted, tmp_path / "bistair") == [
        "bistair.geometry.stereo", "cv2"]


def test_the_door_rules_catch_planted_violations(tmp_path):
    pkg = tmp_path / "bistair" / "core"
    pkg.mkdir(parents=True)
    files = {"phase.py": "from .phase_jit import arctan2_32\n",
             "phase_jit.py": "from .jit import _numba_inline, inline\n",
             "jit.py": "", "measure.py": "from .phase_jit import shift_weights\n",
             "regions.py": "from .regions_labels_jit import relabel\n",
             "regions_labels_jit.py": "from .regions_jit import TILE\n", "regions_jit.py": "",
             "stair.py": "from . import stair_jit\nfrom .phase import _octant, TWO_PI as _P\n",
             "stair_jit.py": ""}
    modules = {}
    for file, text in files.items():
        (pkg / file).write_text(text)
        modules[f"bistair.core.{file[:-3]}"] = pkg / file
    private = {n: private_imports(n, p, modules) for n, p in modules.items()}
    twins = {n: twin_importers(n, p, modules) for n, p in modules.items()}
    assert {n: h for n, h in private.items() if h} == {
        "bistair.core.phase_jit": ["bistair.core.jit: _numba_inline"],
        "bistair.core.stair": ["bistair.core.phase: _octant"]}
    assert {n: h for n, h in twins.items() if h} == {
        "bistair.core.measure": ["bistair.core.phase_jit"]}


def _private_imports(path: Path, modules: dict[str, Path], name: str) -> list[str]:
    """``module._name`` for every name with a leading underscore that the file imports from
    another bistair module (at the top or in a function)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.ImportFrom):
            continue
        base = node.module or ""
        if node.level:
            parts = package.split(".")
            base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
        if not base.startswith("bistair"):
            continue
        found += [f"{base}.{a.name}" for a in node.names
                  if a.name.startswith("_") and a.name != "__future__"
                  and f"{base}.{a.name}" not in modules]  # a module of its own is no name
    return found


def test_app_imports_no_private_name_from_another_file():
    """A name with a leading underscore stays in its file (issue 35): what another file of
    app/ needs is public there."""
    modules = _modules()
    found = {name: _private_imports(path, modules, name) for name, path in modules.items()
             if name.startswith("bistair.app.")}
    assert not {name: names for name, names in found.items() if names}


def test_each_command_module_has_its_job_module(graph):
    """``ls app/cli/`` and ``ls app/`` show the commands and their jobs under the same names:
    app/cli/NAME.py holds the commands of app/NAME.py and imports that job module (when a
    command runs), and the group itself imports no job (``bistair --help`` stays fast)."""
    commands = sorted(p.stem for p in (SRC / "app" / "cli").glob("*.py")
                      if p.stem not in ("__init__", "options"))
    assert len(commands) >= 9
    missing = [name for name in commands if not (SRC / "app" / f"{name}.py").is_file()]
    assert not missing
    unused = [name for name in commands
              if not any(d == f"bistair.app.{name}" or d.startswith(f"bistair.app.{name}.")
                         for d in graph[f"bistair.app.cli.{name}"][1])]
    assert not unused
    jobs_at_start = {name: sorted(d for d in top if d.startswith("bistair.app.")
                                  and not d.startswith("bistair.app.cli"))
                     for name, (top, _) in graph.items() if name.startswith("bistair.app.cli")}
    assert not {name: deps for name, deps in jobs_at_start.items() if deps}


# app/ modules that are no command's job: what every job shares
APP_SHARED = {"engine", "progress", "kernels"}
# ... and the old module names issue 35 moved, kept one release as aliases (2026-11-28)
APP_ALIASES = {"jobs", "stream", "series"}


def test_every_job_module_is_a_family_or_part_of_one():
    """``ls app/`` lists the jobs: each module is NAME.py of a command module app/cli/NAME.py,
    or a part of that family, NAME_PART.py (decode_stream.py: ``decode --window``), or one of
    the modules every job shares."""
    families = {p.stem for p in (SRC / "app" / "cli").glob("*.py")} - {"__init__", "options"}
    strays = [p.name for p in (SRC / "app").glob("*.py")
              if p.stem not in families | APP_SHARED | APP_ALIASES | {"__init__"}
              and not any(p.stem.startswith(f"{family}_") for family in families)]
    assert not strays


#: Issue 35: a module short enough to read whole.
MOST_LINES_OF_CODE = 450


def lines_of_code(text: str) -> int:
    """Lines holding code: not blank, not a comment, not a docstring.

    >>> lines_of_code(chr(10).join(['"Module doc."', '', '# a note', 'x = 1', 'def f():',
    ...                              '    "Doc."', '    return x']))
    3
    """
    tree = ast.parse(text)
    docs: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            body = node.body
            if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)):
                docs.update(range(body[0].lineno, (body[0].end_lineno or body[0].lineno) + 1))
    code: set[int] = set()
    skip = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT,
            tokenize.ENDMARKER)
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type not in skip:
            code.update(n for n in range(tok.start[0], tok.end[0] + 1) if n not in docs)
    return len(code)


def test_no_module_is_over_450_lines_of_code():
    """Files short enough to read whole (issue 35): split a longer module by concept."""
    long = {str(p.relative_to(SRC)): n for p in SRC.rglob("*.py")
            if (n := lines_of_code(p.read_text())) > MOST_LINES_OF_CODE}
    assert not long


def test_the_old_app_module_names_read_on():
    """Issue 35 moved app/'s jobs by command; the old module names stay one release, each
    name the same object as in its new home."""
    from bistair.app import calibrate, decode, decode_stream, jobs, patterns, scan_series, series
    from bistair.app import stream as old_stream

    assert jobs.decode_folder is decode.decode_folder
    assert jobs.save_patterns is patterns.save_patterns
    assert jobs.import_projection_matrices is calibrate.import_projection_matrices
    assert old_stream.decode_stream is decode_stream.decode_stream
    assert series.scan_series is scan_series.scan_series
    assert set(jobs.__all__) == {
        "save_patterns", "save_ramp", "measure_gamma", "read_gamma", "decode_folder",
        "require_valid", "height_folder", "reconstruct_folder", "import_calibration",
        "import_projection_matrices", "parse_size", "parse_keys", "parse_depth_range"}
