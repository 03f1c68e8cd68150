"""What a decode result does through a layer above its own: ``result.save`` and
``result.plot``.

:class:`~bistair.core.result.DecodeResult` lives in ``core/``, which cannot import the
writers (``io/``) that save it or draw it. The result's methods call the function provided
here under their name; the package's ``__init__`` provides them when ``bistair`` is first
imported (before any of its modules can run), each importing its module on first call.
Nothing below the package names a layer above its own.

Examples
--------
>>> provide("shout", lambda text: text.upper())
>>> call("shout", "saved")
'SAVED'
>>> call("whisper", "saved")
Traceback (most recent call last):
...
bistair.errors.BistairError: nothing provides 'whisper' (import bistair first)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .errors import BistairError

_PROVIDED: dict[str, Callable[..., Any]] = {}


def provide(name: str, function: Callable[..., Any]) -> None:
    """Let :func:`call` run ``function`` under ``name`` (replacing any earlier one)."""
    _PROVIDED[name] = function


def call(name: str, *args: Any, **kwargs: Any) -> Any:
    """Run the function provided under ``name``; one-line :class:`BistairError` if none is."""
    try:
        function = _PROVIDED[name]
    except KeyError:
        raise BistairError(f"nothing provides {name!r} (import bistair first)") from None
    return function(*args, **kwargs)
