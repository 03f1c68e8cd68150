"""Compiled passes of the stair checks and edges (:mod:`.stairs`): where the stair code
turns inside a fringe, the stair phase noise per pixel, a sample of the decoded pixels, and
whether each pixel reads its order's local or partition level.

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

from ...core.jit import fmax, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def stair_turns(phi: np.ndarray, cos_t: np.ndarray, sin_t: np.ndarray, valid: np.ndarray,
                noise: np.ndarray, step: float) -> np.ndarray:
    """Horizontal links (H, W-1) where the stair phase (given by its cosine and sine) turns
    by more than ``max(0.75 step, 4 spread)`` between the pairs of pixels either side of
    the link, away from the phase jumps (see
    :func:`bistair.codecs.bidirectional.stair_edges`).

    Away from the phase jumps means the wrapped phase of the link's left pixel lies
    between 15% and 85% of ``2*pi``; all four pixels must be valid.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    cos_t, sin_t : (H, W) float32 arrays
        Cosine and sine of the stair phase.
    valid : (H, W) bool array
        Valid pixels.
    noise : (H, W) float32 array
        Per-pixel stair phase noise in radians (``spread`` combines those of the pairs).
    step : float
        The local stair step in radians (``2*pi / stairs``).

    Returns
    -------
    (H, W-1) bool array
        Links between each pixel and the one to its right where the stair phase turns.

    Examples
    --------
    >>> theta = np.where(np.arange(12) < 6, -2.0, 1.0).astype(np.float32)[None].repeat(2, axis=0)
    >>> phi = np.full((2, 12), np.pi, np.float32)
    >>> edge = stair_turns(phi, np.cos(theta), np.sin(theta), np.ones((2, 12), bool),
    ...                    np.full((2, 12), 0.01, np.float32), 2 * np.pi / 3)
    >>> [np.flatnonzero(row).tolist() for row in edge]
    [[5], [5]]
    """
    h, w = phi.shape
    edge = np.zeros((h, w - 1), np.bool_)
    lo = np.float32(0.15 * 2.0 * math.pi)
    hi = np.float32(0.85 * 2.0 * math.pi)
    base = 0.75 * step
    cb, sb = math.cos(base), math.sin(base)
    for y in prange(h):
        for x in range(1, w - 2):
            if not (valid[y, x - 1] and valid[y, x] and valid[y, x + 1] and valid[y, x + 2]):
                continue
            mid = phi[y, x]
            if not (mid > lo and mid < hi):
                continue
            lr = cos_t[y, x - 1] + cos_t[y, x]
            li = sin_t[y, x - 1] + sin_t[y, x]
            rr = cos_t[y, x + 1] + cos_t[y, x + 2]
            ri = sin_t[y, x + 1] + sin_t[y, x + 2]
            re = rr * lr + ri * li
            im = ri * lr - rr * li
            # well inside the base angle: no edge, and no arctangent needed
            if cb * abs(im) - sb * re < -1e-6 * (abs(im) + abs(re)):
                continue
            turn = abs(np.float32(math.atan2(im, re)))
            a = max(noise[y, x - 1], noise[y, x + 2])
            b = max(noise[y, x], noise[y, x + 1])
            spread = np.float32(math.sqrt(a * a + b * b))
            if turn > max(base, 4.0 * spread):
                edge[y, x] = True
    return edge


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
def _agreement(levels: np.ndarray, theta: np.ndarray, order: np.ndarray, stairs: int,
               partitions: int) -> np.ndarray:
    h, w = levels.shape
    out = np.empty((h, w), np.bool_)
    scale = np.float32(partitions / (2.0 * math.pi))
    pi32 = np.float32(math.pi)
    span = stairs * partitions
    inv = 1.0 / stairs
    for y in prange(h):
        rare = 0
        for x in range(w):  # branch-free for orders in [-1, P*S) and phases in [-pi, pi]
            k = np.int64(order[y, x])
            # k // S and k % S as Python gives them, without a division: exact for |k| far
            # below 2**40 (a rare order outside [-1, P*S) is judged again below)
            part = np.int64(math.floor((np.float64(k) + 0.5) * inv))
            q = np.int64(math.floor((theta[y, x] + pi32) * scale))
            q = q - partitions if q >= partitions else q
            out[y, x] = (np.int64(levels[y, x]) == k - part * stairs) | (q == part)
            rare += (k < -1) | (k >= span) | (q < 0) | (q >= partitions)
        if rare:
            for x in range(w):
                k = np.int64(order[y, x])
                q = np.int64(math.floor((theta[y, x] + pi32) * scale))
                if k >= -1 and k < span and q >= 0 and q < partitions + partitions:
                    continue
                # Python's floor division and modulo, as NumPy's
                out[y, x] = levels[y, x] == k % stairs or q % partitions == k // stairs
    return out


def stair_agreement(levels: np.ndarray, theta: np.ndarray, order: np.ndarray, stairs: int,
                    partitions: int) -> np.ndarray:
    """Pixels that read their fringe order's local level ``k % S`` (``levels``) or whose
    stair phase quantises to its partition level ``k // S``
    (:func:`~bistair.core.stair.quantize` of ``theta``), Python's ``%`` and ``//`` for
    negative orders.

    Parameters
    ----------
    levels : (H, W) int array
        The local stair level per pixel.
    theta : (H, W) float32 array
        The stair phase in radians.
    order : (H, W) int array
        The fringe order per pixel.
    stairs, partitions : int
        Levels ``S`` of the local and ``P`` of the partition stair.

    Returns
    -------
    (H, W) bool array
        The pixels whose code fits their order.

    Examples
    --------
    >>> theta = np.float32([[-3.0, 0.5, 3.0]])
    >>> stair_agreement(np.int32([[1, 0, 2]]), theta, np.int64([[1, 5, 7]]), 4, 3).tolist()
    [[True, True, False]]
    """
    # (a view of a part of the maps is copied first: the kernel is 3-7 times slower on
    # arrays that are not contiguous, as it runs on a sample or a box)
    return _agreement(np.ascontiguousarray(levels), np.ascontiguousarray(theta, np.float32),
                      np.ascontiguousarray(order), int(stairs), int(partitions))


@kernel(parallel=True)
def stair_noise(stair_mod: np.ndarray, noise_scale: float) -> np.ndarray:
    """Stair phase noise per pixel, ``noise_scale / max(stair_mod, 1e-6)`` (float64
    arithmetic, float32 result, as NumPy gives it).

    Parameters
    ----------
    stair_mod : (H, W) float32 array
        Modulation of the stair pair.
    noise_scale : float
        Camera noise times ``sqrt(2)``.

    Returns
    -------
    (H, W) float32 array
        Radians.

    Examples
    --------
    >>> stair_noise(np.float32([[0.5, 0.0]]), 0.01).tolist()
    [[0.019999999552965164, 10000.0]]
    """
    h, w = stair_mod.shape
    noise = np.empty((h, w), np.float32)
    tiny = np.float32(1e-6)
    for y in prange(h):
        for x in range(w):
            noise[y, x] = np.float32(noise_scale / np.float64(fmax(stair_mod[y, x], tiny)))
    return noise
