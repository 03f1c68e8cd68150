"""bistair: absolute phase measurement for fringe projection profilometry.

The headline method is the bidirectional stair-phase coding of Qi, Zhou et al.; the methods
it is compared with sit beside it behind the same interface. ``ARCHITECTURE.md`` at the
repository root maps the packages: :mod:`bistair.core` (building blocks on arrays),
:mod:`bistair.codecs` (one per method, and the registry), :mod:`bistair.io`,
:mod:`bistair.geometry`, :mod:`bistair.sim`, :mod:`bistair.evaluation`,
:mod:`bistair.acquire` and :mod:`bistair.app` (jobs and the command line); each is an
attribute of the package, imported on first use.

In a notebook::

    stack, spec = bistair.read_captures("caps/")   # spec.json beside them
    result = bistair.decode(stack, spec)           # one-line repr
    result.plot()                                  # six panels with colour bars
    result.save("result/")                         # what `bistair decode` writes
    cloud = bistair.reconstruct(result, "calib.json")
    cloud.save("cloud.ply")

Examples
--------
>>> import bistair
>>> spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
>>> patterns = bistair.encode(spec)
>>> result = bistair.decode(patterns, spec)
>>> int(result.order[0, 1079]), round(float(result.coord[0, 1079]), 3)
(35, 1079.0)
>>> result
DecodeResult('bidirectional', shape (1080, 1080), 100.00% valid, noise 0.00% of full scale)
"""

from __future__ import annotations

import importlib as _importlib
import typing as _typing

from . import hooks as _hooks
from .errors import BistairError

if _typing.TYPE_CHECKING:
    from . import acquire as acquire
    from . import app as app
    from . import codecs as codecs
    from . import core as core
    from . import evaluation as evaluation
    from . import geometry as geometry
    from . import io as io
    from . import sim as sim
    from .acquire import scan
    from .codecs import decode, encode, get_codec, make_spec, methods, spec_from_dict
    from .core.result import AxesResult, DecodeResult
    from .geometry.calibration import load_calibration
    from .geometry.stereo import stereo
    from .geometry.triangulate import Reconstruction, reconstruct
    from .io.figures import plot_result
    from .io.read import load_spec
    from .io.read import read_with_spec as read_captures
    from .io.writers import save_result

__version__ = "0.1.0"

# the public names, imported on first use (PEP 562) so that ``import bistair`` and
# ``bistair --version`` do not pay for SciPy and the codecs before they are needed:
# name -> (module, attribute in it)
_LAZY = {
    "decode": (".codecs", "decode"), "encode": (".codecs", "encode"),
    "get_codec": (".codecs", "get_codec"), "make_spec": (".codecs", "make_spec"),
    "methods": (".codecs", "methods"), "spec_from_dict": (".codecs", "spec_from_dict"),
    "DecodeResult": (".core.result", "DecodeResult"),
    "AxesResult": (".core.result", "AxesResult"),
    "load_spec": (".io.read", "load_spec"), "read_captures": (".io.read", "read_with_spec"),
    "save_result": (".io.writers", "save_result"), "plot_result": (".io.figures", "plot_result"),
    "load_calibration": (".geometry.calibration", "load_calibration"),
    "reconstruct": (".geometry.triangulate", "reconstruct"),
    "Reconstruction": (".geometry.triangulate", "Reconstruction"),
    "scan": (".acquire", "scan"), "stereo": (".geometry.stereo", "stereo"),
}
# the subpackages, attributes of the package on first use (``bistair.sim.preset(...)``)
_SUBPACKAGES = ("acquire", "app", "codecs", "core", "evaluation", "geometry", "io", "sim")

__all__ = ["AxesResult", "BistairError", "DecodeResult", "Reconstruction", "decode", "encode",
           "get_codec", "load_calibration", "load_spec", "make_spec", "methods", "plot_result",
           "read_captures", "reconstruct", "save_result", "scan", "spec_from_dict", "stereo"]


def __getattr__(name: str) -> _typing.Any:
    if name in _SUBPACKAGES:
        return _importlib.import_module(f".{name}", __name__)  # the import sets the attribute
    if name not in _LAZY:
        raise AttributeError(f"module 'bistair' has no attribute {name!r}")
    module, attribute = _LAZY[name]
    value = getattr(_importlib.import_module(module, __name__), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*__all__, *_SUBPACKAGES, "__version__"])


def _provided(name: str) -> _typing.Callable[..., _typing.Any]:
    """A function that calls the public function ``name``, importing it on first call."""

    def run(*args: _typing.Any, **kwargs: _typing.Any) -> _typing.Any:
        return __getattr__(name)(*args, **kwargs)

    return run


# ``result.save`` and ``result.plot``: core's results reach the io layer through these
_hooks.provide("save", _provided("save_result"))
_hooks.provide("plot", _provided("plot_result"))
