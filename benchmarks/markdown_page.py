"""A benchmark's printed output kept as a page of the documentation's results
(``--markdown docs/results/NAME.md``): what the script printed, as it printed it, under a
title and the command that wrote it."""

from __future__ import annotations

import contextlib
import io
import platform
import sys
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def markdown_page(path: Path | None, title: str, about: str) -> Iterator[None]:
    """Print as usual; with a ``path``, also write what was printed into a Markdown page."""
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
    page = [f"# {title}", "", about, "",
            f"Written by `{command}` on {platform.machine()} with Python "
            f"{platform.python_version()}; the machine is shared, so compare the ratios "
            "within a run rather than times across runs.", "", "```text",
            buffer.getvalue().rstrip(), "```", ""]
    path.write_text("\n".join(page))
    print(f"wrote {path}")
