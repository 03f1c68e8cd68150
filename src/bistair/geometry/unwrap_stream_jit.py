"""Compiled passes of stereo phase unwrapping over a stream (:mod:`bistair.geometry.
unwrap_stream`): the search near the previous window's disparity, the projector column of
each decided pixel, and the depth where the left camera's ray cuts the projector's column
plane.

They run over rows on every core and have no NumPy twin (the row search has no one-pass
NumPy form); ``tests/test_stereo_stream.py`` checks them against the renderer's truth and
against :func:`~bistair.geometry.unwrap.unwrap_stereo`'s full search.

The row search tests few intervals: a crossing of ``a`` between columns ``j`` and ``j + 1``
has ``e_j = near(o_j - a)`` and ``e_(j+1)`` of opposite signs less than pi apart, so
``|e_j| + |e_(j+1)|`` is the phase step ``|near(o_(j+1) - o_j)|``. One pass without
branches (float32, :data:`SLACK` for its rounding) keeps the intervals where the sum is at
most the step (about one a pixel in a search 12 px wide, against 13); only those are
tested as before, in float64: the same candidates in the same order. Fewer are scanned:
the phase moves at most a step an interval, so two bisections of the row's running sums of
steps bound the intervals where a crossing may lie (:mod:`.unwrap_stream_bounds_jit`): 1.3
of the 13 of a narrow search on average (two-masks at 640 x 480). A search of more than
``LONG`` intervals (the full range: ~92 at the benchmark's rig) is not bounded (the bounds
cut little there; the bisections cost more than they save) and splits its pass in two: the
distances in a loop that vectorises, then the test of their sums (the same float32
expressions: the same intervals). The candidate's
projector column comes, without distortion, from coefficients of the row linear in the
pixel and the disparity (:func:`_row_plane`: one division, the full search's four): the
same test to rounding (``unwrap_rows``' decisions, bit for bit, on the test stream).

Examples
--------
The rig of :mod:`bistair.geometry.unwrap_jit` (``f`` = 100 px, cameras 100 mm apart, a
projector 25 mm right of the left camera, a period of 8 px) and its plane at 500 mm (a
disparity of 20 px); the previous window found 19.5 px, so only 17.5-21.5 is searched:

>>> import numpy as np
>>> cols = np.arange(80, dtype=np.float32)[None]
>>> left = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
>>> right = (2 * np.pi * (cols + 15) / 8) % (2 * np.pi)
>>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
>>> previous = np.full((1, 80), 19.5, np.float32)
>>> n_in, disparity, near, _ = track_rows(
...     left, right, previous, 2.0, 1.0, 40.0, 0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k,
...     np.zeros(5), np.eye(3), np.array([-25.0, 0, 0]), 8.0, 0.2, 400.0, 600.0, 1000)
>>> int(n_in[0, 50]), round(float(disparity[0, 50]), 4), int(near[0, 50])
(1, 20.0, 1)
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel
from .stereo_jit import near32
from .unwrap_jit import KEPT, near
from .unwrap_stream_bounds_jit import LONG, crossing_bounds, kept_intervals, running_sums

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi
INV_TWO_PI = 1.0 / TWO_PI
#: What the skip leaves for rounding (radians; float32's own is below 1e-6).
SLACK = np.float32(1e-4)


@inline
def _steps(other: np.ndarray, y: int, steps: np.ndarray, sums: np.ndarray) -> None:
    """``steps[j]``: the phase step from column ``j`` to ``j + 1`` of ``other``'s row ``y``
    (``|near32|`` of their difference) plus :data:`SLACK`; NaN beside a NaN.
    ``sums``: their running sums (:func:`~.unwrap_stream_bounds_jit.running_sums`)."""
    for j in range(other.shape[1] - 1):
        steps[j] = abs(near32(other[y, j + 1] - other[y, j])) + SLACK
    running_sums(steps, other.shape[1] - 1, sums)


@inline
def _scan(own: np.ndarray, other: np.ndarray, steps: np.ndarray, index: np.ndarray, y: int,
          x: int, a: float, j0: int, j1: int, lo: float, hi: float, shift: float, f: float,
          cx: float, yr: float, tx: float, back: np.ndarray, kp: np.ndarray, dp: np.ndarray,
          rp: np.ndarray, tp: np.ndarray, period: float, tolerance: float, zmin: float,
          zmax: float, width: int, from_right: bool, skip: bool, kept: np.ndarray,
          plane: np.ndarray) -> tuple[int, float]:
    """The consistent candidates in the depth range of one pixel among the crossings of
    ``a`` on ``other``'s row between columns ``j0`` and ``j1`` (disparities ``lo..hi``):
    their count and, for one, its disparity (the test of ``unwrap_jit._unwrap``); the
    first ``kept.shape[2]`` candidates' disparities into ``kept[y, x]``.

    With ``skip``, only the intervals whose ends' phase distances to ``a`` add up to at
    most the step between them (``steps``: :func:`_steps`) are tested, and only those
    between the two bounds of the steps' sums (``plane[8:]``: :func:`_steps`' ``sums``):
    a crossing needs both (the module's docstring); the same candidates, in the same
    order; a search of more than ``LONG`` intervals tests its distances (kept in ``steps``'
    second half) in a pass of their own, unbounded (the module's docstring). ``plane[:8]``:
    :func:`_row_plane`'s coefficients (``plane[7]`` 0: the projector is distorted)."""
    count = 0
    found = math.nan
    first = max(j0, 0)
    end = min(j1, other.shape[1] - 1)
    n = end - first
    if skip and n > LONG:  # (a pass of distances that vectorises, then the test; unbounded)
        dist = steps[other.shape[1]:other.shape[1] + n + 1]
        row, a32 = other[y, first:end + 1], np.float32(a)
        for i in range(n + 1):
            dist[i] = abs(near32(row[i] - a32))
        n = kept_intervals(dist, steps[first:end], first, index)
    elif skip:  # (one pass without branches, between the bounds of the sums)
        a32, n = np.float32(a), 0
        start, stop = crossing_bounds(plane[8:], first, end,
                                      float(abs(near32(other[y, first] - a32))),
                                      float(abs(near32(other[y, end] - a32))))
        after = abs(near32(other[y, start] - a32))
        for j in range(start, stop):
            before = after
            after = abs(near32(other[y, j + 1] - a32))
            index[n] = j
            n += before + after <= steps[j]
    k = -f * tx  # the depth times the disparity
    inv_f, per_column = 1.0 / f, TWO_PI / period
    e1 = near(float(other[y, first]) - a)
    for q in range(n):
        if skip:
            j = index[q]
            e0 = near(float(other[y, j]) - a)
        else:  # (every interval: the last one's end)
            j = first + q
            e0 = e1
        e1 = near(float(other[y, j + 1]) - a)
        if not ((e0 <= 0.0 < e1) or (e1 <= 0.0 < e0)) or abs(e1 - e0) > math.pi:
            continue
        xs = j + e0 / (e0 - e1)
        d = xs - x - shift if from_right else x - xs - shift
        if not (lo <= d <= hi and k * d > 0.0):  # (k * d: the depth k / d beyond 0)
            continue
        xl = ((xs if from_right else x) - cx) * inv_f
        if plane[7] != 0.0:  # no distortion: the column of the row's coefficients (_row_plane)
            z = plane[3] * xl + plane[4] + tp[2] * d
            u = (plane[0] * xl + plane[1] + plane[2] * d) / z + kp[0, 2] if z * d > 0.0 \
                else math.nan
            pzd = plane[5] * xl + plane[6]
        else:  # distortion: the point (as the full search finds it), then its projection
            zr = k / d
            qx, qy = xl * zr, yr * zr
            pz = back[2, 0] * qx + back[2, 1] * qy + back[2, 2] * zr
            u = _project(back[0, 0] * qx + back[0, 1] * qy + back[0, 2] * zr,
                         back[1, 0] * qx + back[1, 1] * qy + back[1, 2] * zr, pz, kp, dp, rp,
                         tp)[0]
            pzd = pz * d
        if not (-0.5 <= u <= width - 0.5):
            continue
        miss = u * per_column - a
        miss = abs(miss - TWO_PI * math.floor(miss * INV_TWO_PI + 0.5))
        if miss > tolerance:
            continue
        near_z, far_z = (zmin * d, zmax * d) if d > 0.0 else (zmax * d, zmin * d)
        if near_z <= pzd <= far_z:  # (the depth k / d in the range)
            count += 1
            found = d if count == 1 else math.nan
            if count <= kept.shape[2]:
                kept[y, x, count - 1] = d
    return count, found


@inline
def _row_plane(yr: float, k: float, back: np.ndarray, kp: np.ndarray, rp: np.ndarray,
               tp: np.ndarray, plane: np.ndarray) -> None:
    """The coefficients of a candidate's projector column without distortion on the
    rectified row ``yr``, linear in the point's ``xl`` and ``d`` (the point is ``(xl, yr,
    1) * k / d``): the projector's ``(K X)_x`` (``plane[0] * xl + plane[1] + plane[2] * d``),
    ``Z`` (``plane[3] * xl + plane[4] + tp[2] * d``) and the left camera's depth
    (``plane[5] * xl + plane[6]``), each times ``d``; ``plane[7]`` 1."""
    a0, a1, a2 = back[0, 0], back[1, 0], back[2, 0]  # q = a * xl + b: the ray
    b0 = back[0, 1] * yr + back[0, 2]
    b1 = back[1, 1] * yr + back[1, 2]
    b2 = back[2, 1] * yr + back[2, 2]
    ax = k * (rp[0, 0] * a0 + rp[0, 1] * a1 + rp[0, 2] * a2)
    bx = k * (rp[0, 0] * b0 + rp[0, 1] * b1 + rp[0, 2] * b2)
    ay = k * (rp[1, 0] * a0 + rp[1, 1] * a1 + rp[1, 2] * a2)
    by = k * (rp[1, 0] * b0 + rp[1, 1] * b1 + rp[1, 2] * b2)
    plane[0] = kp[0, 0] * ax + kp[0, 1] * ay
    plane[1] = kp[0, 0] * bx + kp[0, 1] * by
    plane[2] = kp[0, 0] * tp[0] + kp[0, 1] * tp[1]
    plane[3] = k * (rp[2, 0] * a0 + rp[2, 1] * a1 + rp[2, 2] * a2)
    plane[4] = k * (rp[2, 0] * b0 + rp[2, 1] * b1 + rp[2, 2] * b2)
    plane[5], plane[6], plane[7] = k * a2, k * b2, 1.0


@inline
def _project(px: float, py: float, pz: float, kp: np.ndarray, dp: np.ndarray,
             rp: np.ndarray, tp: np.ndarray) -> tuple[float, float]:
    """The projector pixel (OpenCV's model, distortion ``k1, k2, p1, p2, k3``) of a point of
    the left camera's frame; NaN behind the projector."""
    x = rp[0, 0] * px + rp[0, 1] * py + rp[0, 2] * pz + tp[0]
    y = rp[1, 0] * px + rp[1, 1] * py + rp[1, 2] * pz + tp[1]
    z = rp[2, 0] * px + rp[2, 1] * py + rp[2, 2] * pz + tp[2]
    if not z > 0.0:
        return math.nan, math.nan
    x /= z
    y /= z
    r2 = x * x + y * y
    radial = 1.0 + r2 * (dp[0] + r2 * (dp[1] + r2 * dp[4]))
    xd = x * radial + 2.0 * dp[2] * x * y + dp[3] * (r2 + 2.0 * x * x)
    yd = y * radial + dp[2] * (r2 + 2.0 * y * y) + 2.0 * dp[3] * x * y
    return kp[0, 0] * xd + kp[0, 1] * yd + kp[0, 2], kp[1, 1] * yd + kp[1, 2]


@kernel(parallel=True)
def _track(own: np.ndarray, other: np.ndarray, previous: np.ndarray, margin: float,
           lo: float, hi: float, shift: float, f: float, cx: float, cy: float, tx: float,
           back: np.ndarray, kp: np.ndarray, dp: np.ndarray, rp: np.ndarray, tp: np.ndarray,
           period: float, tolerance: float, zmin: float, zmax: float, width: int,
           from_right: bool, keep: int, needed: np.ndarray, skip: bool, plain: bool
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    h, w = own.shape
    gated = needed.shape[0] == h
    wr = other.shape[1]
    kept = np.empty((h, w, keep), np.float32)  # (only the first n_in are read)
    n_in = np.zeros((h, w), np.int16)
    disparity = np.full((h, w), np.nan, np.float32)
    near = np.zeros((h, w), np.uint8)
    for y in prange(h):
        yr = (y - cy) / f
        steps, index = np.empty(2 * wr, np.float32), np.empty(wr, np.int64)  # (steps, scratch)
        plane = np.zeros(8 + wr, np.float64)  # (plane[7]: 1 without distortion; sums)
        if plain:
            _row_plane(yr, -f * tx, back, kp, rp, tp, plane)
        if skip:
            _steps(other, y, steps, plane[8:])
        for x in range(w):
            a = float(own[y, x])
            if a != a:
                continue
            if from_right:
                j0, j1 = int(math.floor(x + shift + lo)), int(math.ceil(x + shift + hi))
            else:
                j0, j1 = int(math.floor(x - shift - hi)), int(math.ceil(x - shift - lo))
            if j0 < 0 or j1 > wr - 1:  # as the full search: a candidate may lie beyond
                n_in[y, x] = -1
                continue
            p = float(previous[y, x])
            if p == p:
                plo, phi = max(lo, p - margin), min(hi, p + margin)
                if from_right:
                    k0, k1 = int(math.floor(x + shift + plo)), int(math.ceil(x + shift + phi))
                else:
                    k0, k1 = int(math.floor(x - shift - phi)), int(math.ceil(x - shift - plo))
                count, d = _scan(own, other, steps, index, y, x, a, k0, k1, plo, phi, shift,
                                 f, cx, yr, tx, back, kp, dp, rp, tp, period, tolerance, zmin,
                                 zmax, width, from_right, skip, kept, plane)
                if count == 1:
                    n_in[y, x] = 1
                    disparity[y, x] = d
                    near[y, x] = 1
                    continue
            if gated and needed[y, x] == 0:  # no pixel of the other grid reads it
                n_in[y, x] = -2
                continue
            count, d = _scan(own, other, steps, index, y, x, a, j0, j1, lo, hi, shift, f, cx,
                             yr, tx, back, kp, dp, rp, tp, period, tolerance, zmin, zmax,
                             width, from_right, skip, kept, plane)
            n_in[y, x] = min(count, 32000)
            if count == 1:
                disparity[y, x] = d
    return n_in, disparity, near, kept


def track_rows(own: np.ndarray, other: np.ndarray, previous: np.ndarray, margin: float,
               lo: float, hi: float, shift: float, f: float, cx: float, cy: float, tx: float,
               back: np.ndarray, kp: np.ndarray, dp: np.ndarray, rp: np.ndarray,
               tp: np.ndarray, period: float, tolerance: float, zmin: float, zmax: float,
               width: int, from_right: bool = False, keep: int = KEPT,
               needed: np.ndarray | None = None, skip: bool = True
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The consistent candidates of each rectified pixel, searched first within
    ``margin`` of its ``previous`` disparity and over the full range ``[lo, hi]`` where
    that finds none or two or more (or there is no previous disparity).

    A candidate is what :func:`~bistair.geometry.unwrap_jit.unwrap_rows` takes: a place
    of equal wrapped phase on the other grid's row whose point the projector confirms
    within ``tolerance`` and whose depth lies in ``[zmin, zmax]``.

    Parameters
    ----------
    own, other : numpy.ndarray
        ``(H, W)`` float32 wrapped phase on the rectified grids (``own``: the pixels
        searched for; the left grid's, or the right grid's with ``from_right``), NaN where
        unknown.
    previous : numpy.ndarray
        ``(H, W)`` float32 disparities of ``own``'s pixels in the previous window, NaN
        where none.
    margin : float
        Half the width (rectified pixels) of the search about a previous disparity.
    lo, hi, shift, f, cx, cy, tx, back, kp, dp, rp, tp, period, tolerance, zmin, zmax, width
        As for :func:`~bistair.geometry.unwrap_jit.unwrap_rows`.
    from_right : bool, optional
        ``own`` is the right grid (the same disparity convention).
    keep : int, optional
        Keep the disparities of the first ``keep`` candidates of each pixel (what
        :func:`~bistair.geometry.unwrap_jit.grow` chooses among; by default ``KEPT`` of
        :mod:`~bistair.geometry.unwrap_jit`, 0 keeps none).
    needed : numpy.ndarray, optional
        ``(H, W)`` uint8: search the full range only where 1 (:func:`match_targets`: the
        pixels whose decision the other grid's confirmation reads); a pixel of 0 whose
        narrow search does not decide is left undecided (``n_in`` -2). By default every
        pixel.
    skip : bool, optional
        Test only the intervals where a crossing can lie (the module's docstring; the same
        result); ``False`` tests every interval of the search.

    Returns
    -------
    n_in : numpy.ndarray
        ``(H, W)`` int16 consistent candidates in the range of the search that decided
        (1 from the narrow one; else the full one's count), -1 where the full search would
        reach past the other view, -2 where it was not ``needed``.
    disparity : numpy.ndarray
        ``(H, W)`` float32 the one candidate's disparity, NaN elsewhere.
    near : numpy.ndarray
        ``(H, W)`` uint8 1 where the narrow search decided.
    kept : numpy.ndarray
        ``(H, W, keep)`` float32 the candidates' disparities in the order found by the
        search that decided (only the first ``min(n_in, keep)`` of a pixel are set).

    Examples
    --------
    No previous disparity: the full search, as ``unwrap_rows`` (the module's rig):

    >>> cols = np.arange(80, dtype=np.float32)[None]
    >>> left = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
    >>> right = (2 * np.pi * (cols + 15) / 8) % (2 * np.pi)
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> none = np.full((1, 80), np.nan, np.float32)
    >>> n_in, d, near, kept = track_rows(
    ...     left, right, none, 2.0, 1.0, 40.0, 0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k,
    ...     np.zeros(5), np.eye(3), np.array([-25.0, 0, 0]), 8.0, 0.2, 400.0, 600.0, 1000)
    >>> int(n_in[0, 50]), round(float(d[0, 50]), 4), int(near[0, 50]), int(n_in[0, 30])
    (1, 20.0, 0, -1)
    >>> round(float(kept[0, 50, 0]), 4)
    20.0
    """
    def arr(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(a, np.float64).reshape(shape))

    return _track(np.ascontiguousarray(own, np.float32), np.ascontiguousarray(other, np.float32),
                  np.ascontiguousarray(previous, np.float32), float(margin), float(lo),
                  float(hi), float(shift), float(f), float(cx), float(cy), float(tx),
                  arr(back, (3, 3)), arr(kp, (3, 3)), arr(dp, (5,)), arr(rp, (3, 3)),
                  arr(tp, (3,)), float(period), float(tolerance), float(zmin), float(zmax),
                  int(width), bool(from_right), int(keep),
                  np.zeros((0, 0), np.uint8) if needed is None
                  else np.ascontiguousarray(needed, np.uint8), bool(skip),
                  bool(skip and not np.any(np.asarray(dp, np.float64)[:5])))


@kernel(parallel=True)
def _targets(disparity: np.ndarray, shift: float, width: int) -> np.ndarray:
    h, w = disparity.shape
    out = np.zeros((h, width), np.uint8)
    for y in prange(h):
        for x in range(w):
            d = float(disparity[y, x])
            if d == d:
                xr = int(np.rint(x - shift - d))
                if 0 <= xr < width:
                    out[y, xr] = 1
    return out


def match_targets(disparity: np.ndarray, shift: float, width: int) -> np.ndarray:
    """The right grid's pixels that the left grid's single candidates match (the nearest
    pixel, as :func:`confirm` reads them).

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 the left grid's single candidates, NaN elsewhere.
    shift : float
        ``cx_left - cx_right`` (px).
    width : int
        The right grid's width.

    Returns
    -------
    numpy.ndarray
        ``(H, width)`` uint8: 1 where some left pixel's candidate lands.

    Examples
    --------
    >>> match_targets(np.float32([[np.nan, 1.0, 1.2, 0.4]]), -1.0, 4).tolist()
    [[0, 1, 1, 0]]
    """
    return _targets(np.ascontiguousarray(disparity, np.float32), float(shift), int(width))


@kernel(parallel=True)
def _columns(disparity: np.ndarray, shift: float, f: float, cx: float, cy: float, tx: float,
             back: np.ndarray, kp: np.ndarray, dp: np.ndarray, rp: np.ndarray,
             tp: np.ndarray, plain: bool) -> tuple[np.ndarray, np.ndarray]:
    h, w = disparity.shape
    cols = np.empty((h, w), np.float32)
    rows = np.empty((0, 0) if plain else (h, w), np.float32)
    nan32, inv_f, k = np.float32(np.nan), 1.0 / f, -f * tx
    for y in prange(h):
        if plain:  # the row's coefficients, linear in x and d: one division (_row_plane)
            plane = np.empty(8, np.float64)
            _row_plane((y - cy) * inv_f, k, back, kp, rp, tp, plane)
            for x in range(w):  # (no branch: the pass vectorises)
                d, xl = float(disparity[y, x]), (x - cx) * inv_f
                z = plane[3] * xl + plane[4] + tp[2] * d  # the projector's Z times d
                u = (plane[0] * xl + plane[1] + plane[2] * d) / z + kp[0, 2]
                cols[y, x] = np.float32(u) if (d * tx < 0.0) & (z * d > 0.0) else nan32
            continue
        for x in range(w):
            d = float(disparity[y, x])
            cols[y, x] = rows[y, x] = nan32
            if not d * tx < 0.0:
                continue
            zr = k / d
            qx, qy = (x - cx) / f * zr, (y - cy) / f * zr
            px = back[0, 0] * qx + back[0, 1] * qy + back[0, 2] * zr
            py = back[1, 0] * qx + back[1, 1] * qy + back[1, 2] * zr
            pz = back[2, 0] * qx + back[2, 1] * qy + back[2, 2] * zr
            cols[y, x], rows[y, x] = _project(px, py, pz, kp, dp, rp, tp)
    return cols, rows


def projector_pixels(disparity: np.ndarray, shift: float, f: float, cx: float, cy: float,
                     tx: float, back: np.ndarray, kp: np.ndarray, dp: np.ndarray,
                     rp: np.ndarray, tp: np.ndarray, rows: bool = True
                     ) -> tuple[np.ndarray, np.ndarray | None]:
    """The projector pixel (column, row) of each rectified left pixel's point.

    Without distortion and without ``rows``, each column comes from coefficients of its
    row linear in the pixel and the disparity (one division a pixel: the row search's
    ``_row_plane``), equal to the projection to rounding.

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 on the rectified left grid, NaN where undecided.
    shift, f, cx, cy, tx, back, kp, dp, rp, tp
        As for :func:`track_rows` (``shift`` is not used: disparities are relative to it).
    rows : bool, optional
        Give the rows too (:func:`plane_depth` reads them only through a distorted
        projector); ``False`` gives None for them where ``dp`` is all 0.

    Returns
    -------
    columns, rows : numpy.ndarray
        ``(H, W)`` float32 projector pixel, NaN where ``disparity`` is (``rows`` None:
        not asked for, the projector undistorted).

    Examples
    --------
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> u, v = projector_pixels(np.float32([[20.0, np.nan]]), 0.0, 100.0, 0.0, 0.0, -100.0,
    ...                         np.eye(3), k, np.zeros(5), np.eye(3), np.array([-25.0, 0, 0]))
    >>> [round(float(a), 3) for a in (u[0, 0], v[0, 0])], bool(np.isnan(u[0, 1]))
    ([-5.0, 0.0], True)
    >>> u, v = projector_pixels(np.float32([[20.0, np.nan]]), 0.0, 100.0, 0.0, 0.0, -100.0,
    ...                         np.eye(3), k, np.zeros(5), np.eye(3), np.array([-25.0, 0, 0]),
    ...                         rows=False)
    >>> round(float(u[0, 0]), 3), v is None
    (-5.0, True)
    """
    def arr(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(a, np.float64).reshape(shape))

    plain = not (rows or np.any(arr(dp, (5,))))  # (no rows: None)
    cols, out_rows = _columns(np.ascontiguousarray(disparity, np.float32), float(shift),
                              float(f), float(cx), float(cy), float(tx), arr(back, (3, 3)),
                              arr(kp, (3, 3)), arr(dp, (5,)), arr(rp, (3, 3)), arr(tp, (3,)),
                              plain)
    return cols, None if plain else out_rows


@kernel(parallel=True)
def _plane_depth(cols: np.ndarray, rows: np.ndarray | None, u: np.ndarray, v: np.ndarray,
                 phase: np.ndarray, ax: np.ndarray, az: np.ndarray, period: float,
                 max_step: float, kp: np.ndarray, dp: np.ndarray, t0: float, t2: float,
                 zmin: float, zmax: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    h, w = u.shape
    (gh, gw), nan32 = cols.shape, np.float32(np.nan)
    depth = np.empty((h, w), np.float32)  # (each pixel written once: no fill before)
    order = np.empty((h, w), np.int32)
    column = np.empty((h, w), np.float32)
    fx, skew, cxp, fy, cyp = kp[0, 0], kp[0, 1], kp[0, 2], kp[1, 1], kp[1, 2]
    distorted = dp[0] != 0.0 or dp[1] != 0.0 or dp[2] != 0.0 or dp[3] != 0.0 or dp[4] != 0.0
    inv_period, inv_two_pi, inv_fx, inv_fy = 1.0 / period, 1.0 / TWO_PI, 1.0 / fx, 1.0 / fy
    for y in prange(h):
        for x in range(w):  # (no branch but the rig's: the pass vectorises)
            phi, su, sv = float(phase[y, x]), float(u[y, x]), float(v[y, x])
            fx0, fy0 = math.floor(su), math.floor(sv)
            inside = (fx0 >= 0.0) & (fy0 >= 0.0) & (fx0 + 1.0 < gw) & (fy0 + 1.0 < gh)
            x0, y0 = int(fx0) if inside else 0, int(fy0) if inside else 0
            fu, fv = su - x0, sv - y0
            g0, g1 = float(cols[y0, x0]), float(cols[y0, x0 + 1])  # the four corners
            g2, g3 = float(cols[y0 + 1, x0]), float(cols[y0 + 1, x0 + 1])
            c = (1 - fu) * (1 - fv) * g0 + fu * (1 - fv) * g1 + (1 - fu) * fv * g2 + fu * fv * g3
            spread = max(max(g0, g1), max(g2, g3)) - min(min(g0, g1), min(g2, g3))
            # (reciprocals precomputed: no division but the plane's)
            k = math.floor(c * inv_period - phi * inv_two_pi + 0.5)
            xp = (phi * inv_two_pi + k) * period  # the column of the absolute phase
            if rows is None:  # (a compiled version of its own: the pass vectorises)
                xn = (xp - cxp) * inv_fx
            elif distorted:  # the row of the sample, for the column plane's local slope
                r = (1 - fv) * ((1 - fu) * rows[y0, x0] + fu * rows[y0, x0 + 1]) + fv * (
                    (1 - fu) * rows[y0 + 1, x0] + fu * rows[y0 + 1, x0 + 1])
                yd = (r - cyp) * inv_fy
                xd = (xp - cxp - skew * yd) * inv_fx
                xn, yn = xd, yd
                for _ in range(8):  # undistort (OpenCV's iteration)
                    r2 = xn * xn + yn * yn
                    radial = 1.0 + r2 * (dp[0] + r2 * (dp[1] + r2 * dp[4]))
                    dx = 2.0 * dp[2] * xn * yn + dp[3] * (r2 + 2.0 * xn * xn)
                    dy = dp[2] * (r2 + 2.0 * yn * yn) + 2.0 * dp[3] * xn * yn
                    xn, yn = (xd - dx) / radial, (yd - dy) / radial
            else:  # skewed
                xn = (xp - cxp - skew * ((float(rows[y0, x0]) - cyp) * inv_fy)) * inv_fx
            z = (xn * t2 - t0) / (float(ax[y, x]) - xn * float(az[y, x]))  # (0: inf, NaN)
            # (a NaN phase or corner makes z NaN; every corner decided: c is a number)
            ok = inside & (c == c) & (spread <= max_step) & (zmin <= z) & (z <= zmax)
            depth[y, x] = np.float32(z) if ok else nan32
            order[y, x] = int(k) if ok else -1
            column[y, x] = np.float32(xp) if ok else nan32
    return depth, order, column


def plane_depth(columns: np.ndarray, rows: np.ndarray | None, u: np.ndarray, v: np.ndarray,
                phase: np.ndarray, ax: np.ndarray, az: np.ndarray, period: float,
                max_step: float, kp: np.ndarray, dp: np.ndarray, tp: np.ndarray,
                zmin: float, zmax: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The depth where each left pixel's ray cuts the projector's plane of the column of
    its absolute phase.

    The order comes from the projector columns decided on the rectified grid, read
    bilinearly at the pixel's rectified position (four decided corners that spread by at
    most ``max_step`` columns); the absolute phase is the pixel's own wrapped phase plus
    ``2*pi`` times the order that puts it nearest that column. The point ``z * (x, y, 1)``
    of the pixel's ray lies on the column's plane where the projector's normalised
    ``X - x_n Z`` is 0: ``z = (x_n t_z - t_x) / (a_x - x_n a_z)`` with ``a = R (x, y, 1)``
    (``ax``, ``az``) precomputed per pixel.

    Parameters
    ----------
    columns, rows : numpy.ndarray
        ``(h, w)`` float32 projector pixel of each rectified left pixel
        (:func:`projector_pixels`), NaN where undecided; ``rows`` is read only through a
        distorted or skewed projector (None else).
    u, v : numpy.ndarray
        ``(H, W)`` float32 the left pixels' rectified positions.
    phase : numpy.ndarray
        ``(H, W)`` float32 the left camera's wrapped phase (radians), NaN where unknown.
    ax, az : numpy.ndarray
        ``(H, W)`` float32 the projector frame's x and z of each pixel's ray.
    period : float
        The fringe period (projector pixels).
    max_step : float
        The largest spread (projector columns) of the four corners.
    kp, dp, tp : numpy.ndarray
        The projector's intrinsics, distortion (5) and translation from the left camera.
    zmin, zmax : float
        The depth range kept (mm).

    Returns
    -------
    depth : numpy.ndarray
        ``(H, W)`` float32 ``z`` (mm), NaN where undecided or outside the range.
    order : numpy.ndarray
        ``(H, W)`` int32 fringe order, -1 where ``depth`` is NaN.
    column : numpy.ndarray
        ``(H, W)`` float32 the projector column of the absolute phase
        (``Phi * period / (2*pi)``), NaN where ``depth`` is.

    Raises
    ------
    ValueError
        ``rows`` None where the projector is distorted or skewed.

    Examples
    --------
    A projector 25 mm right of the camera, both ``f`` = 100 px, columns ``x - 5`` on a
    plane at 500 mm (the ray of pixel 50 is ``(0.5, 0, 1)``), period 8:

    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> ones = np.ones((1, 1), np.float32)
    >>> cols, rows = np.full((2, 2), 45.2, np.float32), np.zeros((2, 2), np.float32)
    >>> phase = np.float32([[2 * np.pi * 45 / 8 % (2 * np.pi)]])
    >>> z, order, column = plane_depth(cols, rows, 0.5 * ones, 0.5 * ones, phase, 0.5 * ones, ones,
    ...                        8.0, 2.0, k, np.zeros(5), np.array([-25.0, 0, 0]), 400, 600)
    >>> round(float(z[0, 0]), 3), int(order[0, 0]), round(float(column[0, 0]), 3)
    (500.0, 5, 45.0)
    """
    k = np.ascontiguousarray(np.asarray(kp, np.float64).reshape(3, 3))
    d = np.ascontiguousarray(np.asarray(dp, np.float64).reshape(5))
    t = np.asarray(tp, np.float64).reshape(3)
    bent = bool(np.any(d) or k[0, 1] != 0.0)  # (else None: a version without its branch)
    if rows is None and bent:
        raise ValueError("plane_depth needs the projector rows of a distorted or skewed "
                         "projector")
    return _plane_depth(np.ascontiguousarray(columns, np.float32),
                        np.ascontiguousarray(rows, np.float32) if bent else None,
                        np.asarray(u, np.float32), np.asarray(v, np.float32),
                        np.asarray(phase, np.float32),
                        np.asarray(ax, np.float32), np.asarray(az, np.float32), float(period),
                        float(max_step), k, d, float(t[0]), float(t[2]), float(zmin),
                        float(zmax))


@kernel(parallel=True)
def _confirm(disparity: np.ndarray, n_in: np.ndarray, valid: np.ndarray, right: np.ndarray,
             shift: float, support: float, edge: int
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    h, w = disparity.shape
    wr = right.shape[1]
    crossed = np.empty((h, w), np.float32)
    occluded = np.empty((h, w), np.uint8)
    blocked = np.empty((h, w), np.bool_)
    out = np.empty((h, w), np.float32)
    counts = np.zeros((h, 2), np.int64)  # not confirmed, unsupported
    for y in prange(h):
        for x in range(w):
            d = float(disparity[y, x])
            crossed[y, x] = np.nan
            contradicted = False
            if d == d:
                xr = int(np.rint(x - shift - d))
                if 0 <= xr < wr:
                    r = float(right[y, xr])
                    if abs(r - d) <= support:
                        crossed[y, x] = d
                    elif r == r:  # the right pixel decided another point
                        contradicted = True
            occluded[y, x] = valid[y, x] and (n_in[y, x] == 0 or contradicted)
            if n_in[y, x] == 1 and crossed[y, x] != crossed[y, x]:
                counts[y, 0] += 1
    for y in prange(h):
        for x in range(w):
            near = False
            for k in range(max(x - edge, 0), min(x + edge + 1, w)):
                if occluded[y, k]:
                    near = True
                    break
            blocked[y, x] = near
            out[y, x] = np.nan
            c = float(crossed[y, x])
            if c != c:
                continue
            ok = not near and ((y > 0 and abs(c - float(crossed[y - 1, x])) <= support) or (
                y < h - 1 and abs(c - float(crossed[y + 1, x])) <= support))
            if ok:
                out[y, x] = c
            else:
                counts[y, 1] += 1
    return out, crossed, blocked, counts[:, 0].copy(), counts[:, 1].copy()


def confirm(disparity: np.ndarray, n_in: np.ndarray, valid: np.ndarray, right: np.ndarray,
            shift: float, support: float, edge: int
            ) -> tuple[np.ndarray, np.ndarray, int, int]:
    """The decided disparities that the full search would keep: confirmed by the right
    grid's decision at the match (within ``support`` px), by the row above or below
    (within ``support``), and not within ``edge`` pixels along the row of an occluded pixel
    (a valid one with no candidate, or whose match the right grid decided as another
    point); what :func:`~bistair.geometry.unwrap.unwrap_stereo` does after its search and
    before its growth, in one pass.

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 the left grid's single candidates, NaN elsewhere.
    n_in : numpy.ndarray
        ``(H, W)`` int16 the candidates counted (:func:`track_rows`).
    valid : numpy.ndarray
        ``(H, W)`` bool: the left grid's pixels of known phase.
    right : numpy.ndarray
        ``(H, W_right)`` float32 the right grid's single candidates.
    shift, support : float
        ``cx_left - cx_right``; the largest disagreement (px).
    edge : int
        The reach (px) of an occlusion along the row.

    Returns
    -------
    kept : numpy.ndarray
        ``(H, W)`` float32 the confirmed disparities, NaN elsewhere.
    blocked : numpy.ndarray
        ``(H, W)`` bool: within ``edge`` pixels along the row of an occluded pixel (never
        grown into: :func:`~bistair.geometry.unwrap_jit.grow`).
    not_confirmed : int
        Single candidates the right grid does not confirm.
    unsupported : int
        Confirmed ones dropped by the rows beside or an occlusion.

    Examples
    --------
    >>> d = np.float32([[5, 5, 5, 5], [5, 5, 5, 5]])
    >>> n = np.ones((2, 4), np.int16)
    >>> right = np.full((2, 4), 5.0, np.float32)
    >>> right[0, 1] = np.nan
    >>> kept, blocked, nc, un = confirm(d, n, np.ones((2, 4), bool), right, -3.0, 1.0, 0)
    >>> kept.tolist(), nc, un  # left x matches right x - 2: 0 and 1 beyond, (0, 3) unknown
    ([[nan, nan, 5.0, nan], [nan, nan, 5.0, nan]], 5, 1)
    >>> bool(blocked.any())
    False
    >>> right[0, 1] = 9.0  # the right pixel decided another point: (0, 3) occluded
    >>> blocked = confirm(d, n, np.ones((2, 4), bool), right, -3.0, 1.0, 0)[1]
    >>> blocked.astype(int).tolist()
    [[0, 0, 0, 1], [0, 0, 0, 0]]
    """
    out, _, blocked, nc, un = _confirm(np.ascontiguousarray(disparity, np.float32),
                                       np.ascontiguousarray(n_in, np.int16),
                                       np.ascontiguousarray(valid, np.bool_),
                                       np.ascontiguousarray(right, np.float32), float(shift),
                                       float(support), int(edge))
    return out, blocked, int(nc.sum()), int(un.sum())


@kernel(parallel=True)
def _counts(rectified: np.ndarray, n_in: np.ndarray, near: np.ndarray, alone: np.ndarray,
            kept: np.ndarray) -> np.ndarray:
    h, w = rectified.shape
    rows = np.zeros((h, 5), np.int64)
    for y in prange(h):
        for x in range(w):
            if rectified[y, x] == rectified[y, x]:
                rows[y, 0] += n_in[y, x] == 0
                rows[y, 4] += near[y, x] == 0
            decided = kept[y, x] == kept[y, x]
            rows[y, 1] += n_in[y, x] >= 2 and not decided
            rows[y, 2] += decided and alone[y, x] != alone[y, x]
            rows[y, 3] += near[y, x]
    return rows


def window_counts(rectified: np.ndarray, n_in: np.ndarray, near: np.ndarray,
                  alone: np.ndarray, kept: np.ndarray) -> list[int]:
    """A tracked window's pixel counts in one pass.

    Parameters
    ----------
    rectified : numpy.ndarray
        ``(H, W)`` float32 the left grid's wrapped phase, NaN where unknown.
    n_in, near : numpy.ndarray
        ``(H, W)`` :func:`track_rows`' candidate counts (int16) and narrow decisions
        (uint8).
    alone, kept : numpy.ndarray
        ``(H, W)`` float32 the confirmed disparities (:func:`confirm`) and those after
        growth, NaN where undecided.

    Returns
    -------
    list of int
        No candidate (of the known pixels), undecided with two or more, grown, decided by
        the narrow search, searched in full (known pixels the narrow search did not decide).

    Examples
    --------
    >>> nan = np.nan
    >>> window_counts(np.float32([[1, 1, 1, nan]]), np.int16([[0, 2, 1, 0]]),
    ...               np.uint8([[0, 0, 1, 0]]), np.float32([[nan, nan, 5, nan]]),
    ...               np.float32([[nan, 4, 5, nan]]))
    [1, 0, 1, 1, 2]
    """
    rows = _counts(np.ascontiguousarray(rectified, np.float32),
                   np.ascontiguousarray(n_in, np.int16), np.ascontiguousarray(near, np.uint8),
                   np.ascontiguousarray(alone, np.float32),
                   np.ascontiguousarray(kept, np.float32))
    return [int(v) for v in rows.sum(axis=0)]
