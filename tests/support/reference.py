"""NumPy references of compiled passes that a decode runs, kept as the tests' oracles (no
code in src calls them; issue 35 moved them here from the concept modules):

* :func:`stair_phase`: the stair pair's phase and modulation
  (``bistair.core.stair_jit.pair_phase``, which ``bistair.core.stair.read_stairs`` runs);
* :func:`level_misfit`: a phase's squared distance from a stair level, in half steps
  (the band evidence's compiled ``_level_misfit``);
* :func:`relinearize`: stair phases through a level table
  (``bistair.core.stair_jit.relinearize32``);
* :func:`period_jumps`: the links a fringe period jump cuts
  (``bistair.core.regions_jit.link_bits``);
* :func:`mode_by_label`: the most frequent value per label
  (``bistair.codecs.bidirectional.paper_jit.run_label_modes``);
* :func:`grow_all_seeds`: growth of decided disparities, every decided pixel a seed
  (``bistair.geometry.unwrap_jit.grow``);
* :func:`mixed_pixels`: the decided pixels of a stereo depth map in a ramp or a spike
  (``bistair.geometry.unwrap_jit.mixed_mask``, which ``unwrap.mixed_pixels`` runs), with
  the projector's own model (distortion and all) for the depth one column moves;
* :func:`plane_depth`: a stream's depth through an undistorted projector's column planes
  (``bistair.geometry.unwrap_stream_jit.plane_depth``, a pass without branches).
* :func:`rectified_phase_cv2`: a wrapped phase resampled onto a rectified grid through
  ``cv2.remap`` of its cosine, sine and validity (the resampler before
  ``bistair.geometry.stereo_jit.resample_wrapped``).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from bistair.core.phase import TWO_PI
from bistair.core.phase_jit import arctan2_32
from bistair.core.stair import stair_level_phase


def stair_phase(cos_frame: np.ndarray, sin_frame: np.ndarray,
                avg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference of :func:`bistair.core.stair_jit.pair_phase`, which a decode runs:
    the decoded stair phase in ``[-pi, pi)`` and its modulation (Eq. 19).

    ``avg`` is the average intensity of the fringe frames (Eq. 9).

    Parameters
    ----------
    cos_frame, sin_frame : ndarray
        The captured cosine and sine stair frames, shape (H, W) (any shape, any dtype), as
        fractions of full scale.
    avg : ndarray
        Average intensity ``A`` of the fringe frames, broadcastable to the frames.

    Returns
    -------
    theta : ndarray
        Float32 stair phase in radians (:func:`~bistair.core.phase_jit.arctan2_32` of the frames
        minus ``avg``).
    modulation : ndarray
        Float32 length of that (cos, sin) vector (``sqrt(c*c + s*s)`` in float32), same
        shape.

    Examples
    --------
    >>> from bistair.core.stair import stair_pair
    >>> c, s = stair_pair(stair_level_phase(np.arange(4), 4))
    >>> theta, mod = stair_phase(c, s, np.full(4, 0.5))
    >>> theta.astype(float).round(4).tolist(), mod.astype(float).round(3).tolist()
    ([-2.3562, -0.7854, 0.7854, 2.3562], [0.5, 0.5, 0.5, 0.5])
    """
    c = np.asarray(cos_frame, dtype=np.float32) - np.asarray(avg, np.float32)
    s = np.asarray(sin_frame, dtype=np.float32) - np.asarray(avg, np.float32)
    return arctan2_32(s, c), np.sqrt(c * c + s * s)


def level_misfit(theta: float, level: int, levels: int) -> float:
    """NumPy reference of the band evidence's compiled ``_level_misfit``
    (:mod:`bistair.codecs.bidirectional.evidence_jit`), which a decode runs:
    the squared distance of a phase from a stair level, in half steps (0 on the level, 1 at
    the border of its quantisation bin).

    Parameters
    ----------
    theta : float
        Stair phase in radians.
    level : int
        Stair level index, 0 .. levels-1.
    levels : int
        Number of steps of the stair.

    Returns
    -------
    float
        ``(d / (pi/levels))**2`` with ``d`` the wrapped difference between ``theta`` and the
        level's phase (:func:`stair_level_phase`).

    Examples
    --------
    >>> level_misfit(float(stair_level_phase(2, 6)), 2, 6), round(level_misfit(0.0, 2, 6), 9)
    (0.0, 1.0)
    """
    d = (theta - stair_level_phase(level, levels) + math.pi) % TWO_PI
    return ((d - math.pi) / (math.pi / levels)) ** 2


