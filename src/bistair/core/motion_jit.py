"""Compiled pass of a stream's running sums (:mod:`bistair.core.motion`): one frame added
to a window's sums, its phase and modulation, and binomial self-compensation, in one pass
over rows on every core.

:func:`stream_update` gives what :class:`~bistair.core.motion.PhaseStream`'s NumPy steps
give: the sums in float64, the phase and modulation of their float32 values by
:func:`~bistair.core.phase_jit.phase32` and ``hypot32`` (as
:func:`~bistair.core.phase_jit.phase_of_sums32`), the pairwise means across the wrap as
:func:`~bistair.core.phase_jit.wrap_angles` and ``np.mod`` compute them in float32.

Examples
--------
>>> import numpy as np
>>> x = np.arange(8.0)[None, :]
>>> frames = [np.float32(0.5 + 0.4 * np.cos(2 * np.pi * x / 8 + np.pi * i / 2))
...           for i in range(4)]
>>> state = stream_state((1, 8), 4, 0, np.float32)
>>> for i, f in enumerate(frames):
...     ready = stream_update(state, f, i, 4, 0, 1, 0.0)
>>> ready, state.phase.astype(float).round(4).tolist()[0][:3]
(True, [0.0, 0.7854, 1.5708])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .jit import PI32, TWO_PI32, inline, kernel
from .phase_jit import hypot32, offset_parts, phase32

prange = range  # numba's prange once the first kernel of this module compiles


@inline
def _wrap32(raw: np.float32) -> np.float32:
    """``(raw + pi) % 2pi - pi`` in float32, as :func:`~bistair.core.phase_jit.wrap_angles`
    computes it, for ``-3*pi <= raw < 3*pi`` (the difference of two of a stream's
    phases: each within ``K*pi/2`` of ``[0, 2*pi)``); selects, so that its loop
    vectorises."""
    d = raw + PI32
    m = d - TWO_PI32 if d >= TWO_PI32 else d
    m = m + TWO_PI32 if d < np.float32(0.0) else m
    return m - PI32


@inline
def _mod32(a: np.float32) -> np.float32:
    """``np.mod(a, 2pi)`` of a float32 as NumPy computes it (``fmod``, then ``+ 2pi`` below
    0, one rounding) for ``-2*pi < a < 4*pi``; further out ``a - 2pi * floor(a / 2pi)``.
    Selects, so that its loop vectorises."""
    zero = np.float32(0.0)
    far = a - TWO_PI32 * np.floor(a / TWO_PI32)
    m = a + zero if zero <= a < TWO_PI32 else far  # (a + 0: -0.0 is 0.0)
    m = a - TWO_PI32 if TWO_PI32 <= a < TWO_PI32 + TWO_PI32 else m  # (exact)
    return a + TWO_PI32 if -TWO_PI32 < a < zero else m


@kernel(parallel=True)
def _update(frame: np.ndarray, kept: np.ndarray, slot: int, full: bool, sin_k: float,
            cos_k: float, num: np.ndarray, den: np.ndarray, windows: int, order: int,
            levels: np.ndarray, mods: np.ndarray, off_hi: np.float32, off_lo: np.float32,
            scale: np.float32, phase: np.ndarray, mod: np.ndarray) -> None:
    h, w = frame.shape
    half, two = np.float32(0.5), np.float32(2.0)
    for y in prange(h):  # (loops without branches out: they vectorise)
        for x in range(w):
            f = float(frame[y, x])
            diff = f - float(kept[slot, y, x]) if full else f
            kept[slot, y, x] = frame[y, x]
            num[y, x] -= sin_k * diff
            den[y, x] += cos_k * diff
        if windows == 0:
            continue
        for x in range(w):
            a, b = np.float32(num[y, x]), np.float32(den[y, x])
            phase[y, x] = phase32(a, b, off_hi, off_lo)
            mod[y, x] = hypot32(a, b) * scale
        for level in range(order + 1):  # phase, mod: the newest value of the level
            if level == order or level + 1 >= windows:  # (no previous window above)
                for x in range(w):
                    levels[level, y, x], mods[level, y, x] = phase[y, x], mod[y, x]
                break
            reduce = level == order - 1
            for x in range(w):
                previous, previous_mod = levels[level, y, x], mods[level, y, x]
                new, new_mod = phase[y, x], mod[y, x]
                levels[level, y, x], mods[level, y, x] = new, new_mod
                mean = previous + _wrap32(new - previous) / two
                phase[y, x] = _mod32(mean) if reduce else mean
                mod[y, x] = (previous_mod + new_mod) * half


@dataclass
class StreamState:
    """The buffers of :func:`stream_update`: the last ``N`` frames (``kept``), the float64
    sums, the newest value of each round of pairwise means (``levels``, ``mods``) and the
    newest window's compensated ``phase`` and ``mod`` (float32)."""

    kept: np.ndarray
    num: np.ndarray
    den: np.ndarray
    levels: np.ndarray
    mods: np.ndarray
    phase: np.ndarray
    mod: np.ndarray


def stream_state(shape: tuple[int, int], steps: int, order: int, dtype: type) -> StreamState:
    """New buffers for a stream of ``shape`` frames.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    steps, order : int
        ``N`` and ``K``.
    dtype : type
        The frames' type (kept as they are).

    Returns
    -------
    StreamState

    Examples
    --------
    >>> stream_state((2, 3), 4, 1, np.uint8).levels.shape
    (2, 2, 3)
    """
    return StreamState(np.zeros((steps, *shape), dtype), np.zeros(shape, np.float64),
                       np.zeros(shape, np.float64), np.zeros((order + 1, *shape), np.float32),
                       np.zeros((order + 1, *shape), np.float32),
                       np.zeros(shape, np.float32), np.zeros(shape, np.float32))


def stream_update(state: StreamState, frame: np.ndarray, count: int, steps: int, order: int,
                  shift_sign: int, phase_offset: float) -> bool:
    """Add frame ``count`` (0-based) of a stream to ``state``: its difference to the frame
    ``N`` before it (of the same shift) into the sums; once ``N`` frames are in, the
    window's phase and modulation into the rounds of pairwise means.

    Parameters
    ----------
    state : StreamState
        :func:`stream_state`'s buffers, updated.
    frame : numpy.ndarray
        ``(H, W)`` the next frame, of the state's type.
    count : int
        Frames added before this one.
    steps, order, shift_sign, phase_offset : int, int, int, float
        ``N``, ``K`` and the stream's conventions.

    Returns
    -------
    bool
        Whether ``state.phase`` and ``state.mod`` hold the newest window's compensated
        phase and modulation (``N + K`` frames in).

    Examples
    --------
    >>> state = stream_state((1, 2), 3, 0, np.float64)
    >>> [stream_update(state, np.float64([[v, 2 * v]]), i, 3, 0, 1, 0.0)
    ...  for i, v in enumerate((1.0, 2.0, 3.0))]
    [False, False, True]
    """
    slot = count % steps
    shift = np.float64(shift_sign * (2.0 * math.pi) * slot / steps)  # (stream_shifts)
    windows = max(count + 2 - steps, 0)  # windows complete with this frame
    hi, lo = offset_parts(phase_offset)
    _update(np.ascontiguousarray(frame, state.kept.dtype), state.kept, slot, count >= steps,
            float(np.sin(shift)), float(np.cos(shift)), state.num, state.den, windows, order,
            state.levels, state.mods, hi, lo, np.float32(2.0 / steps), state.phase,
            state.mod)
    return windows >= order + 1
