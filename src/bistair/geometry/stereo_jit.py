"""Compiled passes of the rectified grids (:mod:`bistair.geometry.stereo`): where each raw
pixel lands on the rectified grid, maps resampled without mixing surfaces, a wrapped phase
resampled without crossing a wrap (:func:`resample_wrapped`), and the points on the left
camera's own grid (depth, counts per row, points and the cloud).

Each runs over image rows on every core; none has a NumPy twin, so
``tests/test_stereo_jit.py`` checks them against exact answers (the wrapped phase:
``tests/test_stereo_stream.py``, against the renderer's truth and the ``cv2.remap`` of its
cosine and sine that it replaced). The row search between them is
:mod:`bistair.geometry.stereo_match_jit`.

Examples
--------
>>> import numpy as np
>>> depth = np.float32([[500.0, np.nan]])
>>> rays = np.float32([[0.1, 0.2]]), np.float32([[0.0, 0.0]])
>>> grid_points(depth, *rays)[0, 0].tolist()
[50.0, 0.0, 500.0]
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@inline
def _bilinear(values: np.ndarray, sx: float, sy: float, max_step: float) -> float:
    """``values`` at ``(sx, sy)`` from the 2 x 2 pixels around it, NaN when one of those it
    needs is NaN or outside, or when they spread over more than ``max_step``."""
    if not (sx >= 0.0 and sy >= 0.0):  # also NaN
        return math.nan
    h, w = values.shape
    x0, y0 = int(sx), int(sy)
    fx, fy = sx - x0, sy - y0
    x1 = x0 + 1 if fx > 0.0 else x0
    y1 = y0 + 1 if fy > 0.0 else y0
    if x1 >= w or y1 >= h:
        return math.nan
    a, b = float(values[y0, x0]), float(values[y0, x1])
    c, d = float(values[y1, x0]), float(values[y1, x1])
    if a != a or b != b or c != c or d != d:
        return math.nan
    if max(max(a, b), max(c, d)) - min(min(a, b), min(c, d)) > max_step:
        return math.nan
    return (a * (1.0 - fx) + b * fx) * (1.0 - fy) + (c * (1.0 - fx) + d * fx) * fy


@kernel(parallel=True)
def _remap(values: np.ndarray, map_x: np.ndarray, map_y: np.ndarray,
           max_step: float) -> np.ndarray:
    h, w = map_x.shape
    out = np.empty((h, w), np.float32)
    for y in prange(h):
        for x in range(w):
            out[y, x] = _bilinear(values, map_x[y, x], map_y[y, x], max_step)
    return out


def remap_valid(values: np.ndarray, map_x: np.ndarray, map_y: np.ndarray,
                max_step: float) -> np.ndarray:
    """Resample ``values`` at ``(map_x, map_y)`` bilinearly, NaN where a needed neighbour is
    NaN or off the image or where the 2 x 2 neighbours spread over more than ``max_step``
    (two surfaces: never a value between them).

    Parameters
    ----------
    values : numpy.ndarray
        ``(H, W)`` float map, NaN where invalid.
    map_x, map_y : numpy.ndarray
        ``(h, w)`` float32 source positions (pixel centres at integers).
    max_step : float
        Largest spread of the neighbours interpolated between.

    Returns
    -------
    numpy.ndarray
        ``(h, w)`` float32.

    Examples
    --------
    >>> v = np.float32([[0, 1, 2], [10, 11, np.nan]])
    >>> remap_valid(v, np.float32([[0.5, 1.5]]), np.float32([[0.0, 0.0]]), 2.0).tolist()
    [[0.5, 1.5]]
    >>> remap_valid(v, np.float32([[0.5, 1.5]]), np.float32([[0.5, 0.5]]), 20.0).tolist()
    [[5.5, nan]]
    >>> remap_valid(v, np.float32([[0.5]]), np.float32([[0.5]]), 2.0).tolist()  # 0 .. 11
    [[nan]]
    """
    return _remap(np.ascontiguousarray(values, np.float32), np.asarray(map_x, np.float32),
                  np.asarray(map_y, np.float32), float(max_step))


#: A rectified pixel is known where its known corners carry this much of the bilinear
#: weight (an unknown corner or one outside the image at most 0.001).
KNOWN_WEIGHT = np.float32(0.999)
_PI32, _TWO_PI32 = np.float32(math.pi), np.float32(2.0 * math.pi)


@inline
def near32(d: np.float32) -> np.float32:
    """A difference of two phases in ``[0, 2*pi)`` wrapped into ``[-pi, pi)`` (float32,
    by selects, so that its loops vectorise; also the stream's row search's).

    Parameters
    ----------
    d : numpy.float32
        The difference, in ``(-2*pi, 2*pi)``.

    Returns
    -------
    numpy.float32

    Examples
    --------
    >>> round(float(near32(np.float32(6.0))), 4), round(float(near32(np.float32(-0.5))), 4)
    (-0.2832, -0.5)
    """
    e = d - _TWO_PI32 if d >= _PI32 else d
    return e + _TWO_PI32 if d < -_PI32 else e


@inline
def _wrap32(a: np.float32) -> np.float32:
    """A phase wrapped into ``[0, 2*pi)`` (float32: one that rounds to ``2*pi`` is 0)."""
    if a < np.float32(0.0) or a >= _TWO_PI32:
        a = a - _TWO_PI32 * np.floor(a / _TWO_PI32)
        if a < np.float32(0.0):
            a = a + _TWO_PI32
    return np.float32(0.0) if a >= _TWO_PI32 else a


@inline
def _edge_sample(phase: np.ndarray, sx: np.float32, sy: np.float32) -> np.float32:
    """The wrapped ``phase`` at ``(sx, sy)`` from the known corners of nonzero weight
    inside the image: each unwrapped against the last before it around the square
    ``(0, 0), (0, 1), (1, 1), (1, 0)`` (their step wrapped into ``[-pi, pi)``), averaged
    with their bilinear weights renormalised, in ``[0, 2*pi)``; NaN where they carry less
    than :data:`KNOWN_WEIGHT`."""
    if not (sx > -1.0 and sy > -1.0 and sx < phase.shape[1] and sy < phase.shape[0]):
        return np.float32(np.nan)  # (also NaN)
    fx0, fy0 = np.floor(sx), np.floor(sy)
    x0, y0 = int(fx0), int(fy0)
    fx, fy = np.float32(sx - fx0), np.float32(sy - fy0)
    last, at, first = np.float32(np.nan), np.float32(0.0), np.float32(np.nan)
    acc, good = np.float32(0.0), np.float32(0.0)
    for k in range(4):
        dx, dy = int(k == 1 or k == 2), k // 2
        w = (fx if dx else np.float32(1.0) - fx) * (fy if dy else np.float32(1.0) - fy)
        y, x = y0 + dy, x0 + dx
        if not (w > 0.0 and 0 <= y < phase.shape[0] and 0 <= x < phase.shape[1]):
            continue
        p = phase[y, x]
        if p != p:
            continue
        if last == last:
            at = at + near32(p - last)
        else:
            first = p
        last = p
        acc += w * at
        good += w
    if not good >= KNOWN_WEIGHT:
        return np.float32(np.nan)
    if good < np.float32(0.99999):  # (an unknown corner of weight <= 0.001)
        acc = acc / good
    return _wrap32(first + acc)


@kernel(parallel=True)
def _resample(phi: np.ndarray, mod: np.ndarray, threshold: float, map_x: np.ndarray,
              map_y: np.ndarray, phase: np.ndarray, out: np.ndarray) -> int:
    h, w = phi.shape
    count = 0
    for y in prange(h):
        for x in range(w):
            if mod[y, x] >= threshold:
                phase[y, x] = phi[y, x]
                count += 1
            else:
                phase[y, x] = np.float32(np.nan)
    flat = phase.reshape(-1)  # (unsigned flat indices: no wraparound tests)
    right, below = np.float32(w - 1), np.float32(h - 1)
    step, one, zero = np.uint64(w), np.uint64(1), np.float32(0.0)
    for y in prange(map_x.shape[0]):
        for x in range(map_x.shape[1]):
            sx, sy = map_x[y, x], map_y[y, x]
            v = np.float32(-1.0)  # (to the next loop)
            if sx >= zero and sy >= zero and sx < right and sy < below:
                x0, y0 = np.uint64(sx), np.uint64(sy)
                i = y0 * step + x0
                p00, p01 = flat[i], flat[i + one]
                p11, p10 = flat[i + step + one], flat[i + step]
                fx, fy = sx - np.float32(x0), sy - np.float32(y0)
                gx, gy = np.float32(1.0) - fx, np.float32(1.0) - fy
                if p00 == p00 and p01 == p01 and p11 == p11 and p10 == p10:
                    u01 = near32(p01 - p00)  # (around the square, as _edge_sample)
                    u11 = u01 + near32(p11 - p01)
                    u10 = u11 + near32(p10 - p11)
                    v = _wrap32(p00 + (fx * gy * u01 + fx * fy * u11 + gx * fy * u10))
                elif ((p00 == p00) * gx * gy + (p01 == p01) * fx * gy + (p11 == p11) * fx * fy
                      + (p10 == p10) * gx * fy) < KNOWN_WEIGHT:
                    v = np.float32(np.nan)  # (the common unknown pixel)
            out[y, x] = v
    for y in prange(map_x.shape[0]):  # (a loop of its own: inlined into the loop above,
        for x in range(map_x.shape[1]):  # it slows the common pixels threefold)
            if out[y, x] < 0.0:
                out[y, x] = _edge_sample(phase, map_x[y, x], map_y[y, x])
    return count


def resample_wrapped(phi: np.ndarray, maps: tuple[np.ndarray, np.ndarray],
                     mod: np.ndarray | None = None, threshold: float = 0.0,
                     buffers: dict | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """A wrapped phase, NaN where its modulation is below ``threshold``, and that phase
    resampled onto a rectified grid, in one compiled pass over each grid.

    Each rectified pixel reads the four camera pixels around its table position: the
    phase there is the first known corner's plus the bilinear mean of every known corner's
    difference from it, each wrapped into ``[-pi, pi)`` (never across a wrap; no cosine or
    sine), wrapped into ``[0, 2*pi)``. It is unknown (NaN) where the known corners inside
    the image carry less than :data:`KNOWN_WEIGHT` of the weight (exact weights; an unknown
    corner of weight at most 0.001 is left out, the others' weights renormalised).

    Parameters
    ----------
    phi : numpy.ndarray
        ``(H, W)`` float32 wrapped phase (radians, ``[0, 2*pi)``), NaN where unknown.
    maps : tuple of numpy.ndarray
        The rectified grid's remap tables (rectified pixel -> camera pixel, float32).
    mod : numpy.ndarray, optional
        ``(H, W)`` modulation; by default every finite pixel of ``phi`` is known.
    threshold : float, optional
        The modulation a known pixel needs.
    buffers : dict, optional
        Arrays to reuse from one call to the next (an empty dict at first; the results
        are among them: the next call overwrites them).

    Returns
    -------
    phase : numpy.ndarray
        ``(H, W)`` float32 ``phi``, NaN where not known.
    rectified : numpy.ndarray
        ``maps``' shape, float32: the phase on the rectified grid, in ``[0, 2*pi)``, NaN
        where unknown.
    known : int
        The known pixels of ``phase``.

    Examples
    --------
    Half way between 6.2 and 0.1 rad (across the wrap: not 3.15), half way to a pixel
    below the threshold (unknown), and half a thousandth of a pixel from it
    (its weight left out):

    >>> phi = np.float32([[6.2, 0.1, 3.0]])
    >>> mod = np.float32([[1.0, 1.0, 0.0]])
    >>> maps = (np.float32([[0.5, 1.5, 1.0005]]), np.float32([[0.0, 0.0, 0.0]]))
    >>> phase, rect, n = resample_wrapped(phi, maps, mod, 0.5)
    >>> [round(float(v), 4) for v in rect[0]], n, bool(np.isnan(phase[0, 2]))
    ([0.0084, nan, 0.1], 2, True)
    """
    phi = np.ascontiguousarray(phi, np.float32)
    if mod is None:
        mod, threshold = phi, -math.inf  # (NaN is not >= -inf)
    shape = maps[0].shape
    b = {} if buffers is None else buffers
    if "phase" not in b or b["phase"].shape != phi.shape or b["rectified"].shape != shape:
        b["phase"] = np.empty(phi.shape, np.float32)
        b["rectified"] = np.empty(shape, np.float32)
    mx, my = (np.ascontiguousarray(m, np.float32) for m in maps)
    count = _resample(phi, np.ascontiguousarray(mod, np.float32), float(threshold), mx, my,
                      b["phase"], b["rectified"])
    return b["phase"], b["rectified"], int(count)


@kernel(parallel=True)
def _positions(k: np.ndarray, dist: np.ndarray, rot: np.ndarray, f: float, cx: float,
               cy: float, h: int, w: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    u = np.empty((h, w), np.float32)
    v = np.empty((h, w), np.float32)
    rx = np.empty((h, w), np.float32)
    ry = np.empty((h, w), np.float32)
    k1, k2, p1, p2, k3 = dist[0], dist[1], dist[2], dist[3], dist[4]
    for row in prange(h):
        yd = (row - k[1, 2]) / k[1, 1]
        for col in range(w):
            xd = (col - k[0, 2] - k[0, 1] * yd) / k[0, 0]
            x, y = xd, yd
            for _ in range(30):  # Newton on OpenCV's distortion
                r2 = x * x + y * y
                radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
                drad = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
                ex = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) - xd
                ey = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y - yd
                if abs(ex) < 1e-15 and abs(ey) < 1e-15:
                    break
                a = radial + 2.0 * x * x * drad + 2.0 * p1 * y + 6.0 * p2 * x
                b = 2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y
                d = radial + 2.0 * y * y * drad + 6.0 * p1 * y + 2.0 * p2 * x
                det = a * d - b * b
                x -= (d * ex - b * ey) / det
                y -= (a * ey - b * ex) / det
            rx[row, col] = x
            ry[row, col] = y
            rz = rot[2, 0] * x + rot[2, 1] * y + rot[2, 2]
            if rz > 0.0:
                u[row, col] = f * (rot[0, 0] * x + rot[0, 1] * y + rot[0, 2]) / rz + cx
                v[row, col] = f * (rot[1, 0] * x + rot[1, 1] * y + rot[1, 2]) / rz + cy
            else:
                u[row, col] = np.nan
                v[row, col] = np.nan
    return u, v, rx, ry


def rectified_positions(K: np.ndarray, dist: np.ndarray, rotation: np.ndarray, f: float,
                        cx: float, cy: float, size: tuple[int, int]
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Where every pixel of a camera image lands on its rectified grid, and its ray: the
    pixel undistorted exactly (Newton steps), turned by ``rotation`` and projected with
    focal length ``f`` and principal point ``(cx, cy)``.

    Parameters
    ----------
    K : numpy.ndarray
        3 x 3 intrinsic matrix.
    dist : numpy.ndarray
        ``(k1, k2, p1, p2, k3)``.
    rotation : numpy.ndarray
        3 x 3 rectifying rotation (``R1`` or ``R2`` of ``cv2.stereoRectify``).
    f, cx, cy : float
        The rectified grid's focal length and principal point (pixels).
    size : tuple of int
        ``(width, height)`` of the camera image.

    Returns
    -------
    u, v : numpy.ndarray
        ``(height, width)`` float32 rectified coordinates (NaN behind the rectified view).
    x, y : numpy.ndarray
        ``(height, width)`` float32 ray of each pixel in the camera's frame: the point at
        depth ``z`` is ``z * (x, y, 1)``.

    Examples
    --------
    >>> K = np.array([[100.0, 0, 2], [0, 100, 1], [0, 0, 1]])
    >>> u, v, x, y = rectified_positions(K, np.zeros(5), np.eye(3), 200.0, 10.0, 5.0, (4, 3))
    >>> u[1].tolist(), v[:, 0].tolist(), [round(float(r), 4) for r in x[0]]
    ([6.0, 8.0, 10.0, 12.0], [3.0, 5.0, 7.0], [-0.02, -0.01, 0.0, 0.01])
    """
    width, height = size
    return _positions(np.asarray(K, np.float64), np.asarray(dist, np.float64).ravel()[:5],
                      np.asarray(rotation, np.float64), float(f), float(cx), float(cy),
                      int(height), int(width))


@kernel(parallel=True)
def _depth(disparity: np.ndarray, u: np.ndarray, v: np.ndarray, decoded: np.ndarray, f: float,
           cx: float, cy: float, tx: float, rt: np.ndarray, zmin: float, zmax: float,
           max_step: float) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, int]:
    """:func:`grid_depth` of the pixels where ``decoded`` (a coordinate map) is not NaN,
    with the mask of the depths found (uint8), the points outside the range, the depths
    found per row and the pixels decoded."""
    h, w = u.shape
    depth = np.empty((h, w), np.float32)
    found = np.empty((h, w), np.uint8)
    outside = np.zeros(h, np.int64)
    per_row = np.zeros(h, np.int64)
    valid = np.zeros(h, np.int64)
    for y in prange(h):
        n_valid, n_found, n_outside = 0, 0, 0  # (in registers)
        for x in range(w):
            z = math.nan
            d = math.nan
            if decoded[y, x] == decoded[y, x]:
                n_valid += 1
                d = _bilinear(disparity, u[y, x], v[y, x], max_step)
            if d * tx < 0.0:  # not NaN, and in front of the cameras
                scale = -tx / d  # Z / f in the rectified frame
                z = ((u[y, x] - cx) * rt[2, 0] + (v[y, x] - cy) * rt[2, 1] + f * rt[2, 2]) * scale
                if not zmin <= z <= zmax:
                    n_outside += 1
                    z = math.nan
            depth[y, x] = z
            found[y, x] = z == z
            n_found += 1 if z == z else 0
        valid[y], per_row[y], outside[y] = n_valid, n_found, n_outside
    return depth, found, outside.sum(), per_row, valid.sum()


