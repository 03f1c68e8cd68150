"""Every prose paragraph of the documentation is at most 150 words (issue 35): the guides
are read in short sections, lists and tables, as the docstrings are held to numpydoc.

A paragraph is a run of non-blank prose lines; each list item counts on its own (its
continuation lines with it). Tables, code and directive fences, headings, targets and
comments are not prose. ``docs/results`` is written by the benchmarks and is not checked.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
MOST_WORDS = 150
# Pages other helpers rewrite at the same time (issue 35): the coordinator removes each
# name here once its rewrite is merged.
EXEMPT = ()
GENERATED = ("results/",)

FENCE = re.compile(r"^\s*(`{3,}|~{3,}|:{3,})")
LIST_ITEM = re.compile(r"^\s*([-*+]|\d+[.)])\s+")
NOT_PROSE = re.compile(r"^\s*(\||#{1,6}\s|\(.*\)=\s*$|<!--|\.\. |---+\s*$)")


def paragraphs(text: str) -> list[tuple[int, str]]:
    """The prose paragraphs of a Markdown page, each with the number of its first line.

    Parameters
    ----------
    text : str
        The page.

    Returns
    -------
    list of (int, str)
        The line number (from 1) and the words of each paragraph or list item.

    Examples
    --------
    >>> paragraphs("# A\\n\\nOne two.\\n- three\\n  four\\n\\n| a |\\n")
    [(3, 'One two.'), (4, 'three four')]
    """
    found: list[tuple[int, list[str]]] = []
    fence: str | None = None
    current: list[str] | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        opened = FENCE.match(line)
        if fence is not None:
            if opened and opened.group(1)[0] == fence[0] and len(opened.group(1)) >= len(fence):
                fence = None
            continue
        if opened:
            fence, current = opened.group(1), None
            continue
        if not line.strip() or NOT_PROSE.match(line):
            current = None
            continue
        item = LIST_ITEM.match(line)
        if item or current is None:
            current = []
            found.append((number, current))
            line = line[item.end():] if item else line
        current.append(line.strip())
    return [(number, " ".join(words)) for number, words in found]


def long_paragraphs(text: str, most: int = MOST_WORDS) -> list[str]:
    """Where a page has a paragraph over ``most`` words: its line, length and first words.

    Parameters
    ----------
    text : str
        The page.
    most : int
        The most words a paragraph may have.

    Returns
    -------
    list of str
        ``line N (W words): first words...`` for each paragraph over the limit.

    Examples
    --------
    >>> long_paragraphs("word " * 151)
    ['line 1 (151 words): word word word word word word word word...']
    """
    return [f"line {number} ({len(words.split())} words): "
            f"{' '.join(words.split()[:8])}..."
            for number, words in paragraphs(text) if len(words.split()) > most]


def pages() -> list[Path]:
    """The documentation's Markdown pages that this test holds."""
    every = sorted(DOCS.rglob("*.md"))
    return [p for p in every
            if not p.relative_to(DOCS).as_posix().startswith(GENERATED)
            and p.relative_to(DOCS).as_posix() not in EXEMPT]


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.relative_to(DOCS).as_posix())
def test_no_paragraph_is_over_150_words(page):
    long = long_paragraphs(page.read_text())
    assert not long, (f"docs/{page.relative_to(DOCS).as_posix()}: a paragraph over "
                      f"{MOST_WORDS} words (split it into sections, a list or a table): "
                      + "; ".join(long))


def test_the_exempt_pages_exist():
    # a renamed page must not stay exempt by accident
    for name in EXEMPT:
        assert (DOCS / name).is_file(), f"docs/{name} is exempt but does not exist"


def test_the_parts_that_are_not_prose_are_not_counted():
    page = ("# Heading " + "h " * 200 + "\n\n```sh\n" + "code " * 200 + "\n```\n\n"
            "| " + "cell " * 200 + "|\n\n```{note}\n" + "note " * 200 + "\n```\n\n"
            "(a-target)=\n\n<!-- " + "c " * 200 + "-->\n")
    assert paragraphs(page) == []


def test_list_items_count_one_by_one_with_their_continuation_lines():
    items = "".join(f"- {'w ' * 100}\n  {'v ' * 40}\n" for _ in range(3))
    assert [len(words.split()) for _, words in paragraphs(items)] == [140, 140, 140]
    assert long_paragraphs(items) == []
    assert long_paragraphs("- " + "w " * 100 + "\n  " + "v " * 60 + "\n") == [
        "line 1 (160 words): w w w w w w w w..."]


def test_a_long_paragraph_is_named_by_its_line_and_first_words():
    page = "# T\n\nShort.\n\n" + "Long " + "word " * 150 + "\nend.\n"
    assert long_paragraphs(page) == [
        "line 5 (152 words): Long word word word word word word word..."]
