"""The checks guide's table and the code stay in step (issue 35): every method of
:class:`bistair.core.checks.Judge` and every ``refuse(...)`` site of the codecs has a row in
``docs/guide/checks.md``'s table, found by the code-formatted key in its first cell, and a
row without a site fails as a site without a row does; the Judge's rows come in the order a
decode runs them; the guide stays in short pieces (no paragraph over 150 words, one short
line per cell of the table)."""

from __future__ import annotations

import ast
import re
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "bistair"
GUIDE = ROOT / "docs" / "guide" / "checks.md"
TABLE = "## The checks, in order"
LONGEST_PARAGRAPH = 150  # words
LONGEST_CELL = 25  # words


def table_rows(text: str) -> list[list[str]]:
    """The cells of each row of the table under ``TABLE`` (the header and rule left out)."""
    assert TABLE + "\n" in text, f"the checks guide has no section {TABLE!r}"
    section = text.split(TABLE + "\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("|")]
    return [[c.strip() for c in row.strip("|").split("|")] for row in rows[2:]]


def row_keys(text: str) -> list[str]:
    keys = []
    for cells in table_rows(text):
        found = re.fullmatch(r"`([\w.]+)`", cells[0])
        assert found, f"a row of the checks table without a key in its first cell: {cells}"
        keys.append(found.group(1))
    return keys


def _judge() -> ast.ClassDef:
    tree = ast.parse((SRC / "core" / "checks.py").read_text())
    return next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Judge")


def judge_methods() -> list[str]:
    """The Judge's public methods (not its properties), in the order they are defined."""
    return [f.name for f in _judge().body if isinstance(f, ast.FunctionDef)
            and not f.name.startswith("_")
            and not any(ast.unparse(d) == "property" for d in f.decorator_list)]


def _calls_refuse(node: ast.AST) -> int:
    return sum(isinstance(n, ast.Call) and (
        isinstance(n.func, ast.Name) and n.func.id == "refuse"
        or isinstance(n.func, ast.Attribute) and n.func.attr == "refuse")
        for n in ast.walk(node))


def refuse_sites() -> list[str]:
    """``module.function`` of every ``refuse(...)`` call outside core/checks.py (the codecs'
    own checks), once per call; a codec module is named without ``codecs.``."""
    sites = []
    for path in sorted(SRC.rglob("*.py")):
        if path == SRC / "core" / "checks.py":
            continue
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        parts = [p for p in parts if p != "__init__"]
        if parts[:1] == ["codecs"]:
            parts = parts[1:]
        for node in ast.parse(path.read_text()).body:
            inner = node.body if isinstance(node, ast.ClassDef) else [node]
            for func in inner:
                if isinstance(func, ast.FunctionDef | ast.AsyncFunctionDef):
                    name = (f"{node.name}.{func.name}" if isinstance(node, ast.ClassDef)
                            else func.name)
                    sites += [".".join([*parts, name])] * _calls_refuse(func)
    return sites


def test_every_check_has_a_row_and_every_row_a_check():
    rows = Counter(row_keys(GUIDE.read_text()))
    sites = Counter([f"Judge.{m}" for m in judge_methods()] + refuse_sites())
    assert rows == sites, (f"sites without a row: {dict(sites - rows)}; "
                           f"rows without a site: {dict(rows - sites)}")


def test_the_judges_rows_follow_a_decode():
    """The Judge's rows in the table, its methods as defined and the calls of a decode
    (its ``__call__`` on pass 0's sample, then ``Codec._decode``) run in one order."""
    keys = [k.split(".", 1)[1] for k in row_keys(GUIDE.read_text()) if k.startswith("Judge.")]
    assert keys == judge_methods()
    call = next(f for f in _judge().body if isinstance(f, ast.FunctionDef)
                and f.name == "__call__")
    on_sample = [n.func.attr for n in ast.walk(call) if isinstance(n, ast.Call)
                 and isinstance(n.func, ast.Attribute) and ast.unparse(n.func.value) == "self"]
    base = ast.parse((SRC / "codecs" / "base.py").read_text())
    decode = next(n for n in ast.walk(base) if isinstance(n, ast.FunctionDef)
                  and n.name == "_decode")
    calls = sorted((n.lineno, n.col_offset, n.func.attr) for n in ast.walk(decode)
                   if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
                   and ast.unparse(n.func.value) == "judge")
    assert "sample_checks(judge)" in ast.unparse(decode)
    assert on_sample + [name for *_, name in calls] == keys


def _paragraphs(text: str) -> list[str]:
    """Prose paragraphs and list items (tables, code and headings left out)."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    pieces = []
    for block in re.split(r"\n\s*\n", text):
        lines = [ln for ln in block.splitlines()
                 if not ln.lstrip().startswith(("|", "#"))]
        items = re.split(r"\n(?=\s*(?:[-*]|\d+\.) )", "\n".join(lines))
        pieces += [item for item in items if item.strip()]
    return pieces


def test_the_guide_is_in_short_pieces():
    text = GUIDE.read_text()
    long = [(len(p.split()), p[:60]) for p in _paragraphs(text)
            if len(p.split()) > LONGEST_PARAGRAPH]
    assert not long, long
    wide = [(len(c.split()), c[:60]) for row in table_rows(text) for c in row
            if len(c.split()) > LONGEST_CELL]
    assert not wide, wide
    assert all(len(row) == 5 for row in table_rows(text))
