"""Compiled passes of the wrapped phase (:mod:`bistair.core.phase`): the arctangent, the
N-step sums and the phase's last pass.

Every pass gives, bit for bit, what the NumPy expression it replaces gives (the same float32
or float64 operations in the same order), without the temporaries. The arctangent is the one
exception: NumPy's float32 ``arctan2`` rounds differently from machine to machine (on
AVX-512 a third of its values are 1-3 units in the last place from the true angle, without
AVX-512 it is several times slower), so the phases come from :func:`arctan2_32`, the
correctly rounded angle on every machine. Loops over chunks of pixels run on every core
(:func:`bistair.core.jit.set_threads`; each chunk writes only its own outputs, so the
results do not depend on the threads).

Examples
--------
>>> import numpy as np
>>> num, den = np.float32([0.0, 3.0]), np.float32([4.0, -4.0])
>>> phi = np.arctan2(num, den)
>>> mod = finish_phase(phi, num, den, 2)  # phi is made [0, 2*pi) in place
>>> phi.astype(float).round(4).tolist(), mod.tolist()
([0.0, 2.4981], [4.0, 5.0])
"""

from __future__ import annotations

import math

import numpy as np

from .jit import TWO_PI32, _numba_inline, chunk_count, kernel, kernel_frames

prange = range  # numba's prange once the first kernel of this module compiles
# atan(u) / u = P(u^2) on |u| <= tan(pi/8): a Chebyshev fit, relative error 2.6e-14
_ATAN = (0.9999999999999744, -0.3333333333087206, 0.1999999961323299,
         -0.1428569081054061, 0.11110393860558447, -0.09078501279416004,
         0.07564453629534063, -0.05877189674091674, 0.030701474337983595)


@_numba_inline
def _atan2(y: np.float32, x: np.float32) -> np.float32:
    """``arctan2(y, x)`` of float32 values, in float64 (relative error under 3e-14) and
    rounded once to float32: the correctly rounded angle unless it lies within 3e-14 of a
    float32 rounding boundary, with ``arctan2``'s signs of zero (``atan2(+-0, -0) =
    +-pi``), infinities and NaN. Branch-free (the loops over it vectorise)."""
    ax = abs(np.float64(x))
    ay = abs(np.float64(y))
    both = ax == math.inf and ay == math.inf  # the diagonal: pi/4 and its reflections
    ax = 1.0 if both else ax
    ay = 1.0 if both else ay
    steep = ay > ax
    hi = ay if steep else ax
    lo = ax if steep else ay
    # t = lo / hi in [0, 1]; past tan(pi/8), atan(t) = pi/4 + atan((lo - hi) / (lo + hi))
    big = lo > 0.41421356237309503 * hi
    u = (lo - hi if big else lo) / (lo + hi if big else (hi if hi > 0.0 else 1.0))
    w = u * u
    p = (((((((_ATAN[8] * w + _ATAN[7]) * w + _ATAN[6]) * w + _ATAN[5]) * w + _ATAN[4]) * w
           + _ATAN[3]) * w + _ATAN[2]) * w + _ATAN[1]) * w + _ATAN[0]
    r = (math.pi / 4 if big else 0.0) + u * p
    r = math.pi / 2 - r if steep else r
    r = math.pi - r if math.copysign(1.0, np.float64(x)) < 0.0 else r  # also x = -0
    r = np.nan if (x != x or y != y) else r
    return np.float32(math.copysign(r, np.float64(y)))