def grid_depth(disparity: np.ndarray, u: np.ndarray, v: np.ndarray, valid: np.ndarray,
               f: float, cx: float, cy: float, tx: float, rotation: np.ndarray,
               min_depth: float = 0.0, max_depth: float = math.inf,
               max_step: float = 2.0) -> tuple[np.ndarray, int]:
    """Depth on a camera's own image grid from the disparity on its rectified grid.

    Each valid pixel reads the disparity ``d`` at its rectified position ``(u, v)``
    (bilinear between four confirmed disparities that spread by at most ``max_step``),
    triangulates in the rectified frame (``Z = -f * tx / d``) and takes the point's ``z``
    in the camera frame (``rotation`` is the rectifying rotation, ``R1``); the point is
    ``z`` times the pixel's ray (:func:`rectified_positions`).

    Parameters
    ----------
    disparity : numpy.ndarray
        ``(h, w)`` float32 on the rectified grid, NaN where unknown.
    u, v : numpy.ndarray
        ``(H, W)`` rectified positions of the camera's pixels
        (:func:`rectified_positions`).
    valid : numpy.ndarray
        ``(H, W)`` bool: pixels that decoded (the others stay NaN).
    f, cx, cy : float
        The rectified grid's focal length and principal point.
    tx : float
        The other camera's x in the rectified frame (mm; ``-baseline`` for a camera to the
        right).
    rotation : numpy.ndarray
        The rectifying rotation of this camera.
    min_depth, max_depth : float, optional
        Depths ``z`` (camera frame) kept.
    max_step : float, optional
        Largest spread of the disparities interpolated between.

    Returns
    -------
    depth : numpy.ndarray
        ``(H, W)`` float32 ``z`` in the camera frame (mm), NaN where unknown.
    outside : int
        Pixels triangulated but outside the depth range.

    Examples
    --------
    >>> d = np.full((3, 4), 20.0, np.float32)  # f = 100, baseline 60 mm: 300 mm away
    >>> u, v = np.float32([[1.0, 2.5]]), np.float32([[1.0, 1.0]])
    >>> z, out = grid_depth(d, u, v, np.ones((1, 2), bool), 100.0, 1.0, 1.0, -60.0, np.eye(3))
    >>> z.tolist(), out
    ([[300.0, 300.0]], 0)
    """
    decoded = np.where(np.asarray(valid, bool), np.float32(0), np.float32(np.nan))
    out = depth_counts(disparity, u, v, decoded, f, cx, cy, tx, rotation, min_depth,
                       max_depth, max_step)
    return out[0], out[2]


