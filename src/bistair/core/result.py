"""The decode result every codec returns (written to a folder by :mod:`bistair.io.writers`).

Examples
--------
>>> import numpy as np
>>> phi = np.full((2, 3), 1.0, np.float32)
>>> order = np.array([[0, 1, 2], [3, -1, 5]])
>>> res = make_result("demo", phi, order, period=30.0, modulation=np.ones((2, 3)))
>>> [round(float(c), 3) for c in res.coord[0]], int(res.mask.sum())
([4.775, 34.775, 64.775], 5)
>>> res  # one line, whatever the size
DecodeResult('demo', shape (2, 3), 83.33% valid)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..hooks import call
from ..spec import BaseSpec
from .measure import FringeSet
from .result_jit import assemble, coord_factor

if TYPE_CHECKING:
    from matplotlib.figure import Figure

# the arrays a decode writes as NAME.npy (DecodeResult.arrays)
ARRAY_NAMES = ("phase", "coord", "order", "wrapped", "modulation", "mask")
# the per-pixel arrays of a DecodeResult, as its constructor names them (coord: None when
# it is computed from the phase)
PIXEL_FIELDS = ("phase", "coord", "order", "wrapped", "modulation", "average", "mask", "code")


@dataclass
class DecodeResult:
    """Absolute phase and everything needed to judge it, per camera pixel.

    Attributes
    ----------
    phase : float32, absolute phase ``Phi = 2*pi*x_p/T`` (NaN where invalid).
    coord : float32, projector coordinate ``x_p`` along the coded axis (NaN where invalid):
        computed from ``phase`` when asked for, ``phase * float32(period / (2*pi))`` (a new
        array each time: read it once), unless the result was made with one.
    order : int32, fringe order ``floor(x_p/T)`` (-1 where invalid).
    wrapped : float32, wrapped phase in ``[0, 2*pi)`` (NaN where the modulation is too low).
    modulation : float32, fringe modulation ``B`` as a fraction of full scale.
    average : float32, average intensity ``A`` as a fraction of full scale.
    mask : bool, pixels with a valid absolute phase.
    code : int32, the method's decoded code word per pixel (``k_s`` for stair methods; -1
        where not decoded), for previews and diagnosis. A decode stores it in the smallest
        of int8, int16 and int32 that holds every code word the spec allows
        (:func:`code_dtype`) and widens it to int32 when read (a new array each time unless
        it is stored as int32: read it once), so arithmetic on it never wraps around.
    period : projector pixels per fringe of ``phase`` and ``order``.
    method : the codec's name.
    info : figures about the decode (thresholds, counts, consistency checks).
    texture : the fully lit frame (fraction of full scale) when the spec has ``white``.
    spec : the spec the captures were decoded with (set by :func:`bistair.decode`), for
        :func:`bistair.reconstruct`.

    A decode holds 22 bytes per camera pixel (phase, order, wrapped, modulation, average:
    4 each; mask and a code stored as int8: 1 each). ``repr`` is one line (method, shape, valid
    share, noise); :meth:`save` writes what ``bistair decode`` writes, :meth:`plot` draws
    the six-panel figure.
    """

    phase: np.ndarray
    coord: np.ndarray | None  # a property once the class is made (None: from the phase)
    order: np.ndarray
    wrapped: np.ndarray
    modulation: np.ndarray
    average: np.ndarray
    mask: np.ndarray
    code: np.ndarray
    period: float
    method: str
    info: dict[str, Any] = field(default_factory=dict)
    texture: np.ndarray | None = None  # the white frame if the spec has one (camera axes)
    spec: BaseSpec | None = None  # the spec it was decoded with, if known

    def __repr__(self) -> str:
        return f"DecodeResult({_summary(self, f'{_share(self.mask)} valid')})"

    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays written as ``NAME.npy`` (:data:`ARRAY_NAMES`)."""
        return {name: getattr(self, name) for name in ARRAY_NAMES}

    def save(self, folder: str | Path, previews: bool = True) -> Path:
        """Write what ``bistair decode`` writes (arrays, previews, ``info.json``) into
        ``folder``, atomically: :func:`bistair.save_result`."""
        return call("save", self, folder, previews=previews)

    def plot(self) -> Figure:
        """The six-panel figure (wrapped phase, absolute phase, coordinate, order,
        modulation, mask) with colour bars in their units: :func:`bistair.plot_result`."""
        return call("plot", self)

    def transposed(self) -> DecodeResult:
        """The same result with image axes swapped (for the rows orientation)."""
        arrays = {name: _stored(self, name) for name in PIXEL_FIELDS}
        swap = {name: None if a is None else np.ascontiguousarray(a.T)
                for name, a in arrays.items()}
        return DecodeResult(**swap, period=self.period, method=self.method, info=self.info,
                            texture=self.texture, spec=self.spec)


