"""Compiled pass of stereo phase unwrapping (:mod:`bistair.geometry.unwrap`): for each
pixel of the rectified left grid, the places of equal wrapped phase along the same row of
the rectified right grid, each triangulated and checked against the projector.

It runs over rectified rows on every core and has no NumPy twin (the row search has no
one-pass NumPy form); ``tests/test_unwrap.py`` checks it against the renderer's truth.

Examples
--------
Two cameras 100 mm apart (``f`` = 100 px) and a projector 25 mm right of the left camera
(the same optics, a period of 8 px) look at a plane 500 mm away (a disparity of 20 px):

>>> import numpy as np
>>> cols = np.arange(80, dtype=np.float32)[None]
>>> left = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)  # the projector column is x - 5
>>> right = (2 * np.pi * (cols + 15) / 8) % (2 * np.pi)  # the same points 20 px on
>>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
>>> n_in, disparity, n_all, z_all = unwrap_rows(
...     left, right, 1.0, 40.0, 0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k, np.zeros(5),
...     np.eye(3), np.array([-25.0, 0, 0]), 8.0, 0.2, 400.0, 600.0, 1000)
>>> int(n_in[0, 50]), round(float(disparity[0, 50]), 4), round(float(z_all[0, 50]), 3)
(1, 20.0, 500.0)
>>> int(n_in[0, 30])  # disparities up to 40 would reach past the right row's start
-1

Four other places of equal phase (disparities 4, 12, 28 and 36) put the point where the
projector shows another phase.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles
TWO_PI = 2.0 * math.pi
#: The consistent candidates in the depth range kept per pixel (:func:`unwrap_candidates`).
KEPT = 4


@inline
def _wrapped(angle: float) -> float:
    """``angle`` wrapped into ``[-pi, pi)``."""
    return angle - TWO_PI * math.floor((angle + math.pi) / TWO_PI)


@inline
def near(difference: float) -> float:
    """The difference of two phases in ``[0, 2*pi)`` wrapped into ``[-pi, pi)`` (NaN
    stays NaN; also the stream's row search's).

    Parameters
    ----------
    difference : float
        In ``(-2*pi, 2*pi)``.

    Returns
    -------
    float

    Examples
    --------
    >>> round(near(6.0), 4), near(-0.5), math.isnan(near(math.nan))
    (-0.2832, -0.5, True)
    """
    if difference >= math.pi:
        return difference - TWO_PI
    if difference < -math.pi:
        return difference + TWO_PI
    return difference


@inline
def projector_column(px: float, py: float, pz: float, kp: np.ndarray, dp: np.ndarray,
                      rp: np.ndarray, tp: np.ndarray) -> float:
    """The projector column (OpenCV's model, distortion ``k1, k2, p1, p2, k3``) of the
    point ``(px, py, pz)`` of the left camera's frame; NaN behind the projector.

    Parameters
    ----------
    px, py, pz : float
        The point (left camera frame, mm).
    kp, dp, rp, tp : numpy.ndarray
        The projector's intrinsics ``(3, 3)``, distortion (5), rotation ``(3, 3)`` and
        translation (3) from the left camera's frame.

    Returns
    -------
    float
        The column (projector pixels), NaN behind the projector.

    Examples
    --------
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> float(projector_column(50.0, 0.0, 500.0, k, np.zeros(5), np.eye(3),
    ...                        np.array([-25.0, 0, 0])))
    5.0
    """
    x = rp[0, 0] * px + rp[0, 1] * py + rp[0, 2] * pz + tp[0]
    y = rp[1, 0] * px + rp[1, 1] * py + rp[1, 2] * pz + tp[1]
    z = rp[2, 0] * px + rp[2, 1] * py + rp[2, 2] * pz + tp[2]
    if not z > 0.0:
        return math.nan
    x /= z
    y /= z
    r2 = x * x + y * y
    radial = 1.0 + r2 * (dp[0] + r2 * (dp[1] + r2 * dp[4]))
    xd = x * radial + 2.0 * dp[2] * x * y + dp[3] * (r2 + 2.0 * x * x)
    yd = y * radial + dp[2] * (r2 + 2.0 * y * y) + 2.0 * dp[3] * x * y
    return kp[0, 0] * xd + kp[0, 1] * yd + kp[0, 2]


@kernel(parallel=True)
def _unwrap(left: np.ndarray, right: np.ndarray, lo: float, hi: float, shift: float,
            f: float, cx: float, cy: float, tx: float, back: np.ndarray, kp: np.ndarray,
            dp: np.ndarray, rp: np.ndarray, tp: np.ndarray, period: float, tolerance: float,
            zmin: float, zmax: float, width: int, rows: np.ndarray, from_right: bool,
            whole: bool
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    h, wl = left.shape
    wr = right.shape[1]
    n = rows.size
    n_in = np.zeros((n, wl), np.int16)
    n_all = np.zeros((n, wl), np.int16)
    disparity = np.full((n, wl), np.nan, np.float32)
    z_all = np.full((n, wl), np.nan, np.float32)
    kept = np.full((n, wl, KEPT), np.nan, np.float32)
    for i in prange(n):
        y = rows[i]
        yr = (y - cy) / f
        for x in range(wl):
            a = float(left[y, x])
            if a != a:
                continue
            if from_right:  # x is a right pixel, the searched row the left one's
                j0, j1 = int(math.floor(x + shift + lo)), int(math.ceil(x + shift + hi))
            else:
                j0, j1 = int(math.floor(x - shift - hi)), int(math.ceil(x - shift - lo))
            if whole and (j0 < 0 or j1 > wr - 1):  # the other view ends within the search: a place
                n_in[i, x] = -1  # of equal phase may lie beyond it, so none is alone
                n_all[i, x] = -1
                continue
            best = math.inf
            first = max(j0, 0)
            e1 = near(float(right[y, first]) - a)  # NaN where unknown
            for j in range(first, min(j1, wr - 1)):
                e0 = e1
                e1 = near(float(right[y, j + 1]) - a)
                # a crossing of a (not a wrap, where the difference jumps by 2 pi)
                if not ((e0 <= 0.0 < e1) or (e1 <= 0.0 < e0)) or abs(e1 - e0) > math.pi:
                    continue  # (also when either is NaN)
                xs = j + e0 / (e0 - e1)
                d = xs - x - shift if from_right else x - xs - shift
                xl = ((xs if from_right else x) - cx) / f
                if not (lo <= d <= hi):
                    continue
                zr = -f * tx / d
                if not zr > 0.0:
                    continue
                # the point in the left camera's frame (back = R1.T)
                qx, qy = xl * zr, yr * zr
                px = back[0, 0] * qx + back[0, 1] * qy + back[0, 2] * zr
                py = back[1, 0] * qx + back[1, 1] * qy + back[1, 2] * zr
                pz = back[2, 0] * qx + back[2, 1] * qy + back[2, 2] * zr
                u = projector_column(px, py, pz, kp, dp, rp, tp)
                if not (-0.5 <= u <= width - 0.5):
                    continue
                miss = abs(_wrapped(TWO_PI * u / period - a))
                if miss > tolerance:
                    continue
                n_all[i, x] += 1
                if n_all[i, x] == 1 or miss < best:
                    z_all[i, x] = pz
                    best = miss
                if zmin <= pz <= zmax:
                    n_in[i, x] += 1
                    if n_in[i, x] <= KEPT:
                        kept[i, x, n_in[i, x] - 1] = d
                    if n_in[i, x] == 1:
                        disparity[i, x] = d
                    else:
                        disparity[i, x] = math.nan
    return n_in, disparity, n_all, z_all, kept


def unwrap_rows(left: np.ndarray, right: np.ndarray, lo: float, hi: float, shift: float,
                f: float, cx: float, cy: float, tx: float, back: np.ndarray, kp: np.ndarray,
                dp: np.ndarray, rp: np.ndarray, tp: np.ndarray, period: float,
                tolerance: float, zmin: float, zmax: float, width: int,
                rows: np.ndarray | None = None, from_right: bool = False,
                whole: bool = True
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The candidates of each rectified left pixel that the projector confirms.

    For a left pixel of wrapped phase ``a``, every place on the same row of the right grid
    where the right phase passes through ``a`` (between two valid neighbours, not across a
    wrap) at a disparity ``d = x_l - x_r - shift`` in ``[lo, hi]`` is triangulated
    (``Z = -f * tx / d``, turned back into the left camera's frame by ``back``) and
    projected into the projector; it is consistent when the projector's phase there,
    ``2 * pi * u / period``, is within ``tolerance`` of ``a`` and the column lies on the
    projector.

    Parameters
    ----------
    left, right : numpy.ndarray
        ``(H, W)`` float32 wrapped phase in ``[0, 2*pi)`` on the rectified grids (the same
        rows), NaN where unknown.
    lo, hi : float
        The disparities searched (rectified pixels).
    shift, f, cx, cy, tx : float
        The rectification: ``cx_left - cx_right``, the focal length, the left grid's
        principal point and the right camera's x in the rectified frame (mm, negative).
    back : numpy.ndarray
        ``(3, 3)`` the rectified frame to the left camera's (``R1.T``).
    kp, dp, rp, tp : numpy.ndarray
        The projector's intrinsics, distortion (5), rotation and translation from the left
        camera's frame.
    period : float
        The fringe period (projector pixels).
    tolerance : float
        The largest phase disagreement (radians) of a consistent candidate.
    zmin, zmax : float
        The depth range (left camera frame, mm) a candidate counts in.
    width : int
        The projector's width (pixels).
    rows : numpy.ndarray, optional
        The rectified rows to search (int64); all by default.
    from_right : bool, optional
        Search for the pixels of the right grid instead: ``left`` is then the right
        camera's rectified phase and ``right`` the left camera's (the same disparity, the
        same point; the outputs are on the right grid).
    whole : bool, optional
        Count a pixel only when its search lies wholly within the other view (-1 in both
        counts otherwise); ``False`` searches what lies within.

    Returns
    -------
    n_in : numpy.ndarray
        ``(rows, W)`` int16: consistent candidates in the depth range; -1 where the other
        view ends within the disparities searched (a candidate may lie beyond its border,
        so none is taken as the only one).
    disparity : numpy.ndarray
        ``(rows, W)`` float32: the disparity of the one such candidate, NaN where there is
        none or several.
    n_all : numpy.ndarray
        ``(rows, W)`` int16: consistent candidates over all disparities searched (-1 as
        ``n_in``).
    z_all : numpy.ndarray
        ``(rows, W)`` float32: the depth ``z`` of the consistent candidate whose phase
        agrees best, NaN without one.

    Examples
    --------
    The module's rig (``f`` = 100 px, cameras 100 mm apart, the projector 25 mm right of
    the left camera, a period of 8 px) and its plane at 500 mm, two rows, the second alone
    searched, with a depth range that leaves the plane out:

    >>> cols = np.arange(80, dtype=np.float32)[None].repeat(2, axis=0)
    >>> left = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
    >>> right = (2 * np.pi * (cols + 15) / 8) % (2 * np.pi)
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> n_in, disparity, n_all, z_all = unwrap_rows(
    ...     left, right, 1.0, 40.0, 0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k, np.zeros(5),
    ...     np.eye(3), np.array([-25.0, 0, 0]), 8.0, 0.2, 600.0, 900.0, 1000,
    ...     rows=np.array([1]))
    >>> n_in.shape, int(n_in[0, 50]), bool(np.isnan(disparity[0, 50]))  # none in range
    ((1, 80), 0, True)
    >>> int(n_all[0, 50]), round(float(z_all[0, 50]), 3)  # one over all disparities
    (1, 500.0)
    """
    return unwrap_candidates(left, right, lo, hi, shift, f, cx, cy, tx, back, kp, dp, rp, tp,
                             period, tolerance, zmin, zmax, width, rows, from_right,
                             whole)[:4]


def unwrap_candidates(left: np.ndarray, right: np.ndarray, lo: float, hi: float,
                      shift: float, f: float, cx: float, cy: float, tx: float,
                      back: np.ndarray, kp: np.ndarray, dp: np.ndarray, rp: np.ndarray,
                      tp: np.ndarray, period: float, tolerance: float, zmin: float,
                      zmax: float, width: int, rows: np.ndarray | None = None,
                      from_right: bool = False, whole: bool = True
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`unwrap_rows` and the disparities of the first :data:`KEPT` consistent
    candidates in the depth range of each pixel (what :func:`grow` chooses among).

    Parameters
    ----------
    left, right, lo, hi, shift, f, cx, cy, tx, back, kp, dp, rp, tp, period, tolerance, \
zmin, zmax, width, rows, from_right, whole
        As :func:`unwrap_rows`.

    Returns
    -------
    n_in, disparity, n_all, z_all : numpy.ndarray
        As :func:`unwrap_rows`.
    kept : numpy.ndarray
        ``(rows, W, KEPT)`` float32: the candidates' disparities in the order found, NaN
        beyond ``n_in``.

    Examples
    --------
    The module's rig with a depth range that holds the plane (500 mm) and a repeat:

    >>> cols = np.arange(80, dtype=np.float32)[None]
    >>> left = (2 * np.pi * (cols - 5) / 8) % (2 * np.pi)
    >>> right = (2 * np.pi * (cols + 15) / 8) % (2 * np.pi)
    >>> k = np.array([[100.0, 0, 0], [0, 100, 0], [0, 0, 1]])
    >>> out = unwrap_candidates(left, right, 1.0, 40.0, 0.0, 100.0, 0.0, 0.0, -100.0,
    ...                         np.eye(3), k, np.zeros(5), np.eye(3),
    ...                         np.array([-25.0, 0, 0]), 8.0, 0.2, 200.0, 600.0, 1000)
    >>> int(out[0][0, 50]), out[4][0, 50].round(3).tolist()
    (1, [20.0, nan, nan, nan])
    """
    left = np.ascontiguousarray(left, np.float32)
    right = np.ascontiguousarray(right, np.float32)
    rows = (np.arange(left.shape[0], dtype=np.int64) if rows is None
            else np.ascontiguousarray(rows, np.int64))

    def arr(a: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        return np.ascontiguousarray(np.asarray(a, np.float64).reshape(shape))

    return _unwrap(left, right, float(lo), float(hi), float(shift), float(f), float(cx),
                   float(cy), float(tx), arr(back, (3, 3)), arr(kp, (3, 3)), arr(dp, (5,)),
                   arr(rp, (3, 3)), arr(tp, (3,)), float(period), float(tolerance),
                   float(zmin), float(zmax), int(width), rows, bool(from_right),
                   bool(whole))


@kernel(parallel=True)
def _seeds(out: np.ndarray, n_in: np.ndarray, top: int, blocked: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    h, w = out.shape
    columns = np.empty((h, w), np.int32)
    counts = np.zeros(h, np.int64)
    for y in prange(h):  # each row's decided pixels beside one that may grow
        c = 0
        for x in range(w):
            if out[y, x] != out[y, x]:
                continue
            for k in range(4):
                ny, nx = y + (1, -1, 0, 0)[k], x + (0, 0, 1, -1)[k]
                if (0 <= ny < h and 0 <= nx < w and out[ny, nx] != out[ny, nx]
                        and 1 <= n_in[ny, nx] <= top and not blocked[ny, nx]):
                    columns[y, c] = x
                    c += 1
                    break
        counts[y] = c
    return columns, counts


@kernel()
def _grow(disparity: np.ndarray, n_in: np.ndarray, kept: np.ndarray, blocked: np.ndarray,
          reach: float, support: int, columns: np.ndarray, counts: np.ndarray) -> np.ndarray:
    h, w = disparity.shape
    dy, dx = np.array([1, -1, 0, 0]), np.array([0, 0, 1, -1])
    out = disparity.copy()
    queue = np.empty(h * w, np.int64)
    tail = 0
    for y in range(h):  # the seeds (_seeds), in raster order
        for c in range(counts[y]):
            queue[tail] = y * w + columns[y, c]
            tail += 1
    head = 0
    while head < tail:
        y, x = queue[head] // w, queue[head] % w
        head += 1
        for k in range(4):
            ny, nx = y + dy[k], x + dx[k]
            if not (0 <= ny < h and 0 <= nx < w) or out[ny, nx] == out[ny, nx]:
                continue
            m = n_in[ny, nx]
            if m < 1 or m > kept.shape[2] or blocked[ny, nx]:
                continue
            count, chosen = 0, math.nan
            for c in range(m):
                d = kept[ny, nx, c]
                agree = 0
                for j in range(4):
                    my, mx = ny + dy[j], nx + dx[j]
                    if (0 <= my < h and 0 <= mx < w and abs(out[my, mx] - d) <= reach):
                        agree += 1
                if agree >= 1:
                    count += 1
                    if agree >= support:
                        chosen = d
            if count == 1 and chosen == chosen:
                out[ny, nx] = chosen
                queue[tail] = ny * w + nx
                tail += 1
    return out


def grow(disparity: np.ndarray, n_in: np.ndarray, kept: np.ndarray, blocked: np.ndarray,
         reach: float = 1.0, support: int = 1) -> np.ndarray:
    """Decided disparities grown into the pixels left undecided (two or more candidates, or
    one the right camera could not confirm): from the decided pixels outwards (breadth
    first), an undecided pixel takes the one candidate within ``reach`` of a decided
    4-neighbour's disparity when ``support`` of its decided 4-neighbours agree with it,
    and stays undecided when no candidate or more than one is near a decided neighbour.

    A repeat of a surface (a ghost: the fringes of the right camera and the projector
    lining up again) is a continuous surface too: growth from one decided neighbour leaks
    onto it where a depth step matches a repeat's spacing and then floods it (mugs-on-wall
    halfway, 48-px fringes: 46731 pixels an order off). Two agreeing neighbours stop the
    leak on every case of ``benchmarks/stereo_unwrap.py``.

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(H, W)`` float32 decided disparities, NaN where undecided.
    n_in : numpy.ndarray
        ``(H, W)`` int16 candidates of each pixel (:func:`unwrap_candidates`); only pixels
        of 1 to ``KEPT`` grow.
    kept : numpy.ndarray
        ``(H, W, KEPT)`` float32 their disparities (:func:`unwrap_candidates`).
    blocked : numpy.ndarray
        ``(H, W)`` bool: pixels never grown into (beside an occlusion).
    reach : float, optional
        The largest disparity step (pixels) between neighbours of one surface.
    support : int, optional
        The decided 4-neighbours (1 to 4) that must agree with the chosen candidate.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` float32: ``disparity`` and the grown pixels' disparities.

    Examples
    --------
    One decided pixel, a row of pixels with two candidates each (20 and 48):

    >>> d = np.float32([[20.2, np.nan, np.nan, np.nan]])
    >>> n = np.int16([[1, 2, 2, 0]])
    >>> kept = np.full((1, 4, KEPT), np.nan, np.float32)
    >>> kept[0, 1:3, :2] = [[48.0, 20.5], [20.9, 47.8]]
    >>> [round(float(v), 1) for v in grow(d, n, kept, np.zeros((1, 4), bool))[0]]
    [20.2, 20.5, 20.9, nan]
    >>> [round(float(v), 1) for v in grow(d, n, kept, np.zeros((1, 4), bool), support=2)[0]]
    [20.2, nan, nan, nan]
    """
    disparity = np.ascontiguousarray(disparity, np.float32)
    n_in = np.ascontiguousarray(n_in, np.int16)
    kept = np.ascontiguousarray(kept, np.float32)
    blocked = np.ascontiguousarray(blocked, np.bool_)
    columns, counts = _seeds(disparity, n_in, kept.shape[2], blocked)
    return _grow(disparity, n_in, kept, blocked, float(reach), int(support), columns, counts)


@inline
def _decided(depth: np.ndarray, mask: np.ndarray, y: int, x: int) -> float:
    """The depth at ``(y, x)`` where inside and decided, else NaN."""
    if 0 <= y < depth.shape[0] and 0 <= x < depth.shape[1] and mask[y, x]:
        return float(depth[y, x])
    return math.nan


@inline
def _pair(ahead: float, behind: float, limit: float) -> tuple[bool, int, int]:
    """One direction's test: a ramp (both steps over ``limit``, the same way), the steps
    seen and those within ``limit`` (a NaN step is neither)."""
    over = abs(ahead) > limit and abs(behind) > limit and (ahead > 0.0) == (behind > 0.0)
    seen = (ahead == ahead) + (behind == behind)
    return over, seen, (abs(ahead) <= limit) + (abs(behind) <= limit)


@kernel(parallel=True)
def _mixed(depth: np.ndarray, mask: np.ndarray, terms: np.ndarray, t2: float,
           f_left: float, noise: float, period: float, grazing: float, sigmas: float
           ) -> np.ndarray:
    h, w = depth.shape
    out = np.zeros((h, w), np.bool_)
    noise_columns = sigmas * math.sqrt(2.0) * noise * period / TWO_PI
    footprint, root2 = grazing / f_left, math.sqrt(2.0)
    for y in prange(h):
        for x in range(w):
            z = np.float64(depth[y, x])
            if not mask[y, x] or z != z:
                continue
            # the depth one projector column moves along this pixel's ray (column_terms)
            qz = z * terms[y, x, 0] + t2
            per_column = qz * qz * terms[y, x, 1]
            floor, cap = noise_columns * per_column, 0.5 * per_column * period
            straight = min(max(footprint * z, floor), cap)
            diagonal = min(max(footprint * z * root2, floor), cap)
            e, o = _decided(depth, mask, y, x + 1) - z, z - _decided(depth, mask, y, x - 1)
            s, n = _decided(depth, mask, y + 1, x) - z, z - _decided(depth, mask, y - 1, x)
            se = _decided(depth, mask, y + 1, x + 1) - z
            nw = z - _decided(depth, mask, y - 1, x - 1)
            sw = _decided(depth, mask, y + 1, x - 1) - z
            ne = z - _decided(depth, mask, y - 1, x + 1)
            if not ((abs(e) > straight) | (abs(o) > straight) | (abs(s) > straight)
                    | (abs(n) > straight) | (abs(se) > diagonal) | (abs(nw) > diagonal)
                    | (abs(sw) > diagonal) | (abs(ne) > diagonal)):
                continue  # every decided neighbour within its limit: neither ramp nor spike
            r0, s0, n0 = _pair(e, o, straight)
            r1, s1, n1 = _pair(s, n, straight)
            r2, s2, n2 = _pair(se, nw, diagonal)
            r3, s3, n3 = _pair(sw, ne, diagonal)
            out[y, x] = (r0 or r1 or r2 or r3) or (s0 + s1 + s2 + s3 > 0
                                                    and n0 + n1 + n2 + n3 == 0)
    return out


@kernel(parallel=True)
def _column_terms(rx: np.ndarray, ry: np.ndarray, rp: np.ndarray, tp: np.ndarray,
                  fx: float) -> np.ndarray:
    h, w = rx.shape
    out = np.empty((h, w, 2), np.float64)
    for y in prange(h):
        for x in range(w):
            ax = rp[0, 0] * rx[y, x] + rp[0, 1] * ry[y, x] + rp[0, 2]
            az = rp[2, 0] * rx[y, x] + rp[2, 1] * ry[y, x] + rp[2, 2]
            rate = abs(fx * (ax * tp[2] - tp[0] * az))
            out[y, x, 0], out[y, x, 1] = az, 1.0 / rate if rate != 0.0 else math.inf
    return out


def column_terms(rays: tuple[np.ndarray, np.ndarray], rotation: np.ndarray,
                 translation: np.ndarray, fx: float) -> np.ndarray:
    """Per pixel, what the depth one projector column moves along its ray needs beside the
    depth: the ray's ``a_z`` and ``1 / |fx (a_x t_z - t_x a_z)|``, with ``a = R (x, y, 1)``.

    The point ``z (x, y, 1)`` is ``q = z a + t`` in the projector's frame; its column moves
    by ``du/dz = fx (a_x q_z - q_x a_z) / q_z**2 = fx (a_x t_z - t_x a_z) / q_z**2`` (``z``
    cancels), so one column is ``q_z**2`` times the second term in depth: no division
    per window (:func:`mixed_mask`).

    Parameters
    ----------
    rays : tuple of numpy.ndarray
        The pixels' undistorted rays ``x / z``, ``y / z`` (each ``(H, W)``).
    rotation, translation : numpy.ndarray
        The projector's pose (``X_p = R X + T``).
    fx : float
        The projector's focal length (pixels).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 2)`` float64: ``a_z`` and the depth of one column over ``q_z**2`` (inf
        where a column does not move along the ray).

    Examples
    --------
    A projector 100 mm to the side, ``fx`` 2000: at 600 mm, one column is 1.8 mm deep.

    >>> one = np.zeros((1, 1), np.float32)
    >>> terms = column_terms((one, one), np.eye(3), np.array([-100.0, 0.0, 0.0]), 2000.0)
    >>> terms[0, 0].tolist(), float(600.0 ** 2 * terms[0, 0, 1])
    ([1.0, 5e-06], 1.8)
    """
    return _column_terms(np.ascontiguousarray(rays[0], np.float32),
                         np.ascontiguousarray(rays[1], np.float32),
                         np.ascontiguousarray(rotation, np.float64),
                         np.ascontiguousarray(translation, np.float64).ravel(), float(fx))


def mixed_mask(depth: np.ndarray, mask: np.ndarray, rays: tuple[np.ndarray, np.ndarray],
               rotation: np.ndarray, translation: np.ndarray, fx: float, f_left: float,
               noise: float, period: float, grazing: float, sigmas: float,
               terms: np.ndarray | None = None) -> np.ndarray:
    """The decided pixels of a depth map that are no surface's: in a ramp (the depth steps
    the same way to both neighbours along a row, column or diagonal, each step over the
    limit) or a spike (over the limit from every decided 8-neighbour), the compiled pass of
    :func:`~bistair.geometry.unwrap.mixed_pixels` (one pass, parallel over rows).

    The limit of a pixel: ``grazing`` footprints (``z / f_left`` mm, times the step's
    length), at least ``sigmas * sqrt(2)`` times the depth noise (the depth one projector
    column moves along the pixel's ray, from the projector's pinhole model, times
    ``noise * period / (2*pi)`` columns), at most half the depth of one fringe period.
    That depth is ``q_z**2`` times a term of the ray (:func:`column_terms`: no division a
    depth map); a pixel whose decided neighbours all lie within its limits is neither
    ramp nor spike, and only the others are tested further.

    Parameters
    ----------
    depth, mask : numpy.ndarray
        ``(H, W)`` ``z`` (mm) of the left camera's pixels and where decided.
    rays : tuple of numpy.ndarray
        The left pixels' undistorted rays ``x / z``, ``y / z`` (each ``(H, W)``).
    rotation, translation : numpy.ndarray
        The projector's pose (``X_p = R X + T``, the left camera's frame).
    fx, f_left : float
        The projector's and the left camera's focal lengths (pixels).
    noise, period : float
        The phase noise (radians) and the fringe period (projector pixels).
    grazing, sigmas : float
        The limit's footprints and noise multiples.
    terms : numpy.ndarray, optional
        :func:`column_terms` of ``rays`` and the pose (a stream computes them once); by
        default computed here.

    Returns
    -------
    numpy.ndarray
        ``(H, W)`` bool.

    Raises
    ------
    ValueError
        ``terms`` not of the depth map's shape (and 2).

    Examples
    --------
    >>> z = np.full((5, 9), 600.0, np.float32)
    >>> z[2, 3:6] = [630.0, 660.0, 690.0]  # a ramp up to a wall 120 mm behind
    >>> z[2, 6:] = 720.0
    >>> rays = (np.zeros((5, 9), np.float32), np.zeros((5, 9), np.float32))
    >>> pose = (np.eye(3), np.array([-100.0, 0.0, 0.0]))
    >>> m = mixed_mask(z, np.ones(z.shape, bool), rays, *pose, 2000.0, 150.0, 0.03, 48.0,
    ...                4.0, 4.0)
    >>> np.argwhere(m).tolist()
    [[2, 3], [2, 4], [2, 5]]
    """
    if terms is None:
        terms = column_terms(rays, rotation, translation, fx)
    if np.shape(terms) != (*np.shape(depth), 2):
        raise ValueError(f"column terms of shape {np.shape(terms)} for a depth map of "
                         f"{np.shape(depth)}: another rig's or size's")
    return _mixed(np.ascontiguousarray(depth, np.float32), np.ascontiguousarray(mask, bool),
                  np.ascontiguousarray(terms, np.float64),
                  float(np.asarray(translation, np.float64).ravel()[2]), float(f_left),
                  float(noise), float(period), float(grazing), float(sigmas))