def depth_counts(disparity: np.ndarray, u: np.ndarray, v: np.ndarray, decoded: np.ndarray,
                 f: float, cx: float, cy: float, tx: float, rotation: np.ndarray,
                 min_depth: float = 0.0, max_depth: float = math.inf, max_step: float = 2.0
                 ) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, int]:
    """:func:`grid_depth` of the pixels where the coordinate map ``decoded`` is not NaN,
    with what the checks count, in the same pass (no full-image temporaries).

    Parameters
    ----------
    disparity, u, v, f, cx, cy, tx, rotation, min_depth, max_depth, max_step
        As for :func:`grid_depth`.
    decoded : numpy.ndarray
        ``(H, W)`` float map (the camera's projector coordinate), NaN where not decoded.

    Returns
    -------
    depth : numpy.ndarray
        As :func:`grid_depth`'s.
    mask : numpy.ndarray
        ``(H, W)`` bool: where ``depth`` is not NaN.
    outside : int
        Pixels triangulated but outside the depth range.
    per_row : numpy.ndarray
        ``(H,)`` int64: the depths found in each row.
    valid : int
        The pixels decoded.

    Examples
    --------
    >>> d = np.full((3, 4), 20.0, np.float32)
    >>> u, v = np.float32([[1.0, 2.5, 1.0]]), np.float32([[1.0, 1.0, 9.0]])
    >>> out = depth_counts(d, u, v, np.float32([[3, 4, 5]]), 100.0, 1.0, 1.0, -60.0,
    ...                    np.eye(3))
    >>> out[0].tolist(), out[1].tolist(), out[2], out[3].tolist(), out[4]
    ([[300.0, 300.0, nan]], [[True, True, False]], 0, [2], 3)
    """
    depth, found, outside, per_row, valid = _depth(
        np.ascontiguousarray(disparity, np.float32), np.asarray(u, np.float32),
        np.asarray(v, np.float32), np.asarray(decoded), float(f), float(cx), float(cy),
        float(tx), np.ascontiguousarray(np.asarray(rotation, np.float64).T), float(min_depth),
        float(max_depth), float(max_step))
    return depth, found.view(np.bool_), int(outside), per_row, int(valid)


