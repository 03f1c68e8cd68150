"""Compiled passes of the wrapped phase (:mod:`bistair.core.phase`): the float32
arctangent every phase of a decode comes from, the phase and modulation of N-step sums, and
the wrap of angles.

**The arctangent** (:func:`_octant`, :func:`angle32`, :func:`phase32`; :func:`arctan2_32` on
arrays) is a float32 minimax polynomial after reduction to ``|u| <= tan(pi/8)``, written
with selects (its loops vectorise) in a fixed order of operations and compiled without
fastmath (numba's default here: no reassociation, no fused multiply-add; the decode's
kernels hold no ``fma`` instruction), so that a capture decodes to the same phases, bit for
bit, on every x86 machine whatever its vector units. NumPy's float32 ``arctan2`` does not
(on AVX-512 a third of its values are 1-3 units in the last place from the true angle,
without AVX-512 it is several times slower). Its error is under :data:`ATAN_ERROR`
(3.2e-7 rad, about half a unit in the last place of a phase near 2*pi): the phase is
composed as ``m*pi/4 - offset + t`` from exact parts and rounded once. Loops over chunks of
pixels run on every core (:func:`bistair.core.jit.set_threads`; each chunk writes only its
own outputs, so the results do not depend on the threads).

Examples
--------
>>> import numpy as np
>>> phi, mod = phase_of_sums32(np.float32([0.0, 3.0]), np.float32([4.0, -4.0]), 2)
>>> phi.astype(float).round(4).tolist(), mod.tolist()
([0.0, 2.4981], [4.0, 5.0])
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .jit import TWO_PI32, chunk_count, inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles
# atan(u) = u + u*s*P(s), s = u*u, on |u| <= tan(pi/8): a minimax fit (Lawson's iteration on
# the absolute error), 4.9e-9 rad from atan in exact arithmetic; in float32 here
_P0 = np.float32(-0.33332756763998145)
_P1 = np.float32(0.1997188267143458)
_P2 = np.float32(-0.13824488875543586)
_P3 = np.float32(0.07902710215562109)
_TAN_PI8 = np.float32(math.tan(math.pi / 8))
_QUANTUM = 2.0 ** -12  # pi/4, 2*pi and a phase offset split into a multiple of this and a rest
_PI4_HI = np.float32(round(math.pi / 4 / _QUANTUM) * _QUANTUM)
_PI4_LO = np.float32(math.pi / 4 - float(_PI4_HI))
_TWO_PI_HI = np.float32(8.0 * float(_PI4_HI))
_TWO_PI_LO = np.float32(2.0 * math.pi - float(_TWO_PI_HI))
ATAN_ERROR = 3.2e-7  # the largest error of phase32 and angle32 (radians), measured: see arctan2_32


@inline
def _octant(y: np.float32, x: np.float32) -> tuple[np.float32, np.float32]:
    """``(m, t)`` with ``atan2(y, x) = m*pi/4 + t`` for ``y >= 0`` (``m`` a whole number 0-4
    as float32, ``|t| <= pi/8``); the caller mirrors it for ``y < 0``. Float32, branch-free
    (selects: the loops over it vectorise), in a fixed order of operations."""
    ax = abs(x)
    ay = abs(y)
    steep = ay > ax
    hi = ay if steep else ax
    lo = ax if steep else ay
    # past tan(pi/8), atan(lo/hi) = pi/4 + atan((lo - hi) / (lo + hi))
    big = lo > _TAN_PI8 * hi
    num = lo - hi if big else lo
    den = lo + hi if big else hi
    den = den if den > np.float32(0.0) else np.float32(1.0)  # (0, 0): angle 0
    u = num / den
    s = u * u
    t = u + u * (s * (((_P3 * s + _P2) * s + _P1) * s + _P0))
    m = np.float32(1.0) if big else np.float32(0.0)
    m = np.float32(2.0) - m if steep else m  # pi/2 - angle
    t = -t if steep else t
    left = x < np.float32(0.0)
    m = np.float32(4.0) - m if left else m  # pi - angle
    t = -t if left else t
    return m, t


@inline
def angle32(y: np.float32, x: np.float32) -> np.float32:
    """``arctan2(y, x)`` in ``[-pi, pi]`` of finite float32 values, float32 (see
    :func:`arctan2_32`; ``atan2(-0.0, x < 0)`` is ``pi`` here): the angle the kernels of
    the stair pair and of the stair's noise use.

    Parameters
    ----------
    y, x : numpy.float32
        The sine and cosine parts.

    Returns
    -------
    numpy.float32
        The angle in radians.

    Examples
    --------
    >>> float(angle32(np.float32(1.0), np.float32(-1.0)))  # 3*pi/4 in float32
    2.356194496154785
    """
    m, t = _octant(y, x)
    below = y < np.float32(0.0)
    m = -m if below else m
    t = -t if below else t
    return m * _PI4_HI + (m * _PI4_LO + t)  # m * _PI4_HI is exact


@inline
def phase32(y: np.float32, x: np.float32, off_hi: np.float32, off_lo: np.float32
           ) -> np.float32:
    """The phase of ``(x, y)`` less a phase offset (``off_hi + off_lo``,
    :func:`offset_parts`), in ``[0, 2*pi)``, float32, one rounding at the end (see
    :func:`arctan2_32`): the wrapped phase of every pass that measures one.

    Parameters
    ----------
    y, x : numpy.float32
        The sine and cosine sums.
    off_hi, off_lo : numpy.float32
        The phase offset in two parts (:func:`offset_parts`).

    Returns
    -------
    numpy.float32
        The phase in ``[0, 2*pi)``.

    Examples
    --------
    >>> float(phase32(np.float32(-1.0), np.float32(0.0), *offset_parts(0.0)))  # 3*pi/2
    4.71238899230957
    """
    m, t = _octant(y, x)
    below = y < np.float32(0.0)
    m = np.float32(8.0) - m if below else m  # 2*pi - angle
    t = -t if below else t
    a = m * _PI4_HI - off_hi  # exact: both multiples of 2**-12 under 2**11
    b = (m * _PI4_LO - off_lo) + t
    r = a + b
    low = r < np.float32(0.0)
    high = r >= TWO_PI32
    a = a + _TWO_PI_HI if low else a  # (exact)
    b = b + _TWO_PI_LO if low else b
    a = a - _TWO_PI_HI if high else a
    b = b - _TWO_PI_LO if high else b
    r = a + b
    # a phase just short of 2*pi rounds to 2*pi (then below 0 once 2*pi is taken off): 0
    return r if (r >= np.float32(0.0) and r < TWO_PI32) else np.float32(0.0)


@inline
def hypot32(a: np.float32, b: np.float32) -> np.float32:
    """``hypot(a, b)`` of float32 values in float32: the square root of ``a*a + b*b``
    (correctly rounded; values of a capture neither overflow nor matter where they
    underflow).

    Parameters
    ----------
    a, b : numpy.float32
        Two sums.

    Returns
    -------
    numpy.float32
        The length of ``(a, b)``.

    Examples
    --------
    >>> float(hypot32(np.float32(3.0), np.float32(4.0)))
    5.0
    """
    return np.sqrt(a * a + b * b)


@inline
def quarter_turns(sin_w: np.ndarray, cos_w: np.ndarray) -> bool:
    """Four shifts a quarter turn apart (:func:`shift_weights` of N = 4): weights 0 where
    :func:`quarter_sums` leaves them out.

    Parameters
    ----------
    sin_w, cos_w : (N,) float32 array
        The weights of :func:`shift_weights`.

    Returns
    -------
    bool
        :func:`quarter_sums` gives their sums.

    Examples
    --------
    >>> bool(quarter_turns(*shift_weights(4))), bool(quarter_turns(*shift_weights(3)))
    (True, False)
    """
    return (sin_w.size == 4 and sin_w[0] == 0 and sin_w[2] == 0 and cos_w[1] == 0
            and cos_w[3] == 0)


@inline
def quarter_sums(v0: Any, v1: Any, v2: Any, v3: Any, scale: np.float32,
                  sin_w: np.ndarray, cos_w: np.ndarray
                  ) -> tuple[np.float32, np.float32, np.float32]:
    """``(num, den, avg)`` of a pixel's four quarter-turn frames (raw values times
    ``scale``): ``-(s1*f1 + s3*f3)``, ``c0*f0 + c2*f2`` and the mean, float32; what the
    frame-by-frame sums over all four weights give (the others are 0), in fewer
    operations.

    Parameters
    ----------
    v0, v1, v2, v3 : number
        The pixel's raw values in the four frames.
    scale : numpy.float32
        Raw value to intensity.
    sin_w, cos_w : (4,) float32 array
        The weights (:func:`quarter_turns` of them is true).

    Returns
    -------
    tuple of numpy.float32
        ``(num, den, avg)``.

    Examples
    --------
    >>> s = quarter_sums(2, 3, 0, 1, np.float32(1.0), *shift_weights(4))
    >>> [float(v) for v in s]
    [-2.0, 2.0, 1.5]
    """
    f0 = np.float32(v0) * scale
    f1 = np.float32(v1) * scale
    f2 = np.float32(v2) * scale
    f3 = np.float32(v3) * scale
    num = -(sin_w[1] * f1 + sin_w[3] * f3)
    den = cos_w[0] * f0 + cos_w[2] * f2
    return num, den, (((f0 + f1) + f2) + f3) * np.float32(0.25)


def shift_weights(steps: int, shift_sign: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Sine and cosine of each frame's phase shift ``shift_sign*2*pi*n/steps``, float32,
    those within 1e-12 of 0 or of 1 in size made exactly so (``sin(pi)`` is 0, not 1.2e-16):
    the weights of the N-step sums.

    Parameters
    ----------
    steps : int
        Number of frames ``N``.
    shift_sign : int
        +1 or -1.

    Returns
    -------
    sin_w, cos_w : (N,) float32 arrays

    Examples
    --------
    >>> [w.tolist() for w in shift_weights(4, -1)]
    [[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, -1.0, 0.0]]
    """
    d = shift_sign * 2.0 * math.pi * np.arange(steps) / steps
    out = []
    for w in (np.sin(d), np.cos(d)):
        near = np.round(w)
        out.append(np.where(np.abs(w - near) < 1e-12, near, w).astype(np.float32) + 0.0)
    return out[0], out[1]


