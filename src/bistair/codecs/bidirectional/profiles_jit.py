"""Compiled passes of the row profiles (:mod:`.profiles`): sums per (region label, image
row), kept only for the pairs that have pixels, of any values or of the stair values
computed as they are summed.

A region decoder reads each fringe region row by row. Summing into a bin for every
(label, row) pair would take ``(labels + 1) * H`` bins, which a noisy 12 MP capture with
ten thousand small regions turns into gigabytes; here each row lists its own labels first
(:func:`row_entries`), the sums go to those entries only, and :func:`label_major` puts
them in (label, row) order. The sums are float64, each pair's pixels added in raster
order, as ``np.bincount`` adds them.

Examples
--------
>>> labels = np.array([[1, 1, 2], [0, 2, 2]], np.int32)
>>> start, entry = row_entries(labels, 2)
>>> start.tolist(), entry.tolist()
([0, 2, 3], [1, 2, 2])
"""

from __future__ import annotations

import math

import numpy as np

from ...core.jit import called, fmax, fmin, inline, kernel
from ...core.memory import row_bands
from ...core.regions_jit import TILE

prange = range  # numba's prange once the first kernel of this module compiles
BLOCK = 32  # rows per task of the parallel loops
TWO_PI = 2.0 * math.pi


@called
def _row_labels(labels: np.ndarray, n_labels: int, y0: int, y1: int, start: np.ndarray,
                entry: np.ndarray, write: bool) -> None:
    """Rows ``y0 .. y1-1``: the number of distinct labels (> 0) into ``start[y + 1]``, or,
    with ``write``, the labels in order of first appearance into ``entry[start[y]:]``."""
    w = labels.shape[1]
    seen = np.zeros(n_labels + 1, np.bool_)
    ids = np.empty(w, np.int32)
    for y in range(y0, y1):
        m = 0
        for x in range(w):
            lab = labels[y, x]
            if lab > 0 and not seen[lab]:
                seen[lab] = True
                ids[m] = lab
                m += 1
        for i in range(m):
            seen[ids[i]] = False
            if write:
                entry[start[y] + i] = ids[i]
        if not write:
            start[y + 1] = m


