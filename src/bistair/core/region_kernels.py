"""Compiled loops of the region stage: per-region statistics in one pass over their entries
(the per-pixel passes are in :mod:`bistair.core.region_maps`).

Like :mod:`bistair.core.kernels` (same decorator: compiled with numba on the first call and
cached on disk), for the work on fringe regions and their row profiles that NumPy would do
with a Python loop over regions, rows or levels. Each gives exactly what the NumPy code it
replaces gave (the same order statistics, the same float64 arithmetic in the same order).

Examples
--------
>>> import numpy as np
>>> region = np.array([1, 1, 1, 2, 2])
>>> region_quantile(region, np.array([3.0, 1.0, 2.0, 5.0, 4.0]), 0.8).tolist()
[2.0, 2.0, 2.0, 4.0, 4.0]
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import _numba_called, _numba_inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi


@_numba_inline
def _wrapped_abs(x: float) -> float:
    """``abs((x + pi) % 2pi - pi)`` in float64, as NumPy computes it."""
    a = x + math.pi
    if 0.0 <= a < TWO_PI:
        m = a
    elif TWO_PI <= a < 2.0 * TWO_PI:
        m = a - TWO_PI  # exact, as fmod
    elif -TWO_PI < a < 0.0:
        m = a + TWO_PI  # fmod leaves a; Python's modulo then adds the divisor
    else:
        m = a % TWO_PI  # Python's float modulo, as NumPy's
    return abs(m - math.pi)


@kernel()
def nearest_levels(theta: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """Index of the level nearest each phase on the circle: ``argmin |wrap(theta - level)|``
    (the first of equally near levels, as ``numpy.argmin``).

    Parameters
    ----------
    theta : (n,) float64 array
        Phases in radians.
    levels : (L,) float64 array
        Level phases in radians.

    Returns
    -------
    (n,) int32 array
        Indices into ``levels``.

    Examples
    --------
    >>> levels = np.array([-2.0, 0.0, 2.0])
    >>> nearest_levels(np.array([0.9, 1.0, 3.1, -3.1]), levels).tolist()
    [1, 1, 2, 0]
    """
    out = np.zeros(theta.size, np.int32)
    for i in range(theta.size):
        out[i] = _nearest_level(theta[i], levels)
    return out


@_numba_inline
def _nearest_level(t: float, levels: np.ndarray) -> int:
    """One phase's :func:`nearest_levels`."""
    best = 0
    low = _wrapped_abs(t - levels[0])
    if low != low:
        return 0
    for j in range(1, levels.size):
        d = _wrapped_abs(t - levels[j])
        if d != d:  # NaN: numpy.argmin returns the first one
            return j
        if d < low:
            low = d
            best = j
    return best


@kernel()
def region_quantile(region: np.ndarray, values: np.ndarray, q: float) -> np.ndarray:
    """Per entry, the ``floor(q * (count - 1))``-th smallest of the values of its region;
    ``region`` must be non-decreasing (each region's entries contiguous).

    Parameters
    ----------
    region : (n,) int array
        Region of each entry, non-decreasing.
    values : (n,) float64 array
        The values.
    q : float
        Quantile in [0, 1].

    Returns
    -------
    (n,) float64 array
        The chosen order statistic of each entry's region (NaNs sort last).

    Examples
    --------
    >>> region_quantile(np.array([0, 0, 3]), np.array([2.0, 1.0, 7.0]), 0.5).tolist()
    [1.0, 1.0, 7.0]
    """
    out = np.empty(region.size, np.float64)
    _region_quantile(region, values, q, out)
    return out


@_numba_called
def _region_quantile(region: np.ndarray, values: np.ndarray, q: float, out: np.ndarray
                     ) -> None:
    """:func:`region_quantile` into ``out``."""
    n = region.size
    i = 0
    while i < n:
        j = i + 1
        while j < n and region[j] == region[i]:
            j += 1
        k = int(math.floor(q * (j - i - 1)))
        seg = values[i:j]
        if np.isnan(seg).any():  # NaNs sort last
            pick = np.sort(seg)[k]
        else:
            pick = np.partition(seg, k)[k]
        for k in range(i, j):
            out[k] = pick
        i = j


@kernel()
def group_percentiles(group: np.ndarray, values: np.ndarray, n_groups: int,
                      q: float) -> np.ndarray:
    """``numpy.percentile(values[group == g], 100 * q)`` (linear interpolation) for every
    group ``g`` in ``0 .. n_groups-1``; NaN for a group without values.

    Parameters
    ----------
    group : (n,) int array
        Group of each value, in ``0 .. n_groups-1``.
    values : (n,) float64 array
        The values.
    n_groups : int
        Number of groups.
    q : float
        Quantile in [0, 1] (``percentile / 100``).

    Returns
    -------
    (n_groups,) float64 array
        Each group's quantile, computed as NumPy's ``linear`` method does.

    Examples
    --------
    >>> group_percentiles(np.array([0, 0, 0, 2]), np.array([1.0, 2.0, 4.0, 5.0]), 3,
    ...                   0.8).tolist()
    [3.2, nan, 5.0]
    """
    return _group_percentiles(group, values, n_groups, q)


