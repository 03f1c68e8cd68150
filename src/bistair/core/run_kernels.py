"""Compiled loops of the band analysis: the row profiles of fringe regions read as stair
levels and cut into runs of one level (the passes of
:func:`bistair.codecs.bidirectional.bands.row_runs`).

Like :mod:`bistair.core.region_kernels` (same decorator, same helpers): each gives exactly
what the NumPy it replaces gave, float64 sums in the same order. The arctangents stay with
the caller: NumPy's vectorised ``arctan2`` and the C library's differ in the last bit.

The profile entries come sorted by region, then row (as
:class:`~bistair.codecs.bidirectional.bands.RowProfiles` keeps them).
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import _numba_inline, kernel
from .region_kernels import _group_percentiles, _nearest_level, _region_quantile, _wrapped_abs

prange = range  # numba's once the first kernel compiles (the helpers above compiled with it)


@kernel()
def band_sums(region: np.ndarray, level: np.ndarray, theta: np.ndarray, weight: np.ndarray,
              levels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The band-core rows and, per nominal level, the weighted stair phasor of the core rows
    read nearest it.

    A core row's modulation ``level`` reaches 0.7 of its region's 80th percentile row
    (``floor(0.8 (count - 1))``-th smallest); the sums are ``np.bincount(uid, weight *
    np.cos(theta))``, the same with ``sin``, and ``np.bincount(uid, weight)``, over the
    core rows, ``uid`` their nearest level.

    Parameters
    ----------
    region : (n,) int array
        Region of each profile entry, non-decreasing.
    level : (n,) float64 array
        The entries' stair-pair over fringe modulation.
    theta : (n,) float64 array
        The entries' stair phase, radians.
    weight : (n,) float64 array
        The entries' weight.
    levels : (L,) float64 array
        Nominal level phases, radians.

    Returns
    -------
    core : (n,) bool array
        The band-core entries.
    cos, sin, weight : (L,) float64 arrays
        The core entries' sums per level.

    Examples
    --------
    >>> region = np.array([1, 1, 1, 2])
    >>> level = np.array([1.0, 0.2, 1.0, 1.0])  # the second row a blurred transition
    >>> theta = np.array([0.1, 0.1, 3.0, -3.1])
    >>> core, c, s, w = band_sums(region, level, theta, np.ones(4), np.array([0.0, 3.0]))
    >>> core.tolist(), w.tolist()
    ([True, False, True, True], [1.0, 2.0])
    """
    n, m = region.size, levels.size
    q = np.empty(n, np.float64)
    _region_quantile(region, level, 0.8, q)
    core = np.empty(n, np.bool_)
    c = np.zeros(m, np.float64)
    s = np.zeros(m, np.float64)
    w = np.zeros(m, np.float64)
    for i in range(n):
        core[i] = level[i] >= 0.7 * q[i]
        if core[i]:
            u = _nearest_level(theta[i], levels)
            c[u] += weight[i] * math.cos(theta[i])
            s[u] += weight[i] * math.sin(theta[i])
            w[u] += weight[i]
    return core, c, s, w


