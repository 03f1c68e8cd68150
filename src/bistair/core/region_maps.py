"""Compiled per-pixel passes of the region stage: the maps the fringe-region decoders read
and the tests they make on whole images, each in one pass.

Like :mod:`bistair.core.region_kernels` (same decorator, compiled with numba on the first
call and cached on disk); each gives exactly what the NumPy code it replaces gave.

Examples
--------
>>> import numpy as np
>>> pixel_orders(np.array([[0, 1, 2]], np.int32), np.array([-1, 3, 7])).tolist()
[[-1, 3, 7]]
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import _numba_called, _numba_inline, kernel
from .label_rows import BLOCK, label_major, row_entries

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi


def row_bands(height: int) -> range:
    """First rows of the bands of an image worked a band at a time: an eighth of the image
    (at least 64 rows), so that a band's temporaries take an eighth of a whole image's, in
    few kernel calls (the stair phase's cosine and sine here, for example: a byte per pixel
    rather than eight).

    Parameters
    ----------
    height : int
        Rows of the image.

    Returns
    -------
    range
        The bands' first rows; its ``step`` is the band height.

    Examples
    --------
    >>> list(row_bands(1000)), list(row_bands(100))
    ([0, 125, 250, 375, 500, 625, 750, 875], [0, 64])
    """
    return range(0, height, max(64, -(-height // 8)))


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


@_numba_inline
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


@_numba_inline
def _fmax(a: float, b: float) -> float:
    """``np.maximum`` of two floats (NaN from either)."""
    if a != a or b != b:
        return a if a != a else b
    return a if a >= b else b


@_numba_inline
def _fmin(a: float, b: float) -> float:
    """``np.minimum`` of two floats (NaN from either)."""
    if a != a or b != b:
        return a if a != a else b
    return a if a <= b else b


@_numba_inline
def _stair_values(p: np.float32, cos_t: np.float32, sin_t: np.float32, sm: np.float32,
                  m: np.float32) -> tuple:
    """One pixel's ``weight * cos``, ``weight * sin``, ``weight`` and ``ratio`` in float32,
    as NumPy computes :func:`bistair.codecs.bidirectional.bands.stair_values`' inputs:
    ``ratio = clip(stair_mod / max(mod, 1e-6), 0, 2)``, ``weight = core_weight(phi) *
    min(ratio, 1)`` (:func:`bistair.core.regions.core_weight`)."""
    tiny = np.float32(1e-6)
    zero, one, two = np.float32(0.0), np.float32(1.0), np.float32(2.0)
    ratio = _fmin(_fmax(sm / _fmax(m, tiny), zero), two)
    core = _fmin(_fmax(_fmin(p, np.float32(TWO_PI) - p) / np.float32(math.pi / 2),
                       np.float32(0.1)), one)
    weight = core * _fmin(ratio, one)
    return weight * cos_t, weight * sin_t, weight, ratio


@kernel(parallel=True)
def stair_noise(stair_mod: np.ndarray, noise_scale: float) -> np.ndarray:
    """Stair phase noise per pixel, ``noise_scale / max(stair_mod, 1e-6)`` (float64
    arithmetic, float32 result, as NumPy gives it).

    Parameters
    ----------
    stair_mod : (H, W) float32 array
        Modulation of the stair pair.
    noise_scale : float
        Camera noise times ``sqrt(2)``.

    Returns
    -------
    (H, W) float32 array
        Radians.

    Examples
    --------
    >>> stair_noise(np.float32([[0.5, 0.0]]), 0.01).tolist()
    [[0.019999999552965164, 10000.0]]
    """
    h, w = stair_mod.shape
    noise = np.empty((h, w), np.float32)
    tiny = np.float32(1e-6)
    for y in prange(h):
        for x in range(w):
            noise[y, x] = np.float32(noise_scale / np.float64(_fmax(stair_mod[y, x], tiny)))
    return noise


@_numba_called
def _stair_sum_rows(labels: np.ndarray, phi: np.ndarray, cos_t: np.ndarray,
                    sin_t: np.ndarray, stair_mod: np.ndarray, mod: np.ndarray, n_labels: int,
                    start: np.ndarray, entry: np.ndarray, y0: int, y1: int,
                    count: np.ndarray, acc: np.ndarray) -> None:
    """:func:`stair_sums` of rows ``y0 .. y1-1``."""
    w = labels.shape[1]
    slot = np.empty(n_labels + 1, np.int64)
    for y in range(y0, y1):
        for i in range(start[y], start[y + 1]):
            slot[entry[i]] = i
        for x in range(w):
            lab = labels[y, x]
            if lab > 0:
                i = slot[lab]
                count[i] += 1
                c, s, weight, ratio = _stair_values(phi[y, x], cos_t[y, x], sin_t[y, x],
                                                    stair_mod[y, x], mod[y, x])
                acc[0, i] += np.float64(c)
                acc[1, i] += np.float64(s)
                acc[2, i] += np.float64(weight)
                acc[3, i] += np.float64(ratio)
                acc[4, i] += np.float64(np.float32(x))


@kernel(parallel=True)
def stair_sums(labels: np.ndarray, phi: np.ndarray, cos_t: np.ndarray, sin_t: np.ndarray,
               stair_mod: np.ndarray, mod: np.ndarray, n_labels: int, start: np.ndarray,
               entry: np.ndarray, count: np.ndarray, acc: np.ndarray) -> None:
    """Add the five values of :func:`bistair.codecs.bidirectional.bands.stair_values`
    (``weight * cos``, ``weight * sin``, ``weight``, ``ratio``, the column; see
    :func:`_stair_values`), computed per pixel as they are summed, to
    the pixel ``count`` (K,) and sums ``acc`` (5, K) of the entries of
    :func:`bistair.core.label_rows.row_entries` (of these rows: ``start`` has one more
    element than the maps have rows; ``entry`` is the whole image's).

    Parameters
    ----------
    labels : (R, W) int32 array
        Region labels, 0 outside any.
    phi, cos_t, sin_t, stair_mod, mod : (R, W) float32 arrays
        Wrapped phase, cosine and sine of the stair phase, modulation of the stair
        pair and of the fringes.
    n_labels : int
        Highest label.
    start, entry : numpy.ndarray
        From :func:`bistair.core.label_rows.row_entries` (``start`` of these rows).
    count : (K,) int64 array
        Pixels per entry, added to.
    acc : (5, K) float64 array
        Sums per entry, added to.

    Examples
    --------
    >>> one = np.ones((1, 3), np.float32)
    >>> count, acc = np.zeros(1, np.int64), np.zeros((5, 1))
    >>> stair_sums(np.int32([[1, 1, 0]]), np.pi * one, one, 0 * one, one, one, 1,
    ...            np.array([0, 1]), np.int32([1]), count, acc)
    >>> count.tolist(), acc[:, 0].tolist()
    ([2], [2.0, 0.0, 2.0, 2.0, 1.0])
    """
    h = labels.shape[0]
    for b in prange((h + BLOCK - 1) // BLOCK):
        _stair_sum_rows(labels, phi, cos_t, sin_t, stair_mod, mod, n_labels, start, entry,
                        b * BLOCK, min(b * BLOCK + BLOCK, h), count, acc)


def label_stair_sums(labels: np.ndarray, phi: np.ndarray, theta: np.ndarray,
                     stair_mod: np.ndarray, mod: np.ndarray, n_labels: int
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`bistair.core.label_rows.label_row_sums` of the five values of
    :func:`bistair.codecs.bidirectional.bands.stair_values`
    (from ``np.cos(theta)`` and ``np.sin(theta)``), computed per pixel as they are summed:
    no (5, H, W) array, the cosine and sine made for a band of rows at a time. Returns
    ``(keys, counts, sums (5, K))``, ``keys = label * H + row`` ascending, float64 sums in
    raster order.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels, 0 outside any.
    phi, theta, stair_mod, mod : (H, W) float32 arrays
        Wrapped phase, stair phase and the modulations of the stair pair and the fringes.
    n_labels : int
        Highest label.

    Returns
    -------
    keys : (K,) int64 array
        ``label * H + row`` of each (label, row) with pixels, ascending.
    counts : (K,) int64 array
        Pixels per key.
    sums : (5, K) float64 array
        The sums of ``weight * cos``, ``weight * sin``, ``weight``, ``ratio`` and the column.

    Examples
    --------
    >>> one = np.ones((1, 3), np.float32)
    >>> keys, counts, sums = label_stair_sums(np.int32([[1, 1, 0]]), np.pi * one, 0 * one,
    ...                                       one, one, 1)
    >>> keys.tolist(), counts.tolist(), sums[:, 0].tolist()
    ([1], [2], [2.0, 0.0, 2.0, 2.0, 1.0])
    """
    start, entry = row_entries(labels, n_labels)
    count = np.zeros(entry.size, np.int64)
    acc = np.zeros((5, entry.size), np.float64)
    bands = row_bands(labels.shape[0])
    for y0 in bands:
        rows = slice(y0, y0 + bands.step)
        t = theta[rows]
        stair_sums(labels[rows], phi[rows], np.cos(t), np.sin(t), stair_mod[rows], mod[rows],
                   n_labels, start[y0:y0 + bands.step + 1], entry, count, acc)
    return label_major(start, entry, count, acc, n_labels)


@kernel(parallel=True)
def label_orders(labels: np.ndarray, region_order: np.ndarray, valid: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """``region_order[labels]`` and the valid pixels outside any region, in one pass.

    Parameters
    ----------
    labels : (H, W) int array
        Region labels, 0 outside any.
    region_order : (n+1,) int32 array
        Order per label (entry 0 for the pixels outside any region).
    valid : (H, W) bool array
        Valid pixels.

    Returns
    -------
    order : (H, W) int32 array
        Each pixel's region order.
    outside : (H, W) bool array
        ``valid & (labels == 0)``.

    Examples
    --------
    >>> order, outside = label_orders(np.array([[0, 1, 2]], np.int32),
    ...                               np.array([-1, 4, 5], np.int32), np.ones((1, 3), bool))
    >>> order.tolist(), outside.tolist()
    ([[-1, 4, 5]], [[True, False, False]])
    """
    h, w = labels.shape
    order = np.empty((h, w), np.int32)
    outside = np.empty((h, w), np.bool_)
    for y in prange(h):
        for x in range(w):
            lab = labels[y, x]
            order[y, x] = region_order[lab]
            outside[y, x] = valid[y, x] and lab == 0
    return order, outside
