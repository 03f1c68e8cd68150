"""Compiled passes of the band analysis (:mod:`.bands`): the row profiles of fringe regions
read as stair levels and cut into runs of one level (the passes of
:func:`bistair.codecs.bidirectional.bands.row_runs`), and the per-region order statistics
they use.

Each gives exactly what the NumPy it replaces gave, float64 sums in the same order. The
arctangents stay with the caller: NumPy's vectorised ``arctan2`` and the C library's differ
in the last bit. The profile entries come sorted by region, then row (as
:class:`~bistair.codecs.bidirectional.profiles.RowProfiles` keeps them).

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

from ...core.jit import called, inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi


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
    ring = level_ring(levels)
    for i in range(n):
        core[i] = level[i] >= 0.7 * q[i]
        if core[i]:
            u = one_nearest_level(theta[i], levels, ring)
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
    ring = level_ring(levels)
    for i in range(n):
        read[i] = one_nearest_level(theta[i], levels, ring)
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
        off[r] += wrapped_abs(theta[i] - levels[read[i]]) / half_gap[read[i]] * weight[i]
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


@inline
def _goes_on(region: np.ndarray, row: np.ndarray, prev: int, i: int) -> bool:
    """Kept entry ``i`` follows kept entry ``prev`` in one region, the rows between them
    (at most three) all dropped entries."""
    gap = row[i] - row[prev] - 1
    return region[i] == region[prev] and gap == i - prev - 1 and gap <= 3


@inline
def wrapped_abs(x: float) -> float:
    """``abs((x + pi) % 2pi - pi)`` in float64, as NumPy computes it: how far an angle is
    from 0 around the circle (for the kernels here and in :mod:`.response_jit`).

    Parameters
    ----------
    x : float
        An angle in radians.

    Returns
    -------
    float
        Its distance from 0 on the circle, in ``[0, pi]``.

    Examples
    --------
    >>> round(wrapped_abs(2 * math.pi - 0.25), 6), round(wrapped_abs(-3.0), 6)
    (0.25, 3.0)
    """
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
    ring = level_ring(levels)
    for i in range(theta.size):
        out[i] = one_nearest_level(theta[i], levels, ring)
    return out


RING_GAP = 1e-9  # levels this far apart at least (radians) are searched as a ring


@inline
def level_ring(levels: np.ndarray) -> bool:
    """Whether the levels ascend in [-pi, pi), each at least ``RING_GAP`` from the next
    around the circle: then the nearest to a phase in [-pi, pi] is one of the two that
    bracket it (:func:`one_nearest_level`).

    Parameters
    ----------
    levels : (L,) float64 array
        Level phases in radians.

    Returns
    -------
    bool
        They form such a ring.

    Examples
    --------
    >>> bool(level_ring(np.array([-2.0, 0.0, 2.0]))), bool(level_ring(np.array([0.0, -2.0])))
    (True, False)
    """
    m = levels.size
    if m < 2:
        return False
    for j in range(m):
        if not -math.pi <= levels[j] < math.pi:  # (NaN too)
            return False
        if j > 0 and not levels[j] - levels[j - 1] >= RING_GAP:
            return False
    return levels[0] + TWO_PI - levels[m - 1] >= RING_GAP


@inline
def one_nearest_level(t: float, levels: np.ndarray, ring: bool) -> int:
    """One phase's :func:`nearest_levels`.

    On a ring of levels (:func:`level_ring`) a phase in [-pi, pi] is compared with the two
    levels that bracket it only, the lower index first (ties go to it, as ``argmin``): any
    other level lies beyond one of them, at least ``RING_GAP`` farther, far more than the
    distances' rounding. Otherwise every level, in order.

    Parameters
    ----------
    t : float
        A phase in radians.
    levels : (L,) float64 array
        Level phases in radians.
    ring : bool
        ``level_ring(levels)``.

    Returns
    -------
    int
        The index of the nearest level (the first of equally near ones).

    Examples
    --------
    >>> levels = np.array([-2.0, 0.0, 2.0])
    >>> one_nearest_level(3.1, levels, level_ring(levels))
    2
    """
    if ring and -math.pi <= t <= math.pi:
        m = levels.size
        hi = 0
        while hi < m and levels[hi] <= t:
            hi += 1
        if hi == 0 or hi == m:  # between the last level and the first, across the wrap
            a, b = 0, m - 1
        else:
            a, b = hi - 1, hi
        return a if wrapped_abs(t - levels[a]) <= wrapped_abs(t - levels[b]) else b
    best = 0
    low = wrapped_abs(t - levels[0])
    if low != low:
        return 0
    for j in range(1, levels.size):
        d = wrapped_abs(t - levels[j])
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


@called
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


@called
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


@inline
def _wrapped(x: float) -> float:
    """``(x + pi) % 2pi - pi`` in float64, as NumPy computes it (:func:`wrapped_abs`)."""
    a = x + math.pi
    if 0.0 <= a < TWO_PI:
        m = a
    elif TWO_PI <= a < 2.0 * TWO_PI:
        m = a - TWO_PI
    elif -TWO_PI < a < 0.0:
        m = a + TWO_PI
    else:
        m = a % TWO_PI
    return m - math.pi


@kernel()
def transitions(uid: np.ndarray, length: np.ndarray, theta: np.ndarray, top_ok: np.ndarray,
                bottom_ok: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
    """The runs of :func:`bistair.codecs.bidirectional.bands.row_runs` that are not bands
    (:func:`bistair.codecs.bidirectional.bands._drop_transitions` says which) and what
    dropping them leaves: ``(drop, length, top_ok, bottom_ok, any)``, an inner transition's
    length given half to each neighbour (the one above first, then the one below, as two
    ``np.add.at`` add them), the band next to a dropped ragged end no longer bounded there.
    The same float64 values as the NumPy it replaced (``tests/support/labelspace_before.py``).

    Parameters
    ----------
    uid : (n,) int32 array
        Stair level of each run.
    length, theta : (n,) float64 arrays
        Rows and circular mean stair phase of each run.
    top_ok, bottom_ok : (n,) bool arrays
        Bounded above / below by another run of the same region.

    Returns
    -------
    drop : (n,) bool array
    length : (n,) float64 array
    top_ok, bottom_ok : (n,) bool arrays
    any : bool
        Whether any run is dropped (else the other arrays are the inputs' values).

    Raises
    ------
    IndexError
        The last run an inner transition (its half for the run below has nowhere to go), as
        ``np.add.at`` raised.

    Examples
    --------
    >>> uid, length = np.int32([1, 2, 3]), np.array([10.0, 2.0, 10.0])
    >>> ok = np.array([False, True, True]), np.array([True, True, False])
    >>> drop, length, top, bottom, some = transitions(uid, length, np.array([0.0, 0.5, 1.0]),
    ...                                               *ok)
    >>> drop.tolist(), length.tolist(), some
    ([False, True, False], [11.0, 2.0, 11.0], True)
    """
    n = uid.size
    drop = np.zeros(n, np.bool_)
    inner = np.zeros(n, np.bool_)
    top_end = np.zeros(n, np.bool_)
    bottom_end = np.zeros(n, np.bool_)
    some = False
    for i in range(n):
        prev_uid = uid[i - 1] if i > 0 else -1
        next_uid = uid[i + 1] if i < n - 1 else -1
        prev_len = length[i - 1] if i > 0 else 0.0
        next_len = length[i + 1] if i < n - 1 else 0.0
        prev_theta = theta[i - 1] if i > 0 else theta[0]
        next_theta = theta[i + 1] if i < n - 1 else theta[n - 1]
        to_here = _wrapped(theta[i] - prev_theta)
        to_next = _wrapped(next_theta - prev_theta)
        between = to_here * to_next > 0 and abs(to_here) < abs(to_next)
        short = length[i] <= 2.0
        inner[i] = ((short or (between and length[i] <= 0.4 * min(prev_len, next_len)))
                    and top_ok[i] and bottom_ok[i] and prev_uid != next_uid)
        top_end[i] = short and not top_ok[i] and bottom_ok[i]
        bottom_end[i] = short and top_ok[i] and not bottom_ok[i]
        drop[i] = inner[i] or top_end[i] or bottom_end[i]
        some = some or drop[i]
    out = length.copy()
    top = top_ok.copy()
    bottom = bottom_ok.copy()
    if not some:
        return drop, out, top, bottom, False
    for j in range(n):  # as np.add.at(length, j - 1, ...): index -1 is the last run
        if inner[j]:
            out[j - 1 if j > 0 else n - 1] += length[j] / 2
    for j in range(n):
        if inner[j]:
            if j + 1 >= n:
                raise IndexError("index out of bounds")
            out[j + 1] += length[j] / 2
    for i in range(1, n):
        top[i] = top[i] and not top_end[i - 1]
        bottom[i - 1] = bottom[i - 1] and not bottom_end[i]
    return drop, out, top, bottom, True
