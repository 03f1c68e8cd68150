"""Compiled pass of the decode result (:mod:`bistair.core.result`): absolute phase, order,
wrapped phase and mask from the wrapped phase and the orders, in one pass that writes the
order and the wrapped phase into the arrays it was given (pass 2's one write of every
output; the projector coordinate is computed from the phase when it is asked for).

Examples
--------
>>> import numpy as np
>>> phase, order, wrapped, mask, outside = assemble(
...     np.float32([[1.0, 2.0]]), np.int32([[0, -1]]), 20.0)
>>> phase.tolist(), order.tolist(), mask.tolist(), outside
([[1.0, nan]], [[0, -1]], [[True, False]], 0)
"""

from __future__ import annotations

import math

import numpy as np

from .jit import TWO_PI32, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def _assemble(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, masked: bool,
              factor: float, top: int, limit: float, bounded: bool
              ) -> tuple[np.ndarray, np.ndarray, int]:
    """Phase and mask new; ``order`` (-1 where invalid) and ``phi`` (NaN outside ``valid``
    when ``masked``) written in place, each pixel read before it is written."""
    h, w = phi.shape
    phase = np.empty((h, w), np.float32)
    mask = np.empty((h, w), np.bool_)
    outside = np.zeros(h, np.int64)
    f32 = np.float32(factor)
    lim32 = np.float32(limit)
    top32 = np.int32(top)
    nan32 = np.float32(np.nan)
    for y in prange(h):
        out = 0
        for x in range(w):
            p = phi[y, x]
            k = order[y, x]
            ok = k >= 0 and np.isfinite(p)
            if ok and bounded and not (k < top32 or (k == top32 and p * f32 < lim32)):
                ok = False
                out += 1
            mask[y, x] = ok
            if ok:
                phase[y, x] = p + TWO_PI32 * np.float32(k)
            else:
                phase[y, x] = nan32
                order[y, x] = -1
            if masked and not valid[y, x]:
                phi[y, x] = nan32
        outside[y] = out
    return phase, mask, outside.sum()


def coord_factor(period: float) -> np.float32:
    """Projector pixels per radian, ``period / (2*pi)`` in float32: the coordinate of a pixel
    is its float32 phase times this (one rounding).

    Parameters
    ----------
    period : float
        Projector pixels per fringe.

    Returns
    -------
    numpy.float32

    Examples
    --------
    >>> coord_factor(2 * math.pi)
    np.float32(1.0)
    """
    return np.float32(period / (2.0 * math.pi))


def assemble(phi: np.ndarray, order: np.ndarray, period: float, length: float | None = None,
             valid: np.ndarray | None = None, reuse: bool = False
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """The per-pixel arrays of :func:`~bistair.core.result.make_result` in one pass.

    With ``reuse``, the caller gives ``phi`` and ``order`` up: when they are float32 and
    int32, C-contiguous and writable, the wrapped phase and the order returned are these
    arrays, written over (no new array for either); otherwise (and without ``reuse``)
    copies are written and the arguments are left as they were.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)`` (NaN where unknown).
    order : (H, W) int array
        Fringe order per pixel, negative where invalid.
    period : float
        Projector pixels per fringe.
    length : float, optional
        Projector pixels along the coded axis (coordinates at or past it are invalid).
    valid : (H, W) bool array, optional
        Where to report the wrapped phase (NaN elsewhere); everywhere when not given.
    reuse : bool, optional
        Write the wrapped phase and the order into ``phi`` and ``order`` where their dtypes
        and layouts allow.

    Returns
    -------
    phase : (H, W) float32 array
        Absolute phase ``phi + 2*pi*order``, NaN where invalid (the projector coordinate is
        ``phase * coord_factor(period)``).
    order : (H, W) int32 array
        The order, -1 where invalid.
    wrapped : (H, W) float32 array
        ``phi``, NaN outside ``valid``.
    mask : (H, W) bool array
        Pixels with a valid absolute phase.
    outside : int
        Pixels whose coordinate ``length`` invalidated.

    Examples
    --------
    >>> phi = np.full((1, 3), np.pi, np.float32)
    >>> phase, order, wrapped, mask, outside = assemble(
    ...     phi, np.array([[0, 2, -1]]), 10.0, length=25)
    >>> (phase * coord_factor(10.0)).tolist(), order.tolist(), outside
    ([[5.0, nan, nan]], [[0, -1, -1]], 1)
    """
    phi = _writable(phi, np.float32, reuse)
    order = _writable(order, np.int32, reuse)
    top, limit = 0, 0.0
    if length is not None:
        top = np.floor(np.float32(length) / np.float32(period)).astype(np.int32)
        limit = float(np.float32(length - top * period))
    where = np.ones((1, 1), bool) if valid is None else np.asarray(valid, bool)
    phase, mask, outside = _assemble(phi, order, where, valid is not None,
                                     float(coord_factor(period)), int(top), limit,
                                     length is not None)
    return phase, order, phi, mask, int(outside)


def _writable(a: np.ndarray, dtype: type, reuse: bool) -> np.ndarray:
    """``a`` itself if ``reuse`` and it can be written over as a C-contiguous ``dtype``
    array, else a C-contiguous copy."""
    a = np.asarray(a)
    if reuse and a.dtype == dtype and a.flags.c_contiguous and a.flags.writeable:
        return a
    return np.array(a, dtype=dtype, order="C")
