"""Fused per-pixel passes of the checks and the result: code steps, sampled pixels, order
steps across wraps, the result's arrays (see :mod:`bistair.core.fused`: bit for bit the
NumPy they replace).

Examples
--------
>>> import numpy as np
>>> order = np.int32([[0, -1, 1, 2]])
>>> decoded_sample(np.ones((1, 4), bool), order, 10).tolist()
[0, 2, 3]
"""

from __future__ import annotations

import math

import numpy as np

from .fused import TWO_PI32
from .kernels import kernel

prange = range  # numba's prange once the first kernel compiles


@kernel(parallel=True)
def _code_steps(phi: np.ndarray, edges: np.ndarray, valid: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    h, w = edges.shape
    counts = np.zeros(h + 1, np.int64)
    for y in prange(h):
        m = 0
        for j in range(w - 3):
            a = edges[y, j + 1] if valid[y, j + 1] else -1
            b = edges[y, j + 2] if valid[y, j + 2] else -1
            if a < 0 or b < 0 or a == b:
                continue
            a0 = edges[y, j] if valid[y, j] else -1
            b1 = edges[y, j + 3] if valid[y, j + 3] else -1
            if a0 == a and b1 == b:
                m += 1
        counts[y + 1] = m
    start = np.cumsum(counts)
    total = start[h]
    pa = np.empty(total, np.float64)
    pb = np.empty(total, np.float64)
    step = np.empty(total, np.int64)
    for y in prange(h):
        i = start[y]
        for j in range(w - 3):
            a = edges[y, j + 1] if valid[y, j + 1] else -1
            b = edges[y, j + 2] if valid[y, j + 2] else -1
            if a < 0 or b < 0 or a == b:
                continue
            a0 = edges[y, j] if valid[y, j] else -1
            b1 = edges[y, j + 3] if valid[y, j + 3] else -1
            if a0 == a and b1 == b:
                pa[i] = np.float64(phi[y, j + 1])
                pb[i] = np.float64(phi[y, j + 2])
                step[i] = np.int64(b - a)
                i += 1
    return pa, pb, step


def code_steps(phi: np.ndarray, edges: np.ndarray, valid: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The steps of a code along the rows between runs of at least two equal codes (the
    pairs :func:`~bistair.core.checks.edge_alignment` judges), in raster order.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    edges : (H, W) int array
        The code per pixel, -1 where not read.
    valid : (H, W) bool array
        Pixels whose phase counts (the others read as -1).

    Returns
    -------
    pa, pb : float64 arrays
        The phase of the last pixel before each step and of the first after it.
    step : int64 array
        The code after the step less the code before it.

    Examples
    --------
    >>> phi = np.float32([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]])
    >>> code = np.int32([[1, 1, 2, 2, 2, 5]])
    >>> [a.round(3).tolist() for a in code_steps(phi, code, np.ones((1, 6), bool))]
    [[0.2], [0.3], [1]]
    """
    return _code_steps(phi, edges, np.asarray(valid, bool))


@kernel(parallel=True)
def _sample(valid: np.ndarray, order: np.ndarray, samples: int) -> np.ndarray:
    h, w = valid.shape
    counts = np.zeros(h + 1, np.int64)
    for y in prange(h):
        m = 0
        for x in range(w):
            if valid[y, x] and order[y, x] >= 0:
                m += 1
        counts[y + 1] = m
    start = np.cumsum(counts)
    total = start[h]
    every = max(1, total // samples)
    out = np.empty((total + every - 1) // every, np.int64)
    for y in prange(h):
        rank = start[y]
        for x in range(w):
            if valid[y, x] and order[y, x] >= 0:
                if rank % every == 0:
                    out[rank // every] = y * w + x
                rank += 1
    return out


def decoded_sample(valid: np.ndarray, order: np.ndarray, samples: int) -> np.ndarray:
    """Flat indices of about ``samples`` decoded pixels (valid, order >= 0): every
    ``max(1, count // samples)``-th of them in raster order, as
    ``np.flatnonzero(valid & (order >= 0))[::every]`` gives them.

    Parameters
    ----------
    valid : (H, W) bool array
        Valid pixels.
    order : (H, W) int array
        Fringe orders, -1 where not decoded.
    samples : int
        About how many pixels to pick (at least 1).

    Returns
    -------
    int64 array
        The flat indices, ascending.

    Examples
    --------
    >>> order = np.int32([[0, -1, 1, 2], [3, 4, 5, 6]])
    >>> decoded_sample(np.ones((2, 4), bool), order, 3).tolist()  # every second one
    [0, 3, 5, 7]
    """
    return _sample(np.asarray(valid, bool), order, max(1, int(samples)))


@kernel(parallel=True)
def _assemble(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, masked: bool,
              factor: float, top: int, limit: float, bounded: bool
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    h, w = phi.shape
    phase = np.empty((h, w), np.float32)
    coord = np.empty((h, w), np.float32)
    out_order = np.empty((h, w), np.int32)
    wrapped = np.empty((h, w), np.float32)
    mask = np.empty((h, w), np.bool_)
    outside = np.zeros(h, np.int64)
    f32 = np.float32(factor)
    lim32 = np.float32(limit)
    top32 = np.int32(top)
    nan32 = np.float32(np.nan)
    for y in prange(h):
        out = 0
        for x in range(w):
            p = phi[y, x]
            k = np.int32(order[y, x])
            ok = k >= 0 and np.isfinite(p)
            if ok and bounded and not (k < top32 or (k == top32 and p * f32 < lim32)):
                ok = False
                out += 1
            mask[y, x] = ok
            if ok:
                v = p + TWO_PI32 * np.float32(k)
                phase[y, x] = v
                coord[y, x] = v * f32
                out_order[y, x] = k
            else:
                phase[y, x] = nan32
                coord[y, x] = nan32
                out_order[y, x] = -1
            wrapped[y, x] = p if (not masked or valid[y, x]) else nan32
        outside[y] = out
    return phase, coord, out_order, wrapped, mask, outside.sum()


def assemble(phi: np.ndarray, order: np.ndarray, period: float, length: float | None = None,
             valid: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """The per-pixel arrays of :func:`~bistair.core.result.make_result` in one pass.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)`` (NaN where unknown).
    order : (H, W) int array
        Fringe order per pixel, negative where invalid.
    period : float
        Projector pixels per fringe.
    length : float, optional
        Projector pixels along the coded axis (coordinates at or past it are invalid).
    valid : (H, W) bool array, optional
        Where to report the wrapped phase (NaN elsewhere); everywhere when not given.

    Returns
    -------
    phase, coord : (H, W) float32 arrays
        Absolute phase ``phi + 2*pi*order`` and projector coordinate, NaN where invalid.
    order : (H, W) int32 array
        The order, -1 where invalid.
    wrapped : (H, W) float32 array
        ``phi``, NaN outside ``valid``.
    mask : (H, W) bool array
        Pixels with a valid absolute phase.
    outside : int
        Pixels whose coordinate ``length`` invalidated.

    Examples
    --------
    >>> phi = np.full((1, 3), np.pi, np.float32)
    >>> phase, coord, order, wrapped, mask, outside = assemble(
    ...     phi, np.array([[0, 2, -1]]), 10.0, length=25)
    >>> coord.tolist(), order.tolist(), outside
    ([[5.0, nan, nan]], [[0, -1, -1]], 1)
    """
    phi = np.asarray(phi, np.float32)
    top, limit = 0, 0.0
    if length is not None:
        top = np.floor(np.float32(length) / np.float32(period)).astype(np.int32)
        limit = float(np.float32(length - top * period))
    where = np.ones((1, 1), bool) if valid is None else np.asarray(valid, bool)
    return _assemble(phi, order, where, valid is not None,
                     float(np.float32(period / (2.0 * math.pi))), int(top), limit,
                     length is not None)


@kernel()
def _wrap_steps(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, every: int,
                reach: int) -> tuple[int, int, int]:
    h, w = phi.shape
    rows = (h + every - 1) // every
    span = 2 * reach + 1
    pi32 = np.float32(math.pi)
    near = np.float32(0.6)
    counts = np.zeros((rows, 3), np.int64)
    for r in range(rows):
        y = r * every
        bad_sum = np.zeros(w, np.int32)  # prefix counts over the w - 1 pairs
        wrap_sum = np.zeros(w, np.int32)
        for x in range(w - 1):
            d = np.float32(phi[y, x + 1]) - np.float32(phi[y, x])
            ok = (valid[y, x] and order[y, x] >= 0 and valid[y, x + 1]
                  and order[y, x + 1] >= 0)
            clean = ok and abs(d - TWO_PI32 * np.rint(d / TWO_PI32)) < near
            bad_sum[x + 1] = bad_sum[x] + (0 if clean else 1)
            wrap_sum[x + 1] = wrap_sum[x] + (1 if clean and abs(d) > pi32 else 0)
        bad = 0
        big = 0
        judged = 0
        for j in range(w - span):
            c = j + reach
            d = np.float32(phi[y, c + 1]) - np.float32(phi[y, c])
            if not abs(d) > pi32:
                continue
            if bad_sum[j + span] - bad_sum[j] != 0 or wrap_sum[j + span] - wrap_sum[j] != 1:
                continue
            judged += 1
            want = -1 if d > 0 else 1
            off = abs(np.int64(order[y, j + span]) - np.int64(order[y, j]) - want)
            if off != 0:
                bad += 1
            if off >= 2:
                big += 1
        counts[r, 0] = bad
        counts[r, 1] = big
        counts[r, 2] = judged
    return counts[:, 0].sum(), counts[:, 1].sum(), counts[:, 2].sum()


def wrap_step_counts(phi: np.ndarray, order: np.ndarray, valid: np.ndarray, every: int,
                     reach: int) -> tuple[int, int, int]:
    """:func:`~bistair.core.checks.wrap_steps` in one pass over the rows it judges:
    ``(violations, big violations, places)``.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in [0, 2*pi) (read as float32).
    order : (H, W) int array
        Fringe orders, -1 where invalid.
    valid : (H, W) bool array
        Pixels to judge.
    every : int
        Judge every ``every``-th row.
    reach : int
        Pixels on either side of a wrap that must run on smoothly.

    Returns
    -------
    (violations, big violations, places) : tuple of int
        As :func:`~bistair.core.checks.wrap_steps` counts them.

    Examples
    --------
    >>> x = np.arange(80) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 20) % (2 * np.pi), (2, 1)).astype(np.float32)
    >>> order = np.tile((x // 20).astype(np.int32), (2, 1))
    >>> wrap_step_counts(phi, order, np.ones(phi.shape, bool), 1, 3)
    (0, 0, 6)
    >>> wrap_step_counts(phi, np.where(x < 40, order, order + 2), np.ones(phi.shape, bool), 1, 3)
    (2, 2, 6)
    """
    if phi.shape[1] < 2 * reach + 2:
        return 0, 0, 0
    bad, big, places = _wrap_steps(phi, order, np.asarray(valid, bool), int(every),
                                   int(reach))
    return int(bad), int(big), int(places)
