"""Compiled loops of the band analysis: the row profiles of fringe regions read as stair
levels and cut into runs of one level (the passes of
:func:`bistair.codecs.bidirectional.bands.row_runs`).

Like :mod:`bistair.core.region_kernels` (same decorator, same helpers): each gives exactly
what the NumPy it replaces gave, float64 sums in the same order. The arctangents stay with
the caller: NumPy's vectorised ``arctan2`` and the C library's differ in the last bit.

The profile entries come sorted by region, then row (as
:class:`~bistair.codecs.bidirectional.bands.RowProfiles` keeps them).

Examples
--------
>>> import numpy as np
>>> region = np.array([1, 1, 1, 2])
>>> level = np.array([1.0, 0.2, 1.0, 1.0])
>>> theta = np.array([0.1, 0.1, 3.0, -3.1])
>>> core, c, s, w = band_sums(region, level, theta, np.ones(4), np.array([0.0, 3.0]))
>>> core.tolist(), w.tolist()
([True, False, True, True], [1.0, 2.0])
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
        distance of its rows from their level in ``half_gap``\\ s, weighted.
    """
    n = region.size
    runs = 0
    prev = -1
    for i in range(n):  # count the runs
        if kept[i]:
            if prev < 0 or not _goes_on(region, row, prev, i) or read[i] != read[prev]:
                runs += 1
            prev = i
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
    misfit = np.empty(runs, np.float64)
    for r in range(runs):
        bottom_ok[r] = r + 1 < runs and top_ok[r + 1]
        half_bottom = half_top[r + 1] if bottom_ok[r] else 0.0
        length[r] = np.float64(y1[r] - y0[r] + 1) + half_top[r] + half_bottom
        misfit[r] = off[r] / (ww[r] if (ww[r] != ww[r] or ww[r] >= 1e-12) else 1e-12)
    return reg, y0, y1, length, cw, sw, ww, misfit, uid, top_ok, bottom_ok


@_numba_inline
def _goes_on(region: np.ndarray, row: np.ndarray, prev: int, i: int) -> bool:
    """Kept entry ``i`` follows kept entry ``prev`` in one region, the rows between them
    (at most three) all dropped entries."""
    gap = row[i] - row[prev] - 1
    return region[i] == region[prev] and gap == i - prev - 1 and gap <= 3
