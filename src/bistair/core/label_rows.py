"""Sums per (region label, image row), kept only for the pairs that have pixels.

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

import numpy as np

from .kernels import _numba_called, kernel

prange = range  # numba's prange once the first kernel of this module compiles
BLOCK = 32  # rows per task of the parallel loops


@_numba_called
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


@_numba_called
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
