"""The codecs, one module (or package) per method behind one interface, and the one registry
of methods.

A codec module declares its spec class and its stage functions once, in a
:class:`~bistair.codecs.base.Codec` it registers here; the command line, the simulator, the
benchmark and the report take their method lists from :func:`methods`.

Examples
--------
>>> methods()
['bidirectional', 'lv', 'phase-coding', 'graycode', 'multifreq']
>>> spec = make_spec("lv", width=480, height=64, period=30)
>>> spec_from_dict(spec.to_dict()) == spec
True
>>> decode(encode(spec), spec).order[0, ::60].tolist()
[0, 2, 4, 6, 8, 10, 12, 14]
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..core.result import DecodeResult
from ..errors import BistairError
from ..spec import BaseSpec, check_fields
from . import bidirectional, graycode, lv, multifreq, phase_coding
from .base import Codec, CodeMap, Orders

__all__ = ["Codec", "CodeMap", "Orders", "decode", "encode", "get_codec", "make_spec",
           "methods", "spec_from_dict"]

REGISTRY: dict[str, Codec] = {
    c.name: c for c in (bidirectional.CODEC, lv.CODEC, phase_coding.CODEC, graycode.CODEC,
                        multifreq.CODEC)
}


def methods() -> list[str]:
    """The registered method names, the headline method first and the reference last."""
    return list(REGISTRY)


def get_codec(method: str) -> Codec:
    """The codec for a method name (one-line :class:`BistairError` if there is none)."""
    try:
        return REGISTRY[method]
    except (KeyError, TypeError):
        raise BistairError(
            f"unknown method {method!r} (known: {', '.join(sorted(REGISTRY))})"
        ) from None


def make_spec(method: str, **params: Any) -> BaseSpec:
    """A validated spec for ``method`` with the given parameters (defaults elsewhere)."""
    codec = get_codec(method)
    try:
        return codec.spec_class(**params)
    except TypeError as exc:
        raise BistairError(f"bad parameters for {method}: {exc}") from None


def spec_from_dict(data: Mapping[str, Any]) -> BaseSpec:
    """Build and validate a spec from its dictionary (as in ``spec.json``)."""
    if not isinstance(data, Mapping):
        raise BistairError("spec must be a JSON object")
    method = data.get("method")
    if method is None:
        raise BistairError("spec misses the field 'method'")
    return check_fields(get_codec(method).spec_class, data)


def encode(spec: BaseSpec) -> np.ndarray:
    """The patterns of a spec: float32 in [0, 1], shape (frames, height, width)."""
    return get_codec(spec.method).encode(spec)


def decode(images: np.ndarray, spec: BaseSpec, **options: Any) -> DecodeResult:
    """Decode a capture stack (frames, height, width), any dtype, with the spec it was made by."""
    return get_codec(spec.method).decode(images, spec, **options)