def relinearize(theta: np.ndarray, table: np.ndarray) -> np.ndarray:
    """NumPy reference of :func:`bistair.core.stair_jit.relinearize32`, which a decode runs:
    stair phases through a :func:`level_table` (float32 arithmetic, as the kernel's).

    Parameters
    ----------
    theta : ndarray
        Stair phases in radians in [-pi, pi], any shape.
    table : (bins,) float32 array
        From :func:`level_table`.

    Returns
    -------
    float32 ndarray
        The mapped phases, ``theta``'s shape.

    Examples
    --------
    >>> from bistair.core.stair import level_readings, level_table
    >>> levels = stair_level_phase(np.arange(6), 6)
    >>> readings = level_readings(levels, 2.2)
    >>> mapped = relinearize(readings.astype(np.float32), level_table(readings, levels))
    >>> bool(np.allclose(mapped, levels, atol=1e-3))
    True
    """
    step = np.float32(table.size / TWO_PI)
    index = ((np.asarray(theta, dtype=np.float32) + np.float32(np.pi)) * step).astype(np.int64)
    return table[np.clip(index, 0, table.size - 1)]


def period_jumps(phi: np.ndarray, valid: np.ndarray, sigma: np.ndarray | float,
                 relative: float = 0.3, half: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference of the period jumps that :func:`bistair.core.regions_jit.link_bits`
    cuts (with ``half`` 3, as a decode runs it): the links across which the fringes'
    spacing or slant jumps (vertical links (H-1, W), horizontal links (H, W-1)) to cut.

    Where one surface hides another the wrapped phase may happen to run on across the edge,
    but its gradient (the fringe period and slant in the image) jumps. Both gradient
    components are averaged over windows of ``half`` pixels along the row on each side of a
    horizontal link, or around the two ends of a vertical link; a link is cut where the
    averages differ by more than ``relative`` of the larger gradient and by more than four
    times their noise (``sigma``: per-pixel phase noise, radians). Only links between two
    valid pixels are cut (no other link joins a region).

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts.
    sigma : (H, W) float array or float
        Per-pixel phase noise in radians.
    relative : float
        Share of the larger mean gradient by which the two must differ.
    half : int
        Window length in pixels (each window also needs ``half`` valid gradients).

    Returns
    -------
    vert : (H-1, W) bool array
        Links between each pixel and the one below it to cut.
    horiz : (H, W-1) bool array
        Links between each pixel and the one to its right to cut.

    Examples
    --------
    >>> x = np.arange(40.0)
    >>> phi = np.tile(np.where(x < 20, 0.2 * x, 0.6 * x) % (2 * np.pi), (6, 1))
    >>> vert, horiz = period_jumps(phi, np.ones(phi.shape, bool), 0.01)
    >>> np.flatnonzero(horiz[0]).tolist(), bool(vert.any())
    ([16, 17, 18, 19, 21, 22], False)
    """
    h, w = phi.shape
    noise = np.broadcast_to(np.asarray(sigma, np.float32), (h, w))

    def wrapped(a: np.ndarray, b: np.ndarray, ok: np.ndarray) -> np.ndarray:
        return (((b - a + np.pi) % TWO_PI) - np.pi).astype(np.float32) * ok

    ok_x = (valid[:, 1:] & valid[:, :-1]).astype(np.float32)
    gx = np.zeros((h, w), np.float32)
    nx = np.zeros((h, w), np.float32)
    gx[:, :-1] = wrapped(phi[:, :-1], phi[:, 1:], ok_x)
    nx[:, :-1] = ok_x
    ok_y = (valid[1:] & valid[:-1]).astype(np.float32)
    gy = np.zeros((h, w), np.float32)
    ny = np.zeros((h, w), np.float32)
    gy[:-1] = wrapped(phi[:-1], phi[1:], ok_y)
    ny[:-1] = ok_y
    sums = [np.pad(np.cumsum(a, axis=1), ((0, 0), (1, 0))) for a in (gx, nx, gy, ny)]

    def window(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Mean gradients and the samples behind them over columns [lo, hi)."""
        lo, hi = np.clip(lo, 0, w), np.clip(hi, 0, w)
        sx, cx, sy, cy = (c[:, hi] - c[:, lo] for c in sums)
        return sx / np.maximum(cx, 1), sy / np.maximum(cy, 1), np.minimum(cx, cy)

    def cut(a: tuple, b: tuple, noise_a: np.ndarray, noise_b: np.ndarray) -> np.ndarray:
        (ax, ay, na), (bx, by, nb) = a, b
        step = np.hypot(ax - bx, ay - by)
        size = np.maximum(np.hypot(ax, ay), np.hypot(bx, by))
        spread = 2.0 * np.maximum(noise_a / np.sqrt(np.maximum(na, 1)),
                                  noise_b / np.sqrt(np.maximum(nb, 1)))
        return ((step > relative * size) & (step > 4.0 * spread)
                & (na >= half) & (nb >= half))

    x = np.arange(w)
    around = window(x - half, x + half)  # gradients around each pixel
    vert = cut(tuple(v[:-1] for v in around), tuple(v[1:] for v in around),
               noise[:-1], noise[1:]) & (ok_y > 0)
    xl = np.arange(w - 1)
    left, right = window(xl - half, xl), window(xl + 1, xl + 1 + half)
    horiz = cut(left, right, noise[:, :-1], noise[:, 1:]) & (ok_x > 0)
    return vert, horiz


def mode_by_label(labels: np.ndarray, values: np.ndarray, n_labels: int, n_values: int,
                  weights: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """NumPy reference of :func:`bistair.codecs.bidirectional.paper_jit.run_label_modes`,
    which a decode runs: the most frequent value (0..n_values-1) per label 1..n_labels; label
    0 and values < 0 ignored.

    Returns ``(mode, support)`` indexed by label (index 0 unused, mode -1 where no vote).

    Parameters
    ----------
    labels : int array
        Region label per pixel (0: none), any shape.
    values : int array
        Value per pixel, same shape; negative values abstain.
    n_labels : int
        Highest label.
    n_values : int
        Values run 0 .. n_values-1.
    weights : float array, optional
        Vote weight per pixel, same shape (1 each when not given).

    Returns
    -------
    mode : (n_labels + 1,) int64 array
        The most supported value per label (the smallest of ties), -1 where no vote.
    support : (n_labels + 1,) array
        Its vote count (or summed weight): int64 without ``weights``, float64 with them.

    Examples
    --------
    >>> labels = np.array([1, 1, 1, 2, 2, 0])
    >>> values = np.array([4, 4, 5, 7, -1, 9])
    >>> mode, support = mode_by_label(labels, values, n_labels=2, n_values=10)
    >>> mode.tolist(), support.tolist()
    ([-1, 4, 7], [0, 2, 1])
    >>> weights = np.array([0.1, 0.1, 1.0, 1.0, 1.0, 1.0])
    >>> mode_by_label(labels, values, 2, 10, weights)[0].tolist()
    [-1, 5, 7]
    """
    labels = np.asarray(labels).ravel()
    values = np.asarray(values).ravel()
    sel = (labels > 0) & (values >= 0)
    w = None if weights is None else np.asarray(weights, np.float64).ravel()[sel]
    key = labels[sel].astype(np.int64) * n_values + values[sel]
    counts = np.bincount(key, weights=w, minlength=(n_labels + 1) * n_values)
    counts = counts.reshape(n_labels + 1, n_values)
    mode = counts.argmax(axis=1)
    support = counts.max(axis=1)
    mode[support <= 0] = -1
    return mode.astype(np.int64), support


def mixed_pixels(depth: np.ndarray, mask: np.ndarray, calibration, period: float,
                 noise: float, rays: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """NumPy reference of :func:`bistair.geometry.unwrap.mixed_pixels` (as first written:
    the depth one column moves by triangulating the next column, distortion included)."""
    from bistair.geometry.calibration import Calibration
    from bistair.geometry.stereo import grid_points
    from bistair.geometry.triangulate import triangulate
    from bistair.geometry.unwrap import EDGE_SIGMAS, GRAZING

    rows, cols = np.nonzero(mask)
    points = grid_points(np.where(mask, depth, np.nan).astype(np.float32), *rays)[rows, cols]
    proj = calibration.projector
    u = proj.project(points)[:, 0]
    pair = Calibration(calibration.left, proj.device, proj.R, proj.T)
    pixels = np.column_stack([cols, rows]).astype(np.float64)
    per_column = np.abs(triangulate(pixels, u + 1.0, pair)[:, 2] - points[:, 2])
    z = np.where(mask, depth, np.nan).astype(np.float64)
    footprint = np.full(z.shape, np.nan)
    footprint[rows, cols] = points[:, 2] / calibration.left.K[0, 0]
    floor = np.zeros(z.shape)
    floor[rows, cols] = EDGE_SIGMAS * math.sqrt(2) * per_column * noise * period / (2 * np.pi)
    cap = np.full(z.shape, np.inf)
    cap[rows, cols] = 0.5 * per_column * period
    h, w = z.shape
    padded = np.pad(z, 1, constant_values=np.nan)
    ramp = np.zeros(z.shape, bool)
    near = np.zeros(z.shape, np.int8)
    neighbours = np.zeros(z.shape, np.int8)
    with np.errstate(invalid="ignore"):
        for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
            limit = np.minimum(np.maximum(GRAZING * footprint * math.hypot(dy, dx), floor),
                               cap)
            ahead = padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] - z
            behind = z - padded[1 - dy:1 - dy + h, 1 - dx:1 - dx + w]
            ramp |= ((np.sign(ahead) == np.sign(behind)) & (np.abs(ahead) > limit)
                     & (np.abs(behind) > limit))
            for step in (ahead, behind):
                neighbours += np.isfinite(step)
                near += np.abs(step) <= limit
    return mask & (ramp | ((neighbours > 0) & (near == 0)))


def grow_all_seeds(disparity: np.ndarray, n_in: np.ndarray, kept: np.ndarray, blocked: np.ndarray,
          reach: float, support: int) -> np.ndarray:
    """Pure-Python reference of :func:`bistair.geometry.unwrap_jit.grow`'s pass as first
    written: every decided pixel seeds the breadth-first queue (the compiled pass seeds only
    those beside a pixel that may grow: the others change nothing when their turn comes)."""
    h, w = disparity.shape
    dy, dx = np.array([1, -1, 0, 0]), np.array([0, 0, 1, -1])
    out = disparity.copy()
    queue = np.empty(h * w, np.int64)
    tail = 0
    for y in range(h):
        for x in range(w):
            if out[y, x] == out[y, x]:
                queue[tail] = y * w + x
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


def plane_depth(columns: np.ndarray, u: np.ndarray, v: np.ndarray, phase: np.ndarray,
                ax: np.ndarray, az: np.ndarray, period: float, max_step: float,
                kp: np.ndarray, tp: np.ndarray, zmin: float, zmax: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """NumPy reference of :func:`bistair.geometry.unwrap_stream_jit.plane_depth` through an
    undistorted projector without skew: the columns read bilinearly at each left pixel's
    rectified position (four finite corners within ``max_step``), the order nearest that
    column, ``z = (x_n t_z - t_x) / (a_x - x_n a_z)`` in the range; depth, order and
    column (NaN, -1, NaN elsewhere)."""
    gh, gw = columns.shape
    x0, y0 = np.floor(u.astype(np.float64)), np.floor(v.astype(np.float64))
    inside = (x0 >= 0) & (y0 >= 0) & (x0 + 1 < gw) & (y0 + 1 < gh)
    xi, yi = np.where(inside, x0, 0).astype(np.int64), np.where(inside, y0, 0).astype(np.int64)
    fu, fv = u - xi, v - yi
    g = np.stack([columns[yi, xi], columns[yi, xi + 1], columns[yi + 1, xi],
                  columns[yi + 1, xi + 1]]).astype(np.float64)
    c = (1 - fu) * (1 - fv) * g[0] + fu * (1 - fv) * g[1] + (1 - fu) * fv * g[2] + fu * fv * g[3]
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.floor(c / period - phase / TWO_PI + 0.5)
        xp = (phase / TWO_PI + k) * period
        xn = (xp - kp[0, 2]) / kp[0, 0]
        z = (xn * tp[2] - tp[0]) / (ax - xn * az)
        ok = (inside & np.isfinite(c) & (g.max(0) - g.min(0) <= max_step) & (z >= zmin)
              & (z <= zmax))
    return (np.where(ok, z, np.nan).astype(np.float32), np.where(ok, k, -1).astype(np.int32),
            np.where(ok, xp, np.nan).astype(np.float32))


def rectified_phase_cv2(phase: np.ndarray, maps: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The wrapped phase on a rectified grid as ``cv2.remap`` gives it (bilinear, 1/32-px
    fixed-point weights, 0 outside the image) from the cosine and sine of the known pixels
    and their validity: ``arctan2`` in ``[0, 2*pi)``, NaN where the validity resampled is
    below 0.999 (what :func:`bistair.geometry.stereo_jit.resample_wrapped` replaced).

    Parameters
    ----------
    phase : numpy.ndarray
        ``(H, W)`` wrapped phase (radians), NaN where unknown.
    maps : tuple of numpy.ndarray
        The grid's remap tables (rectified pixel -> camera pixel).

    Returns
    -------
    numpy.ndarray
        float32, the tables' shape.

    Examples
    --------
    >>> phase = np.float32([[6.2, 0.1, np.nan]])
    >>> out = rectified_phase_cv2(phase, (np.float32([[0.5, 1.5]]), np.float32([[0, 0]])))
    >>> round(float(out[0, 0]), 4), bool(np.isnan(out[0, 1]))
    (0.0084, True)
    """
    valid = np.isfinite(phase)
    ph = np.where(valid, phase, 0).astype(np.float32)
    planes = [np.where(valid, np.cos(ph), 0).astype(np.float32),
              np.where(valid, np.sin(ph), 0).astype(np.float32), valid.astype(np.float32)]
    c, s, w = (cv2.remap(p, maps[0], maps[1], cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_CONSTANT, borderValue=0) for p in planes)
    out = np.arctan2(s, c).astype(np.float32)
    out[out < 0] += np.float32(2 * np.pi)
    out[out >= np.float32(2 * np.pi)] = 0
    out[w < 0.999] = np.nan
    return out
