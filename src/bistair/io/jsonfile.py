"""The project's JSON files (specs, boards, calibrations, figures): reading with one-line
errors, and plain values from NumPy ones for writing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from .inputs import note


def read_json(path: str | Path, what: str, *, state: bool = False) -> Any:
    """Parse ``path``; missing, unreadable or malformed files raise a one-line
    :class:`BistairError` naming ``what`` the file is (e.g. ``"spec file"``).

    Parameters
    ----------
    path : str or Path
        The JSON file (UTF-8).
    what : str
        What the file is, for the messages (``"spec file"``, ``"calibration file"``, ...).
    state : bool
        The file keeps a state the running command may write back (a latency file, a
        batch's marker), rather than an input it must not overwrite: not noted
        (:func:`bistair.io.inputs.note`).

    Returns
    -------
    Any
        The parsed value (``dict``, ``list``, ``str``, ``int``, ``float``, ``bool`` or
        ``None``), as :func:`json.loads` gives it.

    Raises
    ------
    BistairError
        If the file is missing, cannot be read (a folder, no permission, not UTF-8) or is
        not valid JSON (with the parser's message and line).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (tmp / "board.json").write_text('{"type": "checkerboard", "columns": 9}')
    >>> read_json(tmp / "board.json", "board description")
    {'type': 'checkerboard', 'columns': 9}
    >>> _ = (tmp / "bad.json").write_text('{"columns": 9,}')
    >>> read_json(tmp / "bad.json", "board description")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: board description .../bad.json is not valid JSON (...column 15)
    >>> shutil.rmtree(tmp)
    >>> read_json("/nonexistent.json", "spec file")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: spec file /nonexistent.json not found
    """
    path = Path(path)
    if not state:
        note(path)
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise BistairError(f"{what} {path} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0]
        raise BistairError(f"cannot read {what} {path}: {reason}") from None
    except json.JSONDecodeError as exc:
        raise BistairError(
            f"{what} {path} is not valid JSON ({exc.msg.removesuffix(' at')} at line "
            f"{exc.lineno} column {exc.colno})"
        ) from None


def to_jsonable(value: Any) -> Any:
    """``value`` with NumPy scalars as Python numbers and tuples as lists, for ``json.dumps``.

    Dictionaries, lists and tuples are converted recursively (dictionary keys become
    ``str``); anything else is returned as it is (NumPy arrays are not converted: pass
    ``arr.tolist()``).

    Parameters
    ----------
    value : Any
        A value made of dictionaries, lists, tuples, NumPy scalars and plain values.

    Returns
    -------
    Any
        A copy of the containers with NumPy scalars replaced by ``int``, ``float`` or
        ``bool`` (:meth:`numpy.generic.item`) and tuples by lists.

    Examples
    --------
    >>> to_jsonable({"n": np.int64(3), "t": (np.float32(0.5),)})
    {'n': 3, 't': [0.5]}
    """
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def write_json(path: str | Path, value: Any) -> None:
    """Write ``value`` as indented JSON with a final newline.

    Written in place (not atomically); NaN and infinities are written as JSON's
    non-standard ``NaN`` and ``Infinity``.

    Parameters
    ----------
    path : str or Path
        The file to write (replaced if it exists; its folder must exist).
    value : Any
        What to write; converted by :func:`to_jsonable` first (2-space indent).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> write_json(tmp / "info.json", {"valid_pixels": np.int64(1920), "size": (120, 16)})
    >>> print((tmp / "info.json").read_text(), end="")
    {
      "valid_pixels": 1920,
      "size": [
        120,
        16
      ]
    }
    >>> shutil.rmtree(tmp)
    """
    Path(path).write_text(json.dumps(to_jsonable(value), indent=2) + "\n")
