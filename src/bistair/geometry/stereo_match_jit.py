"""Compiled passes of row matching (:mod:`bistair.geometry.stereo_match`): each rectified row's
kinks dropped and its runs smoothed within one surface, the row search for equal phase with
the left-right check, a disparity kept only where the row above or below confirms it, and
the count of each outcome.

Each runs over image rows on every core; none has a NumPy twin (the row search has no
one-pass NumPy form), so ``tests/test_stereo_jit.py`` checks them against exact answers.

Examples
--------
>>> import numpy as np
>>> dst = np.tile(np.arange(20, dtype=np.float32), (2, 1))  # phase = column
>>> src = dst + np.float32(5.25)  # each value lies 5.25 columns on in dst
>>> disparity, status = match_pair(src[:, :10], dst, 0.0, 19.0)
>>> disparity[0, :3].tolist(), status[0, :3].tolist()
([-5.25, -5.25, -5.25], [1, 1, 1])
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles

# status codes of match_rows and check_matches
NO_PHASE, MATCHED, UNMATCHED, AMBIGUOUS, NOT_MONOTONIC, INCONSISTENT, OTHER_AXIS, ALONE = range(8)


@kernel(parallel=True)
def _kinks(values: np.ndarray, limit: float, reach: int) -> np.ndarray:
    h, w = values.shape
    out = values.copy()
    for y in prange(h):
        row = values[y]
        for x in range(1, w - 1):
            a, b, c = row[x - 1], row[x], row[x + 1]
            if a == a and b == b and c == c and abs(a - 2.0 * b + c) > limit:
                for k in range(max(0, x - reach), min(w, x + reach + 1)):
                    out[y, k] = np.nan
    return out


def drop_kinks(values: np.ndarray, limit: float, reach: int = 2) -> np.ndarray:
    """``values`` with NaN within ``reach`` columns of every kink along the rows, where the
    second difference exceeds ``limit``: the blurred step between two surfaces, whose
    pixels mix both (a value between them, which could match a place on neither).

    Parameters
    ----------
    values : numpy.ndarray
        ``(h, w)`` float32 map (projector coordinates on a rectified grid), NaN where
        invalid.
    limit : float
        Largest ``|v[x-1] - 2 v[x] + v[x+1]|`` of one surface.
    reach : int, optional
        Columns on each side of a kink dropped too.

    Returns
    -------
    numpy.ndarray
        A float32 copy with the kinks dropped.

    Examples
    --------
    >>> row = np.float32([[0, 1, 2, 3, 4, 8, 12, 13, 14, 15, 16, 17]])  # a blurred step
    >>> drop_kinks(row, 2.0, reach=1).tolist()
    [[0.0, 1.0, 2.0, nan, nan, nan, nan, nan, 14.0, 15.0, 16.0, 17.0]]
    """
    return _kinks(np.ascontiguousarray(values, np.float32), float(limit), int(reach))


@inline
def _joined(a: float, b: float, jump: float) -> bool:
    """Two neighbouring samples of one surface: both valid, at most ``jump`` apart."""
    return abs(float(a) - float(b)) <= jump  # False where either is NaN


@inline
def _fit_at(line: np.ndarray, x: int, a: int, b: int, radius: int,
            coefficients: np.ndarray) -> float:
    """The least-squares line through ``line[x-a .. x+b]`` at ``x``: a weighted sum."""
    total = 0.0
    for k in range(-a, b + 1):
        total += coefficients[a, b, k + radius] * float(line[x + k])
    return total


@inline
def _reach(line: np.ndarray, x: int, step: int, r: int, jump: float) -> int:
    """How many neighbours of sample ``x`` of ``line``, up to ``r``, its run holds on the
    side ``step`` (-1 or +1)."""
    n = 0
    end = line.shape[0]
    while n < r and 0 <= x + step * (n + 1) < end and _joined(
            line[x + step * n], line[x + step * (n + 1)], jump):
        n += 1
    return n


@kernel(parallel=True)
def _smooth(values: np.ndarray, radius: int, coefficients: np.ndarray, jump: float,
            kink: float, kink_reach: int, negate: bool) -> np.ndarray:
    """:func:`smooth_runs`: the rows, then the columns, in chunks of rows (the scratch made
    once a chunk). Each row is taken negated (``negate``) and without its kinks
    (:func:`drop_kinks`, on a copy of the row). Each pass filters every sample with the
    whole window's weights and notes whether the window's neighbours all join (vector
    loops; NaN wherever the window holds one), then fits again the samples whose run is cut
    short within the window (:func:`_reach` on each side, up to ``radius``)."""
    h, w = values.shape
    r = radius
    full = coefficients[r, r].copy()
    rows = np.empty_like(values)
    out = np.empty_like(values)
    chunks = min(h, 64)
    for c in prange(chunks):  # along the rows
        line = np.empty(w, values.dtype)
        whole = np.empty(w, np.uint8)
        for y in range(c * h // chunks, (c + 1) * h // chunks):
            src = values[y]
            if negate:
                for x in range(w):
                    line[x] = -src[x]
            else:
                line[:] = src
            if kink < math.inf:  # as drop_kinks: found on the row, dropped from the copy
                for x in range(1, w - 1):
                    a, b, d = src[x - 1], src[x], src[x + 1]
                    if a == a and b == b and d == d and abs(a - 2.0 * b + d) > kink:
                        for k in range(max(0, x - kink_reach), min(w, x + kink_reach + 1)):
                            line[k] = np.nan
            _filter_line(line, full, r, jump, rows[y], whole)
            for x in range(w):  # the windows cut short
                if whole[x] == 0:
                    v = line[x]
                    a, b = _reach(line, x, -1, r, jump), _reach(line, x, 1, r, jump)
                    if v != v or a < r or b < r:
                        rows[y, x] = _fit_at(line, x, a, b, r, coefficients) if v == v else v
    for c in prange(chunks):  # down the columns
        whole = np.empty(w, np.uint8)
        for y in range(c * h // chunks, (c + 1) * h // chunks):
            row = out[y]
            whole[:] = 0
            if r == 3 and 3 <= y < h - 3:  # a loop of fixed length, in vector registers
                for x in range(w):
                    total = 0.0
                    joined = True
                    for k in range(7):
                        total += full[k] * float(rows[y + k - 3, x])
                    for k in range(6):
                        joined &= _joined(rows[y + k - 3, x], rows[y + k - 2, x], jump)
                    row[x] = total
                    whole[x] = joined
            elif r <= y < h - r:
                for x in range(w):
                    total = 0.0
                    for k in range(2 * r + 1):
                        total += full[k] * float(rows[y + k - r, x])
                    row[x] = total
            for x in range(w):  # the windows cut short
                if whole[x] == 0:
                    column = rows[:, x]
                    v = column[y]
                    a, b = _reach(column, y, -1, r, jump), _reach(column, y, 1, r, jump)
                    if v != v or a < r or b < r:
                        row[x] = _fit_at(column, y, a, b, r, coefficients) if v == v else v
    return out


@inline
def _filter_line(line: np.ndarray, full: np.ndarray, r: int, jump: float, row: np.ndarray,
                 whole: np.ndarray) -> None:
    """``row``: ``line`` filtered with the whole window's weights ``full`` where the window
    fits in the line; ``whole``: 1 where the window's neighbours all join (radius 3, the
    default sigma: loops of fixed length, in vector registers), else 0."""
    w = line.shape[0]
    whole[:] = 0
    if r == 3:
        for x in range(3, w - 3):
            total = 0.0
            joined = True
            for k in range(7):
                total += full[k] * float(line[x + k - 3])
            for k in range(6):
                joined &= _joined(line[x + k - 3], line[x + k - 2], jump)
            row[x] = total
            whole[x] = joined
    else:
        for x in range(r, w - r):
            total = 0.0
            for k in range(2 * r + 1):
                total += full[k] * float(line[x + k - r])
            row[x] = total


def line_coefficients(weights: np.ndarray) -> np.ndarray:
    """The weights of the least-squares line at a sample through its neighbours ``-a .. b``
    (``weights[k]`` the weight of a neighbour ``k`` away): ``(r+1, r+1, 2r+1)`` for
    ``a, b`` in ``0 .. r`` and the offsets ``-r .. r`` (a lone sample keeps its value).

    Parameters
    ----------
    weights : numpy.ndarray
        ``(r+1,)`` weights of the neighbours 0 to ``r`` samples away.

    Returns
    -------
    numpy.ndarray
        ``(r+1, r+1, 2r+1)`` float64: the value of the line at the sample is the sum of
        ``[a, b, k + r]`` times the neighbour ``k`` away, ``k`` in ``-a .. b``.

    Examples
    --------
    >>> c = line_coefficients(np.array([1.0, 0.5]))
    >>> c[1, 1].round(3).tolist(), c[0, 1].round(3).tolist()  # a mean; the sample itself
    ([0.25, 0.5, 0.25], [0.0, 1.0, 0.0])
    """
    r = len(weights) - 1
    out = np.zeros((r + 1, r + 1, 2 * r + 1))
    for a in range(r + 1):
        for b in range(r + 1):
            k = np.arange(-a, b + 1, dtype=float)
            wk = np.asarray(weights, float)[np.abs(k).astype(int)]
            sw, swk, swkk = wk.sum(), (wk * k).sum(), (wk * k * k).sum()
            det = sw * swkk - swk * swk
            if det > 1e-12:
                out[a, b, k.astype(int) + r] = wk * (swkk - swk * k) / det
            else:
                out[a, b, r] = 1.0
    return out


def smooth_runs(values: np.ndarray, sigma: float, jump: float, kink: float = math.inf,
                kink_reach: int = 2, negate: bool = False) -> np.ndarray:
    """Smooth a map along its rows, then its columns: each valid value becomes that of the
    Gaussian-weighted (``sigma`` px, to 3 sigma) least-squares line through its neighbours,
    taken only up to the first invalid one or step over ``jump`` (never across two
    surfaces; a line, not a mean, so a window cut short on one side is not biased by the
    slope).

    With ``kink`` and ``negate``, the map is first negated and its kinks dropped (as
    :func:`drop_kinks` with ``kink`` and ``kink_reach``) in the same pass, bit for bit
    ``smooth_runs(drop_kinks(-values, kink, kink_reach), sigma, jump)`` without the two
    full-image copies.

    Parameters
    ----------
    values : numpy.ndarray
        ``(h, w)`` float32, NaN where invalid.
    sigma : float
        Gaussian sigma (px); 0 smooths nothing (a copy, negated and without its kinks).
    jump : float
        Largest step between neighbours of one surface.
    kink : float, optional
        Largest second difference along a row of one surface (:func:`drop_kinks`);
        infinite (the default) drops none.
    kink_reach : int, optional
        Columns on each side of a kink dropped too.
    negate : bool, optional
        Smooth ``-values`` (for a coordinate that falls along the rows).

    Returns
    -------
    numpy.ndarray
        ``(h, w)`` float32, NaN where ``values`` is (and at the kinks dropped).

    Examples
    --------
    >>> ramp = np.float32([[0, 1, 2, 3, 4, 20, 21, 22]])  # two surfaces, exact ramps
    >>> np.round(smooth_runs(ramp, 1.0, 5.0), 6).tolist()  # (to float rounding)
    [[0.0, 1.0, 2.0, 3.0, 4.0, 20.0, 21.0, 22.0]]
    >>> noisy = np.float32([[0, 1, 2, 3, 4, 5, 6]]) + np.float32([[0, 0, 0, 0.7, 0, 0, 0]])
    >>> round(float(smooth_runs(noisy, 1.0, 5.0)[0, 3]), 3)  # the spike mostly averaged out
    3.279
    >>> step = np.float32([[0, 1, 2, 3, 4, 8, 12, 13, 14, 15, 16, 17]])  # a blurred step
    >>> np.round(smooth_runs(step, 1.0, 5.0, kink=2.0, kink_reach=1, negate=True), 6).tolist()
    [[0.0, -1.0, -2.0, nan, nan, nan, nan, nan, -14.0, -15.0, -16.0, -17.0]]
    """
    values = np.ascontiguousarray(values, np.float32)
    if not sigma > 0:
        return drop_kinks(-values if negate else values, kink, kink_reach)
    radius = max(1, int(math.ceil(3 * sigma)))
    weights = np.exp(-0.5 * (np.arange(radius + 1) / sigma) ** 2)
    return _smooth(values, radius, line_coefficients(weights), float(jump), float(kink),
                   int(kink_reach), bool(negate))


@inline
def _first_at_least(arr: np.ndarray, a: int, b: int, q: float, hint: int) -> int:
    """The first index in ``[a, b)`` of the non-decreasing ``arr`` with ``arr >= q`` (``b``
    if none), searched from ``hint`` outward in doubling steps (the answer is usually a
    step or two from the last one), then by halving."""
    # the answer is mostly the hint or the one after it (the value searched for moves on
    # by about a sample from pixel to pixel): two looks before any search
    if a <= hint < b:
        if arr[hint] >= q:
            if hint == a or arr[hint - 1] < q:
                return hint
        elif hint + 1 == b or arr[hint + 1] >= q:
            return hint + 1
    lo, hi = a, b  # arr[lo - 1] < q (or lo == a), arr[hi] >= q (or hi == b)
    step = 1
    if hint < b and arr[hint] >= q:
        hi = hint
        while hi - step >= a and arr[hi - step] >= q:
            hi -= step
            step *= 2
        lo = max(a, hi - step + 1)
    else:
        lo = hint + 1
        while lo + step - 1 < b and arr[lo + step - 1] < q:
            lo += step
            step *= 2
        hi = min(b, lo + step - 1)
    while lo < hi:
        mid = (lo + hi) // 2
        if arr[mid] >= q:
            hi = mid
        else:
            lo = mid + 1
    return lo


@inline
def _fit_crossing(xs: np.ndarray, vs: np.ndarray, a: int, b: int, q: float,
                  fallback: float) -> float:
    """Where the least-squares line through the samples ``[a, b)`` takes ``q``."""
    x0 = float(xs[a])
    sx, sv, sxx, sxv = 0.0, 0.0, 0.0, 0.0
    for k in range(a, b):
        dx, v = xs[k] - x0, vs[k]
        sx += dx
        sv += v
        sxx += dx * dx
        sxv += dx * v
    n = b - a
    cov = n * sxv - sx * sv
    if not cov > 0.0:
        return fallback
    return x0 + (sx + (n * q - sv) * (n * sxx - sx * sx) / cov) / n


@inline
def _along(row: np.ndarray, x: float) -> float:
    """``row`` at ``x``, linear between its two neighbours (NaN if one it needs is)."""
    if not x >= 0.0:
        return math.nan
    x0 = int(x)
    f = x - x0
    if f > 0.0:
        if x0 + 1 >= row.shape[0]:
            return math.nan
        a, b = float(row[x0]), float(row[x0 + 1])
        return a + f * (b - a)
    if x0 >= row.shape[0]:
        return math.nan
    return float(row[x0])


@inline
def _bridged(xs: np.ndarray, vs: np.ndarray, k: int, e: int, n: int) -> bool:
    """Whether samples ``e - 1`` and ``e`` (``k``: the run's first) may be joined across the
    columns between them: always beside each other; across a gap, where the step is what
    the slope on either side (the neighbours beside each, where there are) carries over
    the gap, within half a column's worth of it. A surface's own pixels left out (dim, at
    a code edge) keep its slope; where the gap hides a step of two surfaces (a camera's
    view of one object's edge, the other camera seeing a strip of the surface behind it),
    interpolating across it would give that strip matches it has not."""
    g = xs[e] - xs[e - 1]
    if g <= 1:
        return True
    total = 0.0
    count = 0
    if e - 2 >= k and xs[e - 1] - xs[e - 2] == 1:
        total += vs[e - 1] - vs[e - 2]
        count += 1
    if e + 1 < n and xs[e + 1] - xs[e] == 1:
        total += vs[e + 1] - vs[e]
        count += 1
    if count == 0:
        return True  # no slope beside it: judged by the jump alone
    slope = total / count
    return abs(vs[e] - vs[e - 1] - g * slope) <= 0.5 * abs(slope) * g


@inline
def _runs(row: np.ndarray, gap: int, jump: float, xs: np.ndarray, vs: np.ndarray,
          begins: np.ndarray, ends: np.ndarray, pmax: np.ndarray, smin: np.ndarray,
          hints: np.ndarray) -> int:
    """The runs of a row (valid samples at most ``gap`` columns and ``jump`` per column
    apart, two samples at least): their samples ``xs, vs``, bounds, prefix maxima and
    suffix minima, and in ``hints`` (runs, 3) the search hints and whether each rises
    strictly; returns how many."""
    n = 0
    for x in range(row.shape[0]):  # a select, not a branch
        value = row[x]
        xs[n] = x
        vs[n] = value
        n += 1 if value == value else 0
    runs = 0
    k = 0
    while k < n:
        e = k + 1
        rising = 1
        while e < n and xs[e] - xs[e - 1] <= gap and (
                abs(vs[e] - vs[e - 1]) <= jump * (xs[e] - xs[e - 1])) and (
                _bridged(xs, vs, k, e, n)):
            rising = rising if vs[e] > vs[e - 1] else 0
            e += 1
        if e - k >= 2:
            begins[runs] = k
            ends[runs] = e
            hints[runs, 0] = k
            hints[runs, 1] = k
            hints[runs, 2] = rising
            runs += 1
            top = vs[k]  # (kept in a register, not read back)
            pmax[k] = top
            for i in range(k + 1, e):
                top = max(top, vs[i])
                pmax[i] = top
            low = vs[e - 1]
            smin[e - 1] = low
            for i in range(e - 2, k - 1, -1):
                low = min(low, vs[i])
                smin[i] = low
        k = e
    return runs


@inline
def _value_alone(vs: np.ndarray, begins: np.ndarray, ends: np.ndarray, runs: int,
                 alone: np.ndarray) -> None:
    """Mark the runs whose value range (first to last value, rising) meets no other run's:
    a value such a run holds is held by no other run of the row."""
    first = np.empty(runs, np.float64)
    for r in range(runs):
        alone[r] = 0
        lo, hi = vs[begins[r]], vs[ends[r] - 1]
        first[r] = lo if lo <= hi else math.inf  # a falling run holds no value: last
    order = np.argsort(first)
    reach = -math.inf  # the largest last value of the runs before, in that order
    for i in range(runs):
        r = order[i]
        lo, hi = vs[begins[r]], vs[ends[r] - 1]
        if not lo <= hi:
            break
        meets = reach >= lo or (i + 1 < runs and first[order[i + 1]] <= hi)
        alone[r] = 0 if meets else 1
        reach = max(reach, hi)


@inline
def _crossing(r: int, q: float, xlo: float, xhi: float, xs: np.ndarray, vs: np.ndarray,
              begins: np.ndarray, ends: np.ndarray, pmax: np.ndarray, smin: np.ndarray,
              hints: np.ndarray, reach: int) -> tuple[bool, float, float]:
    """Whether run ``r`` holds ``q`` within ``[xlo, xhi]``: ``(hit, first, last)``, the
    first and last crossings of ``q`` (the same where it rises through it once)."""
    a, b = begins[r], ends[r]
    if xs[b - 1] < xlo or xs[a] > xhi or not (vs[a] <= q <= vs[b - 1]):
        return False, 0.0, 0.0
    i = _first_at_least(pmax, a, b, q, hints[r, 0])  # first crossing in (i-1, i]
    if hints[r, 2] == 1:  # rising strictly: the first crossing is the last
        j = i - 1
    else:
        j = _first_at_least(smin, a, b, q, hints[r, 1]) - 1  # last one in (j, j+1]
    hints[r, 0] = i
    hints[r, 1] = j + 1
    if i == j + 1 and reach > 1 and i - reach >= a and j + reach < b:  # one crossing
        x1 = x2 = mid = _fit_crossing(xs, vs, i - reach, j + reach + 1, q, math.nan)
        if mid != mid:  # no line (never for a rising run): between the neighbours
            x1 = x2 = mid = xs[j] + (q - vs[j]) / (vs[i] - vs[j]) * (xs[i] - xs[j])
    else:
        x1, x2 = float(xs[a]), float(xs[a])  # q is the run's first value
        if i > a:
            x1 = xs[i - 1] + (q - vs[i - 1]) / (vs[i] - vs[i - 1]) * (xs[i] - xs[i - 1])
        if j >= a:
            x2 = xs[j] + (q - vs[j]) / (vs[j + 1] - vs[j]) * (xs[j + 1] - xs[j])
        mid = 0.5 * (x1 + x2)
    if mid < xlo or mid > xhi:
        return False, 0.0, 0.0
    return True, x1, x2


@inline
def _find(q: float, xlo: float, xhi: float, xs: np.ndarray, vs: np.ndarray,
          begins: np.ndarray, ends: np.ndarray, pmax: np.ndarray, smin: np.ndarray,
          hints: np.ndarray, runs: int, wiggle: float, reach: int, alone: np.ndarray,
          last: np.ndarray) -> tuple[int, float]:
    """``(status, position)`` of the value ``q`` on a row's runs within ``[xlo, xhi]``.

    The run that held the last value searched (``last[0]``) is tried first: where it holds
    ``q`` and no other run shares its values (``alone``), no other run can hold it."""
    c = last[0]
    if c < runs and alone[c] == 1 and vs[begins[c]] <= q <= vs[ends[c] - 1]:
        hit, x1, x2 = _crossing(c, q, xlo, xhi, xs, vs, begins, ends, pmax, smin, hints,
                                reach)
        if not hit:
            return UNMATCHED, math.nan
        if x2 - x1 > wiggle:
            return NOT_MONOTONIC, math.nan
        return MATCHED, 0.5 * (x1 + x2)
    found, bad, best = 0, False, math.nan
    for r in range(runs):
        hit, x1, x2 = _crossing(r, q, xlo, xhi, xs, vs, begins, ends, pmax, smin, hints,
                                reach)
        if not hit:
            continue
        found += 1
        best = 0.5 * (x1 + x2)
        last[0] = r
        if x2 - x1 > wiggle:
            bad = True
    if found == 0:
        return UNMATCHED, math.nan
    if found > 1:
        return AMBIGUOUS, math.nan
    return (NOT_MONOTONIC, math.nan) if bad else (MATCHED, best)


@kernel(parallel=True)
def _pair(left: np.ndarray, right: np.ndarray, lo: float, hi: float, shift: float,
          tolerance: float, gap: int, wiggle: float, jump: float, reach: int,
          other: np.ndarray, other_right: np.ndarray, other_tolerance: float
          ) -> tuple[np.ndarray, np.ndarray]:
    h, w = left.shape
    wr = right.shape[1]
    both = other.shape[0] > 0
    disparity = np.full((h, w), np.nan, np.float32)
    status = np.zeros((h, w), np.int8)
    chunks = min(h, 64)
    for c in prange(chunks):  # rows in chunks: the scratch arrays made once a chunk
        rxs, rvs = np.empty(wr, np.int64), np.empty(wr, np.float64)
        rb, re = np.empty(wr // 2 + 1, np.int64), np.empty(wr // 2 + 1, np.int64)
        rmax, rmin = np.empty(wr, np.float64), np.empty(wr, np.float64)
        rhint = np.empty((wr // 2 + 1, 3), np.int64)
        lxs, lvs = np.empty(w, np.int64), np.empty(w, np.float64)
        lb, le = np.empty(w // 2 + 1, np.int64), np.empty(w // 2 + 1, np.int64)
        lmax, lmin = np.empty(w, np.float64), np.empty(w, np.float64)
        lhint = np.empty((w // 2 + 1, 3), np.int64)
        alone = np.empty(w, np.uint8)  # not bool: numba reads bool arrays slowly
        ralone, lalone = np.empty(wr // 2 + 1, np.uint8), np.empty(w // 2 + 1, np.uint8)
        rlast, llast = np.zeros(1, np.int64), np.zeros(1, np.int64)
        for y in range(c * h // chunks, (c + 1) * h // chunks):
            nr = _runs(right[y], gap, jump, rxs, rvs, rb, re, rmax, rmin, rhint)
            nl = _runs(left[y], gap, jump, lxs, lvs, lb, le, lmax, lmin, lhint)
            _value_alone(rvs, rb, re, nr, ralone)
            _value_alone(lvs, lb, le, nl, lalone)
            _alone(lxs, lb, le, lhint, nl, lalone, alone)
            rlast[0] = llast[0] = 0
            for x in range(w):
                q = left[y, x]
                if q != q:
                    continue
                found, xm = _find(q, x + lo, x + hi, rxs, rvs, rb, re, rmax, rmin, rhint,
                                  nr, wiggle, reach, ralone, rlast)
                if found != MATCHED:
                    status[y, x] = found
                    continue
                back, xb = MATCHED, float(x)
                if alone[x] == 0:
                    back, xb = _find(q, xm - hi, xm - lo, lxs, lvs, lb, le, lmax, lmin,
                                     lhint, nl, wiggle, 1, lalone, llast)
                if back != MATCHED or not abs(xb - x) <= tolerance:
                    status[y, x] = INCONSISTENT
                    continue
                if both:
                    a, b = other[y, x], _along(other_right[y], xm)
                    if a == a and b == b and abs(a - b) > other_tolerance:
                        status[y, x] = OTHER_AXIS
                        continue
                status[y, x] = MATCHED
                disparity[y, x] = x - xm - shift
    return disparity, status


@inline
def _alone(xs: np.ndarray, begins: np.ndarray, ends: np.ndarray, hints: np.ndarray,
           runs: int, value_alone: np.ndarray, alone: np.ndarray) -> None:
    """Mark the columns of the runs that rise strictly (``hints[r, 2]``) and share no value
    with another run (:func:`_value_alone`): each of their pixels comes back to itself, no
    search back is needed there."""
    alone[:] = 0
    for r in range(runs):
        if hints[r, 2] == 1 and value_alone[r] == 1:
            for k in range(begins[r], ends[r]):
                alone[xs[k]] = 1


def match_pair(left: np.ndarray, right: np.ndarray, lo: float, hi: float, shift: float = 0.0,
               tolerance: float = 1.0, gap: int = 3, wiggle: float = 1.0,
               jump: float = math.inf, reach: int = 2, other: np.ndarray | None = None,
               other_right: np.ndarray | None = None, other_tolerance: float = 2.0
               ) -> tuple[np.ndarray, np.ndarray]:
    """For every valid pixel of the rectified ``left`` map, the position on the same row of
    ``right`` where the value (phase, projector coordinate) is the pixel's own, checked by
    the match back, as a disparity.

    A row is read as runs of valid pixels at most ``gap`` columns apart whose values change
    by at most ``jump`` per column (a longer gap or a larger step, two surfaces, ends a
    run: no value is read across it). A run gives a match when its ends bracket the value
    with the phase rising (first at or below it, last at or above it): the match lies
    between the first and the last crossing of the value, linearly interpolated between the
    two valid neighbours around each; they must lie within ``wiggle`` px of each other (the phase
    runs monotonically there, up to noise) and the match is their midpoint. Where the
    phase rises through the value once and the run holds ``reach - 1`` more samples on
    either side, the match is where the least-squares line through those ``2 * reach``
    samples takes the value (less noisy than two: ``reach = 2`` brings the disparity noise
    of a 4-step decode down by about 7%). A value that two runs give in the search window
    is ambiguous: no match.

    The match ``x_r`` of a left pixel ``x`` (searched for in ``x_r - x`` in ``[lo, hi]``)
    holds when searching the same value back on the left row (``x - x_r`` in
    ``[-hi, -lo]``) finds one place, within ``tolerance`` px of ``x``; and where both maps
    have a second coordinate (``other`` at ``x``, ``other_right`` at ``x_r``, linear
    between neighbours), the two differ by at most ``other_tolerance``. Values must rise
    along the rows (negate both maps for values that fall).

    Parameters
    ----------
    left, right : numpy.ndarray
        ``(h, w_left)`` and ``(h, w_right)`` float32 values on rectified grids whose rows are
        the same epipolar lines; NaN where invalid.
    lo, hi : float
        The search window of ``x_r - x``.
    shift : float, optional
        ``disparity = x - x_r - shift`` (the difference of the grids' principal points).
    tolerance : float, optional
        Pixels the match back may miss ``x`` by.
    gap : int, optional
        Largest column step between valid neighbours interpolated between.
    wiggle : float, optional
        Largest distance (px) between the first and last crossing of a run.
    jump : float, optional
        Largest change of the value per column between neighbours of a run.
    reach : int, optional
        Samples on each side of a single crossing fitted with a line (1: the two
        neighbours only, plain linear interpolation).
    other, other_right : numpy.ndarray or None, optional
        The second coordinate on both grids (NaN where not decoded).
    other_tolerance : float, optional
        Largest difference of the second coordinate.

    Returns
    -------
    disparity : numpy.ndarray
        ``(h, w_left)`` float32, NaN without a confirmed match.
    status : numpy.ndarray
        ``(h, w_left)`` int8: :data:`NO_PHASE`, :data:`MATCHED`, :data:`UNMATCHED`,
        :data:`AMBIGUOUS`, :data:`NOT_MONOTONIC`, :data:`INCONSISTENT` or
        :data:`OTHER_AXIS`.

    Examples
    --------
    >>> right = np.float32([[0, 1, 2, np.nan, np.nan, np.nan, np.nan, 3, 4, 5]])
    >>> left = np.float32([[1.5, 2.5, 3.5]])
    >>> d, status = match_pair(left, right, -5.0, 10.0, reach=1)
    >>> d.tolist(), status.tolist()  # 2.5 lies in a gap of 5 columns
    ([[-1.5, nan, -5.5]], [[1, 2, 1]])
    >>> twice = np.float32([[0, 1, 2, 3, 0, 1, 2, 3]])  # the phase falls back in one run
    >>> match_pair(np.float32([[1.5]]), twice, 0.0, 7.0)[1].tolist()  # NOT_MONOTONIC
    [[4]]
    >>> apart = np.float32([[0, 1, 2, 3] + [np.nan] * 4 + [0, 1, 2, 3]])  # two runs
    >>> match_pair(np.float32([[1.5]]), apart, 0.0, 11.0)[1].tolist()  # AMBIGUOUS
    [[3]]
    """
    empty = np.zeros((0, 0), np.float32)
    return _pair(np.ascontiguousarray(left, np.float32), np.ascontiguousarray(right, np.float32),
                 float(lo), float(hi), float(shift), float(tolerance), int(gap), float(wiggle),
                 float(jump), int(reach),
                 empty if other is None else np.ascontiguousarray(other, np.float32),
                 empty if other_right is None else np.ascontiguousarray(other_right,
                                                                        np.float32),
                 float(other_tolerance))


@kernel(parallel=True)
def _supported(disparity: np.ndarray, status: np.ndarray, support: float
               ) -> tuple[np.ndarray, np.ndarray]:
    h, w = disparity.shape
    kept = disparity.copy()
    out = status.copy()
    for y in prange(h):
        for x in range(w):
            d = disparity[y, x]
            if d != d:
                continue
            up = y > 0 and abs(disparity[y - 1, x] - d) <= support
            down = y + 1 < h and abs(disparity[y + 1, x] - d) <= support
            if not (up or down):
                kept[y, x] = np.nan
                out[y, x] = ALONE
    return kept, out


def supported(disparity: np.ndarray, status: np.ndarray, support: float = 2.0
              ) -> tuple[np.ndarray, np.ndarray]:
    """Keep the disparities that the row above or below confirms (within ``support``
    px): a match one row thin is no surface but a coincidence of equal phases (a
    projector ray grazing an edge lights the edge and the surface behind it alike).

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(h, w)`` float32 (:func:`check_matches`), NaN where unmatched.
    status : numpy.ndarray
        Its status codes.
    support : float, optional
        Largest disparity change to the neighbouring row.

    Returns
    -------
    disparity : numpy.ndarray
        The supported disparities (NaN elsewhere).
    status : numpy.ndarray
        ``status`` with :data:`ALONE` where a disparity was dropped.

    Examples
    --------
    >>> d = np.float32([[10, 10], [10, 11], [10, 50]])
    >>> kept, s = supported(d, np.ones((3, 2), np.int8))
    >>> kept.tolist(), s[:, 1].tolist()
    ([[10.0, 10.0], [10.0, 11.0], [10.0, nan]], [1, 1, 7])
    """
    return _supported(np.ascontiguousarray(disparity, np.float32),
                      np.ascontiguousarray(status, np.int8), float(support))


@kernel(parallel=True)
def _count(status: np.ndarray, n: int) -> np.ndarray:
    h, w = status.shape
    per_row = np.zeros((h, n), np.int64)
    for y in prange(h):
        for x in range(w):
            per_row[y, status[y, x]] += 1
    counts = np.zeros(n, np.int64)
    for y in range(h):
        for k in range(n):
            counts[k] += per_row[y, k]
    return counts


def count_status(status: np.ndarray) -> np.ndarray:
    """How many pixels have each status code (:data:`NO_PHASE` to :data:`ALONE`):
    ``np.bincount(status.ravel(), minlength=8)`` without its copy of the codes.

    Parameters
    ----------
    status : numpy.ndarray
        ``(h, w)`` int8 codes, 0 to 7 (:func:`match_pair`, :func:`supported`).

    Returns
    -------
    numpy.ndarray
        ``(8,)`` int64.

    Examples
    --------
    >>> count_status(np.int8([[1, 1, 2], [7, 0, 1]])).tolist()
    [1, 3, 1, 0, 0, 0, 0, 1]
    """
    return _count(np.ascontiguousarray(status, np.int8), 8)