@kernel(parallel=True)
def row_entries(labels: np.ndarray, n_labels: int) -> tuple[np.ndarray, np.ndarray]:
    """Each row's distinct labels: ``(start (H+1,), entry (K,))``, row ``y``'s labels (in
    order of first appearance) at ``entry[start[y]:start[y+1]]``.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels, 0 outside any.
    n_labels : int
        Highest label.

    Returns
    -------
    start : (H+1,) int64 array
        Where each row's entries begin.
    entry : (K,) int32 array
        The label of each entry.

    Examples
    --------
    >>> start, entry = row_entries(np.array([[2, 0, 1, 2]], np.int32), 2)
    >>> start.tolist(), entry.tolist()
    ([0, 2], [2, 1])
    """
    h = labels.shape[0]
    start = np.zeros(h + 1, np.int64)
    none = np.empty(0, np.int32)
    for b in prange((h + BLOCK - 1) // BLOCK):
        _row_labels(labels, n_labels, b * BLOCK, min(b * BLOCK + BLOCK, h), start, none,
                    False)
    for y in range(h):
        start[y + 1] += start[y]
    entry = np.empty(start[h], np.int32)
    for b in prange((h + BLOCK - 1) // BLOCK):
        _row_labels(labels, n_labels, b * BLOCK, min(b * BLOCK + BLOCK, h), start, entry,
                    True)
    return start, entry


@kernel()
def label_major(start: np.ndarray, entry: np.ndarray, count: np.ndarray, acc: np.ndarray,
                n_labels: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-entry counts and sums in (label, row) order: ``(keys, counts, sums)``,
    ``keys = label * H + row`` ascending.

    Parameters
    ----------
    start, entry : numpy.ndarray
        From :func:`row_entries`.
    count : (K,) int64 array
        Pixels per entry.
    acc : (V, K) float64 array
        Sums per entry.
    n_labels : int
        Highest label.

    Returns
    -------
    keys, counts : (K,) int64 arrays
    sums : (V, K) float64 array

    Examples
    --------
    >>> start, entry = np.array([0, 2, 3]), np.array([2, 1, 1], np.int32)
    >>> keys, counts, sums = label_major(start, entry, np.array([5, 6, 7]),
    ...                                  np.array([[0.5, 1.5, 2.5]]), 2)
    >>> keys.tolist(), counts.tolist(), sums.tolist()
    ([2, 3, 4], [6, 7, 5], [[1.5, 2.5, 0.5]])
    """
    h = start.size - 1
    k = entry.size
    nv = acc.shape[0]
    at = np.zeros(n_labels + 2, np.int64)
    for i in range(k):
        at[entry[i] + 1] += 1
    for lab in range(n_labels + 1):
        at[lab + 1] += at[lab]
    keys = np.empty(k, np.int64)
    counts = np.empty(k, np.int64)
    sums = np.empty((nv, k), np.float64)
    for y in range(h):  # rows in order: each label's rows ascend
        for i in range(start[y], start[y + 1]):
            lab = entry[i]
            p = at[lab]
            at[lab] += 1
            keys[p] = np.int64(lab) * h + y
            counts[p] = count[i]
            for v in range(nv):
                sums[v, p] = acc[v, i]
    return keys, counts, sums


@called
def _sum_rows(labels: np.ndarray, values: np.ndarray, n_labels: int, start: np.ndarray,
              entry: np.ndarray, y0: int, y1: int, count: np.ndarray, acc: np.ndarray
              ) -> None:
    """:func:`row_sums` of rows ``y0 .. y1-1``."""
    nv, _, w = values.shape
    slot = np.empty(n_labels + 1, np.int64)
    for y in range(y0, y1):
        for i in range(start[y], start[y + 1]):
            slot[entry[i]] = i
        for x in range(w):
            lab = labels[y, x]
            if lab > 0:
                i = slot[lab]
                count[i] += 1
                for v in range(nv):
                    acc[v, i] += np.float64(values[v, y, x])


@kernel(parallel=True)
def row_sums(labels: np.ndarray, values: np.ndarray, n_labels: int, start: np.ndarray,
             entry: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixels and float64 sums of ``values`` (V, H, W) per entry of :func:`row_entries`.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels, 0 outside any.
    values : (V, H, W) float32 array
        The V quantities to sum.
    n_labels : int
        Highest label.
    start, entry : numpy.ndarray
        From :func:`row_entries`.

    Returns
    -------
    count : (K,) int64 array
    acc : (V, K) float64 array

    Examples
    --------
    >>> labels = np.array([[1, 1, 2]], np.int32)
    >>> count, acc = row_sums(labels, np.ones((1, 1, 3), np.float32), 2, *row_entries(labels, 2))
    >>> count.tolist(), acc.tolist()
    ([2, 1], [[2.0, 1.0]])
    """
    nv, h, _ = values.shape
    count = np.zeros(entry.size, np.int64)
    acc = np.zeros((nv, entry.size), np.float64)
    for b in prange((h + BLOCK - 1) // BLOCK):
        _sum_rows(labels, values, n_labels, start, entry, b * BLOCK,
                  min(b * BLOCK + BLOCK, h), count, acc)
    return count, acc


def label_row_sums(labels: np.ndarray, values: np.ndarray, n_labels: int
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sums of ``values`` (V, H, W) per (label, row) over the labelled pixels (label > 0):
    ``(keys, counts, sums (V, K))``, ``keys = label * H + row`` ascending. Float64 sums in
    raster order, as ``np.bincount`` adds them.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels, 0 outside any.
    values : (V, H, W) float32 array
        The V quantities to sum.
    n_labels : int
        Highest label.

    Returns
    -------
    keys : (K,) int64 array
        ``label * H + row`` of each (label, row) with pixels, ascending.
    counts : (K,) int64 array
        Pixels per key.
    sums : (V, K) float64 array
        Each quantity's sum per key.

    Examples
    --------
    >>> labels = np.array([[1, 1, 2], [0, 2, 2]], np.int32)
    >>> values = np.arange(6, dtype=np.float32).reshape(1, 2, 3)
    >>> [a.tolist() for a in label_row_sums(labels, values, 2)]
    [[2, 4, 5], [2, 1, 2], [[1.0, 2.0, 9.0]]]
    """
    start, entry = row_entries(labels, n_labels)
    count, acc = row_sums(labels, values, n_labels, start, entry)
    return label_major(start, entry, count, acc, n_labels)


@inline
def _stair_values(p: np.float32, cos_t: np.float32, sin_t: np.float32, sm: np.float32,
                  m: np.float32) -> tuple:
    """One pixel's ``weight * cos``, ``weight * sin``, ``weight`` and ``ratio`` in float32,
    as NumPy computes :func:`bistair.codecs.bidirectional.profiles.stair_values`' inputs:
    ``ratio = clip(stair_mod / max(mod, 1e-6), 0, 2)``, ``weight = core_weight(phi) *
    min(ratio, 1)`` (:func:`bistair.core.regions.core_weight`)."""
    tiny = np.float32(1e-6)
    zero, one, two = np.float32(0.0), np.float32(1.0), np.float32(2.0)
    ratio = fmin(fmax(sm / fmax(m, tiny), zero), two)
    core = fmin(fmax(fmin(p, np.float32(TWO_PI) - p) / np.float32(math.pi / 2),
                       np.float32(0.1)), one)
    weight = core * fmin(ratio, one)
    return weight * cos_t, weight * sin_t, weight, ratio


@called
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
    """Add the five values of :func:`bistair.codecs.bidirectional.profiles.stair_values`
    (``weight * cos``, ``weight * sin``, ``weight``, ``ratio``, the column; see
    :func:`_stair_values`), computed per pixel as they are summed, to
    the pixel ``count`` (K,) and sums ``acc`` (5, K) of the entries of
    :func:`row_entries` (of these rows: ``start`` has one more
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
        From :func:`row_entries` (``start`` of these rows).
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
    """:func:`label_row_sums` of the five values of
    :func:`bistair.codecs.bidirectional.profiles.stair_values`
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


@called
def _relabel_count(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray, n_labels: int,
                   y0: int, y1: int, count: np.ndarray) -> None:
    """Rows ``y0 .. y1-1``: the final labels ``remap[roots[labels]]`` written in place (as
    :func:`bistair.core.regions_labels_jit.relabel` writes them, a run of one label looked up
    once) and each row's distinct final labels (> 0) counted into ``count[y + 1]``."""
    w = labels.shape[1]
    stamp = np.zeros(n_labels + 1, np.int32)  # the row (+ 1) a label was last counted in
    for y in range(y0, y1):
        row = labels[y]
        mark = np.int32(y + 1)
        last = np.int32(0)
        final = np.int32(0)
        m = 0
        for x in range(w):
            lab = row[x]
            if lab != last:
                last = lab
                final = remap[roots[lab]]
                if final > 0 and stamp[final] != mark:
                    stamp[final] = mark
                    m += 1
            row[x] = final
        count[y + 1] = m


@called
def _stair_run_sums(labels: np.ndarray, phi: np.ndarray, cos_t: np.ndarray,
                    sin_t: np.ndarray, stair_mod: np.ndarray, mod: np.ndarray, n_labels: int,
                    y0: int, y1: int, start: np.ndarray, entry: np.ndarray,
                    count: np.ndarray, acc: np.ndarray) -> None:
    """Rows ``y0 .. y1-1`` (final labels): each row's labels in order of first appearance
    into ``entry[start[y]:]``, their pixels into ``count`` and the five stair values
    (:func:`_stair_values`, made for the row in a vector loop) added into ``acc``, pixel by
    pixel in raster order (a run of one label added in registers: the same float64 sums
    as one slot added to pixel by pixel)."""
    w = labels.shape[1]
    slot = np.empty(n_labels + 1, np.int64)
    stamp = np.zeros(n_labels + 1, np.int32)
    vc = np.empty(w, np.float32)
    vs = np.empty(w, np.float32)
    vw = np.empty(w, np.float32)
    vr = np.empty(w, np.float32)
    for y in range(y0, y1):
        p, c, s, sm, m = phi[y], cos_t[y], sin_t[y], stair_mod[y], mod[y]
        for x in range(w):
            vc[x], vs[x], vw[x], vr[x] = _stair_values(p[x], c[x], s[x], sm[x], m[x])
        row = labels[y]
        mark = np.int32(y + 1)
        nxt = start[y]
        x = 0
        while x < w:
            lab = row[x]
            if lab == 0:
                x += 1
                continue
            if stamp[lab] != mark:
                stamp[lab] = mark
                slot[lab] = nxt
                entry[nxt] = lab
                nxt += 1
            i = slot[lab]
            a0, a1, a2, a3, a4 = acc[0, i], acc[1, i], acc[2, i], acc[3, i], acc[4, i]
            k = count[i]
            while x < w and row[x] == lab:
                a0 += np.float64(vc[x])
                a1 += np.float64(vs[x])
                a2 += np.float64(vw[x])
                a3 += np.float64(vr[x])
                a4 += np.float64(np.float32(x))
                k += 1
                x += 1
            acc[0, i], acc[1, i], acc[2, i], acc[3, i], acc[4, i] = a0, a1, a2, a3, a4
            count[i] = k


@kernel(parallel=True)
def relabel_sums(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray, phi: np.ndarray,
                 cos_t: np.ndarray, sin_t: np.ndarray, stair_mod: np.ndarray,
                 mod: np.ndarray, n_labels: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The final labels of a band of rows written in place
    (:func:`bistair.core.regions_labels_jit.relabel`, the hook its docstring describes) and, in
    the same visit of each tile of rows, the five values of
    :func:`bistair.codecs.bidirectional.profiles.stair_values` summed per (label, row):
    ``(start (R+1,), entry (K,), count (K,), acc (5, K))``, row ``y``'s labels in order of
    first appearance at ``entry[start[y]:start[y+1]]`` (as :func:`row_entries` lists
    them), float64 sums added pixel by pixel in raster order (as :func:`stair_sums`).

    Parameters
    ----------
    labels : (R, W) int32 array
        Provisional labels (:func:`bistair.core.regions_labels_jit.label_kept`), changed in
        place to the final ones.
    roots : int32 array
        The region of each provisional label.
    remap : (regions+1,) int32 array
        The final number of each region (0: dropped).
    phi, cos_t, sin_t, stair_mod, mod : (R, W) float32 arrays
        Wrapped phase, cosine and sine of the stair phase, modulation of the stair pair
        and of the fringes.
    n_labels : int
        The highest final label.

    Returns
    -------
    start : (R+1,) int64 array
    entry : (K,) int32 array
    count : (K,) int64 array
    acc : (5, K) float64 array

    Examples
    --------
    >>> one = np.ones((1, 4), np.float32)
    >>> labels = np.int32([[5, 5, 0, 7]])
    >>> roots = np.zeros(8, np.int32)
    >>> roots[5], roots[7] = 1, 2
    >>> start, entry, count, acc = relabel_sums(labels, roots, np.int32([0, 2, 1]),
    ...                                         np.pi * one, one, 0 * one, one, one, 2)
    >>> labels.tolist(), start.tolist(), entry.tolist(), count.tolist(), acc[4].tolist()
    ([[2, 2, 0, 1]], [0, 2], [2, 1], [2, 1], [1.0, 3.0])
    """
    h = labels.shape[0]
    tiles = (h + TILE - 1) // TILE
    start = np.zeros(h + 1, np.int64)
    for t in prange(tiles):
        _relabel_count(labels, roots, remap, n_labels, t * TILE, min(t * TILE + TILE, h),
                       start)
    for y in range(h):
        start[y + 1] += start[y]
    k = start[h]
    entry = np.empty(k, np.int32)
    count = np.zeros(k, np.int64)
    acc = np.zeros((5, k), np.float64)
    for t in prange(tiles):
        _stair_run_sums(labels, phi, cos_t, sin_t, stair_mod, mod, n_labels, t * TILE,
                        min(t * TILE + TILE, h), start, entry, count, acc)
    return start, entry, count, acc


def relabel_stair_sums(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray,
                       phi: np.ndarray, theta: np.ndarray, stair_mod: np.ndarray,
                       mod: np.ndarray, n_labels: int
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The final labels written in place (``remap[roots[labels]]``) and
    :func:`label_stair_sums` of them, gathered as they are written: a band of rows at a
    time (:func:`relabel_sums`, the cosine and sine of the band's stair phase from NumPy),
    no scan of the labels of its own. Returns ``(keys, counts, sums (5, K))``, ``keys =
    label * H + row`` ascending, float64 sums in raster order: what
    :func:`label_stair_sums` gives on the final labels, bit for bit.

    Parameters
    ----------
    labels : (H, W) int32 array
        Provisional labels (:func:`bistair.core.regions_labels_jit.label_kept`), changed in
        place to the final ones.
    roots : int32 array
        The region of each provisional label.
    remap : (regions+1,) int32 array
        The final number of each region (0: dropped).
    phi, theta, stair_mod, mod : (H, W) float32 arrays
        Wrapped phase, stair phase and the modulations of the stair pair and the fringes.
    n_labels : int
        The highest final label.

    Returns
    -------
    keys : (K,) int64 array
    counts : (K,) int64 array
    sums : (5, K) float64 array

    Examples
    --------
    >>> one = np.ones((2, 3), np.float32)
    >>> labels = np.int32([[3, 3, 0], [0, 3, 4]])
    >>> roots = np.int32([0, 0, 0, 1, 2])
    >>> keys, counts, sums = relabel_stair_sums(labels, roots, np.int32([0, 1, 2]),
    ...                                         np.pi * one, 0 * one, one, one, 2)
    >>> labels.tolist(), keys.tolist(), counts.tolist(), sums[4].tolist()
    ([[1, 1, 0], [0, 1, 2]], [2, 3, 5], [2, 1, 1], [1.0, 1.0, 2.0])
    """
    h = labels.shape[0]
    bands = row_bands(h)
    starts, entries = [np.zeros(1, np.int64)], [np.zeros(0, np.int32)]
    counts, sums = [np.zeros(0, np.int64)], [np.zeros((5, 0))]
    offset = 0
    for y0 in bands:
        rows = slice(y0, y0 + bands.step)
        t = theta[rows]
        start, entry, count, acc = relabel_sums(labels[rows], roots, remap, phi[rows],
                                                np.cos(t), np.sin(t), stair_mod[rows],
                                                mod[rows], n_labels)
        starts.append(start[1:] + offset)
        offset += int(start[-1])
        entries.append(entry)
        counts.append(count)
        sums.append(acc)
    return label_major(np.concatenate(starts), np.concatenate(entries),
                       np.concatenate(counts), np.concatenate(sums, axis=1), n_labels)


@kernel()
def profile_centroids(region: np.ndarray, row: np.ndarray, count: np.ndarray,
                      col_sum: np.ndarray, n_regions: int) -> np.ndarray:
    """The (row, column) centroid of each region from its row profiles, in one pass: the
    three ``np.bincount`` sums of :func:`~.profiles.profile_centroids` (pixels, row times
    pixels, column sums; float64, added in entry order), each over at least one pixel.

    Parameters
    ----------
    region, row, count : (n,) int arrays
        The entries' region (at least 0), row and pixel count.
    col_sum : (n,) float64 array
        The entries' sums of column indices.
    n_regions : int
        The highest region label (more rows where an entry's region is higher, as
        ``np.bincount``).

    Returns
    -------
    (max(n_regions, max(region)) + 1, 2) float64 array
        The centroids (0, 0 for a region without pixels).

    Examples
    --------
    >>> profile_centroids(np.array([1, 1]), np.array([0, 1]), np.array([2, 2]),
    ...                   np.array([1.0, 1.0]), 2).tolist()
    [[0.0, 0.0], [0.5, 0.5], [0.0, 0.0]]
    """
    m = n_regions + 1
    for i in range(region.size):
        m = max(m, region[i] + 1)
    pixels = np.zeros(m, np.float64)
    rows = np.zeros(m, np.float64)
    cols = np.zeros(m, np.float64)
    for i in range(region.size):
        r = region[i]
        pixels[r] += np.float64(count[i])
        rows[r] += np.float64(row[i] * count[i])
        cols[r] += col_sum[i]
    out = np.empty((m, 2), np.float64)
    for r in range(m):
        c = max(pixels[r], 1.0)
        out[r, 0] = rows[r] / c
        out[r, 1] = cols[r] / c
    return out
