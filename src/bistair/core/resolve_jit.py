"""Compiled passes of the order resolution (:mod:`bistair.core.resolve`): votes per region
and code, messages between regions, each region's order painted on its pixels (the parts'
passes are in :mod:`.parts_jit`).

Each gives exactly what the NumPy code it replaced gave (the same order statistics, the same
float64 arithmetic in the same order).

Examples
--------
>>> import numpy as np
>>> order, outside = label_orders(np.array([[0, 1, 2]], np.int32),
...                               np.array([-1, 3, 7], np.int32), np.ones((1, 3), bool))
>>> order.tolist()
[[-1, 3, 7]]
"""

from __future__ import annotations

import numpy as np

from .jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles


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
