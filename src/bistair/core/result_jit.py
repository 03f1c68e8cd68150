"""Compiled pass of the decode result (:mod:`bistair.core.result`): absolute phase,
projector coordinate, order and mask from the wrapped phase and the orders, in one pass.

Examples
--------
>>> import numpy as np
>>> phase, coord, order, wrapped, mask, outside = assemble(
...     np.float32([[1.0, 2.0]]), np.int32([[0, -1]]), 20.0)
>>> coord.astype(float).round(3).tolist(), order.tolist(), mask.tolist(), outside
([[3.183, nan]], [[0, -1]], [[True, False]], 0)
"""

from __future__ import annotations

import math

import numpy as np

from .jit import TWO_PI32, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def _assemble(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, masked: bool,
              factor: float, top: int, limit: float, bounded: bool
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    h, w = phi.shape
    phase = np.empty((h, w), np.float32)
    coord = np.empty((h, w), np.float32)
    out_order = np.empty((h, w), np.int32)
    wrapped = np.empty((h, w), np.float32)
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
            k = np.int32(order[y, x])
            ok = k >= 0 and np.isfinite(p)
            if ok and bounded and not (k < top32 or (k == top32 and p * f32 < lim32)):
                ok = False
                out += 1
            mask[y, x] = ok
            if ok:
                v = p + TWO_PI32 * np.float32(k)
                phase[y, x] = v
                coord[y, x] = v * f32
                out_order[y, x] = k
            else:
                phase[y, x] = nan32
                coord[y, x] = nan32
                out_order[y, x] = -1
            wrapped[y, x] = p if (not masked or valid[y, x]) else nan32
        outside[y] = out
    return phase, coord, out_order, wrapped, mask, outside.sum()



def assemble(phi: np.ndarray, order: np.ndarray, period: float, length: float | None = None,
             valid: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """The per-pixel arrays of :func:`~bistair.core.result.make_result` in one pass.

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

    Returns
    -------
    phase, coord : (H, W) float32 arrays
        Absolute phase ``phi + 2*pi*order`` and projector coordinate, NaN where invalid.
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
    >>> phase, coord, order, wrapped, mask, outside = assemble(
    ...     phi, np.array([[0, 2, -1]]), 10.0, length=25)
    >>> coord.tolist(), order.tolist(), outside
    ([[5.0, nan, nan]], [[0, -1, -1]], 1)
    """
    phi = np.asarray(phi, np.float32)
    top, limit = 0, 0.0
    if length is not None:
        top = np.floor(np.float32(length) / np.float32(period)).astype(np.int32)
        limit = float(np.float32(length - top * period))
    where = np.ones((1, 1), bool) if valid is None else np.asarray(valid, bool)
    return _assemble(phi, order, where, valid is not None,
                     float(np.float32(period / (2.0 * math.pi))), int(top), limit,
                     length is not None)
