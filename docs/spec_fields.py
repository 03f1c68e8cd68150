"""The page of every spec field of every method (``docs/guide/spec-fields.md``), written from
the spec classes: :mod:`docs.conf` writes it when the documentation is built, and
``tests/test_docs_site.py`` checks that the committed page is what it writes (so that the
page also reads right where it is not built, on the repository's web view)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

PAGE = Path(__file__).resolve().parent / "guide" / "spec-fields.md"


def spec_fields_page() -> str:
    """The page's Markdown."""
    from bistair.codecs import REGISTRY
    from bistair.spec import BaseSpec

    base = {f.name for f in dataclasses.fields(BaseSpec)}
    lines = ["# Every spec field", "",
             "Written from the spec classes (`docs/spec_fields.py`). A spec read "
             "from a file must name every field that shapes the patterns (marked *shapes*; those "
             "added later may be left out and mean what older files meant); "
             "the others may be left out and take their defaults. Numbers may be written as "
             "fractions or with `pi` (`\"1920/58\"`, `\"-2*pi/3\"`); `frames` lists the "
             "captures in order (the method's frame names, and `white`, `black`, `ignore`).",
             "", "## Every method", "", "| field | default | shapes | meaning |",
             "| --- | --- | --- | --- |"]

    def row(f: dataclasses.Field) -> str:
        default = f.default if f.default is not dataclasses.MISSING else ""
        needed = f.metadata.get("shapes", True) and f.metadata.get("cli", True) is not False
        shapes = "yes" if needed else ""
        if needed and f.metadata.get("later"):  # added after spec files were written
            shapes = f"yes (left out: `{f.default!r}`)"
        meaning = f.metadata.get("help", "").replace("|", "\\|")
        name = "frames" if f.name == "frame_order" else f.name
        return f"| `{name}` | `{default!r}` | {shapes} | {meaning} |"

    lines += [row(f) for f in dataclasses.fields(BaseSpec)]
    for name, codec in REGISTRY.items():
        own = [f for f in dataclasses.fields(codec.spec_class) if f.name not in base]
        lines += ["", f"## `{name}`", "", codec.summary + ".", "",
                  "| field | default | shapes | meaning |", "| --- | --- | --- | --- |",
                  *(row(f) for f in own)]
    return "\n".join(lines) + "\n"


def write_spec_fields_page() -> None:
    """Write the page if it differs from what is there."""
    content = spec_fields_page()
    if not PAGE.exists() or PAGE.read_text() != content:
        PAGE.write_text(content)


if __name__ == "__main__":
    write_spec_fields_page()
