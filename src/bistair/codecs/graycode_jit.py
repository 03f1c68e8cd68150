"""Compiled passes of the Gray code (:mod:`bistair.codecs.graycode`): the code bits read
against their inverses or the mid-level (bit for bit the NumPy they replace), the orders
from them with the evidence of each pixel's order (:func:`read_orders`), and the Gray code
without phase shifts.

Examples
--------
>>> import numpy as np
>>> raw = np.float32([[[0.1, 0.1, 0.9, 0.9]], [[0.1, 0.9, 0.9, 0.1]]])  # cells 0, 1, 2, 3
>>> code, edges, carried, beyond = read_orders(
...     raw, 0, 2, 1.0, np.full((1, 4), 0.5, np.float32), False, np.full((1, 4), 3.0, np.float32),
...     np.full((1, 4), 0.4, np.float32), np.ones((1, 4), bool), 0, 4, 0.01, 0.01, 3.0, 0.5, 0.5)
>>> code.tolist(), carried.tolist()
([[0, 1, 2, 3]], [[True, True, True, True]])
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import called, inline, kernel, kernel_frames

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


@inline
def _binary(g: np.int32) -> np.int32:
    """Gray code to binary: the XOR of all the right shifts of ``g``."""
    shift = 1
    while shift < 32:
        g = g ^ (g >> shift)
        shift <<= 1
    return g


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


MAX_UNCLEAR = 5  # more unclear bits than this: the pixel is left out
QUARTER32 = np.float32(0.5 * math.pi)
HALF32 = np.float32(math.pi)
THREE32 = np.float32(1.5 * math.pi)


@inline
def _order_of(g: np.int64, p: np.float32, mode: int, fringes: int
              ) -> tuple[np.int64, np.int64]:
    """The order the code word ``g`` gives at wrapped phase ``p`` (the rule of ``mode``)
    and the code whose steps mark the edges."""
    if mode == 1:  # complementary: the three-zone rule
        k1 = _binary(g >> 1)
        k2 = (_binary(g) + 1) // 2
        return (k2 if p < QUARTER32 else (k2 - 1 if p >= THREE32 else k1)), k1
    e = _binary(g)
    if mode == 2:  # the code shifted by half a fringe
        return (e if p < HALF32 else e - 1), e
    if mode == 3:  # shifted and cyclic: code 0 past the phase's middle is the last fringe
        if e >= fringes:
            return np.int64(fringes), e
        return (e if p < HALF32 else (e - 1 if e > 0 else np.int64(fringes - 1))), e
    return e, e


@called
def _fits(d: np.ndarray, g: np.int64, p: np.float32, mod: float, mode: int, fringes: int,
          inverse: bool, noise_d: float, phase_noise: float, z: float, share: float,
          reach: float, target: np.int64, alone: bool) -> bool:
    """Whether order ``target`` fits the evidence of a pixel whose code reads ``g`` (bit
    margins ``d``) at wrapped phase ``p`` and, with ``alone``, is the only order that does
    and has the phase at the end of its code cell the edge bits say (see
    :func:`read_orders`)."""
    bits = d.shape[0]
    # the pixel's code contrast: its strongest bit's margin (of each sign without inverses,
    # whose threshold, the fringes' average, need not sit midway between dark and bright)
    c_pos = 0.0
    c_neg = 0.0
    for b in range(bits):
        if d[b] > 0:
            c_pos = max(c_pos, np.float64(d[b]))
        else:
            c_neg = max(c_neg, -np.float64(d[b]))
    if inverse:
        c_pos = c_neg = max(c_pos, c_neg)
    elif c_pos == 0:
        c_pos = c_neg
    elif c_neg == 0:
        c_neg = c_pos
    # the unclear bits (LSB = bit 0): those that do not clear their noise or that read
    # under `share` of the pixel's contrast (`faint`); a bit read on the wrong side away
    # from its edge is `possible` only where noise could have made up its contrast and more
    unclear = 0
    faint = 0
    possible = 0
    n_unclear = 0
    for b in range(bits):
        c = c_pos if d[b] > 0 else c_neg
        m = abs(d[b])
        bit = 1 << (bits - 1 - b)
        if not m > share * c:
            faint |= bit
        if not m > max(z * noise_d, share * c):
            unclear |= bit
            n_unclear += 1
            if not c + m > z * noise_d:
                possible |= bit
    if n_unclear > MAX_UNCLEAR or not mod > 0:
        return False
    sigma = phase_noise / mod  # the wrapped phase's noise, radians
    unit = 2.0 if mode == 1 else 1.0  # code cells per fringe
    shift = 0.5 if mode >= 2 else 0.0  # the code's cells start half a fringe later
    slack = z * sigma / (2.0 * math.pi)  # in fringes
    limit = (reach + slack) * unit
    frac = np.float64(p) / (2.0 * math.pi)
    found = False
    flips = unclear
    while True:  # every reading of the unclear bits: the order it gives, if it fits
        k, _ = _order_of(g ^ flips, p, mode, fringes)
        if k >= 0 and k < fringes:
            u = unit * (k + frac) + shift  # the pixel's place in code cells
            if mode == 3 and u >= fringes:  # past the wrap (u < fringes + 1/2)
                u -= fringes
            fits = True
            for b in range(bits):
                if not (unclear >> b) & 1:
                    continue
                if _edge_distance(u, b, mode, fringes) <= limit:
                    continue  # beside its edge: a bit may read anything
                # away from its edge: a flipped bit only where noise could flip it, a
                # faint one not at all
                if ((flips >> b) & 1 and not (possible >> b) & 1) or (
                        not (flips >> b) & 1 and (faint >> b) & 1):
                    fits = False
                    break
            if fits:
                if k == target:
                    found = True
                elif alone:
                    return False  # two orders fit the evidence
        if flips == 0:
            break
        flips = (flips - 1) & unclear
    if not found:
        return False
    if mode == 1 or not alone:
        return True
    # beside a code edge at the phase's wrap: the weaker edge bit must be on the phase's side
    cell = frac if mode == 0 else (frac + 0.5) % 1.0
    if not (cell < slack or cell > 1.0 - slack):
        return True
    level = _binary(g)
    low = _edge_margin(d, level, c_pos, c_neg) if level > 0 else -1.0
    high = _edge_margin(d, level + 1, c_pos, c_neg)
    if mode == 3 and fringes == 1 << bits:  # the cyclic code's wrap: its top bit's edge
        if level == 0:
            low = _edge_margin(d, np.int64(1 << (bits - 1)), c_pos, c_neg)
        if level == fringes - 1:
            high = _edge_margin(d, np.int64(1 << (bits - 1)), c_pos, c_neg)
    if low < 0 or high < 0:
        return True  # a cell at the end of the code: one edge only
    if cell > 1.0 - slack and high > low:
        return False
    if cell < slack and low > high:
        return False
    return True


@inline
def _edge_distance(u: float, b: int, mode: int, fringes: int) -> float:
    """How far, in code cells, place ``u`` lies from the nearest edge of bit ``b`` (LSB 0):
    the Gray code's bit ``b`` steps at the odd multiples of ``2**b``; the cyclic code's
    (``mode`` 3) also at its wrap, ``0 = fringes``, where the last level's code has it set."""
    span = np.float64(1 << b)
    r = (u / span - 1.0) % 2.0
    dist = span * min(r, 2.0 - r)
    if mode == 3:
        last = fringes - 1
        if ((last ^ (last >> 1)) >> b) & 1:
            dist = min(dist, u, fringes - u)
    return dist