def offset_parts(offset: float) -> tuple[np.float32, np.float32]:
    """A phase offset as the two float32 parts the compiled phase subtracts: the offset
    modulo 2*pi, rounded to a multiple of 2**-12, and the rest.

    Parameters
    ----------
    offset : float
        Radians, finite.

    Returns
    -------
    (hi, lo) : tuple of numpy.float32
        ``hi + lo`` is the offset in ``[0, 2*pi)`` to float32's precision of ``lo``.

    Examples
    --------
    >>> hi, lo = offset_parts(-np.pi / 2)
    >>> float(hi) * 4096 % 1, round(float(hi) + float(lo), 6)
    (0.0, 4.712389)
    """
    wrapped = float(offset) % (2.0 * math.pi)
    hi = round(wrapped / _QUANTUM) * _QUANTUM
    return np.float32(hi), np.float32(wrapped - hi)


def arctan2_32(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``np.arctan2`` of float32 arrays, as the decode computes its phases: a float32
    minimax polynomial after reduction to ``|u| <= tan(pi/8)``, in a fixed order of
    operations, compiled without fastmath (no reassociation, no fused multiply-add), so
    the same bits on every x86 machine whatever its vector units, in one pass on every core.

    Error against float64 ``np.arctan2``: under :data:`ATAN_ERROR` (3.2e-7 rad; measured
    2.8e-7 on every pair of whole numbers in [-512, 512] and 3.0e-7 on 4 million random
    pairs over five decades, offsets included; 0.5-0.65 units in the last place of
    ``[4, 2*pi)``); 92-95% of the angles are the correctly rounded ones. Finite values
    only (``arctan2(0, 0) = 0``; ``atan2(-0.0, x < 0)`` is ``pi``, not ``-pi``).

    Parameters
    ----------
    y, x : float32 arrays
        Of one shape, finite.

    Returns
    -------
    float32 array
        The angle of ``(x, y)`` in ``[-pi, pi]``, of their shape.

    Examples
    --------
    >>> arctan2_32(np.float32([0.0, 1.0, -1.0, 0.0]), np.float32([1.0, 1.0, -1.0, -1.0])
    ...            ).astype(float).round(6).tolist()
    [0.0, 0.785398, -2.356194, 3.141593]
    """
    yf = np.ascontiguousarray(y, np.float32).reshape(-1)
    out = arctan2_flat(yf, np.ascontiguousarray(x, np.float32).reshape(-1))
    return out.reshape(np.shape(y))


@kernel(parallel=True)
def arctan2_flat(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The pass of :func:`arctan2_32`: :func:`angle32` of each pair, over flat arrays.

    Parameters
    ----------
    y, x : (n,) float32 array
        Contiguous, the same size.

    Returns
    -------
    (n,) float32 array
        The angles in radians.

    Examples
    --------
    >>> arctan2_flat(np.float32([0.0, 1.0]), np.float32([1.0, 0.0])).tolist()
    [0.0, 1.5707963705062866]
    """
    out = np.empty(y.size, np.float32)
    for i in prange(y.size):  # (one flat loop: numba vectorises it)
        out[i] = angle32(y[i], x[i])
    return out


@kernel(parallel=True)
def _phase_of_sums(num: np.ndarray, den: np.ndarray, off_hi: np.float32, off_lo: np.float32,
                   scale: np.float32, chunks: int) -> tuple[np.ndarray, np.ndarray]:
    n = num.size
    phi = np.empty(n, np.float32)
    mod = np.empty(n, np.float32)
    for c in prange(chunks):
        for i in range(c * n // chunks, (c + 1) * n // chunks):
            a = num[i]
            b = den[i]
            phi[i] = phase32(a, b, off_hi, off_lo)
            mod[i] = hypot32(a, b) * scale
    return phi, mod


def phase_of_sums32(num: np.ndarray, den: np.ndarray, steps: int, phase_offset: float = 0.0
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The wrapped phase ``atan2(num, den) - phase_offset`` in ``[0, 2*pi)`` and the
    modulation ``2/N * hypot(num, den)`` of N-step sums, float32, in one pass: the
    arithmetic of the decode's own pass (:func:`bistair.core.measure_jit.front_end`).

    Parameters
    ----------
    num, den : float32 arrays
        ``-sum I_n sin d_n`` and ``sum I_n cos d_n``, of one shape.
    steps : int
        Number of frames ``N`` the sums are over.
    phase_offset : float
        Radians subtracted from the phase.

    Returns
    -------
    phi, mod : float32 arrays
        Of ``num``'s shape.

    Examples
    --------
    >>> phi, mod = phase_of_sums32(np.float32([[-1.0, 1.0]]), np.float32([[-1.0, 0.0]]), 4)
    >>> phi.astype(float).round(4).tolist(), mod.astype(float).round(4).tolist()
    ([[3.927, 1.5708]], [[0.7071, 0.5]])
    """
    a = np.ascontiguousarray(num, np.float32).reshape(-1)
    hi, lo = offset_parts(phase_offset)
    phi, mod = _phase_of_sums(a, np.ascontiguousarray(den, np.float32).reshape(-1), hi, lo,
                              np.float32(2.0 / steps), chunk_count(a.size))
    return phi.reshape(np.shape(num)), mod.reshape(np.shape(num))


@kernel(parallel=True)
def _wrap(a: np.ndarray, pi: float, two_pi: float, chunks: int) -> np.ndarray:
    n = a.size
    out = np.empty_like(a)
    for c in prange(chunks):
        lo = c * n // chunks
        hi = (c + 1) * n // chunks
        far = 0
        for i in range(lo, hi):  # branch-free: NumPy's remainder where it is one exact
            d = a[i] + pi  # subtraction (Sterbenz, d in [2pi, 4pi)) or one rounded addition
            m = d - two_pi if d >= two_pi else d
            m = m + two_pi if d < 0 else m
            far += not (d >= -two_pi and d < two_pi + two_pi)  # also NaN
            out[i] = m - pi
        if far:
            for i in range(lo, hi):  # NumPy's own rule further out
                d = a[i] + pi
                if not (d >= -two_pi and d < two_pi + two_pi):
                    out[i] = d % two_pi - pi
    return out


def wrap_angles(angle: np.ndarray) -> np.ndarray:
    """``(angle + pi) % (2*pi) - pi`` of a float32 or float64 array, as NumPy computes it
    (in the array's precision), in one pass.

    Parameters
    ----------
    angle : float32 or float64 array
        Angles in radians, any shape.

    Returns
    -------
    ndarray
        The angles wrapped into ``[-pi, pi)``, of ``angle``'s shape and dtype.

    Examples
    --------
    >>> wrap_angles(np.array([0.5, 4.0, -4.0, np.pi, 20.0])).round(4).tolist()
    [0.5, -2.2832, 2.2832, -3.1416, 1.1504]
    """
    flat = np.ascontiguousarray(angle).reshape(-1)
    kind = flat.dtype.type
    out = _wrap(flat, kind(math.pi), kind(2.0 * math.pi), chunk_count(flat.size))
    return out.reshape(np.shape(angle))
