"""Where a crossing may lie in a row search of :mod:`bistair.geometry.unwrap_stream_jit`:
the row's running sums of phase steps and, for one pixel's phase, the intervals of a
search between their two bounds.

From column ``j`` to ``j + 1`` of the other grid's row the phase moves at most ``steps[j]``
(``unwrap_stream_jit._steps``: the step plus ``SLACK``, NaN beside a NaN). A crossing of
``a`` in interval ``i`` (``a`` between ``o_i`` and ``o_(i+1)``) therefore lies at most the
steps' sum from ``first`` to ``i + 1`` away from ``o_first`` and at most the sum from ``i``
to ``end`` away from ``o_end`` (the phase distance on the circle obeys the triangle
inequality; a NaN step counts as 4, more than any phase distance). The sums of float32
steps are exact in float64, the slack of each step covers the float32 rounding of the
distances: the bounds keep every interval the float32 pass keeps. A long search (more
than :data:`LONG` intervals) skips the bounds and keeps its intervals from the distances
of a pass of their own (:func:`kept_intervals`).

Examples
--------
A row whose phase climbs 0.5 rad a column; a pixel of phase 2.2 can cross only between
columns 4 and 5 of a search over columns 0-10:

>>> import numpy as np
>>> steps = np.full(10, 0.5001, np.float32)
>>> sums = np.empty(11)
>>> running_sums(steps, 10, sums)
>>> crossing_bounds(sums, 0, 10, 2.2, 2.8)
(4, 5)
"""

from __future__ import annotations

import numpy as np

from ..core.jit import inline

#: A search of more intervals than this is not bounded: its distances, then their test.
LONG = 24


@inline
def running_sums(steps: np.ndarray, count: int, sums: np.ndarray) -> None:
    """The running sums of a row's phase steps.

    Parameters
    ----------
    steps : numpy.ndarray
        float32 phase steps of the row's first ``count`` intervals, NaN beside a NaN.
    count : int
        The intervals.
    sums : numpy.ndarray
        float64, at least ``count + 1`` long: set to the steps before each column added up
        (exact), a NaN step counted as 4.

    Returns
    -------
    None

    Examples
    --------
    >>> sums = np.empty(4)
    >>> running_sums(np.float32([0.25, np.nan, 0.5]), 3, sums)
    >>> sums.tolist()
    [0.0, 0.25, 4.25, 4.75]
    """
    total = 0.0
    for j in range(count):
        sums[j] = total
        step = float(steps[j])
        total += step if step == step else 4.0
    sums[count] = total


@inline
def crossing_bounds(sums: np.ndarray, first: int, end: int, near_first: float,
                    near_end: float) -> tuple[int, int]:
    """The intervals ``start .. stop - 1`` of a search over intervals ``first .. end - 1``
    where a crossing of a phase may lie (the module's docstring), by two bisections.

    Parameters
    ----------
    sums : numpy.ndarray
        float64 :func:`running_sums` of the row.
    first, end : int
        The search's first and last column.
    near_first, near_end : float
        The phase distances of columns ``first`` and ``end`` to the phase (NaN: no bound
        from that end).

    Returns
    -------
    start, stop : int
        The first interval that may hold a crossing and one past the last.

    Examples
    --------
    >>> sums = np.arange(11) * 0.5
    >>> crossing_bounds(sums, 0, 10, 1.2, 1.7), crossing_bounds(sums, 0, 10, np.nan, 1.7)
    ((2, 7), (0, 7))
    """
    start, top = first, end
    below, above = sums[first] + near_first, sums[end] - near_end
    while start < top:  # the first i with sums[i + 1] >= below (NaN: first)
        m = (start + top) >> 1
        if sums[m + 1] < below:
            start = m + 1
        else:
            top = m
    stop, top = start, end
    while stop < top:  # the first i with sums[i] > above (NaN: end)
        m = (stop + top) >> 1
        if not sums[m] > above:
            stop = m + 1
        else:
            top = m
    return start, stop


@inline
def kept_intervals(dist: np.ndarray, steps: np.ndarray, first: int, index: np.ndarray) -> int:
    """The intervals of a search whose ends' phase distances to a pixel's phase add up to
    at most the phase step between them, in order.

    Parameters
    ----------
    dist : numpy.ndarray
        float32 phase distances of the search's columns to the phase (one more than
        ``steps``).
    steps : numpy.ndarray
        float32 phase steps of the search's intervals.
    first : int
        The search's first column.
    index : numpy.ndarray
        int64, longer than ``steps``: the kept intervals' first columns are written first.

    Returns
    -------
    int
        The kept intervals.

    Examples
    --------
    >>> index = np.empty(4, np.int64)
    >>> dist, steps = np.float32([0.5, 0.2, 0.3, 1.0]), np.float32([0.75, 0.75, 0.75])
    >>> kept_intervals(dist, steps, 10, index), index[:2].tolist()
    (2, [10, 11])
    """
    n = 0
    for i in range(steps.shape[0]):
        if dist[i] + dist[i + 1] <= steps[i]:
            index[n] = first + i
            n += 1
    return n
