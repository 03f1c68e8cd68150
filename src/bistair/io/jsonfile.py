"""The project's JSON files (specs, boards, calibrations, figures): reading with one-line
errors, and plain values from NumPy ones for writing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError


def read_json(path: str | Path, what: str) -> Any:
    """Parse ``path``; missing, unreadable or malformed files raise a one-line
    :class:`BistairError` naming ``what`` the file is (e.g. ``"spec file"``).

    >>> read_json("/nonexistent.json", "spec file")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: spec file /nonexistent.json not found
    """
    path = Path(path)
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise BistairError(f"{what} {path} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc).splitlines()[0]
        raise BistairError(f"cannot read {what} {path}: {reason}") from None
    except json.JSONDecodeError as exc:
        raise BistairError(
            f"{what} {path} is not valid JSON ({exc.msg}, line {exc.lineno})"
        ) from None


def to_jsonable(value: Any) -> Any:
    """``value`` with NumPy scalars as Python numbers and tuples as lists, for ``json.dumps``.

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
    """Write ``value`` as indented JSON with a final newline."""
    Path(path).write_text(json.dumps(to_jsonable(value), indent=2) + "\n")