@kernel(parallel=True)
def _pick(values: np.ndarray, starts: np.ndarray, picks: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    h, w = values.shape
    rows = np.empty(len(picks), np.int64)
    cols = np.empty(len(picks), np.int64)
    for y in prange(h):
        i = np.searchsorted(picks, starts[y])  # the first pick in this row
        if i == len(picks) or picks[i] >= starts[y + 1]:
            continue
        k = starts[y]
        for x in range(w):
            if values[y, x] == values[y, x]:
                while i < len(picks) and picks[i] == k:
                    rows[i] = y
                    cols[i] = x
                    i += 1
                k += 1
    return rows, cols


def pick_finite(values: np.ndarray, per_row: np.ndarray, picks: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """The rows and columns of the finite values of ``values`` whose places in row-major
    order are ``picks``: ``np.nonzero(np.isfinite(values))`` at ``picks``, without the
    list of them all.

    Parameters
    ----------
    values : numpy.ndarray
        ``(H, W)`` float map, NaN where invalid.
    per_row : numpy.ndarray
        ``(H,)`` the finite values in each row.
    picks : numpy.ndarray
        Non-decreasing places, each less than ``per_row.sum()``.

    Returns
    -------
    rows, cols : numpy.ndarray
        int64, one per pick.

    Examples
    --------
    >>> m = np.float32([[np.nan, 1, 2], [3, np.nan, 4]])
    >>> [a.tolist() for a in pick_finite(m, np.array([2, 2]), np.array([0, 2, 3]))]
    [[0, 1, 1], [1, 0, 2]]
    """
    starts = np.zeros(len(per_row) + 1, np.int64)
    np.cumsum(per_row, out=starts[1:])
    return _pick(np.asarray(values), starts, np.ascontiguousarray(picks, np.int64))


@kernel(parallel=True)
def _points(depth: np.ndarray, rx: np.ndarray, ry: np.ndarray) -> np.ndarray:
    h, w = depth.shape
    out = np.empty((h, w, 3), np.float32)
    for y in prange(h):
        for x in range(w):
            z = depth[y, x]
            out[y, x, 0] = z * rx[y, x]
            out[y, x, 1] = z * ry[y, x]
            out[y, x, 2] = z
    return out


def grid_points(depth: np.ndarray, rx: np.ndarray, ry: np.ndarray) -> np.ndarray:
    """The points ``z * (x, y, 1)`` of a depth map and its pixels' rays, on its grid:
    ``np.stack([depth * rx, depth * ry, depth], axis=-1)`` in one pass.

    Parameters
    ----------
    depth : numpy.ndarray
        ``(H, W)`` float32 ``z`` (NaN where unknown).
    rx, ry : numpy.ndarray
        ``(H, W)`` float32 rays (:func:`rectified_positions`).

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` float32.

    Examples
    --------
    >>> z = np.float32([[2, np.nan]])
    >>> grid_points(z, np.float32([[0.5, 1]]), np.float32([[-1, 1]])).tolist()
    [[[1.0, -2.0, 2.0], [nan, nan, nan]]]
    """
    return _points(np.ascontiguousarray(depth, np.float32), np.asarray(rx, np.float32),
                   np.asarray(ry, np.float32))


@kernel(parallel=True)
def _cloud(depth: np.ndarray, rx: np.ndarray, ry: np.ndarray, grey: np.ndarray,
           mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    h, w = depth.shape
    per_row = np.zeros(h, np.int64)
    for y in prange(h):
        n = 0
        for x in range(w):
            n += 1 if mask[y, x] != 0 else 0
        per_row[y] = n
    starts = np.zeros(h + 1, np.int64)
    for y in range(h):
        starts[y + 1] = starts[y] + per_row[y]
    pts = np.empty((starts[h], 3), np.float32)
    cols = np.empty((starts[h], 3), np.uint8)
    for y in prange(h):
        i = starts[y]
        for x in range(w):
            if mask[y, x] != 0:
                z = depth[y, x]
                pts[i, 0] = z * rx[y, x]
                pts[i, 1] = z * ry[y, x]
                pts[i, 2] = z
                g = grey[y, x]
                cols[i, 0] = g
                cols[i, 1] = g
                cols[i, 2] = g
                i += 1
    return pts, cols


def cloud_points(depth: np.ndarray, rx: np.ndarray, ry: np.ndarray, grey: np.ndarray,
                 mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The points of ``mask`` in row-major order and their grey as RGB, in one pass: what
    ``grid_points(depth, rx, ry)[mask]`` and ``np.repeat(grey[mask][:, None], 3, axis=1)``
    give, without the full grids.

    Parameters
    ----------
    depth, rx, ry : numpy.ndarray
        As for :func:`grid_points`.
    grey : numpy.ndarray
        ``(H, W)`` uint8.
    mask : numpy.ndarray
        ``(H, W)`` bool: the points kept.

    Returns
    -------
    points : numpy.ndarray
        ``(N, 3)`` float32.
    colors : numpy.ndarray
        ``(N, 3)`` uint8.

    Examples
    --------
    >>> z = np.float32([[2, 4], [np.nan, 1]])
    >>> pts, rgb = cloud_points(z, np.ones((2, 2), np.float32), np.zeros((2, 2), np.float32),
    ...                         np.uint8([[10, 20], [30, 40]]), np.isfinite(z))
    >>> pts.tolist(), rgb[:, 0].tolist()
    ([[2.0, 0.0, 2.0], [4.0, 0.0, 4.0], [1.0, 0.0, 1.0]], [10, 20, 40])
    """
    return _cloud(np.ascontiguousarray(depth, np.float32), np.asarray(rx, np.float32),
                  np.asarray(ry, np.float32), np.ascontiguousarray(grey, np.uint8),
                  np.ascontiguousarray(mask, np.bool_).view(np.uint8))
