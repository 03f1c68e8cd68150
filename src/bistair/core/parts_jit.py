"""Compiled passes of the parts of fringe regions (:mod:`bistair.core.parts`): each pixel's
region order, and the tests for dense patches of wrong steps (a cheap one over tiles, then
a window's share around each pixel).

Each gives exactly what the NumPy code it replaced gave (the same order statistics, the same
float64 arithmetic in the same order).

Examples
--------
>>> import numpy as np
>>> pixel_orders(np.array([[0, 1, 2]], np.int32), np.array([-1, 3, 7])).tolist()
[[-1, 3, 7]]
"""

from __future__ import annotations

import numpy as np

from .jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles

@kernel(parallel=True)
def pixel_orders(labels: np.ndarray, region_order: np.ndarray) -> np.ndarray:
    """Each pixel's region order, -1 outside any region (``labels`` 0).

    Parameters
    ----------
    labels : (H, W) int array
        Region labels, 0 outside any.
    region_order : (n+1,) int64 array
        Order per label.

    Returns
    -------
    (H, W) int32 array
        ``region_order[labels]`` where ``labels > 0``, else -1.

    Examples
    --------
    >>> pixel_orders(np.array([[0, 1, 2]], np.int32), np.array([5, 3, -1])).tolist()
    [[-1, 3, -1]]
    """
    h, w = labels.shape
    out = np.empty((h, w), np.int32)
    for y in prange(h):
        for x in range(w):
            lab = labels[y, x]
            out[y, x] = np.int32(region_order[lab]) if lab > 0 else np.int32(-1)
    return out


@kernel()
def dense_tile(bad: np.ndarray, decided: np.ndarray, share: float, block: int) -> bool:
    """Whether some ``block`` x ``block`` tile (from the top left; the last ones cut by the
    image's edge) has more than ``0.9 * share`` of its decided pixels (at least one) bad.

    Parameters
    ----------
    bad, decided : (H, W) bool arrays
        The pixels counted.
    share : float
        The share of bad pixels a window needs (the tiles are tested against 0.9 of it).
    block : int
        Tile side in pixels.

    Returns
    -------
    bool
        Whether such a tile exists.

    Examples
    --------
    >>> bad = np.zeros((16, 16), bool)
    >>> bad[8:12, 8:16] = True
    >>> dense_tile(bad, np.ones((16, 16), bool), 0.7, 8), dense_tile(bad, bad, 0.7, 8)
    (False, True)
    """
    h, w = bad.shape
    limit = 0.9 * share
    for ty in range(0, h, block):
        for tx in range(0, w, block):
            nbad = 0
            ndec = 0
            for y in range(ty, min(ty + block, h)):
                for x in range(tx, min(tx + block, w)):
                    nbad += bad[y, x]
                    ndec += decided[y, x]
            if nbad > limit * max(ndec, 1):
                return True
    return False


@inline
def _reflect(i: int, n: int) -> int:
    """Index ``i`` reflected into ``0..n-1`` (d c b a | a b c d | d c b a), for
    ``-n <= i < 2n``."""
    if i < 0:
        return -i - 1
    if i >= n:
        return 2 * n - i - 1
    return i


@kernel()
def window_seeds(bad: np.ndarray, decided: np.ndarray, window: int, share: float
                 ) -> tuple[np.ndarray, bool]:
    """Bad pixels whose ``window`` x ``window`` neighbourhood (reflected at the edges, as
    ``scipy.ndimage.uniform_filter`` extends an image) holds more than ``share`` of its
    decided pixels bad, from exact counts; and whether any bad pixel's share is within
    1e-3 pixel of the limit (where the float32 filters could round either way).

    Parameters
    ----------
    bad, decided : (H, W) bool arrays
        The pixels counted (both at least ``window`` wide and high).
    window : int
        Side of the neighbourhood.
    share : float
        Share of the decided pixels that must be bad.

    Returns
    -------
    seeds : (H, W) bool array
        The bad pixels with a bad neighbourhood.
    close : bool
        Some bad pixel's count lies within 1e-3 of ``share`` times its decided count.

    Examples
    --------
    >>> bad = np.zeros((9, 9), bool)
    >>> bad[2:7, 2:6] = True
    >>> seeds, close = window_seeds(bad, np.ones((9, 9), bool), 3, 0.7)
    >>> int(seeds.sum()), bool(close)
    (6, False)
    """
    h, w = bad.shape
    lo = window // 2
    hi = window - lo - 1
    seeds = np.zeros((h, w), np.bool_)
    close = False
    col_bad = np.zeros(w, np.int64)  # counts down each column over the window's rows
    col_dec = np.zeros(w, np.int64)
    for yy in range(-lo, hi + 1):
        ry = _reflect(yy, h)
        for x in range(w):
            col_bad[x] += bad[ry, x]
            col_dec[x] += decided[ry, x]
    for y in range(h):
        if y > 0:  # the window moves down a row
            out_row, in_row = _reflect(y - 1 - lo, h), _reflect(y + hi, h)
            for x in range(w):
                col_bad[x] += np.int64(bad[in_row, x]) - np.int64(bad[out_row, x])
                col_dec[x] += np.int64(decided[in_row, x]) - np.int64(decided[out_row, x])
        for x in range(w):
            if not bad[y, x]:
                continue
            nbad = 0
            ndec = 0
            for xx in range(x - lo, x + hi + 1):
                rx = _reflect(xx, w)
                nbad += col_bad[rx]
                ndec += col_dec[rx]
            gap = nbad - share * ndec
            if abs(gap) <= 1e-3:
                close = True
            seeds[y, x] = gap > 0
    return seeds, close
