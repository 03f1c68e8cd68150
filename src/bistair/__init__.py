"""bistair: absolute phase measurement for fringe projection profilometry.

The headline method is the bidirectional stair-phase coding of Qi, Zhou et al.; the methods
it is compared with sit beside it behind the same interface. ``ARCHITECTURE.md`` at the
repository root maps the packages: :mod:`bistair.core` (building blocks on arrays),
:mod:`bistair.codecs` (one per method, and the registry), :mod:`bistair.io`,
:mod:`bistair.geometry`, :mod:`bistair.sim`, :mod:`bistair.evaluation` and
:mod:`bistair.app` (jobs and the command line).

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

import importlib
from typing import TYPE_CHECKING, Any

from .errors import BistairError

if TYPE_CHECKING:
    from .acquire import scan
    from .codecs import decode, encode, get_codec, make_spec, methods, spec_from_dict
    from .core.result import DecodeResult
    from .geometry.stereo import stereo
    from .io.read import load_spec

__all__ = ["BistairError", "DecodeResult", "decode", "encode", "get_codec", "load_spec",
           "make_spec", "methods", "scan", "spec_from_dict", "stereo"]
__version__ = "0.1.0"

# the public names, imported on first use (PEP 562) so that ``import bistair`` and
# ``bistair --version`` do not pay for SciPy and the codecs before they are needed
_LAZY = {"decode": ".codecs", "encode": ".codecs", "get_codec": ".codecs",
         "make_spec": ".codecs", "methods": ".codecs", "spec_from_dict": ".codecs",
         "DecodeResult": ".core.result", "load_spec": ".io.read", "scan": ".acquire",
         "stereo": ".geometry.stereo"}


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module 'bistair' has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name], __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
