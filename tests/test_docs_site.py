"""The documentation's generated pages that are also committed are current (issue 25)."""

from __future__ import annotations

import re
import runpy
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import PATIENCE

from bistair.codecs import REGISTRY

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_committed_spec_fields_page_is_what_the_spec_classes_write():
    page = runpy.run_path(str(DOCS / "spec_fields.py"))
    assert (DOCS / "guide" / "spec-fields.md").read_text() == page["spec_fields_page"](), \
        "docs/guide/spec-fields.md is stale: run `python docs/spec_fields.py` (or make docs)"


# -- the site's look, on a small site built with docs/site_settings.py (where Sphinx is) ----
INDEX = """Home
====

.. toctree::
   :hidden:

   cli
   section/index
"""
SECTION = "A section\n=========\n\n.. toctree::\n\n   page\n"


@pytest.fixture(scope="module")
def small_site(tmp_path_factory) -> Path:
    """A root page, a section with one page, and docs/cli.rst, built as the site is built
    (the theme, smartquotes, sidebars and command-line reference of site_settings.py)."""
    for module in ("sphinx", "sphinx_click", "pydata_sphinx_theme"):
        pytest.importorskip(module, reason="the docs extra is not installed (make docs)")
    src = tmp_path_factory.mktemp("site")
    (src / "conf.py").write_text(
        f"import sys\nsys.path.insert(0, {str(DOCS)!r})\n"
        "from site_settings import (html_theme, html_theme_options, html_title, setup_site,\n"
        "                           smartquotes)\n"
        "extensions = ['sphinx_click']\n\n\ndef setup(app):\n    setup_site(app)\n")
    (src / "index.rst").write_text(INDEX)
    (src / "cli.rst").write_text((DOCS / "cli.rst").read_text())
    (src / "section").mkdir()
    (src / "section" / "index.rst").write_text(SECTION)
    (src / "section" / "page.rst").write_text("A page\n======\n")
    out = src / "_build"
    done = subprocess.run([sys.executable, "-m", "sphinx", "-q", "-b", "html", str(src),
                           str(out)], capture_output=True, text=True, timeout=PATIENCE)
    assert done.returncode == 0, done.stderr
    return out


def _section_navigation(html: str) -> str | None:
    """The inside of the primary sidebar's "Section Navigation", None without one."""
    found = re.search(r'aria-label="Section Navigation">(.*?)</nav>', html, re.S)
    return None if found is None else found.group(1)


def test_the_command_line_reference_shows_options_as_typed(small_site):
    """'--count' in a command's help stays two hyphens: an en dash ('–count') made a command
    copied from the page fail ('Got unexpected extra arguments (–count 3)', issue 31)."""
    html = (small_site / "cli.html").read_text()
    assert re.findall(r"–-?[a-z]", html) == []
    assert "With --count N" in html  # simulate's help, in prose
    for method in REGISTRY:  # made when asked for: in the reference all the same
        assert f'id="bistair-patterns-{method}"' in html, method


def test_no_page_shows_an_empty_section_navigation(small_site):
    """A top-level page without pages of its own has no "Section Navigation" (the theme
    showed the heading over nothing on the command-line reference); a section's pages list
    theirs."""
    assert _section_navigation((small_site / "cli.html").read_text()) is None
    listed = _section_navigation((small_site / "section" / "page.html").read_text())
    assert listed is not None and ">A page</a>" in listed
