"""Compiled passes of the band evidence (:mod:`.evidence`): each region's runs weighed as
evidence for its orders, and where a region's band values change (exactly what the NumPy
loops over regions gave, to 1e-12: sums in order, the C library's ``log``).
"""

from __future__ import annotations

import math

import numpy as np

from ...core.jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles


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


@inline
def _minimum(a: float, b: float) -> float:
    """``np.minimum``: NaN if either is."""
    if a != a or b != b:
        return np.nan
    return a if a <= b else b


@inline
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


@inline
def _quantize(theta: float, levels: int) -> int:
    """:func:`bistair.core.stair.quantize` of one phase."""
    two_pi = 2.0 * math.pi
    return int(math.floor(((theta + math.pi) % two_pi) * levels / two_pi)) % levels


@inline
def _level_misfit(theta: float, level: int, levels: int) -> float:
    """The squared distance of a phase from a stair level, in half steps (its NumPy
    reference: ``tests/support/reference.py:level_misfit``)."""
    two_pi = 2.0 * math.pi
    phase = -math.pi + math.pi / levels + two_pi * level / levels
    d = (theta - phase + math.pi) % two_pi
    return ((d - math.pi) / (math.pi / levels)) ** 2


@inline
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


@inline
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
def split_order(region: np.ndarray, row: np.ndarray, n_regions: int) -> np.ndarray:
    """The order of the row profiles by region, then row, after :func:`~.evidence.
    split_profiles` gave some of their tails new labels above ``n_regions``: a stable
    counting sort by region, the same as ``np.lexsort((row, region))`` where the entries
    were sorted by (region before the splits, row), each pair once; that lexsort otherwise
    (an empty order returned: the caller sorts).

    Parameters
    ----------
    region : (n,) int array
        The entries' regions after the splits, in ``0 ..`` (labels above ``n_regions`` the
        new ones).
    row : (n,) int array
        The entries' rows.
    n_regions : int
        The highest label before the splits.

    Returns
    -------
    (n,) int64 array
        The order, or (0,) where the rows of a region do not ascend in entry order.

    Examples
    --------
    >>> split_order(np.array([1, 1, 3, 3, 2]), np.array([0, 1, 2, 3, 0]), 2).tolist()
    [0, 1, 4, 2, 3]
    """
    n = region.size
    m = n_regions + 1
    for i in range(n):
        m = max(m, region[i] + 1)
    last = np.full(m, -1, np.int64)
    counts = np.zeros(m + 1, np.int64)
    for i in range(n):
        r = region[i]
        if row[i] <= last[r]:  # not ascending within the region: lexsort decides
            return np.zeros(0, np.int64)
        last[r] = row[i]
        counts[r + 1] += 1
    fill = np.cumsum(counts)[:-1]
    order = np.empty(n, np.int64)
    for i in range(n):
        r = region[i]
        order[fill[r]] = i
        fill[r] += 1
    return order
