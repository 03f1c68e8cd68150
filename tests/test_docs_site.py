"""The documentation's generated pages that are also committed are current (issue 25)."""

from __future__ import annotations

import runpy
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_committed_spec_fields_page_is_what_the_spec_classes_write():
    page = runpy.run_path(str(DOCS / "spec_fields.py"))
    assert (DOCS / "guide" / "spec-fields.md").read_text() == page["spec_fields_page"](), \
        "docs/guide/spec-fields.md is stale: run `python docs/spec_fields.py` (or make docs)"