@kernel()
def band_reads(region: np.ndarray, level: np.ndarray, theta: np.ndarray, core: np.ndarray,
               levels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The level each entry reads and the entries kept as band rows.

    Each entry's modulation is taken relative to its level's 80th percentile over the core
    entries (``numpy.percentile``, linear; 1 for a level no core entry reads, at least
    1e-6); an entry is kept where that reaches 0.7 of its region's 80th percentile entry.

    Parameters
    ----------
    region, level, theta : (n,) arrays
        As for :func:`band_sums`.
    core : (n,) bool array
        The band-core entries (:func:`band_sums`).
    levels : (L,) float64 array
        The level phases as observed, radians.

    Returns
    -------
    read : (n,) int32 array
        The nearest level of each entry.
    kept : (n,) bool array
        The band rows.

    Examples
    --------
    >>> region = np.array([1, 1, 1, 2])
    >>> level = np.array([1.0, 0.2, 1.0, 1.0])
    >>> theta = np.array([0.1, 0.1, 3.0, -3.1])
    >>> core = np.array([True, False, True, True])
    >>> read, kept = band_reads(region, level, theta, core, np.array([0.0, 3.0]))
    >>> read.tolist(), kept.tolist()
    ([0, 0, 1, 1], [True, False, True, True])
    """
    n, m = region.size, levels.size
    read = np.empty(n, np.int32)
    cores = 0
    for i in range(n):
        read[i] = _nearest_level(theta[i], levels)
        cores += core[i]
    group = np.empty(cores, np.int32)
    values = np.empty(cores, np.float64)
    seen = np.zeros(m, np.bool_)
    j = 0
    for i in range(n):
        if core[i]:
            group[j] = read[i]
            values[j] = level[i]
            seen[read[i]] = True
            j += 1
    expected = _group_percentiles(group, values, m, 0.8)
    for u in range(m):
        if not seen[u]:
            expected[u] = 1.0
    rel = np.empty(n, np.float64)
    for i in range(n):
        e = expected[read[i]]
        rel[i] = level[i] / (e if (e != e or e >= 1e-6) else 1e-6)  # as np.maximum
    q = np.empty(n, np.float64)
    _region_quantile(region, rel, 0.8, q)
    kept = np.empty(n, np.bool_)
    for i in range(n):
        kept[i] = rel[i] >= 0.7 * q[i]
    return read, kept


@kernel()
def band_runs(region: np.ndarray, row: np.ndarray, read: np.ndarray, kept: np.ndarray,
              cos: np.ndarray, sin: np.ndarray, weight: np.ndarray, theta: np.ndarray,
              levels: np.ndarray, half_gap: np.ndarray) -> tuple:
    """Runs of one level down the kept entries of each region.

    A run goes on from one kept entry to the next of the same region and level when the
    rows between them (at most three) are exactly the dropped entries between them; it
    is bounded above (``top_ok``) when it follows another run across such a gap, and
    below when the next run is bounded above. Its length counts half of the gaps that
    bound it.

    Parameters
    ----------
    region, row : (n,) int arrays
        The entries' region (non-decreasing) and row (increasing within a region).
    read : (n,) int32 array
        The entries' level (:func:`band_reads`).
    kept : (n,) bool array
        The band rows (:func:`band_reads`).
    cos, sin, weight : (n,) float64 arrays
        The entries' weighted stair phasor and weight.
    theta : (n,) float64 array
        The entries' stair phase, radians.
    levels : (L,) float64 array
        The level phases as observed, radians.
    half_gap : (L,) float64 array
        Half the distance from each level to its nearest other one, radians.

    Returns
    -------
    tuple of (runs,) arrays
        ``region, y0, y1`` (int64), ``length, cos, sin, weight, misfit`` (float64),
        ``uid`` (int32), ``top_ok, bottom_ok`` (bool): each run's sums and the mean
        distance of its rows from their level, in units of ``half_gap``, weighted.

    Examples
    --------
    Six rows of one region, three read as level 0 and three as level 1:

    >>> one = np.ones(6)
    >>> runs = band_runs(np.ones(6, np.int64), np.arange(6), np.int32([0, 0, 0, 1, 1, 1]),
    ...                  np.ones(6, bool), one, 0 * one, one, np.array([0, 0, 0, 3, 3, 3.0]),
    ...                  np.array([0.0, 3.0]), np.array([1.5, 1.5]))
    >>> y0, y1, length, top_ok, bottom_ok = runs[1], runs[2], runs[3], runs[9], runs[10]
    >>> y0.tolist(), y1.tolist(), length.tolist(), top_ok.tolist(), bottom_ok.tolist()
    ([0, 3], [2, 5], [3.0, 3.0], [False, True], [True, False])
    """
    n = region.size
    runs = 0  # at most one a kept entry: the arrays are cut to the runs found
    for i in range(n):
        runs += kept[i]
    reg = np.empty(runs, np.int64)
    y0 = np.empty(runs, np.int64)
    y1 = np.empty(runs, np.int64)
    length = np.empty(runs, np.float64)
    cw = np.zeros(runs, np.float64)
    sw = np.zeros(runs, np.float64)
    ww = np.zeros(runs, np.float64)
    off = np.zeros(runs, np.float64)
    uid = np.empty(runs, np.int32)
    top_ok = np.zeros(runs, np.bool_)
    bottom_ok = np.zeros(runs, np.bool_)
    half_top = np.zeros(runs, np.float64)
    r = -1
    prev = -1
    for i in range(n):
        if not kept[i]:
            continue
        soft = prev >= 0 and _goes_on(region, row, prev, i)
        if prev < 0 or not soft or read[i] != read[prev]:
            r += 1
            reg[r], y0[r], uid[r] = region[i], row[i], read[i]
            top_ok[r] = soft  # (and the level changed: a new run that goes on)
            if soft:
                half_top[r] = (row[i] - row[prev] - 1) / 2.0
        y1[r] = row[i]
        cw[r] += cos[i]
        sw[r] += sin[i]
        off[r] += _wrapped_abs(theta[i] - levels[read[i]]) / half_gap[read[i]] * weight[i]
        ww[r] += weight[i]
        prev = i
    runs = r + 1
    misfit = np.empty(runs, np.float64)
    for r in range(runs):
        bottom_ok[r] = r + 1 < runs and top_ok[r + 1]
        half_bottom = half_top[r + 1] if bottom_ok[r] else 0.0
        length[r] = np.float64(y1[r] - y0[r] + 1) + half_top[r] + half_bottom
        misfit[r] = off[r] / (ww[r] if (ww[r] != ww[r] or ww[r] >= 1e-12) else 1e-12)
    return (reg[:runs], y0[:runs], y1[:runs], length[:runs], cw[:runs], sw[:runs],
            ww[:runs], misfit, uid[:runs], top_ok[:runs], bottom_ok[:runs])


@_numba_inline
def _goes_on(region: np.ndarray, row: np.ndarray, prev: int, i: int) -> bool:
    """Kept entry ``i`` follows kept entry ``prev`` in one region, the rows between them
    (at most three) all dropped entries."""
    gap = row[i] - row[prev] - 1
    return region[i] == region[prev] and gap == i - prev - 1 and gap <= 3


@kernel()
def band_evidence(region: np.ndarray, uid: np.ndarray, weight: np.ndarray,
                  length: np.ndarray, misfit: np.ndarray, complete: np.ndarray,
                  heights: np.ndarray, levels: np.ndarray, stairs: int, partitions: int,
                  local_share: float, default_height: float, n_regions: int) -> np.ndarray:
    """The order evidence of every region from its band runs (the loop of
    :func:`bistair.codecs.bidirectional.evidence.region_evidence`, whose docstring says
    what it weighs).

    Parameters
    ----------
    region : (n,) int array
        The runs' regions, non-decreasing.
    uid : (n,) int array
        The runs' levels (indices into ``levels``).
    weight, length, misfit : (n,) float64 arrays
        The runs' weight, length in rows and level misfit.
    complete : (n,) bool array
        Runs bounded by other runs above and below.
    heights : (n_regions + 1,) float64 array
        Group height per region, camera rows (NaN: ``default_height``).
    levels : (L,) float64 array
        Nominal phases of the union levels, radians.
    stairs, partitions : int
        ``S`` and ``P``.
    local_share : float
        Local rows over group rows.
    default_height : float
        Group height where a region has none.
    n_regions : int
        The highest region label.

    Returns
    -------
    (n_regions + 1, S*P) float64 array
        Evidence per region and order (zero for regions without runs or whose rows read
        between levels).

    Examples
    --------
    One region of order 5 with ``S = 4``, ``P = 3``: its bands read local level 1 (10 rows
    of a 16-row group) and partition level 1 (6 rows), alternately:

    >>> from bistair.codecs.bidirectional.bands import nearest_level, union_levels
    >>> from bistair.core.stair import stair_level_phase
    >>> levels = union_levels(3, 4)
    >>> uid = nearest_level(np.array([stair_level_phase(1, 4), stair_level_phase(1, 3)]),
    ...                     levels)[[0, 1, 0, 1]].astype(np.int64)
    >>> ev = band_evidence(np.ones(4, np.int64), uid, np.full(4, 10.0),
    ...                    np.array([10.0, 6, 10, 6]), np.zeros(4),
    ...                    np.array([False, True, True, False]), np.array([np.nan, 16.0]),
    ...                    levels, 4, 3, 10 / 16, 16.0, 1)
    >>> ev.shape, int(ev[1].argmax()), float(ev[1].max())
    ((2, 12), 5, 1.0)
    """
    S, P = stairs, partitions
    ev = np.zeros((n_regions + 1, S * P), np.float64)
    f_loc, f_par = local_share, 1.0 - local_share
    cls_w = np.zeros(levels.size, np.float64)
    cls_long = np.zeros(levels.size, np.float64)  # the longest run of each level
    n = region.size
    lo = 0
    while lo < n:
        hi = lo + 1
        while hi < n and region[hi] == region[lo]:
            hi += 1
        r = region[lo]
        h = heights[r] if np.isfinite(heights[r]) else default_height
        total = 0.0
        rows = 0.0
        off = 0.0
        longest = -np.inf
        for i in range(lo, hi):
            total += weight[i]
            rows += length[i]
            off += misfit[i] * weight[i]
            longest = max(longest, length[i])
        row_weight = total / max(rows, 1.0)
        if off > 0.32 * total:  # rows read between levels: blurred together, no order
            lo = hi
            continue
        for i in range(lo, hi):
            cls_w[uid[i]] = 0.0
            cls_long[uid[i]] = -np.inf
        for i in range(lo, hi):
            cls_w[uid[i]] += weight[i]
            cls_long[uid[i]] = max(cls_long[uid[i]], length[i])
        x, y = _two_heaviest(uid, lo, hi, cls_w)
        if y >= 0 and (cls_w[y] < 0.05 * total or cls_long[y] < 2):
            y = -1
        th_x = levels[x]
        if y < 0:
            a, b = _quantize(th_x, S), _quantize(th_x, P)
            if longest >= 1.3 * max(f_loc, f_par) * h:
                fit = _level_misfit(th_x, a, S) + _level_misfit(th_x, b, P)
                ev[r, a + S * b] = cls_w[x] / total - 0.5 * fit
            else:
                share = 0.4 * cls_w[x] / total
                for k in range(S * P):
                    if k % S == a or k // S == b:
                        ev[r, k] = share
            lo = hi
            continue
        th_y = levels[y]
        cost_xy = _length_cost(uid, length, complete, lo, hi, x, y, f_loc * h, f_par * h)
        cost_yx = _length_cost(uid, length, complete, lo, hi, y, x, f_loc * h, f_par * h)
        low = min(cost_xy, cost_yx)
        pen_xy = 0.5 * min(1.0, cost_xy - low)
        pen_yx = 0.5 * min(1.0, cost_yx - low)
        # a class seen in 3 or more rows' worth of pixels is certain
        e_x = _minimum(1.0, cls_w[x] / (3.0 * row_weight))
        e_y = _minimum(1.0, cls_w[y] / (3.0 * row_weight))
        ax, bx, ay, by = _quantize(th_x, S), _quantize(th_x, P), _quantize(th_y, S), \
            _quantize(th_y, P)
        fit_xy = _level_misfit(th_x, ax, S) + _level_misfit(th_y, by, P)
        fit_yx = _level_misfit(th_y, ay, S) + _level_misfit(th_x, bx, P)
        for k in range(S * P):
            a_k, b_k = k % S, k // S
            hits_xy = e_x * (1.0 if a_k == ax else -1.0) + e_y * (1.0 if b_k == by else -1.0)
            hits_yx = e_y * (1.0 if a_k == ay else -1.0) + e_x * (1.0 if b_k == bx else -1.0)
            s_xy = hits_xy / (e_x + e_y) - 0.5 * fit_xy - pen_xy
            s_yx = hits_yx / (e_y + e_x) - 0.5 * fit_yx - pen_yx
            ev[r, k] = s_xy if (s_xy != s_xy or s_xy >= s_yx) else s_yx  # NaN, as np.max
        lo = hi
    return ev


@_numba_inline
def _minimum(a: float, b: float) -> float:
    """``np.minimum``: NaN if either is."""
    if a != a or b != b:
        return np.nan
    return a if a <= b else b


@_numba_inline
def _two_heaviest(uid: np.ndarray, lo: int, hi: int, cls_w: np.ndarray) -> tuple[int, int]:
    """The levels of runs ``lo..hi-1`` with the largest and second largest weight (ties:
    the higher level first; -1 where there is no second)."""
    x = -1
    y = -1
    for i in range(lo, hi):
        u = uid[i]
        if u == x or u == y:
            continue
        if x < 0 or cls_w[u] > cls_w[x] or (cls_w[u] == cls_w[x] and u > x):
            x, y = u, x
        elif y < 0 or cls_w[u] > cls_w[y] or (cls_w[u] == cls_w[y] and u > y):
            y = u
    return x, y


@_numba_inline
def _quantize(theta: float, levels: int) -> int:
    """:func:`bistair.core.stair.quantize` of one phase."""
    two_pi = 2.0 * math.pi
    return int(math.floor(((theta + math.pi) % two_pi) * levels / two_pi)) % levels


@_numba_inline
def _level_misfit(theta: float, level: int, levels: int) -> float:
    """:func:`bistair.core.stair.level_misfit` of one phase."""
    two_pi = 2.0 * math.pi
    phase = -math.pi + math.pi / levels + two_pi * level / levels
    d = (theta - phase + math.pi) % two_pi
    return ((d - math.pi) / (math.pi / levels)) ** 2


@_numba_inline
def _length_cost(uid: np.ndarray, length: np.ndarray, complete: np.ndarray, lo: int,
                 hi: int, loc: int, par: int, h_loc: float, h_par: float) -> float:
    """How badly the run lengths fit the local (level ``loc``) and partition (``par``)
    heights: summed squared log-ratios; a band cut by the region's edge only must not be
    over 1.25 times as long."""
    cost = 0.0
    slack = math.log(1.25)
    for i in range(lo, hi):
        if uid[i] == loc:
            expect = h_loc
        elif uid[i] == par:
            expect = h_par
        else:
            continue
        ratio = math.log(max(length[i], 0.5) / expect)
        if complete[i]:
            cost += ratio * ratio
        else:
            over = max(ratio - slack, 0.0)
            cost += over * over
    return cost