def _coord(result: DecodeResult) -> np.ndarray:
    """Projector coordinate per camera pixel (float32, NaN where invalid): the one the result
    was made with, else ``phase * float32(period / (2*pi))``, computed anew."""
    given = _given_coord(result)
    if given is not None:
        return given
    return np.multiply(result.phase, coord_factor(result.period), dtype=np.float32)


def _set_coord(result: DecodeResult, value: np.ndarray | None) -> None:
    result.__dict__["_coord"] = value  # None: computed from the phase when read


def _given_coord(result: DecodeResult) -> np.ndarray | None:
    """The coordinate the result was made with (``None``: computed from the phase)."""
    return result.__dict__.get("_coord")


def _code(result: DecodeResult) -> np.ndarray:
    """The code words per camera pixel as int32 (stored narrower by a decode)."""
    return result.__dict__["_code"].astype(np.int32, copy=False)


def _set_code(result: DecodeResult, value: np.ndarray) -> None:
    result.__dict__["_code"] = value


def _stored(result: DecodeResult, name: str) -> np.ndarray | None:
    """A per-pixel array as the result holds it (``coord``: None when computed from the
    phase; ``code``: in its stored dtype), not as reading the attribute makes it."""
    if name in ("coord", "code"):
        return result.__dict__.get(f"_{name}")
    return getattr(result, name)


# the dataclass's own __init__, fields and replace() name ``coord`` and ``code`` where they
# always stood; reading coord computes it, reading code widens it to int32 (set after the
# class is made, so that the dataclass does not take the properties for the fields' defaults)
DecodeResult.coord = property(_coord, _set_coord)  # type: ignore[assignment]
DecodeResult.code = property(_code, _set_code)  # type: ignore[assignment]


def transpose_own(result: DecodeResult) -> DecodeResult:
    """``result`` itself with its image axes swapped, array by array: each array's transposed
    copy is made once the one before has replaced its original, so a result nothing else
    holds takes one more array while it turns, not a second result
    (:meth:`DecodeResult.transposed` makes a new result and leaves this one as it is).

    Parameters
    ----------
    result : DecodeResult
        A result nothing else holds (a decode's own, before it returns it).

    Returns
    -------
    DecodeResult
        ``result``, its arrays replaced by C-contiguous transposed copies.

    Examples
    --------
    >>> res = make_result("demo", np.zeros((2, 3), np.float32), np.zeros((2, 3), int), 30.0,
    ...                   np.ones((2, 3)))
    >>> transpose_own(res) is res, res.phase.shape, res.coord.shape, res.phase.flags.c_contiguous
    (True, (3, 2), (3, 2), True)
    """
    for name in PIXEL_FIELDS:
        a = _stored(result, name)
        if a is not None:
            setattr(result, name, np.ascontiguousarray(a.T))
    return result