@inline
def _edge_margin(d: np.ndarray, level: np.int64, c_pos: float, c_neg: float) -> float:
    """The margin, as a share of the pixel's contrast, of the bit whose edge lies between
    code cells ``level - 1`` and ``level`` (-1 if the code has no such bit)."""
    bits = d.shape[0]
    b = 0
    while b < bits and not (level >> b) & 1:
        b += 1
    if b >= bits:
        return -1.0
    v = d[bits - 1 - b]
    c = c_pos if v > 0 else c_neg
    return abs(v) / c if c > 0 else 0.0


@kernel(parallel=True)
def _read_orders(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
                 inverse: bool, phi: np.ndarray, mod: np.ndarray, valid: np.ndarray,
                 mode: int, fringes: int, noise_d: float, phase_noise: float, z: float,
                 share: float, reach: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    _, h, w = raw.shape
    code = np.empty((h, w), np.int32)
    edges = np.empty((h, w), np.int32)
    carried = np.empty((h, w), np.bool_)
    beyond = np.zeros(h, np.int64)
    s32 = np.float32(scale)
    for y in prange(h):
        d = np.empty(bits, np.float32)
        out = 0
        for x in range(w):
            g = np.int64(0)
            for b in range(bits):
                v = np.float32(raw[start + b, y, x]) * s32
                ref = np.float32(raw[start + bits + b, y, x]) * s32 if inverse else avg[y, x]
                d[b] = v - ref
                g = (g << 1) | (1 if v > ref else 0)
            p = phi[y, x]
            k, e = _order_of(g, p, mode, fringes)
            ok = valid[y, x]
            inside = ok and k >= 0 and k < fringes
            code[y, x] = k if inside else -1
            edges[y, x] = e if ok else -1
            if ok and k >= fringes:
                out += 1
            carried[y, x] = inside and _fits(d, g, p, mod[y, x], mode, fringes, inverse,
                                             noise_d, phase_noise, z, share, reach, k, True)
        beyond[y] = out
    return code, edges, carried, beyond.sum()


def read_orders(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
                inverse: bool, phi: np.ndarray, mod: np.ndarray, valid: np.ndarray,
                mode: int, fringes: int, noise_d: float, phase_noise: float, z: float,
                share: float, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The Gray code read per pixel in one pass: the code word of ``bits`` frames from
    ``start`` (a bit is set where its frame is brighter than its inverse, the ``bits``
    frames after them, or without ``inverse`` than ``avg``), its order by the rule of
    ``mode`` (plain, complementary or shifted, as
    :func:`~bistair.codecs.graycode.code_columns` reads them), and whether the pixel's own
    evidence carries that order.

    The evidence of a pixel: each bit's margin ``d`` (frame minus inverse, or minus
    ``avg``), the pixel's code contrast ``c`` (the largest ``|d|`` of its bits; without
    inverses, of the bits of each sign apart, since the fringes' average need not sit
    midway between a code frame's dark and bright) and its wrapped phase ``phi`` with noise
    ``sigma = phase_noise / mod``. A bit is unclear where ``|d|`` is at most
    ``max(z * noise_d, share * c)``: it does not clear the noise of its difference, or it
    reads under ``share`` of the contrast, which a bit does only beside its own edge (under
    a blur that leaves the fringes any contrast, a bit half a period from its edge reads
    over 0.8 of it) or where light other than the pattern's reaches the pixel. Each reading
    of the unclear bits (at most three; more and the pixel is left out) gives an order,
    and with the phase a place in the code's cells; a reading fits where every unclear
    bit's edge lies within ``reach`` fringes (plus ``z * sigma``) of that place. The order
    is carried where the readings that fit give one order, the one read. Where the code's
    edges sit on the phase's wrap (plain, ``mode`` 0) or half a fringe off it (2) and the
    phase lies within ``z * sigma`` of that edge, the phase cannot tell the cell's two ends
    apart: the bit of the edge at the phase's end must then read no stronger (as a share
    of the contrast) than the bit of the other end.

    Parameters
    ----------
    raw : (F, H, W) array
        The capture stack, any numeric dtype.
    start : int
        Index of the first code frame.
    bits : int
        Number of code frames (at most 30).
    scale : float
        Factor that turns a raw value into a fraction of full scale.
    avg : (H, W) float32 array
        The threshold without ``inverse`` (the fringes' average).
    inverse : bool
        Compare each frame with its inverse instead.
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    mod : (H, W) float32 array
        The fringes' modulation (fraction of full scale).
    valid : (H, W) bool array
        Pixels to decode.
    mode : int
        0 plain, 1 complementary, 2 shifted by half a fringe, 3 shifted and cyclic (code 0
        past the phase's middle is fringe ``fringes - 1``).
    fringes : int
        Fringes across the projector (orders from 0 to ``fringes - 1``).
    noise_d : float
        The noise sigma of a bit's margin ``d`` (fraction of full scale).
    phase_noise : float
        The phase noise times the modulation (``noise / sqrt(N / 2)``).
    z : float
        How many sigmas a margin, or the phase, must clear.
    share : float
        The share of the pixel's contrast a bit away from its edge reads at least.
    reach : float
        How far from its edge, in fringes, an unclear bit may be.

    Returns
    -------
    code : (H, W) int32 array
        The order as read, -1 where not valid or outside ``[0, fringes)``.
    edges : (H, W) int32 array
        The code whose steps mark the edges, -1 where not valid.
    carried : (H, W) bool array
        Where the pixel's evidence carries its order.
    beyond : int
        Valid pixels whose order is ``fringes`` or more.

    Examples
    --------
    >>> cells = np.arange(8)
    >>> gray = cells ^ (cells >> 1)
    >>> bright = np.stack([(gray >> b) & 1 for b in (2, 1, 0)])[:, None, :] * 0.8 + 0.1
    >>> raw = np.concatenate([bright, 1 - bright]).astype(np.float32)
    >>> phi = np.full((1, 8), 2.0, np.float32)
    >>> out = read_orders(raw, 0, 3, 1.0, phi, True, phi, np.full((1, 8), 0.3, np.float32),
    ...                   np.ones((1, 8), bool), 0, 8, 0.01, 0.01, 3.0, 0.5, 0.5)
    >>> out[0].tolist(), bool(out[2].all())
    ([[0, 1, 2, 3, 4, 5, 6, 7]], True)
    >>> raw[2, 0, 5] = raw[5, 0, 5] = 0.5  # cell 5's last bit reads nothing, so 0: cell 4,
    >>> read_orders(raw, 0, 3, 1.0, phi, True, phi, np.full((1, 8), 0.3, np.float32),
    ...             np.ones((1, 8), bool), 0, 8, 0.01, 0.01, 3.0, 0.5, 0.5)[2].tolist()
    [[True, True, True, True, True, False, True, True]]

    where the phase puts the pixel too far from that bit's edge: it is left out.
    """
    raw, start = kernel_frames(raw, start, 2 * bits if inverse else bits)
    return _read_orders(raw, start, int(bits), float(np.float32(scale)),
                        np.asarray(avg, np.float32), bool(inverse),
                        np.asarray(phi, np.float32), np.asarray(mod, np.float32),
                        np.asarray(valid, bool), int(mode), int(fringes), float(noise_d),
                        float(phase_noise), float(z), float(share), float(reach))


@kernel(parallel=True)
def _orders_fit(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
                inverse: bool, phi: np.ndarray, mod: np.ndarray, order: np.ndarray,
                mode: int, fringes: int, noise_d: float, phase_noise: float, z: float,
                share: float, reach: float) -> np.ndarray:
    _, h, w = raw.shape
    out = np.zeros((h, w), np.bool_)
    s32 = np.float32(scale)
    for y in prange(h):
        d = np.empty(bits, np.float32)
        for x in range(w):
            if order[y, x] < 0:
                continue
            g = np.int64(0)
            for b in range(bits):
                v = np.float32(raw[start + b, y, x]) * s32
                ref = np.float32(raw[start + bits + b, y, x]) * s32 if inverse else avg[y, x]
                d[b] = v - ref
                g = (g << 1) | (1 if v > ref else 0)
            out[y, x] = _fits(d, g, phi[y, x], mod[y, x], mode, fringes, inverse, noise_d,
                              phase_noise, z, share, reach, np.int64(order[y, x]), False)
    return out


def orders_fit(raw: np.ndarray, start: int, bits: int, scale: float, avg: np.ndarray,
               inverse: bool, phi: np.ndarray, mod: np.ndarray, order: np.ndarray, mode: int,
               fringes: int, noise_d: float, phase_noise: float, z: float, share: float,
               reach: float) -> np.ndarray:
    """Where a given order fits the evidence of the Gray code read from ``bits`` frames
    from ``start`` (the reading of :func:`read_orders`, whose arguments these are): some
    reading of the unclear bits gives it, every unclear bit's edge within ``reach``
    fringes, each faint one's only so. Other orders may fit as well (another measurement,
    such as a second period's phase, chose among them).

    Parameters
    ----------
    raw, start, bits, scale, avg, inverse, phi, mod, mode, fringes, noise_d, phase_noise, \
z, share, reach
        As for :func:`read_orders`.
    order : (H, W) int array
        The order to judge per pixel; -1 where none.

    Returns
    -------
    (H, W) bool array
        Where ``order`` is 0 or more and fits.

    Examples
    --------
    >>> raw = np.float32([[[0.9, 0.9]], [[0.9, 0.52]], [[0.1, 0.1]], [[0.1, 0.48]]])
    >>> phi = np.float32([[5.5, 0.5]])  # cell 2 (Gray 11); the second's last bit is faint,
    >>> # and its edge is cell 2's upper end, which the phase puts the pixel far from
    >>> orders_fit(raw, 0, 2, 1.0, phi, True, phi, np.full((1, 2), 0.3, np.float32),
    ...            np.int32([[2, 2]]), 0, 4, 0.01, 0.01, 3.0, 0.5, 0.5).tolist()
    [[True, False]]
    """
    raw, start = kernel_frames(raw, start, 2 * bits if inverse else bits)
    return _orders_fit(raw, start, int(bits), float(np.float32(scale)),
                       np.asarray(avg, np.float32), bool(inverse),
                       np.asarray(phi, np.float32), np.asarray(mod, np.float32),
                       np.ascontiguousarray(order, np.int32), int(mode), int(fringes),
                       float(noise_d), float(phase_noise), float(z), float(share),
                       float(reach))
