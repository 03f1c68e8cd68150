"""A benchmark's printed output kept as a page of the documentation's results
(``--markdown docs/results/NAME.md``): what the script printed, as it printed it, under a
title and the command that wrote it (and, if the script gives them, the machine it ran on
and sections of Markdown made from its figures, before the printed output)."""

from __future__ import annotations

import contextlib
import io
import platform
import sys
from collections.abc import Callable, Iterator
from pathlib import Path


@contextlib.contextmanager
def markdown_page(path: Path | None, title: str, about: str,
                  sections: Callable[[], list[str]] | None = None,
                  machine: Callable[[], str] | None = None) -> Iterator[None]:
    """Print as usual; with a ``path``, also write what was printed into a Markdown page.

    ``sections()`` gives Markdown lines put before the printed output (then headed "What
    the script printed"); ``machine()`` says what the script ran on, in the provenance
    line. Both are called once the block has run."""
    if path is None:
        yield
        return
    buffer = io.StringIO()

    class Tee(io.TextIOBase):
        def write(self, text: str) -> int:
            sys.__stdout__.write(text)
            return buffer.write(text)

        def flush(self) -> None:
            sys.__stdout__.flush()

    with contextlib.redirect_stdout(Tee()):
        yield
    command = " ".join(["python", *(Path(a).as_posix() if i == 0 else a
                                     for i, a in enumerate(sys.argv))])
    where = machine() if machine is not None else platform.machine()
    page = [f"# {title}", "", about, "",
            f"Written by `{command}` on {where} with Python "
            f"{platform.python_version()}; the machine is shared, so compare the ratios "
            "within a run rather than times across runs.", ""]
    if sections is not None:
        page += [*sections(), "", "## What the script printed", ""]
    page += ["```text", buffer.getvalue().rstrip(), "```", ""]
    path.write_text("\n".join(page))
    print(f"wrote {path}")
