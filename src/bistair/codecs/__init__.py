"""The codecs, one module per method, behind one interface (:class:`~.base.Codec`)."""

from __future__ import annotations

from ..errors import BistairError
from . import bidirectional, graycode, lv, multifreq, phase_coding
from .base import Codec

CODECS: dict[str, Codec] = {
    c.name: c
    for c in (bidirectional.CODEC, multifreq.CODEC, phase_coding.CODEC, lv.CODEC, graycode.CODEC)
}


def get_codec(method: str) -> Codec:
    """The codec for a method name."""
    try:
        return CODECS[method]
    except KeyError:
        raise BistairError(
            f"unknown method {method!r} (known: {', '.join(sorted(CODECS))})"
        ) from None
