"""Reading the project's JSON files (specs, boards, calibrations) with one-line errors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from .errors import BistairError


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
