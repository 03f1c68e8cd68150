"""Compiled passes of the Gray code (:mod:`bistair.codecs.graycode`): the code bits read
against their inverses or the mid-level, and the orders from the Gray code words (bit for
bit the NumPy they replace).

Examples
--------
>>> import numpy as np
>>> code, edges, beyond = gray_orders(np.int32([[0, 1, 3, 2]]), np.zeros((1, 4), np.float32),
...                                   np.ones((1, 4), bool), 0, 4)
>>> code.tolist()
[[0, 1, 2, 3]]
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import _numba_inline, kernel, kernel_frames

prange = range  # numba's prange once the first kernel of this module compiles


@kernel()
def _code_bits(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
               inverse: bool) -> np.ndarray:
    _, h, w = raw.shape
    s32 = np.float32(scale)
    out = np.empty((h, w), np.int32)
    for y in range(h):
        for x in range(w):
            word = np.int32(0)
            for b in range(bits):
                v = np.float32(raw[start + b, y, x]) * s32
                ref = np.float32(raw[start + bits + b, y, x]) * s32 if inverse else avg[y, x]
                word = (word << 1) | (1 if v > ref else 0)
            out[y, x] = word
    return out



def code_bits(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
              inverse: bool = False) -> np.ndarray:
    """The code word of ``bits`` binary frames ``start ..`` of a raw capture stack (each
    value times ``scale`` its fraction of full scale), first frame the highest bit: a bit is
    set where the frame is brighter than ``avg``, or with ``inverse`` than its inverse
    frame (the ``bits`` frames that follow).

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    start : int
        Index of the first code frame.
    bits : int
        Number of code frames (at most 31).
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    avg : (H, W) float32 array
        The threshold without ``inverse`` (the fringes' average).
    inverse : bool
        Compare each frame with its inverse instead.

    Returns
    -------
    (H, W) int32 array
        The code word per pixel.

    Examples
    --------
    >>> raw = np.uint8([[[200, 10]], [[200, 200]], [[10, 10]]])
    >>> code_bits(raw, 0, 3, 1 / 255, np.float32([[0.5, 0.5]])).tolist()
    [[6, 2]]
    >>> code_bits(raw, 0, 1, 1 / 255, np.float32([[0.5, 0.5]]), inverse=True).tolist()
    [[0, 0]]
    """
    raw, start = kernel_frames(raw, start, 2 * bits if inverse else bits)
    return _code_bits(raw, start, int(bits), float(np.float32(scale)),
                      np.asarray(avg, np.float32), bool(inverse))



@kernel()
def _gray_orders(gray: np.ndarray, phi: np.ndarray, valid: np.ndarray, mode: int,
                 fringes: int) -> tuple[np.ndarray, np.ndarray, int]:
    h, w = gray.shape
    code = np.empty((h, w), np.int32)
    edges = np.empty((h, w), np.int32)
    beyond = np.zeros(h, np.int64)
    quarter = np.float32(0.5 * math.pi)
    half = np.float32(math.pi)
    three = np.float32(1.5 * math.pi)
    for y in range(h):
        out = 0
        for x in range(w):
            g = np.int32(gray[y, x])
            if mode == 1:  # complementary: the three-zone rule
                k1 = _binary(g >> 1)
                k2 = (_binary(g) + 1) // 2
                p = phi[y, x]
                k = k2 if p < quarter else (k2 - 1 if p >= three else k1)
                e = k1
            elif mode == 2:  # the code shifted by half a fringe
                e = _binary(g)
                k = e if phi[y, x] < half else e - 1
            else:
                e = _binary(g)
                k = e
            ok = valid[y, x]
            code[y, x] = k if ok and k >= 0 and k < fringes else -1
            edges[y, x] = e if ok else -1
            if ok and k >= fringes:
                out += 1
        beyond[y] = out
    return code, edges, beyond.sum()



@_numba_inline
def _binary(g: np.int32) -> np.int32:
    """Gray code to binary: the XOR of all the right shifts of ``g``."""
    shift = 1
    while shift < 32:
        g = g ^ (g >> shift)
        shift <<= 1
    return g



def gray_orders(gray: np.ndarray, phi: np.ndarray, valid: np.ndarray, mode: int,
                fringes: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Fringe orders from Gray code words, per pixel in one pass: the plain code
    (``mode`` 0), the complementary three-zone rule (1: the words carry one more bit) or
    the code shifted by half a fringe (2), as :func:`~bistair.codecs.graycode.code_columns`
    reads them.

    Parameters
    ----------
    gray : (H, W) int32 array
        The code words (non-negative).
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels to decode.
    mode : int
        0 plain, 1 complementary, 2 shifted by half a fringe.
    fringes : int
        Fringes across the projector (orders from 0 to ``fringes - 1``).

    Returns
    -------
    code : (H, W) int32 array
        The order, -1 where not valid or outside ``[0, fringes)``.
    edges : (H, W) int32 array
        The code whose steps mark the edges, -1 where not valid.
    beyond : int
        Valid pixels whose order is ``fringes`` or more.

    Examples
    --------
    >>> gray = np.int32([[0, 1, 3, 2]])
    >>> code, edges, beyond = gray_orders(gray, np.zeros((1, 4), np.float32),
    ...                                   np.ones((1, 4), bool), 0, 3)
    >>> code.tolist(), edges.tolist(), beyond
    ([[0, 1, 2, -1]], [[0, 1, 2, 3]], 1)
    """
    return _gray_orders(gray, np.asarray(phi, np.float32), np.asarray(valid, bool), int(mode),
                        int(fringes))


@kernel(parallel=True)
def alone_levels(raw: np.ndarray, bits: int, inverse: bool, scale: float, white: np.ndarray,
                 black: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mid-level and contrast of a Gray code capture without phase shifts, per pixel.

    With inverses (frames ``2i`` and ``2i+1`` a bit and its inverse): the mid-level is the
    mean over the bits of ``(pattern + inverse) / 2`` and the contrast the median over the
    bits of ``|pattern - inverse| / 2``; without, ``(white + black) / 2`` and
    ``(white - black) / 2`` (negative where black is the brighter).

    Parameters
    ----------
    raw : (F, H, W) array
        The code frames in method order, any dtype.
    bits : int
        Code bits.
    inverse : bool
        Each bit's frame is followed by its inverse.
    scale : float
        Multiplies a raw value into a fraction of full scale.
    white, black : (H, W) float32 arrays
        The white and black frames (fractions of full scale); empty arrays with inverses.

    Returns
    -------
    avg, mod : (H, W) float32 arrays

    Examples
    --------
    >>> raw = np.stack([np.full((1, 3), 200, np.uint8), np.full((1, 3), 40, np.uint8)])
    >>> avg, mod = alone_levels(raw, 1, True, 1 / 255, np.empty((0, 0), np.float32),
    ...                         np.empty((0, 0), np.float32))
    >>> avg.astype(float).round(4).tolist(), mod.astype(float).round(4).tolist()
    ([[0.4706, 0.4706, 0.4706]], [[0.3137, 0.3137, 0.3137]])
    """
    h, w = raw.shape[1], raw.shape[2]
    avg = np.empty((h, w), np.float32)
    mod = np.empty((h, w), np.float32)
    s = np.float32(scale)
    half = np.float32(0.5)
    for y in prange(h):
        diff = np.empty(max(bits, 1), np.float32)
        for x in range(w):
            if not inverse:
                avg[y, x] = (white[y, x] + black[y, x]) * half
                mod[y, x] = (white[y, x] - black[y, x]) * half
                continue
            total = np.float32(0.0)
            for i in range(bits):
                a = np.float32(raw[2 * i, y, x]) * s
                b = np.float32(raw[2 * i + 1, y, x]) * s
                total += a + b
                diff[i] = abs(a - b) * half
            avg[y, x] = total * half / np.float32(bits)
            mod[y, x] = np.median(diff[:bits])
    return avg, mod


@kernel(parallel=True)
def alone_cells(raw: np.ndarray, bits: int, inverse: bool, scale: float, mid: np.ndarray,
                valid: np.ndarray, clear: float) -> np.ndarray:
    """Each pixel's cell from a Gray code without phase shifts, -1 where not ``valid`` or a
    bit is not clear.

    A bit is 1 where its frame is brighter than its inverse (frames ``2i``, ``2i+1``) or,
    without inverses, than the mid-level ``mid``, and clear where the two differ by at least
    ``clear``; the bits, most significant first, form the Gray code word ``g`` of the cell
    ``c`` (``g = c ^ (c >> 1)``).

    Parameters
    ----------
    raw : (F, H, W) array
        The code frames in method order, any dtype.
    bits : int
        Code bits (at most 30).
    inverse : bool
        Each bit's frame is followed by its inverse.
    scale : float
        Multiplies a raw value into a fraction of full scale.
    mid : (H, W) float32 array
        The mid-level (without inverses).
    valid : (H, W) bool array
        Pixels with enough contrast.
    clear : float
        The least difference of a clear bit, fraction of full scale.

    Returns
    -------
    (H, W) int32 array

    Examples
    --------
    >>> cells = np.array([0, 1, 2, 3])
    >>> gray = cells ^ (cells >> 1)
    >>> raw = np.stack([((gray >> 1) & 1), 1 - ((gray >> 1) & 1), gray & 1,
    ...                 1 - (gray & 1)])[:, None, :].astype(np.float32)
    >>> alone_cells(raw, 2, True, 1.0, raw[0], np.ones((1, 4), bool), 0.1).tolist()
    [[0, 1, 2, 3]]
    """
    h, w = raw.shape[1], raw.shape[2]
    out = np.empty((h, w), np.int32)
    s = np.float32(scale)
    lim = np.float32(clear)
    step = 2 if inverse else 1
    for y in prange(h):
        for x in range(w):
            if not valid[y, x]:
                out[y, x] = -1
                continue
            g = 0
            ok = True
            for i in range(bits):
                a = np.float32(raw[step * i, y, x]) * s
                b = np.float32(raw[step * i + 1, y, x]) * s if inverse else mid[y, x]
                d = a - b
                if not abs(d) >= lim:
                    ok = False
                    break
                g = (g << 1) | (1 if d > 0 else 0)
            if not ok:
                out[y, x] = -1
                continue
            c = g
            shift = 1
            while shift < 32:
                c ^= c >> shift
                shift <<= 1
            out[y, x] = c
    return out
