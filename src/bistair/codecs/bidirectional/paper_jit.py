"""Compiled passes of the paper's column scan (:mod:`.paper`): the median filter down the
columns, the runs of equal code in each column and the mode of the runs' orders per fringe,
bit for bit the SciPy and NumPy they replace.

The passes read the images row by row (each thread a block of columns, one state per
column), so that no transposed copy is made.

Examples
--------
>>> import numpy as np
>>> code = np.int32([[0], [0], [0], [1], [0], [2], [2], [2], [-1], [3]])
>>> runs = column_runs(code, np.zeros(code.shape, np.float32), np.ones(code.shape,
...                    np.float32), min_run=3)
>>> runs.col.tolist(), runs.start.tolist(), runs.length.tolist(), runs.first.tolist()
([0, 0, 0], [0, 5, 9], [5, 3, 1], [True, False, True])
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ...core.jit import called, kernel

prange = range  # numba's prange once the first kernel of this module compiles


_BLOCK = 64  # columns per thread block in the column scans


@kernel(parallel=True)
def _median_rows(code: np.ndarray, valid: np.ndarray, size: int) -> np.ndarray:
    h, w = code.shape
    out = np.empty((h, w), code.dtype)
    half = size // 2
    for y in prange(h):
        if size == 5:  # min/max network: the median of five
            r0, r1 = max(y - 2, 0), max(y - 1, 0)
            r3, r4 = min(y + 1, h - 1), min(y + 2, h - 1)
            for x in range(w):
                a, b, c = code[r0, x], code[r1, x], code[y, x]
                d, e = code[r3, x], code[r4, x]
                f = max(min(a, b), min(d, e))
                g = min(max(a, b), max(d, e))
                m = max(min(f, g), min(max(f, g), c))
                out[y, x] = m if valid[y, x] else -1
        else:
            buf = np.empty(size, code.dtype)
            for x in range(w):
                for i in range(size):  # insertion sort of the window
                    v = code[min(max(y - half + i, 0), h - 1), x]
                    j = i
                    while j > 0 and buf[j - 1] > v:
                        buf[j] = buf[j - 1]
                        j -= 1
                    buf[j] = v
                out[y, x] = buf[half] if valid[y, x] else -1
    return out


def column_median(code: np.ndarray, valid: np.ndarray, size: int) -> np.ndarray:
    """``np.where(valid, scipy.ndimage.median_filter(code, size=(size, 1),
    mode="nearest"), -1)``: the median of ``size`` pixels down each column (edge rows
    repeated), -1 outside ``valid``.

    Parameters
    ----------
    code : (H, W) int array
        The values to filter.
    valid : (H, W) bool array
        Where the filtered value is kept.
    size : int
        Pixels in the window (rows ``y - size // 2`` to ``y - size // 2 + size - 1``).

    Returns
    -------
    (H, W) array
        The filtered values, ``code``'s dtype.

    Raises
    ------
    TypeError
        ``code`` is not of an integer dtype.

    Examples
    --------
    >>> code = np.int32([[3], [1], [4], [1], [5], [9]])
    >>> column_median(code, np.ones(code.shape, bool), 3).ravel().tolist()
    [3, 3, 1, 4, 5, 9]
    """
    code = np.ascontiguousarray(code)
    if not np.issubdtype(code.dtype, np.integer):
        raise TypeError(f"column_median takes integers, not {code.dtype}")
    return _median_rows(code, np.ascontiguousarray(valid, np.bool_), int(max(size, 1)))


@kernel(parallel=True)
def _count_runs(code: np.ndarray, min_run: int) -> np.ndarray:
    h, w = code.shape
    count = np.zeros(w, np.int64)
    for b in prange((w + _BLOCK - 1) // _BLOCK):
        x0, x1 = b * _BLOCK, min((b + 1) * _BLOCK, w)
        runs = np.zeros(_BLOCK, np.int64)
        for y in range(h):
            for x in range(x0, x1):
                c = code[y, x]
                p = code[y - 1, x] if y > 0 else -1
                if c < 0 or c == p:
                    continue
                if p < 0:  # a stretch starts: its first run is kept
                    runs[x - x0] += 1
                    continue
                kept = y + min_run <= h  # another run: kept if min_run pixels long
                k = 1
                while kept and k < min_run:
                    kept = code[y + k, x] == c
                    k += 1
                runs[x - x0] += kept
        for x in range(x0, x1):
            count[x] = runs[x - x0]
    return count


@called
def _store(i: int, start: np.ndarray, length: np.ndarray, first: np.ndarray,
           sum_sin: np.ndarray, sum_cos: np.ndarray, m_start: int, m_len: int,
           m_first: bool, m_sin: float, m_cos: float) -> None:
    """Write run ``i``."""
    start[i], length[i], first[i] = m_start, m_len, m_first
    sum_sin[i], sum_cos[i] = m_sin, m_cos


@kernel(parallel=True)
def _scan(code: np.ndarray, sin: np.ndarray, cos: np.ndarray, min_run: int,
          offsets: np.ndarray, start: np.ndarray, length: np.ndarray, first: np.ndarray,
          sum_sin: np.ndarray, sum_cos: np.ndarray) -> None:
    h, w = code.shape
    for b in prange((w + _BLOCK - 1) // _BLOCK):
        x0, x1 = b * _BLOCK, min((b + 1) * _BLOCK, w)
        at = offsets[x0:x1].copy()  # the next run's index, per column
        prev = np.full(_BLOCK, -1, np.int64)  # code of the pixel above (-1: none)
        m_start = np.zeros(_BLOCK, np.int64)  # the run being built (short runs joined)
        m_len = np.zeros(_BLOCK, np.int64)  # 0: none yet in the stretch
        m_first = np.zeros(_BLOCK, np.bool_)
        m_sin = np.zeros(_BLOCK, np.float64)
        m_cos = np.zeros(_BLOCK, np.float64)
        r_start = np.zeros(_BLOCK, np.int64)  # the raw run of equal code under way
        r_len = np.zeros(_BLOCK, np.int64)
        r_sin = np.zeros(_BLOCK, np.float64)
        r_cos = np.zeros(_BLOCK, np.float64)
        for y in range(h + 1):  # row h: past the end, every stretch ends
            beyond = y == h
            row = min(y, h - 1)
            c_row, s_row, k_row = code[row, x0:x1], sin[row, x0:x1], cos[row, x0:x1]
            for j in range(x1 - x0):
                c = np.int64(-1) if beyond else np.int64(c_row[j])
                p = prev[j]
                if c >= 0 and c == p:  # the raw run goes on
                    r_len[j] += 1
                    r_sin[j] += s_row[j]
                    r_cos[j] += k_row[j]
                    continue
                x = x0 + j
                if p >= 0:  # a raw run ends
                    if m_len[j] == 0 or r_len[j] >= min_run:  # kept: a stretch's first too
                        if m_len[j] > 0:  # the run above is done
                            _store(at[j], start, length, first, sum_sin, sum_cos,
                                   m_start[j], m_len[j], m_first[j], m_sin[j], m_cos[j])
                            at[j] += 1
                        m_first[j] = m_len[j] == 0
                        m_start[j], m_len[j] = r_start[j], r_len[j]
                        m_sin[j], m_cos[j] = r_sin[j], r_cos[j]
                    else:  # short: its pixels join the run above, one by one, in order
                        for yy in range(r_start[j], r_start[j] + r_len[j]):
                            m_sin[j] += sin[yy, x]
                            m_cos[j] += cos[yy, x]
                        m_len[j] += r_len[j]
                    if c < 0:  # the stretch ends
                        _store(at[j], start, length, first, sum_sin, sum_cos, m_start[j],
                               m_len[j], m_first[j], m_sin[j], m_cos[j])
                        at[j] += 1
                        m_len[j] = 0
                prev[j] = c
                if c >= 0:
                    r_start[j], r_len[j] = y, 1
                    r_sin[j], r_cos[j] = s_row[j], k_row[j]


class ColumnRuns(NamedTuple):
    """Runs of equal code down the columns, column by column, each top to bottom."""

    offsets: np.ndarray  # (W+1,) int64: column x's runs are offsets[x]:offsets[x+1]
    start: np.ndarray  # (n,) int64 first row
    length: np.ndarray  # (n,) int64 pixels (its own and those of the short runs joined)
    first: np.ndarray  # (n,) bool: the first run of a stretch of valid pixels
    sum_sin: np.ndarray  # (n,) float64 sums of ``sin`` and ``cos`` over its pixels, in order
    sum_cos: np.ndarray

    @property
    def col(self) -> np.ndarray:
        """(n,) int64 column of each run."""
        return np.repeat(np.arange(self.offsets.size - 1), np.diff(self.offsets))


def column_runs(code: np.ndarray, sin: np.ndarray, cos: np.ndarray,
                min_run: int) -> ColumnRuns:
    """Runs of equal ``code`` (>= 0) down each column, a run shorter than ``min_run``
    joined to the run above it in its stretch of valid pixels (a stretch's first run is
    always kept), with the float64 sums of ``sin`` and ``cos`` over each run's pixels.

    The runs are numbered column by column, top to bottom (the order of the pixels of
    ``code.T.ravel()``), and each run's sums add its pixels in that order from 0.0, as
    ``np.bincount(run_of_pixel, weights)`` does.

    Parameters
    ----------
    code : (H, W) int array
        The code per pixel, negative where invalid.
    sin, cos : (H, W) float arrays
        The values summed per run (any float dtype, added as float64).
    min_run : int
        The shortest run kept on its own.

    Returns
    -------
    ColumnRuns
        The runs: column offsets, first row, length, stretch start, sums.

    Raises
    ------
    ValueError
        ``code`` is not 2-D or ``sin`` and ``cos`` are not of its shape.

    Examples
    --------
    >>> code = np.int32([[1, -1], [1, 2], [0, 2], [1, 2]])
    >>> ones = np.ones(code.shape, np.float32)
    >>> runs = column_runs(code, ones, ones, min_run=2)
    >>> runs.offsets.tolist(), runs.start.tolist(), runs.length.tolist()
    ([0, 1, 2], [0, 1], [4, 3])
    >>> runs.sum_sin.tolist(), runs.first.tolist()
    ([4.0, 3.0], [True, True])
    """
    code = np.ascontiguousarray(code)
    sin, cos = np.ascontiguousarray(sin), np.ascontiguousarray(cos)
    if code.ndim != 2 or sin.shape != code.shape or cos.shape != code.shape:
        raise ValueError("column_runs takes 2-D code, sin and cos of one shape")
    h, w = code.shape
    min_run = max(int(min_run), 1)
    offsets = np.zeros(w + 1, np.int64)
    np.cumsum(_count_runs(code, min_run), out=offsets[1:])  # where each column's runs go
    n = int(offsets[-1])
    runs = ColumnRuns(offsets, np.empty(n, np.int64), np.empty(n, np.int64),
                      np.empty(n, np.bool_), np.empty(n), np.empty(n))
    if n:
        _scan(code, sin, cos, min_run, offsets, *runs[1:])
    return runs


@kernel(parallel=True)
def _vote(labels: np.ndarray, offsets: np.ndarray, start: np.ndarray, length: np.ndarray,
          value: np.ndarray, n_values: int, counts: np.ndarray) -> None:
    h, w = labels.shape
    chunks = counts.shape[0]
    for k in prange(chunks):  # run by run down the columns (a block's rows stay cached)
        for x in range(k * w // chunks, (k + 1) * w // chunks):
            for p in range(offsets[x], offsets[x + 1]):
                v = np.int64(value[p])
                if v < 0 or v >= n_values:
                    continue
                for y in range(start[p], start[p] + length[p]):
                    lab = np.int64(labels[y, x])
                    if lab > 0:
                        counts[k, lab * n_values + v] += 1


def run_label_modes(labels: np.ndarray, runs: ColumnRuns, value: np.ndarray, n_labels: int,
                    n_values: int, chunks: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """The most frequent value per label (``tests/support/reference.py:mode_by_label``) of
    ``labels`` and of the image whose pixels take their run's ``value`` (-1 outside every
    run), without making that image.

    Parameters
    ----------
    labels : (H, W) int array
        Region label per pixel (0: none).
    runs : ColumnRuns
        Runs of the image's columns (:func:`column_runs`).
    value : (n,) int array
        Value per run; negative values and values from ``n_values`` on abstain.
    n_labels, n_values : int
        Highest label; values run 0 .. n_values-1.
    chunks : int, default 4
        Column blocks counted apart (in parallel), each with its own counts.

    Returns
    -------
    mode : (n_labels + 1,) int64 array
        The most frequent value per label (the smallest of ties), -1 where no vote.
    support : (n_labels + 1,) int64 array
        Its count.

    Examples
    --------
    >>> code = np.int32([[0, 1], [0, 1], [0, 1]])
    >>> runs = column_runs(code, *np.zeros((2, 3, 2), np.float32), min_run=1)
    >>> labels = np.int32([[1, 1], [1, 2], [0, 2]])
    >>> mode, support = run_label_modes(labels, runs, np.array([3, 5]), 2, 6)
    >>> mode.tolist(), support.tolist()
    ([-1, 3, 5], [0, 2, 2])
    """
    labels = np.ascontiguousarray(labels)
    h, w = labels.shape
    chunks = max(1, min(int(chunks), w))
    counts = np.zeros((chunks, (n_labels + 1) * n_values), np.int64)
    if runs.start.size:
        _vote(labels, runs.offsets, runs.start, runs.length, np.asarray(value), int(n_values),
              counts)
    total = counts.sum(axis=0).reshape(n_labels + 1, n_values)
    mode = total.argmax(axis=1)
    support = total.max(axis=1)
    mode[support <= 0] = -1
    return mode.astype(np.int64), support


@kernel(parallel=True)
def _paint(labels: np.ndarray, table: np.ndarray) -> np.ndarray:
    h, w = labels.shape
    out = np.empty((h, w), np.int32)
    for y in prange(h):
        for x in range(w):
            lab = labels[y, x]
            out[y, x] = table[lab] if lab > 0 else -1
    return out


def paint_labels(labels: np.ndarray, table: np.ndarray) -> np.ndarray:
    """``np.where(labels > 0, table[labels], -1)`` as int32.

    Parameters
    ----------
    labels : (H, W) int array
        Label per pixel, 0 (or negative) for none; at most ``table.size - 1``.
    table : (n + 1,) int array
        Value per label.

    Returns
    -------
    (H, W) int32 array
        Each labelled pixel's value, -1 elsewhere.

    Raises
    ------
    ValueError
        ``labels`` is not 2-D.

    Examples
    --------
    >>> paint_labels(np.int32([[0, 1, 2]]), np.array([9, 4, -1])).tolist()
    [[-1, 4, -1]]
    """
    labels = np.ascontiguousarray(labels)
    if labels.ndim != 2:
        raise ValueError("paint_labels takes a 2-D label image")
    return _paint(labels, np.ascontiguousarray(table))
