"""Compiled passes of :func:`bistair.codecs.bidirectional.response.level_offsets`: how far
the band rows read from their nearest stair level, and the weighted medians of those
shares over all rows and per level.

Each gives exactly what the NumPy it replaces gave (the same float64 running sums in the
same order); the sort of the shares stays NumPy's (``numpy.argsort``), whose order of equal
shares the medians follow.

Examples
--------
>>> import numpy as np
>>> levels = np.array([-2.0, 0.0, 2.0])
>>> nearest, share = level_shares(np.array([0.5, -1.9, 2.5]), levels, np.ones(3))
>>> nearest.tolist(), share.round(3).tolist()
([1, 0, 2], [0.5, 0.1, 0.5])
"""

from __future__ import annotations

import numpy as np

from ...core.jit import inline, kernel
from .bands_jit import level_ring, one_nearest_level, wrapped_abs

prange = range  # numba's prange once the first kernel of this module compiles (its helpers too)


@kernel()
def level_shares(theta: np.ndarray, levels: np.ndarray,
                 half_gap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each phase's nearest level and its distance from it as a share of that level's half
    gap: ``nearest_levels(theta, levels)`` and ``np.abs(wrap(theta - levels[nearest])) /
    half_gap[nearest]``.

    Parameters
    ----------
    theta : (n,) float64 array
        Phases, radians.
    levels : (L,) float64 array
        Level phases, radians.
    half_gap : (L,) float64 array
        Half the gap from each level to its nearest other level (``stair.half_gaps``).

    Returns
    -------
    nearest : (n,) int32 array
        The nearest level of each phase.
    share : (n,) float64 array
        Its distance from that level over the level's half gap.

    Examples
    --------
    >>> nearest, share = level_shares(np.array([3.0]), np.array([-3.0, 0.0]), np.ones(2))
    >>> nearest.tolist(), share.round(4).tolist()  # across the wrap
    ([0], [0.2832])
    """
    n = theta.size
    nearest = np.empty(n, np.int32)
    share = np.empty(n, np.float64)
    ring = level_ring(levels)
    for i in range(n):
        u = one_nearest_level(theta[i], levels, ring)
        nearest[i] = u
        share[i] = wrapped_abs(theta[i] - levels[u]) / half_gap[u]
    return nearest, share


@kernel()
def weighted_medians(order: np.ndarray, share: np.ndarray, nearest: np.ndarray,
                     weight: np.ndarray, n_levels: int) -> tuple[float, np.ndarray]:
    """The weighted median share over all rows and over the rows nearest each level, as
    :func:`~bistair.codecs.bidirectional.response.level_offsets` took them with NumPy.

    All rows: the share at the first place in ``order`` where the running weight reaches
    half the total (``np.searchsorted(np.cumsum(weight[order]), 0.5 * total)``). Per level:
    the rows in ``order`` grouped by level (a stable counting sort, as ``np.argsort(...,
    kind="stable")``), one running weight over all groups; a group's median is where it
    reaches its start plus half the group's weight (searched over the whole running weight,
    at most the group's last row); 0.0 for a level without weight.

    Parameters
    ----------
    order : (n,) int array
        The rows ascending by share (``np.argsort(share)``).
    share : (n,) float64 array
        The rows' shares (:func:`level_shares`).
    nearest : (n,) int32 array
        The rows' nearest levels, in ``0 .. n_levels-1``.
    weight : (n,) float64 array
        The rows' weights (non-negative).
    n_levels : int
        The number of levels.

    Returns
    -------
    offset : float
        The median share of all rows.
    per_level : (n_levels,) float64 array
        The median share of each level's rows.

    Examples
    --------
    >>> share = np.array([0.3, 0.1, 0.2, 0.4])
    >>> offset, per = weighted_medians(np.argsort(share), share, np.array([0, 1, 0, 1],
    ...                                np.int32), np.ones(4), 2)
    >>> offset, per.tolist()
    (0.2, [0.2, 0.1])
    """
    n = order.size
    cum = np.empty(n, np.float64)
    run = 0.0
    for j in range(n):
        run += weight[order[j]]
        cum[j] = run
    offset = share[order[min(_search(cum, 0.5 * cum[n - 1]), n - 1)]]
    counts = np.zeros(n_levels + 1, np.int64)
    for j in range(n):
        counts[nearest[order[j]] + 1] += 1
    starts = np.cumsum(counts)
    fill = starts[:-1].copy()
    grouped = np.empty(n, np.int64)
    for j in range(n):
        u = nearest[order[j]]
        grouped[fill[u]] = order[j]
        fill[u] += 1
    run = 0.0
    for j in range(n):
        run += weight[grouped[j]]
        cum[j] = run
    per_level = np.zeros(n_levels, np.float64)
    for u in range(n_levels):
        first, last = starts[u], starts[u + 1]
        before = cum[first - 1] if first > 0 else 0.0
        total = (cum[last - 1] if last > first else 0.0) - before
        if total > 0:
            at = min(_search(cum, before + 0.5 * total), last - 1)
            per_level[u] = share[grouped[at]]
    return offset, per_level


@inline
def _search(cum: np.ndarray, value: float) -> int:
    """``np.searchsorted(cum, value)`` (side left, NaN above every number) of an ascending
    ``cum``."""
    lo, hi = 0, cum.size
    while lo < hi:
        mid = (lo + hi) >> 1
        c = cum[mid]
        if c < value or (value != value and c == c):
            lo = mid + 1
        else:
            hi = mid
    return lo
