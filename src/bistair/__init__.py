"""bistair: absolute phase measurement for fringe projection profilometry.

The headline method is the bidirectional stair-phase coding of Qi, Zhou et al.; the methods
it is compared with sit beside it behind the same interface.

Examples
--------
>>> import bistair
>>> spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
>>> patterns = bistair.encode(spec)
>>> result = bistair.decode(patterns, spec)
>>> int(result.order[0, 1079]), round(float(result.coord[0, 1079]), 3)
(35, 1079.0)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .codecs import CODECS, get_codec
from .errors import BistairError
from .result import DecodeResult
from .spec import BaseSpec, load_spec, spec_from_dict

__all__ = ["BistairError", "CODECS", "DecodeResult", "decode", "encode", "load_spec",
           "make_spec", "spec_from_dict"]
__version__ = "0.1.0"


def make_spec(method: str, **params: Any) -> BaseSpec:
    """A validated spec for ``method`` with the given parameters (defaults elsewhere)."""
    codec = get_codec(method)
    try:
        return codec.spec_class(**params)
    except TypeError as exc:
        raise BistairError(f"bad parameters for {method}: {exc}") from None


def encode(spec: BaseSpec) -> np.ndarray:
    """The patterns of a spec: float32 in [0, 1], shape (frames, height, width)."""
    return get_codec(spec.method).encode(spec)


def decode(images: np.ndarray, spec: BaseSpec, **options: Any) -> DecodeResult:
    """Decode a capture stack (frames, height, width), any dtype, with the spec it was made by."""
    return get_codec(spec.method).decode(images, spec, **options)