@_numba_called
def _group_percentiles(group: np.ndarray, values: np.ndarray, n_groups: int,
                       q: float) -> np.ndarray:
    """The body of :func:`group_percentiles`."""
    n = group.size
    counts = np.zeros(n_groups + 1, np.int64)
    for i in range(n):
        counts[group[i] + 1] += 1
    starts = np.cumsum(counts)
    fill = starts[:-1].copy()
    buf = np.empty(n, np.float64)
    for i in range(n):
        g = group[i]
        buf[fill[g]] = values[i]
        fill[g] += 1
    out = np.full(n_groups, np.nan)
    for g in range(n_groups):
        m = counts[g + 1]
        if m == 0:
            continue
        seg = buf[starts[g]:starts[g] + m]
        if np.isnan(seg).any():
            continue  # NaN, as NumPy gives
        v = (m - 1) * q
        prev = math.floor(v)
        if v >= m - 1:
            out[g] = seg.max()
            continue
        part = np.partition(seg, int(prev))  # the two order statistics, without a sort
        a = part[int(prev)]
        b = part[int(prev) + 1:].min()
        t = v - prev
        diff = b - a
        r = a + diff * t
        if t >= 0.5:
            r = b - diff * (1.0 - t)
        out[g] = r
    return out


@_numba_inline
def _together(reg: np.ndarray, solid: np.ndarray, first: int, second: int,
              third: int) -> bool:
    """Runs ``first``, ``second`` and ``third`` (-2: none) exist, lie in ``first``'s region
    and are solid."""
    n = reg.size
    if not (0 <= first < n and solid[first]):
        return False
    if not (0 <= second < n and reg[second] == reg[first] and solid[second]):
        return False
    return third == -2 or (0 <= third < n and reg[third] == reg[first] and solid[third])


@kernel()
def value_changes(uid: np.ndarray, reg: np.ndarray, solid: np.ndarray, merged: np.ndarray,
                  y0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The runs where a region's band values change pair (the rules of
    :func:`bistair.codecs.bidirectional.evidence.band_splits`): ``(region, first row)`` of each.

    Parameters
    ----------
    uid : (n,) int array
        Stair level of each run, runs sorted by region, then row.
    reg : (n,) int array
        Region of each run.
    solid : (n,) bool array
        Runs at least two rows long.
    merged : (n,) bool array
        Runs as long as a merged band.
    y0 : (n,) int array
        First row of each run.

    Returns
    -------
    region : int64 array
        Region of each split.
    row : int64 array
        First row of each split's lower part.

    Examples
    --------
    >>> uid = np.array([1, 2, 1, 3, 4, 3])
    >>> reg, solid, merged = np.ones(6, int), np.ones(6, bool), np.zeros(6, bool)
    >>> [a.tolist() for a in value_changes(uid, reg, solid, merged, np.arange(6) * 10)]
    [[1], [30]]
    """
    n = uid.size
    out_r = np.empty(n, np.int64)
    out_y = np.empty(n, np.int64)
    k = 0
    for i in range(1, n):
        if not _together(reg, solid, i - 1, i, -2) or uid[i] == uid[i - 1]:
            continue
        three = _together(reg, solid, i - 2, i - 1, i)
        if three and not merged[i - 1] and uid[i] != uid[i - 2]:
            confirmed = ((_together(reg, solid, i, i + 2, -2) and uid[i + 2] == uid[i])
                         or (_together(reg, solid, i, i + 1, -2) and uid[i + 1] != uid[i - 1]
                             and uid[i + 1] != uid[i - 2])
                         or merged[i])
        elif merged[i - 1]:  # a run of another value after a merged band
            confirmed = (_together(reg, solid, i, i + 2, -2) and uid[i + 2] == uid[i]
                         and not merged[i])
        else:
            confirmed = False
        if not confirmed and merged[i] and three and not merged[i - 1] \
                and uid[i - 2] == uid[i]:
            confirmed = True  # a merged band after alternating bands
        if confirmed and (k == 0 or out_r[k - 1] != reg[i] or out_y[k - 1] < y0[i - 1]):
            out_r[k] = reg[i]
            out_y[k] = y0[i]
            k += 1
    return out_r[:k], out_y[:k]


@kernel()
def drop_small(labels: np.ndarray, n: int, min_size: int) -> int:
    """Set the labels of regions under ``min_size`` pixels to 0 and number the others
    ``1..`` in their order, in place; returns how many are left.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels ``0..n`` (0: none), changed in place.
    n : int
        Highest label.
    min_size : int
        Smallest region kept, in pixels.

    Returns
    -------
    int
        The number of regions kept.

    Examples
    --------
    >>> labels = np.array([[1, 1, 2, 3, 3, 3]], np.int32)
    >>> drop_small(labels, 3, 2), labels.tolist()
    (2, [[1, 1, 0, 2, 2, 2]])
    """
    h, w = labels.shape
    size = np.zeros(n + 1, np.int64)
    for y in range(h):
        x = 0
        while x < w:  # by runs of one label
            lab = labels[y, x]
            x1 = x + 1
            while x1 < w and labels[y, x1] == lab:
                x1 += 1
            size[lab] += x1 - x
            x = x1
    remap = np.zeros(n + 1, np.int32)
    kept = 0
    for lab in range(1, n + 1):
        if size[lab] >= min_size:
            kept += 1
            remap[lab] = kept
    if kept < n:
        for y in range(h):
            for x in range(w):
                labels[y, x] = remap[labels[y, x]]
    return kept


@_numba_inline
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
