"""Compiled pass of the multi-level Gray code (:mod:`bistair.codecs.graylevels`): each
pixel's digits read against the fringes' average and modulation, their order through the
base-L reflected Gray code, and whether each digit is clear.

Examples
--------
>>> import numpy as np
>>> raw = np.float32([[[0.0, 1 / 3, 2 / 3, 1.0]]])  # one frame, digits 0..3
>>> centres = np.float32([[-1, -1 / 3, 1 / 3, 1]])
>>> ones = np.ones((1, 4), np.float32)
>>> code, nearest, carried, beyond = read_levels(
...     raw, 0, 1, 1.0, ones * 0.5, ones * 0.5, np.ones((1, 4), bool), ones * 3.0, centres,
...     np.int32([[0, 1, 2, 3]]), np.int32([4]), 4, 4, 0.01, 3.0, 0.5, 1.0)
>>> code.tolist(), nearest.tolist(), carried.tolist(), beyond
([[0, 1, 2, 3]], [[0, 1, 2, 3]], [[True, True, True, True]], 0)
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import inline, kernel, kernel_frames

prange = range  # numba's prange once the first kernel of this module compiles


@inline
def _level(raw: np.ndarray, frame: int, y: int, x: int, s32: np.float32, avg: np.ndarray,
           mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, reach: int,
           tol: np.float32) -> tuple[np.float32, int]:
    """``(I - A) / B`` of a frame at ``(y, x)``, averaged over the pixels of the same fringe
    within ``reach`` rows (along the fringe, where the code does not change: valid, their
    phase within ``tol`` of the pixel's, unwrapped), and how many were averaged."""
    h = raw.shape[1]
    p0 = phi[y, x]
    total = np.float32(0.0)
    count = 0
    for yy in range(max(0, y - reach), min(h, y + reach + 1)):
        if valid[yy, x] and mod[yy, x] > 0 and abs(phi[yy, x] - p0) < tol:
            total += (np.float32(raw[frame, yy, x]) * s32 - avg[yy, x]) / mod[yy, x]
            count += 1
    return total / np.float32(max(count, 1)), count


@kernel(parallel=True)
def _sample_levels(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
                   mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, ys: np.ndarray,
                   xs: np.ndarray, reach: int, tol: float) -> np.ndarray:
    s32 = np.float32(scale)
    t32 = np.float32(tol)
    out = np.empty((digits, ys.size), np.float32)
    for k in prange(ys.size):
        for i in range(digits):
            out[i, k] = _level(raw, start + i, ys[k], xs[k], s32, avg, mod, valid, phi, reach,
                               t32)[0]
    return out


def sample_levels(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
                  mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, ys: np.ndarray,
                  xs: np.ndarray, reach: int, tol: float) -> np.ndarray:
    """``v = (I - A) / B`` of each code frame at the pixels ``(ys, xs)`` (valid ones),
    averaged along the fringe as :func:`read_levels` reads it.

    Parameters
    ----------
    raw, start, digits, scale, avg, mod, valid, phi
        As :func:`read_levels` takes them.
    ys, xs : numpy.ndarray
        The pixels' rows and columns.
    reach : int
        Rows either side averaged along the fringe.
    tol : float
        The largest phase difference (radians) of a pixel averaged with.

    Returns
    -------
    (digits, len(ys)) float32

    Examples
    --------
    >>> raw = np.float32([[[0.0, 1 / 3], [0.0, 1 / 3]]])
    >>> ones = np.ones((2, 2), np.float32)
    >>> sample_levels(raw, 0, 1, 1.0, ones * 0.5, ones * 0.5, np.ones((2, 2), bool), ones,
    ...               np.int64([0, 1]), np.int64([0, 1]), 2, 0.5).astype(float).round(3).tolist()
    [[-1.0, -0.333]]
    """
    raw, start = kernel_frames(raw, start, digits)
    return _sample_levels(raw, int(start), int(digits), float(np.float32(scale)),
                          np.asarray(avg, np.float32), np.asarray(mod, np.float32),
                          np.asarray(valid, np.bool_), np.asarray(phi, np.float32),
                          np.asarray(ys, np.int64), np.asarray(xs, np.int64), int(reach),
                          float(tol))


@kernel(parallel=True)
def _read_levels(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
                 mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, centres: np.ndarray,
                 digit_of: np.ndarray, used: np.ndarray, levels: int, fringes: int,
                 noise_d: float, z: float, share: float, zone: float, reach: int, tol: float,
                 need: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    _, h, w = raw.shape
    s32 = np.float32(scale)
    t32 = np.float32(tol)
    code = np.full((h, w), -1, np.int32)
    nearest = np.full((h, w), -1, np.int32)
    carried = np.zeros((h, w), np.bool_)
    beyond = np.zeros(h, np.int64)
    two_pi = np.float32(2.0 * math.pi)
    for y in prange(h):
        total = np.zeros(digits, np.float32)
        for x in range(w):
            if not (valid[y, x] and mod[y, x] > 0 and need[y, x]):
                continue
            # each digit's v = (I - A) / B summed along the fringe (its pixels within reach
            # rows: valid, modulated, their phase within tol)
            total[:] = 0.0
            count = np.float32(0.0)
            for yy in range(max(0, y - reach), min(h, y + reach + 1)):
                if valid[yy, x] and mod[yy, x] > 0 and abs(phi[yy, x] - phi[y, x]) < t32:
                    count += np.float32(1.0)
                    for i in range(digits):
                        total[i] += (np.float32(raw[start + i, yy, x]) * s32 - avg[yy, x]) \
                            / mod[yy, x]
            b = mod[y, x]
            parent = 0
            clear = True
            for i in range(digits):
                value = total[i] / max(count, np.float32(1.0))
                n = used[i]
                j = 0  # the nearest level: the first whose upper threshold value is under
                while j < n - 1 and value >= np.float32(0.5) * (centres[i, j]
                                                                + centres[i, j + 1]):
                    j += 1
                c = centres[i, j]
                if value >= c:  # the margin to the threshold on its side (none past the ends)
                    half = (centres[i, j + 1] - c) * np.float32(0.5) if j < n - 1 else \
                        np.float32(np.inf)
                    margin = half - (value - c)
                else:
                    half = (c - centres[i, j - 1]) * np.float32(0.5) if j > 0 else \
                        np.float32(np.inf)
                    margin = half - (c - value)
                if margin < share * half or margin * b * math.sqrt(count) < z * noise_d:
                    clear = False
                g = digit_of[i, j]
                digit = g if parent % 2 == 0 else levels - 1 - g
                parent = parent * levels + digit
            if parent >= fringes:
                if clear:
                    beyond[y] += 1
                continue
            nearest[y, x] = parent
            if clear:
                code[y, x] = parent
                p = phi[y, x]
                carried[y, x] = p >= zone and two_pi - p >= zone
    return code, nearest, carried, beyond


def read_levels(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
                mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, centres: np.ndarray,
                digit_of: np.ndarray, used: np.ndarray, levels: int, fringes: int,
                noise_d: float, z: float, share: float, zone: float, reach: int = 0,
                tol: float = 0.5, need: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The multi-level code read per pixel in one pass.

    Digit ``i`` of a pixel is read from frame ``start + i`` as ``v = (I - avg) / mod`` (the
    frame against the fringes' own average and modulation), averaged over the valid pixels
    within ``reach`` rows whose phase is within ``tol`` of the pixel's (along the fringe,
    in the column layout: the same code cell), at the nearest of the frame's
    ``used[i]`` level positions ``centres[i, :used[i]]`` (increasing; ``digit_of`` names
    their digits). It is clear where ``v`` sits outside the middle ``share`` of the gap to
    the next level on its side (``margin >= share * half-gap``) and its margin clears the
    noise of ``I - avg`` (``noise_d``, fraction of full scale; over the root of the pixels
    averaged) by ``z`` sigmas. The digits,
    most significant first, are a base-``levels`` reflected Gray code of the order: digit
    ``g`` counts forward where the index of the digits before it is even and backward
    (``levels - 1 - g``) where it is odd.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    start, digits : int
        The first code frame and the number of code frames.
    scale : float
        Multiplies a raw value into a fraction of full scale.
    avg, mod : (H, W) float32 arrays
        The fringes' average and modulation.
    valid : (H, W) bool array
        The pixels to read.
    phi : (H, W) float32 array
        Wrapped phase in [0, 2*pi); the code's edges sit at 0.
    centres : (digits, levels) float32 array
        Each frame's level positions in ``v``, increasing, the first ``used[i]`` set.
    digit_of : (digits, levels) int32 array
        The digit of each level position.
    used : (digits,) int32 array
        How many levels each frame uses.
    levels, fringes : int
        L, and the fringes across the coded axis (a higher order is beyond).
    noise_d : float
        The noise of ``I - avg``.
    z, share : float
        The sigmas and the share of a half-gap a clear digit's margin needs.
    zone : float
        A pixel whose phase is within ``zone`` of the code's edges is not carried by its
        own digits.
    reach : int, default 0
        Rows either side averaged along the fringe.
    tol : float, default 0.5
        The largest phase difference (radians) of a pixel averaged with.
    need : (H, W) bool array, optional
        The pixels to read (every valid one if not given; the others still count in
        their neighbours' averages and read as -1).

    Returns
    -------
    code : (H, W) int32
        The order where every digit is clear, -1 elsewhere.
    nearest : (H, W) int32
        The order of the nearest levels, clear or not (-1 where invalid or beyond).
    carried : (H, W) bool
        ``code`` set and the phase at least ``zone`` from the code's edges.
    beyond : int
        Pixels whose clear digits name a fringe past the last.

    Examples
    --------
    >>> raw = np.float32([[[0.0, 2 / 3, 2 / 3]]])  # digit 0, then a digit 2 of one frame
    >>> ones = np.ones((1, 3), np.float32)
    >>> code, nearest, carried, beyond = read_levels(
    ...     raw, 0, 1, 1.0, ones * 0.5, ones * 0.5, np.ones((1, 3), bool),
    ...     np.float32([[3.0, 3.0, 0.1]]), np.float32([[-1, -1 / 3, 1 / 3, 1]]),
    ...     np.int32([[0, 1, 2, 3]]), np.int32([4]), 4, 4, 0.01, 3.0, 0.5, 1.0)
    >>> code.tolist(), carried.tolist()  # the last beside a wrap: not carried
    ([[0, 2, 2]], [[True, True, False]])
    """
    raw, start = kernel_frames(raw, start, digits)
    code, nearest, carried, beyond = _read_levels(
        raw, int(start), int(digits), float(np.float32(scale)), np.asarray(avg, np.float32),
        np.asarray(mod, np.float32), np.asarray(valid, np.bool_), np.asarray(phi, np.float32),
        np.ascontiguousarray(centres, np.float32), np.ascontiguousarray(digit_of, np.int32),
        np.ascontiguousarray(used, np.int32), int(levels), int(fringes), float(noise_d),
        float(z), float(share), float(zone), int(reach), float(tol),
        np.ones(np.shape(valid), np.bool_) if need is None else np.asarray(need, np.bool_))
    return code, nearest, carried, int(beyond.sum())


@kernel(parallel=True)
def _row_fill(order: np.ndarray, nearest: np.ndarray, clear: np.ndarray, carried: np.ndarray,
              phi: np.ndarray, valid: np.ndarray, zone: float, reach: int, cut: float
              ) -> np.ndarray:
    h, w = order.shape
    out = order.copy()
    z32 = np.float32(zone)
    top = np.float32(2.0 * math.pi - zone)
    c32 = np.float32(cut)
    for y in prange(h):
        for x in range(w):
            mine = nearest[y, x]
            if out[y, x] >= 0 or mine < 0:
                continue
            found = -1
            clash = False
            for step in (-1, 1):
                xx = x
                for _ in range(reach):
                    nx = xx + step
                    if nx < 0 or nx >= w or not valid[y, nx] or \
                            abs(phi[y, nx] - phi[y, xx]) >= c32:
                        break  # the fringe ends here (a wrap, a step, the image)
                    xx = nx
                    if carried[y, xx]:
                        if found >= 0 and order[y, xx] != found:
                            clash = True
                        found = order[y, xx]
                        break
            if found < 0 or clash:
                continue
            p = phi[y, x]
            if mine == found or (not clear[y, x] and ((p < z32 and mine == found - 1) or
                                                      (p > top and mine == found + 1))):
                out[y, x] = found
    return out


def row_fill(order: np.ndarray, nearest: np.ndarray, clear: np.ndarray, carried: np.ndarray,
             phi: np.ndarray, valid: np.ndarray, zone: float, reach: int, cut: float
             ) -> np.ndarray:
    """Orders for the pixels read but not decoded, from their fringe along the row (the
    inter-zone rule): the first carried pixel either way within ``reach`` pixels, reached
    without crossing a phase step of ``cut`` or more (a wrap, another surface), names the
    fringe's order (both ways the same where both find one); a pixel takes it where its
    own nearest-level reading is that order or, where a digit is not clear and its phase
    is within ``zone`` of the code's edge, the neighbour on that edge's side (the misread
    an edge's blur makes; a clear reading is not overruled).

    Parameters
    ----------
    order : (H, W) int32
        The orders so far (carried pixels set), -1 elsewhere.
    nearest : (H, W) int32
        Each pixel's nearest-level reading (-1: none).
    clear : (H, W) bool
        Where every digit of that reading is clear.
    carried : (H, W) bool
        The pixels whose own digits carry their order.
    phi : (H, W) float32
        Wrapped phase, the code's edges at 0.
    valid : (H, W) bool
        The valid pixels.
    zone, cut : float
        Radians.
    reach : int
        Pixels searched either way.

    Returns
    -------
    (H, W) int32

    Examples
    --------
    >>> phi = np.float32([[0.2, 1.5, 3.0, 4.5, 6.1]])
    >>> order = np.int32([[-1, 3, 3, 3, -1]])
    >>> carried = order >= 0
    >>> near = np.int32([[2, 3, 3, 3, 4]])  # the edges misread, each by its neighbour
    >>> row_fill(order, near, carried * False, carried, phi, np.ones((1, 5), bool), 1.0, 8,
    ...          2.0).tolist()
    [[3, 3, 3, 3, 3]]
    >>> row_fill(order, near, carried | True, carried, phi, np.ones((1, 5), bool), 1.0, 8,
    ...          2.0).tolist()  # read clearly: not overruled
    [[-1, 3, 3, 3, -1]]
    """
    return _row_fill(np.ascontiguousarray(order, np.int32),
                     np.ascontiguousarray(nearest, np.int32), np.asarray(clear, np.bool_),
                     np.asarray(carried, np.bool_),
                     np.asarray(phi, np.float32), np.asarray(valid, np.bool_), float(zone),
                     int(reach), float(cut))


@kernel()
def _cell_sums(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
               mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, labels: np.ndarray,
               rows: int, zone: float, noise_d: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                          np.ndarray, np.ndarray]:
    _, h, w = raw.shape
    s32 = np.float32(scale)
    z32 = np.float32(zone)
    top = np.float32(2.0 * math.pi - zone)
    blocks = (h + rows - 1) // rows
    n = (labels.max() + 1) * blocks
    cid = np.zeros((h, w), np.int64)
    total = np.zeros((digits, n))
    square = np.zeros((digits, n))
    expect = np.zeros(n)
    count = np.zeros(n, np.int64)
    step = np.zeros(n)
    steps = np.zeros(n, np.int64)
    for y in range(h):
        block = y // rows
        for x in range(w):
            lab = labels[y, x]
            if lab <= 0:
                continue
            c = lab * blocks + block
            cid[y, x] = c
            if x + 1 < w and labels[y, x + 1] == lab:
                d = phi[y, x + 1] - phi[y, x]
                if abs(d) < 1.0:
                    step[c] += d
                    steps[c] += 1
            p = phi[y, x]
            b = mod[y, x]
            if not valid[y, x] or b <= 0 or p < z32 or p > top:
                continue
            count[c] += 1
            expect[c] += (noise_d / b) ** 2
            for i in range(digits):
                v = (np.float32(raw[start + i, y, x]) * s32 - avg[y, x]) / b
                total[i, c] += v
                square[i, c] += v * v
    return cid, total, square, expect, count, step, steps


def cell_sums(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
              mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, labels: np.ndarray,
              rows: int, zone: float, noise_d: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                         np.ndarray, np.ndarray]:
    """The sums a code cell is read from, in one pass: each pixel's cell (``label *
    blocks + y // rows``, 0 outside any region), and per cell over its valid pixels at
    least ``zone`` from the code's edges the sums of each code frame's ``v = (I - A) /
    B`` and of its square, of the noise variance ``(noise_d / B)**2`` and the count; and
    over all its pixels the phase steps to the next pixel along the row in the same
    region (under 1 radian) and their count.

    Parameters
    ----------
    raw, start, digits, scale, avg, mod, valid, phi
        As :func:`read_levels` takes them.
    labels : (H, W) int array
        Fringe regions, 0 outside any.
    rows : int
        Rows of a cell.
    zone : float
        Radians from the code's edges left out of the means.
    noise_d : float
        The noise of ``I - A``.

    Returns
    -------
    cid : (H, W) int64
    total, square : (D, n) float64
    expect : (n,) float64
    count : (n,) int64
    step : (n,) float64
    steps : (n,) int64

    Examples
    --------
    >>> raw = np.float32([[[0.25, 0.25, 0.75]]])
    >>> ones = np.ones((1, 3), np.float32)
    >>> cid, total, square, expect, count, step, steps = cell_sums(
    ...     raw, 0, 1, 1.0, ones * 0.5, ones * 0.5, np.ones((1, 3), bool),
    ...     np.float32([[2.0, 2.5, 3.0]]), np.int32([[1, 1, 2]]), 4, 1.0, 0.01)
    >>> cid.tolist(), total.tolist(), count.tolist(), step.tolist()
    ([[1, 1, 2]], [[0.0, -1.0, 0.5]], [0, 2, 1], [0.0, 0.5, 0.0])
    """
    raw, start = kernel_frames(raw, start, digits)
    return _cell_sums(raw, int(start), int(digits), float(np.float32(scale)),
                      np.asarray(avg, np.float32), np.asarray(mod, np.float32),
                      np.asarray(valid, np.bool_), np.asarray(phi, np.float32),
                      np.ascontiguousarray(labels, np.int32), int(rows), float(zone),
                      float(noise_d))
