"""The inputs of the running command, which its outputs must never replace, hold or mix with.

A command of the command line runs inside :func:`reading`, given the inputs named on its
command line; the readers (:func:`~bistair.io.read.capture_files`,
:func:`~bistair.io.read.read_image`, :func:`~bistair.io.jsonfile.read_json`) add every file
and folder they read (:func:`note`): the ``spec.json`` or ``board.json`` found beside the
captures as well as the captures themselves. :mod:`.atomic` refuses an output that is one of
them, holds one of them or lies in a capture folder as a capture would
(:func:`~bistair.io.atomic.check_output`). Outside :func:`reading` nothing is noted (a
notebook's reads are not kept); the scope belongs to the thread that opened it (the readers'
pool threads note nothing: their files are noted by the caller first).

Examples
--------
>>> with reading("scan/*.png", "calib.json"):
...     note("scan/spec.json")
...     [p.name for p in noted().values()]
['scan', 'calib.json', 'spec.json']
>>> noted()
{}
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterable, Iterator
from pathlib import Path

GLOB = "*?["  # the characters that make a captures argument a glob pattern

_NOTED: contextvars.ContextVar[dict[Path, Path] | None] = contextvars.ContextVar(
    "bistair_inputs", default=None)


def input_path(item: str | Path) -> Path:
    """The path an input stands for: a glob pattern's folder (``scan/pat*.png``: ``scan``),
    else the path itself.

    Parameters
    ----------
    item : str or Path
        A file, a folder or a glob pattern.

    Returns
    -------
    Path
        As given (not resolved).

    Examples
    --------
    >>> input_path("scan/pat*.png").as_posix(), input_path("calib.json").as_posix()
    ('scan', 'calib.json')
    """
    text = str(item)
    if not any(c in text for c in GLOB):
        return Path(item)
    parts = Path(text).parts
    first = next(i for i, part in enumerate(parts) if any(c in part for c in GLOB))
    return Path(*parts[:first]) if first else Path(".")


@contextlib.contextmanager
def reading(*items: str | Path | None) -> Iterator[None]:
    """Within the block, note ``items`` and every file and folder read as inputs of the
    running command (see the module's description); ``None`` items are skipped. A scope
    opened inside another starts with the other's inputs.

    Parameters
    ----------
    *items : str, Path or None
        The inputs named on the command line: files, folders or glob patterns.

    Yields
    ------
    None

    Examples
    --------
    >>> with reading("left", None):
    ...     with reading("right"):  # the inputs of the scope around it, and its own
    ...         [p.name for p in noted().values()]
    ...     [p.name for p in noted().values()]
    ['left', 'right']
    ['left']
    """
    token = _NOTED.set(dict(_NOTED.get() or {}))
    try:
        note(*items)
        yield
    finally:
        _NOTED.reset(token)


def note(*items: str | Path | None) -> None:
    """Add ``items`` (files, folders or glob patterns; ``None`` skipped) to the inputs of the
    running command; nothing outside :func:`reading`.

    Parameters
    ----------
    *items : str, Path or None
        What was read, as it was named.

    Examples
    --------
    >>> note("scan/spec.json")  # no command runs: nothing is kept
    >>> noted()
    {}
    """
    found = _NOTED.get()
    if found is None:
        return
    for item in items:
        if item is None or str(item).strip() == "":
            continue
        path = input_path(item)
        with contextlib.suppress(OSError, RuntimeError):  # a path that cannot be resolved
            found.setdefault(path.resolve(), path)


def noted(extra: Iterable[str | Path | None] = ()) -> dict[Path, Path]:
    """The inputs noted so far, then ``extra`` (as :func:`note` takes them).

    Parameters
    ----------
    extra : iterable of str, Path or None
        More inputs to list after the noted ones (``None`` skipped).

    Returns
    -------
    dict
        Each input once: its resolved path (symbolic links followed) -> the path as named
        (a glob pattern as its folder).

    Examples
    --------
    >>> with reading("scan/*.png"):
    ...     [(k.name, v.as_posix()) for k, v in noted(["scan", "calib.json"]).items()]
    [('scan', 'scan'), ('calib.json', 'calib.json')]
    """
    found = dict(_NOTED.get() or {})
    for item in extra:
        if item is not None and str(item).strip() != "":
            path = input_path(item)
            with contextlib.suppress(OSError, RuntimeError):
                found.setdefault(path.resolve(), path)
    return found
