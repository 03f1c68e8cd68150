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
    """The registered method names, the headline method first and the reference last.

    Returns
    -------
    list of str
        The method names in registration order (a new list on every call).

    Examples
    --------
    >>> methods()[0], methods()[-1], len(methods())
    ('bidirectional', 'multifreq', 5)
    """
    return list(REGISTRY)


def get_codec(method: str) -> Codec:
    """The codec for a method name (one-line :class:`BistairError` if there is none).

    Parameters
    ----------
    method : str
        A registered method name (see :func:`methods`).

    Returns
    -------
    Codec
        The method's codec: its spec class and stage functions.

    Raises
    ------
    BistairError
        ``method`` is not a registered name (or not hashable); the message lists the known
        names.

    Examples
    --------
    >>> codec = get_codec("graycode")
    >>> codec.name, codec.options
    ('graycode', ('min_modulation', 'force', 'strategy'))
    >>> get_codec("fourier")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: unknown method 'fourier' (known: bidirectional, graycode, ...)
    """
    try:
        return REGISTRY[method]
    except (KeyError, TypeError):
        raise BistairError(
            f"unknown method {method!r} (known: {', '.join(sorted(REGISTRY))})"
        ) from None


def make_spec(method: str, **params: Any) -> BaseSpec:
    """A validated spec for ``method`` with the given parameters (defaults elsewhere).

    Parameters
    ----------
    method : str
        A registered method name (see :func:`methods`).
    **params
        Fields of the method's spec class (``width``, ``height``, ``period``, ``steps``,
        ...); fields left out keep their defaults.

    Returns
    -------
    BaseSpec
        An instance of the method's spec class, validated.

    Raises
    ------
    BistairError
        An unknown method, a parameter the spec class does not have, or (from the spec's
        validation) values that do not fit together.

    Examples
    --------
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> spec.method, spec.fringes, spec.frames[:5]
    ('graycode', 8, ('shift-0', 'shift-1', 'shift-2', 'shift-3', 'gray-0'))
    >>> make_spec("graycode", colour=1)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: bad parameters for graycode: ...
    """
    codec = get_codec(method)
    params = {**codec.spec_class.defaults(params), **params}
    try:
        return codec.spec_class(**params)
    except TypeError as exc:
        raise BistairError(f"bad parameters for {method}: {exc}") from None


def spec_from_dict(data: Mapping[str, Any]) -> BaseSpec:
    """Build and validate a spec from its dictionary (as in ``spec.json``).

    Parameters
    ----------
    data : Mapping
        The spec's fields by name, ``method`` among them (as written by
        ``spec.to_dict()``).

    Returns
    -------
    BaseSpec
        An instance of the method's spec class, validated.

    Raises
    ------
    BistairError
        ``data`` is not a mapping, has no ``method``, names an unknown method, or its fields
        do not make a valid spec.

    Examples
    --------
    >>> spec = make_spec("lv", width=480, height=64, period=30)
    >>> spec_from_dict(spec.to_dict()) == spec
    True
    >>> spec_from_dict({"width": 480})
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: spec misses the field 'method'
    """
    if not isinstance(data, Mapping):
        raise BistairError("spec must be a JSON object")
    method = data.get("method")
    if method is None:
        raise BistairError("spec misses the field 'method'")
    return check_fields(get_codec(method).spec_class, data)


def encode(spec: BaseSpec) -> np.ndarray:
    """The patterns of a spec: float32 in [0, 1], shape (frames, height, width).

    Parameters
    ----------
    spec : BaseSpec
        The spec of any registered method (see :func:`make_spec`).

    Returns
    -------
    numpy.ndarray
        (frames, height, width) float32 in [0, 1], in the order of ``spec.frames``, gamma
        pre-compensated; ``black`` and ``ignore`` frames are dark, ``white`` is lit.

    Examples
    --------
    >>> spec = make_spec("phase-coding", width=240, height=32, period=30)
    >>> pats = encode(spec)
    >>> pats.shape, pats.dtype, float(pats.min()), float(pats.max())
    ((6, 32, 240), dtype('float32'), 0.0, 1.0)
    """
    return get_codec(spec.method).encode(spec)


def decode(images: np.ndarray, spec: BaseSpec, **options: Any) -> DecodeResult:
    """Decode a capture stack (frames, height, width), any dtype, with the spec it was made by.

    Parameters
    ----------
    images : numpy.ndarray
        (frames, height, width) captures in the order of ``spec.frames``, any numeric
        dtype (scaled to fractions of full scale).
    spec : BaseSpec
        The spec the projected patterns were made by.
    **options
        Decoder options: ``min_modulation`` (fraction of full scale) and the keyword
        options of the method's order stage (e.g. ``strategy``; see ``Codec.options``).

    Returns
    -------
    DecodeResult
        Absolute phase (radians), projector coordinate (projector pixels) and fringe order
        per camera pixel (NaN / -1 where invalid); an
        :class:`~bistair.core.result.AxesResult` of two decodes for a spec of both axes.

    Raises
    ------
    BistairError
        (From the codec.) Captures that do not fit the spec, unknown options, or captures
        that cannot be decoded.

    Examples
    --------
    >>> spec = make_spec("graycode", width=240, height=32, period=30)
    >>> res = decode(encode(spec), spec, strategy="region")
    >>> res.order[0, ::30].tolist(), res.coord[0, 45:48].round(3).tolist()
    ([0, 1, 2, 3, 4, 5, 6, 7], [45.0, 46.0, 47.0])
    """
    return get_codec(spec.method).decode(images, spec, **options)
