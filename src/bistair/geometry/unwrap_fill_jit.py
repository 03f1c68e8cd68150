"""Compiled pass of :mod:`bistair.geometry.unwrap_fill`: the fringe order of the left
pixels the right camera gives no candidate for, continued from the decided pixels by the
left camera's own phase (breadth first over the rectified left grid).

It has no NumPy twin (a breadth-first growth); ``tests/test_unwrap.py`` checks it against
the renderer's truth.

Examples
--------
Two cameras 100 mm apart (``f`` = 100 px), a projector 25 mm right of the left camera (a
period of 8 px) and a plane at 500 mm (disparity 20): four rows, decided from column 20 on,
columns 0-19 without a candidate, their matches left of the right view:

>>> cols = np.arange(60, dtype=np.float32)[None].repeat(4, axis=0)
>>> phase = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
>>> d = np.where(cols >= 20, np.float32(20), np.float32(np.nan))
>>> n = np.where(cols >= 20, 1, 0).astype(np.int16)
>>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
>>> nearest = np.full((4, 60), np.nan, np.float32)  # the right view holds nothing nearer
>>> right = np.full((4, 60), np.nan, np.float32)  # (and no phase)
>>> rig = (0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k, np.zeros(5), np.eye(3),
...        np.array([-25.0, 0, 0]), 8.0, 1000, 400.0, 600.0)
>>> out, continued = continue_rows(phase, right, d, n, nearest, *rig, 1.0, 0.3, 1.0, 3.0, 0.2)
>>> np.round(out[0, :3], 3).tolist(), int(continued.sum())
([20.0, 20.0, 20.0], 80)

Decided from column 25 on, columns 20-24 match right pixels that see nothing nearer: they
would be seen, so none continues.

>>> d[:, 20:25] = np.nan
>>> int(continue_rows(phase, right, d, n * 0, nearest, *rig, 1.0, 0.3, 1.0, 3.0, 0.2)[1].sum())
0
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel
from .unwrap_jit import projector_column

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi


@inline
def _column_at(d: float, x: float, y: float, f: float, cx: float, cy: float, tx: float,
               back: np.ndarray, kp: np.ndarray, dp: np.ndarray, rp: np.ndarray,
               tp: np.ndarray) -> float:
    """The projector column of rectified left pixel ``(x, y)``'s point at disparity
    ``d``."""
    zr = -f * tx / d
    qx, qy = (x - cx) / f * zr, (y - cy) / f * zr
    px = back[0, 0] * qx + back[0, 1] * qy + back[0, 2] * zr
    py = back[1, 0] * qx + back[1, 1] * qy + back[1, 2] * zr
    pz = back[2, 0] * qx + back[2, 1] * qy + back[2, 2] * zr
    return projector_column(px, py, pz, kp, dp, rp, tp)


@inline
def _depth_at(d: float, x: float, y: float, f: float, cx: float, cy: float, tx: float,
              back: np.ndarray) -> float:
    """The left camera frame's ``z`` of rectified left pixel ``(x, y)``'s point at
    disparity ``d``."""
    zr = -f * tx / d
    return (back[2, 0] * (x - cx) / f + back[2, 1] * (y - cy) / f + back[2, 2]) * zr


@inline
def _agrees(right: np.ndarray, y: int, xr: float, a: float, tolerance: float) -> bool:
    """Whether the right phase at ``(xr, y)`` (linear between its two pixels, not across
    a wrap) lies within ``tolerance`` of ``a``."""
    c = min(int(math.floor(xr)), right.shape[1] - 2)
    r0, r1 = float(right[y, c]), float(right[y, c + 1])
    if r0 != r0 or r1 != r1:
        return False
    step = r1 - r0
    step -= TWO_PI * math.floor((step + math.pi) / TWO_PI)
    there = r0 + (xr - c) * step - a
    there -= TWO_PI * math.floor((there + math.pi) / TWO_PI)
    return abs(there) <= tolerance


@kernel()
def _continue(phase: np.ndarray, right: np.ndarray, disparity: np.ndarray,
              n_in: np.ndarray, nearest: np.ndarray, shift: float, f: float, cx: float,
              cy: float, tx: float, back: np.ndarray, kp: np.ndarray, dp: np.ndarray,
              rp: np.ndarray, tp: np.ndarray, period: float, width: int, zmin: float, zmax: float,
              bound: float, bend: float, reach: float, margin: float,
              tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    h, w = disparity.shape
    wr = nearest.shape[1]
    dy, dx = np.array([1, -1, 0, 0, 1, 1, -1, -1]), np.array([0, 0, 1, -1, 1, -1, 1, -1])
    out = disparity.copy()
    absolute = np.full((h, w), np.nan)
    continued = np.zeros((h, w), np.bool_)
    queue = np.empty(h * w, np.int64)
    tail = 0
    for y in range(h):
        for x in range(w):
            d = float(out[y, x])
            a = float(phase[y, x])
            if d == d and a == a and d > 0.0:
                u = _column_at(d, x, y, f, cx, cy, tx, back, kp, dp, rp, tp)
                if u == u:
                    k = round((TWO_PI * u / period - a) / TWO_PI)
                    absolute[y, x] = a + TWO_PI * k
                    queue[tail] = y * w + x
                    tail += 1
    head = 0
    while head < tail:
        y, x = queue[head] // w, queue[head] % w
        head += 1
        for j in range(8):
            ny, nx = y + dy[j], x + dx[j]
            if not (0 <= ny < h and 0 <= nx < w) or out[ny, nx] == out[ny, nx]:
                continue
            a = float(phase[ny, nx])
            if a != a or n_in[ny, nx] > 0:  # candidates of its own: not this step's
                continue
            votes, order, clash, dsum = 0, 0.0, False, 0.0
            for i in range(8):
                my, mx = ny + dy[i], nx + dx[i]
                if not (0 <= my < h and 0 <= mx < w) or absolute[my, mx] != absolute[my, mx]:
                    continue
                k = round((absolute[my, mx] - a) / TWO_PI)
                if abs(a + TWO_PI * k - absolute[my, mx]) > bound:
                    continue
                fy, fx = my + dy[i], mx + dx[i]  # the phase's line through two neighbours
                if not (0 <= fy < h and 0 <= fx < w) or absolute[fy, fx] != absolute[fy, fx]:
                    continue
                if abs(a + TWO_PI * k - 2.0 * absolute[my, mx] + absolute[fy, fx]) > bend:
                    continue
                if votes > 0 and k != order:
                    clash = True
                votes += 1
                order = k
                dsum += out[my, mx]
            if clash or votes < 2:
                continue
            target = (a + TWO_PI * order) * period / TWO_PI
            d = dsum / votes
            for _ in range(8):  # Newton on the projector column along the left ray
                u0 = _column_at(d, nx, ny, f, cx, cy, tx, back, kp, dp, rp, tp)
                u1 = _column_at(d + 0.01, nx, ny, f, cx, cy, tx, back, kp, dp, rp, tp)
                if not (u0 == u0 and u1 == u1) or u1 == u0:
                    d = math.nan
                    break
                step = (u0 - target) * 0.01 / (u1 - u0)
                d -= step
                if not d > 0.0:
                    d = math.nan
                    break
                if abs(step) < 1e-4:
                    break
            if d != d:
                continue
            z = _depth_at(d, nx, ny, f, cx, cy, tx, back)
            if not (zmin <= z <= zmax):
                continue
            far = False  # the depth continues every voting neighbour's
            limit = max(reach, 4.0 * d / f)
            for i in range(8):
                my, mx = ny + dy[i], nx + dx[i]
                if (0 <= my < h and 0 <= mx < w and absolute[my, mx] == absolute[my, mx]
                        and abs(out[my, mx] - d) > limit * (1.5 if i >= 4 else 1.0)):
                    far = True
            if far:
                continue
            xr = nx - shift - d  # the right camera must not see it: off its view or
            if 0.0 <= xr <= wr - 1.0:  # something nearer there
                c = int(round(xr))
                seen = -math.inf
                for e in range(max(c - 1, 0), min(c + 2, wr)):
                    if nearest[ny, e] == nearest[ny, e]:
                        seen = max(seen, nearest[ny, e])
                if not (seen > d + margin or (n_in[ny, nx] < 0 and _agrees(
                        right, ny, xr, a, tolerance))):
                    continue
            out[ny, nx] = d
            absolute[ny, nx] = a + TWO_PI * order
            continued[ny, nx] = True
            queue[tail] = ny * w + nx
            tail += 1
    for y in range(h):  # where two fronts meet and disagree: left undecided
        for x in range(w):
            if not continued[y, x]:
                continue
            for i in range(8):
                my, mx = y + dy[i], x + dx[i]
                if (0 <= my < h and 0 <= mx < w and absolute[my, mx] == absolute[my, mx]
                        and abs(absolute[my, mx] - absolute[y, x]) > math.pi):
                    out[y, x] = math.nan
    return out, continued & (out == out)


@kernel()
def _nearest(disparity: np.ndarray, shift: float, right_width: int) -> np.ndarray:
    h, w = disparity.shape
    out = np.full((h, right_width), np.nan, np.float32)
    for y in range(h):
        for x in range(w):
            d = disparity[y, x]
            if d != d:
                continue
            xr = x - shift - d
            for c in (int(math.floor(xr)), int(math.ceil(xr))):
                if 0 <= c < right_width and not out[y, c] >= d:
                    out[y, c] = d
    return out


def right_nearest(disparity: np.ndarray, shift: float, right_width: int) -> np.ndarray:
    """The largest decided disparity that lands on each right pixel: what the right camera
    sees nearest there, as far as the left grid's decisions tell.

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 decided disparities of the rectified left grid, NaN elsewhere.
    shift : float
        ``cx_left - cx_right`` of the rectification (pixels).
    right_width : int
        The right grid's width.

    Returns
    -------
    numpy.ndarray
        ``(H, right_width)`` float32, NaN where no decided pixel lands (each lands on the
        two right pixels about ``x - shift - d``).

    Examples
    --------
    >>> right_nearest(np.float32([[np.nan, 1.0, 1.0, 1.5]]), 0.0, 4).tolist()
    [[1.0, 1.5, 1.5, nan]]
    """
    return _nearest(np.ascontiguousarray(disparity, np.float32), float(shift),
                    int(right_width))


def continue_rows(phase: np.ndarray, right: np.ndarray, disparity: np.ndarray,
                  n_in: np.ndarray, nearest: np.ndarray, shift: float, f: float, cx: float,
                  cy: float, tx: float, back: np.ndarray, kp: np.ndarray, dp: np.ndarray,
                  rp: np.ndarray, tp: np.ndarray, period: float, width: int, zmin: float,
                  zmax: float, bound: float, bend: float, reach: float,
                  margin: float, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Decided disparities continued into the left pixels the right camera gives no
    candidate for, breadth first from the decided pixels.

    A pixel of valid phase ``a`` and no candidate of its own (``n_in`` 0 or -1) takes the
    fringe order ``k`` that puts ``a + 2*pi*k`` within ``bound`` of the absolute phase of
    each of its decided (or continued) 8-neighbours that is that near and within ``bend``
    of the line through that neighbour and the next one beyond it (the phase's second
    difference: a steep, blurred side bends it), when at least two are and all of them
    give the same ``k``. Its disparity is where its ray meets the
    projector column of that phase; it is kept when its depth lies in ``[zmin, zmax]``,
    it lies within ``max(reach, 4 * d / f)`` pixels of every such neighbour's disparity (the
    surface turned at most 76 degrees from the ray, as :data:`~.unwrap.GRAZING`) and the
    right camera cannot see it: its match lies off the right view, or the right view holds
    a point more than ``margin`` pixels of disparity nearer there (``nearest``, within a
    pixel). A continued pixel whose order differs from a decided or continued neighbour's
    is left undecided at the end (two fronts that disagree). A pixel of ``n_in`` -1 (its
    search reached past the right view) whose match lies within the right view is kept
    when the right phase there agrees with its own within ``tolerance`` instead (seen, and
    confirmed by both cameras and the projector).

    Parameters
    ----------
    phase, right : numpy.ndarray
        ``(H, W)``, ``(H, W_right)`` float32 the left and the right camera's wrapped phase
        on the rectified grids.
    disparity : numpy.ndarray
        ``(H, W)`` float32 decided disparities, NaN where undecided.
    n_in : numpy.ndarray
        ``(H, W)`` int16 candidates of each pixel (:func:`~.unwrap_jit.unwrap_candidates`).
    nearest : numpy.ndarray
        ``(H, W_right)`` float32: the largest decided disparity seen at each right pixel
        (NaN: none).
    shift, f, cx, cy, tx, back, kp, dp, rp, tp, period, width : float or numpy.ndarray
        As :func:`~.unwrap_jit.unwrap_rows`.
    zmin, zmax : float
        The depth range (left camera frame, mm).
    bound, bend : float
        The largest phase step (radians) to a neighbour and the largest second
        difference.
    reach, margin : float
        The smallest disparity step limit and how much nearer (pixels) the right view's
        point must be.
    tolerance : float
        The largest disagreement (radians) of the right phase at a seen match.

    Returns
    -------
    disparity : numpy.ndarray
        ``(H, W)`` float32: the decided and the continued disparities.
    continued : numpy.ndarray
        ``(H, W)`` bool: the continued pixels.

    Examples
    --------
    The module's plane with the right view holding a nearer surface (disparity 30) over
    columns 0-10: columns 21-29 are hidden by it and continue too.

    >>> cols = np.arange(60, dtype=np.float32)[None].repeat(4, axis=0)
    >>> phase = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
    >>> d = np.where(cols >= 30, np.float32(20), np.float32(np.nan))
    >>> n = np.where(cols >= 30, 1, 0).astype(np.int16)
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> nearest = np.where(cols <= 10, np.float32(30), np.float32(np.nan))
    >>> right = np.full((4, 60), np.nan, np.float32)
    >>> out, continued = continue_rows(
    ...     phase, right, d, n, nearest, 0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k,
    ...     np.zeros(5), np.eye(3), np.array([-25.0, 0, 0]), 8.0, 1000, 400.0, 600.0, 1.0,
    ...     0.3, 1.0, 3.0, 0.2)
    >>> int(continued.sum()), bool(np.allclose(out, 20.0, atol=1e-3))
    (120, True)
    """
    def arr(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(a, np.float64).reshape(shape))

    return _continue(np.ascontiguousarray(phase, np.float32),
                     np.ascontiguousarray(right, np.float32),
                     np.ascontiguousarray(disparity, np.float32),
                     np.ascontiguousarray(n_in, np.int16),
                     np.ascontiguousarray(nearest, np.float32), float(shift), float(f),
                     float(cx), float(cy), float(tx), arr(back, (3, 3)), arr(kp, (3, 3)),
                     arr(dp, (5,)), arr(rp, (3, 3)), arr(tp, (3,)), float(period),
                     int(width), float(zmin), float(zmax), float(bound), float(bend),
                     float(reach),
                     float(margin), float(tolerance))
