"""Compiled passes of the stair phase (:mod:`bistair.core.stair`), which the stair codecs
share: the stair pair's phase and modulation in one pass, and its quantisation to levels.

The codecs call them through their face, :mod:`bistair.core.stair` (``read_stairs``,
``stair_levels``, ``relinearize_levels``). :func:`bistair.core.stair.quantize` and, in the
tests, ``tests/support/reference.py`` (``stair_phase``, ``relinearize``) are the NumPy
references; these give the same, bit for bit (the arctangent is
:func:`bistair.core.phase_jit.arctan2_32`'s). A decode reads the pair in the phase stage's
own pass (:func:`bistair.core.measure_jit.front_end`, the same arithmetic):
:func:`pair_phase` serves a set measured without it.

Examples
--------
>>> import numpy as np
>>> quantize32(np.float32([[0.1, 3.0, -1.6]]), 4, np.ones((1, 3), bool)).tolist()
[[2, 3, 0]]
"""

from __future__ import annotations

import math

import numpy as np

from .jit import PI32, kernel, kernel_frames
from .phase_jit import angle32, hypot32

prange = range  # numba's prange once the first kernel of this module compiles


@kernel(parallel=True)
def quantize32(theta: np.ndarray, levels: int, valid: np.ndarray) -> np.ndarray:
    """:func:`bistair.core.stair.quantize` of a float32 phase map, -1 where not ``valid``.

    Parameters
    ----------
    theta : (H, W) float32 array
        Stair phase in radians.
    levels : int
        Number of steps of the stair.
    valid : (H, W) bool array
        Pixels to quantise.

    Returns
    -------
    (H, W) int32 array
        Level ``floor((theta + pi) * levels / (2*pi)) mod levels``, -1 where not valid.

    Examples
    --------
    >>> quantize32(np.float32([[-3.0, 0.0, 3.0]]), 4, np.array([[True, True, False]])).tolist()
    [[0, 2, -1]]
    """
    h, w = theta.shape
    scale = np.float32(levels / (2.0 * math.pi))
    cycle = np.float64(levels)
    out = np.empty((h, w), np.int32)
    for y in prange(h):
        t = theta[y]
        ok = valid[y]
        o = out[y]
        for x in range(w):  # the modulo in float64 (exact): the loop vectorises
            q = np.float64(math.floor((t[x] + PI32) * scale))
            q = q - cycle * math.floor(q / cycle)
            o[x] = np.int32(q) if ok[x] else np.int32(-1)
    return out


@kernel(parallel=True)
def relinearize32(theta: np.ndarray, table: np.ndarray, levels: int, valid: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The stair phase through a level table (``tests/support/reference.py:relinearize``, bit for
    bit) and its :func:`quantize32` levels, in one pass.

    Parameters
    ----------
    theta : (H, W) float32 array
        Stair phase in radians.
    table : (bins,) float32 array
        From :func:`bistair.core.stair.level_table`.
    levels : int
        Number of steps of the stair the levels are read for.
    valid : (H, W) bool array
        Pixels to quantise.

    Returns
    -------
    mapped : (H, W) float32 array
        The phase through the table.
    level : (H, W) int32 array
        Its level, -1 where not valid.

    Examples
    --------
    >>> table = np.float32([-3.0, -1.0, 1.0, 3.0])  # four steps of the circle
    >>> mapped, level = relinearize32(np.float32([[-3.1, 0.1, 2.0]]), table, 4,
    ...                               np.array([[True, True, False]]))
    >>> mapped.tolist(), level.tolist()
    ([[-3.0, 1.0, 3.0]], [[0, 2, -1]])
    """
    h, w = theta.shape
    n = table.size
    step = np.float32(n / (2.0 * math.pi))
    scale = np.float32(levels / (2.0 * math.pi))
    mapped = np.empty((h, w), np.float32)
    out = np.empty((h, w), np.int32)
    for y in prange(h):
        for x in range(w):
            i = int((theta[y, x] + PI32) * step)
            m = table[min(max(i, 0), n - 1)]
            mapped[y, x] = m
            if valid[y, x]:
                out[y, x] = np.int32(math.floor((m + PI32) * scale)) % levels
            else:
                out[y, x] = -1
    return mapped, out


@kernel(parallel=True)
def _pair_phase(raw: np.ndarray, first: int, scale: float, avg: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    _, h, w = raw.shape
    s32 = np.float32(scale)
    theta = np.empty((h, w), np.float32)
    mod = np.empty((h, w), np.float32)
    for y in prange(h):
        for x in range(w):
            a = np.float32(raw[first, y, x]) * s32 - avg[y, x]
            b = np.float32(raw[first + 1, y, x]) * s32 - avg[y, x]
            theta[y, x] = angle32(b, a)
            mod[y, x] = hypot32(a, b)
    return theta, mod


def pair_phase(raw: np.ndarray, first: int, scale: float, avg: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """The stair phase (``tests/support/reference.py:stair_phase``) of frames ``first``
    (cosine) and ``first + 1`` (sine) of a raw capture stack (each value times ``scale``
    its fraction of full scale), read, centred on ``avg`` and turned into a phase and a
    modulation in one pass.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    first : int
        Index of the cosine frame; the sine frame follows it.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    avg : (H, W) float32 array
        The fringes' average intensity ``A``.

    Returns
    -------
    theta : (H, W) float32 array
        The stair phase in radians, ``arctan2(sin - A, cos - A)`` (as
        :func:`~bistair.core.phase_jit.arctan2_32`), in ``[-pi, pi]``.
    modulation : (H, W) float32 array
        The length of that vector.

    Examples
    --------
    >>> raw = np.uint8([[[255, 128]], [[128, 0]]])
    >>> theta, mod = pair_phase(raw, 0, 1 / 255, np.float32([[0.5, 0.5]]))
    >>> theta.astype(float).round(3).tolist(), mod.astype(float).round(3).tolist()
    ([[0.004, -1.567]], [[0.5, 0.5]])
    """
    raw, first = kernel_frames(raw, first, 2)
    return _pair_phase(raw, first, float(np.float32(scale)), np.asarray(avg, np.float32))