def arctan2_32(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``np.arctan2`` of float32 arrays, in one compiled pass on every core: the correctly
    rounded float32 arctangent (computed in float64 to 3e-14; it matched float64
    ``arctan2`` rounded once on all of 4 million random pairs). NumPy's own float32
    ``arctan2`` differs between machines (a vectorised one with AVX-512, a third of its
    values 1-3 units in the last place off; the C library's without, several times
    slower); this one does not.

    Parameters
    ----------
    y, x : float32 arrays
        Of one shape.

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
    out = _arctan2(yf, np.ascontiguousarray(x, np.float32).reshape(-1))
    return out.reshape(np.shape(y))


@kernel(parallel=True)
def _arctan2(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    out = np.empty(y.size, np.float32)
    for i in prange(y.size):  # (one flat loop: numba vectorises it)
        out[i] = _atan2(y[i], x[i])
    return out


@kernel(parallel=True)
def _finish_phase(phi: np.ndarray, num: np.ndarray, den: np.ndarray, scale: float,
                  chunks: int) -> np.ndarray:
    n = phi.size
    mod = np.empty(n, np.float32)
    s32 = np.float32(scale)
    zero = np.float32(0.0)
    for c in prange(chunks):
        lo = c * n // chunks
        hi = (c + 1) * n // chunks
        for i in range(lo, hi):
            p = phi[i]
            if p < zero:
                p = p + TWO_PI32
            if p >= TWO_PI32:
                p = zero
            phi[i] = p
            a = np.float64(num[i])
            b = np.float64(den[i])
            # hypotf as glibc computes it: the double square root, rounded once
            mod[i] = np.float32(math.sqrt(a * a + b * b)) * s32
    return mod


def finish_phase(phi: np.ndarray, num: np.ndarray, den: np.ndarray, steps: int) -> np.ndarray:
    """Bring an ``arctan2`` phase into ``[0, 2*pi)`` in place and return the modulation
    ``2/N * hypot(num, den)``, in one pass (float32, as NumPy rounds them).

    Parameters
    ----------
    phi : float32 array
        ``arctan2(num, den)`` (possibly less a phase offset), contiguous; changed in place.
    num, den : float32 arrays
        The N-step sums, of ``phi``'s shape.
    steps : int
        Number of frames ``N`` the sums are over.

    Returns
    -------
    float32 array
        The modulation, of ``phi``'s shape.

    Examples
    --------
    >>> num, den = np.float32([[-1.0, 1.0]]), np.float32([[-1.0, 0.0]])
    >>> phi = np.arctan2(num, den)
    >>> mod = finish_phase(phi, num, den, 4)
    >>> mod.astype(float).round(4).tolist(), phi.astype(float).round(4).tolist()
    ([[0.7071, 0.5]], [[3.927, 1.5708]])
    """
    flat = phi.reshape(-1)
    mod = _finish_phase(flat, np.ascontiguousarray(num, np.float32).reshape(-1),
                        np.ascontiguousarray(den, np.float32).reshape(-1),
                        float(np.float32(2.0 / steps)), chunk_count(flat.size))
    return mod.reshape(phi.shape)


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


@kernel(parallel=True)
def _nstep_sums(raw: np.ndarray, start: int, steps: int, scale: float, sin_w: np.ndarray,
                cos_w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    _, h, w = raw.shape
    s32 = np.float32(scale)
    n32 = np.float32(steps)
    zero = np.float32(0.0)
    num = np.empty((h, w), np.float32)
    den = np.empty((h, w), np.float32)
    avg = np.empty((h, w), np.float32)
    for y in prange(h):
        s = num[y]
        c = den[y]
        t = avg[y]
        for x in range(w):
            s[x] = zero
            c[x] = zero
            t[x] = zero
        for n in range(steps):  # frame by frame along the row: the loop over x vectorises
            sw = sin_w[n]
            cw = cos_w[n]
            row = raw[start + n, y]
            for x in range(w):
                f = np.float32(row[x]) * s32
                s[x] += sw * f
                c[x] += cw * f
                t[x] += f
        for x in range(w):
            s[x] = -s[x]
            t[x] = t[x] / n32
    return num, den, avg


def nstep_sums(raw: np.ndarray, start: int, steps: int, scale: float, sin_w: np.ndarray,
               cos_w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(num, den, avg)`` of frames ``start .. start+steps-1`` of a raw capture stack (each
    value times ``scale`` is its fraction of full scale), float32, summed in frame order as
    :func:`bistair.core.phase.wrapped_phase` sums them; the frames are the outer loop of each
    row, so that the loop along the row vectorises.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype, C-contiguous.
    start : int
        Index of the set's first frame.
    steps : int
        Number of frames ``N`` of the set.
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    sin_w, cos_w : (N,) float32 arrays
        Sine and cosine of each frame's phase shift.

    Returns
    -------
    num, den, avg : (H, W) float32 arrays
        ``-sum sin_w[n] I_n``, ``sum cos_w[n] I_n`` and the average intensity.

    Examples
    --------
    >>> raw = np.uint8([[[255, 0]], [[0, 255]], [[0, 0]], [[255, 255]]])
    >>> d = 2 * np.pi * np.arange(4) / 4
    >>> sums = nstep_sums(raw, 0, 4, 1 / 255, np.sin(d).astype(np.float32),
    ...                   np.cos(d).astype(np.float32))
    >>> [(a.astype(float).round(3) + 0.0).tolist() for a in sums]
    [[[1.0, 0.0]], [[1.0, 0.0]], [[0.5, 0.5]]]
    """
    raw, start = kernel_frames(raw, start, steps)
    return _nstep_sums(raw, start, int(steps), float(np.float32(scale)),
                       np.asarray(sin_w, np.float32), np.asarray(cos_w, np.float32))
