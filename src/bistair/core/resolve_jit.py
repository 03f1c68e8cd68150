"""Compiled passes of the order resolution (:mod:`bistair.core.resolve`): votes per region
and code, messages between regions, each region's order painted on its pixels, and the
tests for dense patches of wrong steps.

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


@inline
def _clip(x: float, lo: float, hi: float) -> float:
    """``np.clip`` of one float: NaN stays NaN."""
    if x != x:
        return x
    x = x if x > lo else lo
    return x if x < hi else hi



@kernel()
def pass_messages(evidence: np.ndarray, src: np.ndarray, dst: np.ndarray, step: np.ndarray,
                  strength: np.ndarray, reverse: np.ndarray, iterations: int,
                  cap: float) -> np.ndarray:
    """The beliefs of :func:`bistair.core.resolve.resolve_regions`' max-sum message passing
    (float64, each operation as its NumPy formulation does it, messages added in link
    order).

    Parameters
    ----------
    evidence : (n+1, K) float64 array
        Each region's support for each order.
    src, dst : (E,) int arrays
        The two regions of each directed link.
    step : (E,) int array
        Order step from ``src`` to ``dst``.
    strength : (E,) float64 array
        Weight of each link's message.
    reverse : (E,) int array
        The link in the other direction.
    iterations : int
        Rounds of message passing.
    cap : float
        Largest belief a message carries over.

    Returns
    -------
    (n+1, K) float64 array
        The beliefs after the last round.

    Examples
    --------
    >>> evidence = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    >>> one = np.ones(2)
    >>> pass_messages(evidence, np.array([1, 2]), np.array([2, 1]), np.array([1, -1]),
    ...               0.5 * one, np.array([1, 0]), 2, 2.0).tolist()
    [[0.0, 0.0], [1.0, 0.0], [0.0, 0.375]]
    """
    n_e = src.size
    n_k = evidence.shape[1]
    msgs = np.zeros((n_e, n_k))
    new = np.zeros((n_e, n_k))
    belief = evidence.copy()
    for _ in range(iterations if n_e else 0):
        for e in range(n_e):
            for k in range(n_k):
                pk = k - step[e]
                v = 0.0
                if 0 <= pk < n_k:
                    shifted = belief[src[e], pk] - msgs[reverse[e], pk]
                    v = strength[e] * _clip(shifted, 0.0, cap)
                new[e, k] = 0.5 * msgs[e, k] + 0.5 * v
        msgs, new = new, msgs
        belief[:] = evidence
        for e in range(n_e):
            for k in range(n_k):
                belief[dst[e], k] += msgs[e, k]
    return belief


@kernel()
def label_code_votes(labels: np.ndarray, codes: np.ndarray, weights: np.ndarray,
                     n_labels: int, n_codes: int) -> tuple[np.ndarray, np.ndarray]:
    """Each label's (weighted) votes per code and in all: ``(votes (n+1, C), total
    (n+1,))``, float64, over the pixels with a label (1 .. n) and a code (0 .. C-1; others
    abstain), added in raster order as ``np.bincount`` adds them (one thread: a label
    spans rows).

    Parameters
    ----------
    labels : (H, W) int array
        Region labels, 0 outside any.
    codes : (H, W) int array
        Code per pixel, 0 .. n_codes-1, negative to abstain.
    weights : (H, W) float array or (0, 0) array
        Vote weight per pixel; an empty array for one vote each.
    n_labels, n_codes : int
        Highest label and number of codes.

    Returns
    -------
    votes : (n_labels + 1, n_codes) float64 array
    total : (n_labels + 1,) float64 array

    Examples
    --------
    >>> votes, total = label_code_votes(np.array([[1, 1, 2]]), np.array([[0, 1, -1]]),
    ...                                 np.empty((0, 0)), 2, 2)
    >>> votes.tolist(), total.tolist()
    ([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]], [0.0, 2.0, 0.0])
    """
    h, w = labels.shape
    votes = np.zeros((n_labels + 1, n_codes), np.float64)
    total = np.zeros(n_labels + 1, np.float64)
    weighted = weights.size > 0
    for y in range(h):
        for x in range(w):
            lab = labels[y, x]
            c = codes[y, x]
            if lab > 0 and c >= 0 and lab <= n_labels and c < n_codes:
                v = np.float64(weights[y, x]) if weighted else 1.0
                votes[lab, c] += v
                total[lab] += v
    return votes, total