@dataclass
class AxesResult:
    """A decode of both projector axes: ``x`` (the columns, ``coord_x``) and ``y`` (the
    rows, ``coord_y``), each a :class:`DecodeResult`; ``spec`` the spec of both axes it was
    decoded with, if known. ``repr``, :meth:`save` and :meth:`plot` as for a
    :class:`DecodeResult`."""

    x: DecodeResult
    y: DecodeResult
    spec: BaseSpec | None = None

    def __repr__(self) -> str:
        both = (f"{_share(self.mask)} valid on both axes (x {_share(self.x.mask)}, "
                f"y {_share(self.y.mask)})")
        return f"AxesResult({_summary(self.x, both)})"

    def save(self, folder: str | Path, previews: bool = True) -> Path:
        """Write what ``bistair decode`` writes for both axes into ``folder``, atomically."""
        return call("save", self, folder, previews=previews)

    def plot(self) -> Figure:
        """The six panels of each axis (x above y), with colour bars in their units."""
        return call("plot", self)

    @property
    def mask(self) -> np.ndarray:
        """Pixels valid on both axes."""
        return self.x.mask & self.y.mask

    @property
    def coord_x(self) -> np.ndarray:
        """Projector column per camera pixel (NaN where that axis is invalid)."""
        return self.x.coord

    @property
    def coord_y(self) -> np.ndarray:
        """Projector row per camera pixel (NaN where that axis is invalid)."""
        return self.y.coord

    @property
    def method(self) -> str:
        return self.x.method

    @property
    def texture(self) -> np.ndarray | None:
        return self.x.texture

    @property
    def info(self) -> dict[str, Any]:
        """Each axis's figures, under ``"x"`` and ``"y"``."""
        return {"x": self.x.info, "y": self.y.info}

    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays written as ``NAME.npy``: each axis's with a suffix (``coord_x``,
        ``phase_y``, ...) and ``mask`` where both are valid."""
        out = {f"{name}_{tag}": arr for tag, res in (("x", self.x), ("y", self.y))
               for name, arr in res.arrays().items()}
        out["mask"] = self.mask
        return out


def _share(mask: np.ndarray) -> str:
    return f"{100 * float(mask.mean()) if mask.size else 0.0:.2f}%"


def _summary(result: DecodeResult, valid: str) -> str:
    """``method, shape, valid share, noise[, refused][, warnings]``, for a repr."""
    info = result.info
    parts = [repr(result.method), f"shape {result.mask.shape}", valid]
    if isinstance(info.get("noise"), int | float):
        parts.append(f"noise {100 * info['noise']:.2f}% of full scale")
    if "refused" in info:
        parts.append("refused")
    warnings = len(info.get("warnings", []))
    if warnings:
        parts.append(f"{warnings} warning{'s' if warnings > 1 else ''}")
    return ", ".join(parts)


def make_result(method: str, phi: np.ndarray, order: np.ndarray, period: float,
                modulation: np.ndarray, average: np.ndarray | None = None,
                code: np.ndarray | None = None, wrapped: np.ndarray | None = None,
                info: dict[str, Any] | None = None, length: float | None = None
                ) -> DecodeResult:
    """Assemble a result from the wrapped phase and the fringe order (``< 0`` = invalid).

    ``phi`` must lie in ``[0, 2*pi)``, so ``order`` is ``floor(Phi / 2pi)`` exactly. With
    ``length`` (projector pixels along the coded axis), coordinates outside ``[0, length)``
    are invalid: they cannot come from the projector.

    Parameters
    ----------
    method : str
        The codec's name.
    phi : (H, W) array
        Wrapped phase in radians, in ``[0, 2*pi)`` (NaN where unknown).
    order : (H, W) int array
        Fringe order per pixel, negative where invalid.
    period : float
        Projector pixels per fringe.
    modulation : (H, W) array
        Fringe modulation ``B`` (fraction of full scale).
    average : (H, W) array, optional
        Average intensity ``A`` (fraction of full scale); zeros when not given.
    code : (H, W) int array, optional
        The method's decoded code word per pixel, kept as given; -1 everywhere (int8) when
        not given.
    wrapped : (H, W) array, optional
        The wrapped phase to report (NaN where the modulation is too low); ``phi`` when not
        given.
    info : dict, optional
        Figures about the decode; ``outside_projector`` (a count) is added when ``length``
        invalidates pixels.
    length : float, optional
        Projector pixels along the coded axis.

    Returns
    -------
    DecodeResult
        Absolute phase ``phi + 2*pi*order`` (float32, NaN where invalid; the projector
        coordinate is ``phase * float32(period / (2*pi))``), order (int32, -1 where
        invalid) and the mask of valid pixels.

    Examples
    --------
    >>> phi = np.full((1, 3), np.pi, np.float32)
    >>> res = make_result("demo", phi, np.array([[0, 2, -1]]), period=10.0,
    ...                   modulation=np.ones((1, 3)), length=25)
    >>> res.coord.astype(float).round(3).tolist(), res.order.tolist(), res.info
    ([[5.0, nan, nan]], [[0, -1, -1]], {'outside_projector': 1})
    """
    return _make(method, phi, order, period, modulation, average, code, wrapped, None, info,
                 length)


def _make(method: str, phi: np.ndarray, order: np.ndarray, period: float,
          modulation: np.ndarray, average: np.ndarray | None, code: np.ndarray | None,
          wrapped: np.ndarray | None, valid: np.ndarray | None, info: dict[str, Any] | None,
          length: float | None, reuse: bool = False) -> DecodeResult:
    """:func:`make_result`; with ``valid`` (and no ``wrapped``), the wrapped phase reported is
    ``phi`` where valid, NaN elsewhere; with ``reuse``, ``phi`` and ``order`` are written
    over (:func:`~bistair.core.result_jit.assemble`)."""
    phase, out_order, phi_out, mask, outside = assemble(phi, order, period, length, valid,
                                                        reuse=reuse)
    if wrapped is not None:
        phi_out = np.asarray(wrapped).astype(np.float32)
    return DecodeResult(
        phase=phase, coord=None, order=out_order, wrapped=phi_out,
        modulation=np.asarray(modulation, np.float32),
        average=(np.zeros_like(phase) if average is None
                 else np.asarray(average).astype(np.float32, copy=False)),
        mask=mask, code=(np.full(phase.shape, -1, np.int8) if code is None else code),
        period=float(period), method=method,
        info={**(info or {}), **({"outside_projector": outside} if outside else {})},
    )


def code_dtype(most: int) -> np.dtype:
    """The smallest of int8, int16, int32 and int64 that holds every code word from -1 (not
    decoded) to ``most``.

    Parameters
    ----------
    most : int
        The largest code word.

    Returns
    -------
    numpy.dtype

    Examples
    --------
    >>> [str(code_dtype(n)) for n in (127, 128, 40000)]
    ['int8', 'int16', 'int32']
    """
    return next(np.dtype(t) for t in (np.int8, np.int16, np.int32, np.int64)
                if most <= np.iinfo(t).max)


def narrow_code(code: np.ndarray, most: int) -> np.ndarray:
    """The code words in :func:`code_dtype` of ``most`` (the most the method's spec allows),
    or of the largest word present where one is larger: never a word cut short.

    Parameters
    ----------
    code : (H, W) int array
        Code words, -1 where not decoded.
    most : int
        The largest code word the spec allows.

    Returns
    -------
    (H, W) int array
        The same words, int8 when they fit (``code`` itself if it has that dtype already).

    Examples
    --------
    >>> narrow_code(np.int32([[-1, 5, 63]]), 127).dtype, narrow_code(np.int32([[300]]), 127)
    (dtype('int8'), array([[300]], dtype=int16))
    """
    code = np.asarray(code)
    if code.size:
        low, high = int(code.min()), int(code.max())
        if low < -1:
            most = max(most, -low)  # (no codec writes these: kept whole all the same)
        most = max(most, high)
    return code.astype(code_dtype(most), copy=False)


def result_from_orders(method: str, fs: FringeSet, order: np.ndarray, period: float,
                       code: np.ndarray | None = None, info: dict[str, Any] | None = None,
                       length: float | None = None, reuse: bool = False) -> DecodeResult:
    """A result from a measured fringe set and its fringe orders (-1 = invalid); with
    ``length``, coordinates outside ``[0, length)`` are invalid (:func:`make_result`).

    The wrapped phase reported is the set's, NaN where the set's pixels are not valid; the
    modulation and average are the set's.

    Parameters
    ----------
    method : str
        The codec's name.
    fs : FringeSet
        The measured N-step set whose wrapped phase the orders complete.
    order : (H, W) int array
        Fringe order per pixel, -1 where invalid.
    period : float
        Projector pixels per fringe.
    code : (H, W) int array, optional
        The method's decoded code word per pixel (-1 where not decoded), kept as given.
    info : dict, optional
        Figures about the decode.
    length : float, optional
        Projector pixels along the coded axis.
    reuse : bool, optional
        The caller gives up ``fs.phi`` and ``order``: they become the result's wrapped
        phase and order, written over, where their dtypes and layouts allow (no new array
        for either); pass it only for arrays nothing else holds or shares memory with.

    Returns
    -------
    DecodeResult

    Examples
    --------
    >>> ones = np.ones((1, 3), np.float32)
    >>> fs = FringeSet(ones, 0.5 * ones, 0.4 * ones, np.array([[True, True, False]]), 0.001)
    >>> res = result_from_orders("demo", fs, np.array([[0, 1, -1]]), period=2 * np.pi)
    >>> res.coord.astype(float).round(3).tolist(), res.wrapped.tolist(), res.mask.tolist()
    ([[1.0, 7.283, nan]], [[1.0, 1.0, nan]], [[True, True, False]])
    """
    return _make(method, fs.phi, order, period, fs.mod, fs.avg, code, None, fs.valid, info,
                 length, reuse)
