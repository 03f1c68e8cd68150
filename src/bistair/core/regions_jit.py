"""Compiled passes of the fringe regions (:mod:`bistair.core.regions`), their first half:
the links between neighbouring pixels (wraps, phase steps, backward runs, fringe period
jumps, a codec's own cuts) in one pass over row tiles, and the medians of the cut. The
labelling of the kept pixels, the final numbering and the wraps between regions are the
second half, :mod:`.regions_labels_jit`.

A decode runs them in this order (:func:`bistair.core.regions.label_fringes`):

1. :func:`link_bits`: one byte a pixel, ``LINK_RIGHT | LINK_DOWN | KEPT | VALID`` (or,
   where a labelling takes over the links of an earlier one of the same phase, the
   rows that read a row whose validity changed made again, :func:`valid_changes` and
   :func:`relink`, and the codec's cuts added, :func:`cut_links`);
2. :func:`~.regions_labels_jit.label_kept`, then 3. :func:`~.regions_labels_jit.relabel`.

Each gives exactly what the passes it replaced gave (``period_jump_links`` and
``fringe_links`` of bistair 0.x, kept in ``tests/support/regions_before.py`` as the tests'
oracle; ``tests/support/reference.py:period_jumps`` is the NumPy reference of the period
jumps).

Examples
--------
>>> import numpy as np
>>> x = np.arange(60, dtype=np.float32) + np.float32(0.5)
>>> phi = np.tile(x * np.float32(2 * np.pi / 30) % np.float32(2 * np.pi), (4, 1))
>>> valid = np.ones(phi.shape, bool)
>>> bits = link_bits(phi, valid, np.full(phi.shape, 0.02, np.float32), 1.0, 1, 0.3,
...                  NO_CUTS, NO_CUTS, False)
>>> (bits[0, 28:32] & KEPT).tolist()  # the wrap between columns 29 and 30: 29 dropped
[4, 0, 4, 4]
"""
from __future__ import annotations

import math

import numpy as np

from .jit import PI32, TWO_PI32, called, inline, kernel

prange = range  # numba's prange once the first kernel of this module compiles

TILE = 32  # rows a task of the links pass and of the labelling takes
LINK_RIGHT = 1  # bits of :func:`link_bits`: the link to the right neighbour connects,
LINK_DOWN = 2  # the link to the neighbour below connects,
KEPT = 4  # no cut link dropped the pixel,
VALID = 8  # the pixel is valid
HALF = 3  # gradients in a period-jump window (as the decode uses it; fixed at compile time)
NO_CUTS = np.zeros((0, 0), np.bool_)  # no codec cuts, no second mask


@inline
def _jump(px: np.float32, py: np.float32, pn: np.float32, qx: np.float32, qy: np.float32,
          qn: np.float32, noise_p: np.float32, noise_q: np.float32, rel: np.float32,
          half: np.float32) -> bool:
    """Whether two mean gradients differ by more than ``rel`` of the larger and four times
    their noise (float32, as ``tests/support/reference.py:period_jumps`` computes it)."""
    if pn < half or qn < half:
        return False
    dx, dy = px - qx, py - qy
    d2 = dx * dx + dy * dy
    # clearly below ``rel`` of the larger gradient (most links): no root, no division
    if d2 < rel * rel * max(px * px + py * py, qx * qx + qy * qy) * np.float32(0.9999):
        return False
    one = np.float32(1.0)
    spread = np.float32(2.0) * max(noise_p / np.float32(math.sqrt(max(pn, one))),
                                   noise_q / np.float32(math.sqrt(max(qn, one))))
    limit = np.float32(4.0) * spread
    if d2 < limit * limit * np.float32(0.9999):
        return False  # clearly below the noise: no square root needed
    step = np.float32(math.hypot(dx, dy))
    if not step > np.float32(4.0) * spread:
        return False
    size = max(np.float32(math.hypot(px, py)), np.float32(math.hypot(qx, qy)))
    return step > rel * size


@inline
def _steep(px: np.float32, py: np.float32, qx: np.float32, qy: np.float32,
           rel: np.float32) -> bool:
    """Not clearly below ``rel`` of the larger gradient: :func:`_jump`'s first test, which
    most links fail (True for NaN)."""
    dx, dy = px - qx, py - qy
    return not (dx * dx + dy * dy < rel * rel * max(px * px + py * py, qx * qx + qy * qy)
                * np.float32(0.9999))


@inline
def _loud(px: np.float32, py: np.float32, qx: np.float32, qy: np.float32,
          noise_p: np.float32, noise_q: np.float32, inv_p: np.float32,
          inv_q: np.float32) -> bool:
    """Not clearly below the noise: a looser form of :func:`_jump`'s second test (its
    ``4 * spread`` from ``1/sqrt(count)`` given as ``inv_p``, ``inv_q``, and compared with
    0.999 for 0.9999), true wherever that test passes, and for limits too small to compare
    (True for NaN); without a square root or a division, for a vector loop."""
    dx, dy = px - qx, py - qy
    d2 = dx * dx + dy * dy
    limit = np.float32(8.0) * max(noise_p * inv_p, noise_q * inv_q)
    square = limit * limit
    return not (d2 < square * np.float32(0.999)) or square < np.float32(1e-30)


@inline
def _inverse_root(count: np.float32, inv3: np.float32, inv4: np.float32, inv5: np.float32,
                  inv6: np.float32) -> np.float32:
    """``1/sqrt(count)`` for a window count of 3 to 6, chosen by selects (for a vector
    loop; what the other counts give is not read)."""
    return inv3 if count == 3 else (inv4 if count == 4 else (inv5 if count == 5 else inv6))


@inline
def _wrap_sel(raw: np.float32) -> np.float32:
    """``((raw + pi) % 2pi) - pi`` in float32, as NumPy computes it for ``|raw| < 2pi``, as
    two selects (the same value as two branches for every input, NaN and infinities
    included: after the first step ``d`` is never below 0)."""
    d = raw + PI32
    d = d - TWO_PI32 if d >= TWO_PI32 else d
    d = d + TWO_PI32 if d < np.float32(0.0) else d
    return d - PI32


@inline
def _gradients(p: np.ndarray, v: np.ndarray, pb: np.ndarray, vb: np.ndarray, below: bool,
               g: np.ndarray) -> None:
    """A row's wrapped gradients and their counts, for :func:`_windows`: ``g[0]``, ``g[1]``
    the gradients along the row and down the column (0 where a pixel of the pair is not
    valid, or at the image's last column and row), ``g[2]``, ``g[3]`` (from ``x+3``, the
    first and last three 0) 1 where they count. ``p``, ``v``: the row's phase and
    validity (0/1); ``pb``, ``vb``: the next row's (read only if ``below``). Vector loops,
    each writing one array (more pointers than LLVM checks for overlap leave a loop
    scalar), selected rather than branched."""
    w = p.shape[0]
    zero = np.float32(0.0)
    one = np.float32(1.0)
    gx = g[0]
    gy = g[1]
    nx = g[2]
    ny = g[3]
    for x in range(w - 1):
        gx[x] = _wrap_sel(p[x + 1] - p[x]) if (v[x] & v[x + 1]) != 0 else zero
    gx[w - 1] = zero
    for x in range(w - 1):
        nx[x + 3] = one if (v[x] & v[x + 1]) != 0 else zero
    nx[w + 2] = zero
    if below:
        for x in range(w):
            gy[x] = _wrap_sel(pb[x] - p[x]) if (v[x] & vb[x]) != 0 else zero
        for x in range(w):
            ny[x + 3] = one if (v[x] & vb[x]) != 0 else zero
    else:
        for x in range(w):
            gy[x] = zero
        for x in range(w):
            ny[x + 3] = zero


@inline
def _windows(g: np.ndarray, s: np.ndarray, twice: bool, around: np.ndarray,
             ahead: np.ndarray, ahead_too: bool, around2: np.ndarray, ahead2: np.ndarray,
             ahead2_too: bool) -> None:
    """The mean wrapped gradients (x, y) and sample counts over the columns ``[x-3, x+3)``
    (``around`` (3, W): for the vertical links) and ``[x, x+3)`` (``ahead`` (3, W), with
    ``ahead_too``: for the horizontal ones), clipped to the image, of the row whose
    :func:`_gradients` are ``g[0]``; with ``twice`` also of the row of ``g[1]``
    (``around2``, ``ahead2``).

    As ``period_jumps`` computes them: a window's sum is the difference of two float32
    running sums along the row (``s[r, k]``: (W+7,), ``S[clip(i-3, 0, W)]`` at ``i``, the
    first four 0), counts exact. The running sums are one dependent add a pixel each: two
    rows' four side by side wait a quarter as long as one gradient's."""
    w = around.shape[1]
    zero = np.float32(0.0)
    gx = g[0, 0]
    gy = g[0, 1]
    sx = s[0, 0]
    sy = s[0, 1]
    s0 = zero
    s1 = zero
    if twice:
        hx = g[1, 0]
        hy = g[1, 1]
        tx = s[1, 0]
        ty = s[1, 1]
        s2 = zero
        s3 = zero
        for x in range(w):
            s0 += gx[x]
            s1 += gy[x]
            s2 += hx[x]
            s3 += hy[x]
            sx[x + 4] = s0
            sy[x + 4] = s1
            tx[x + 4] = s2
            ty[x + 4] = s3
        for i in range(w + 4, w + 7):
            tx[i] = s2
            ty[i] = s3
    else:
        for x in range(w):
            s0 += gx[x]
            s1 += gy[x]
            sx[x + 4] = s0
            sy[x + 4] = s1
    for i in range(w + 4, w + 7):
        sx[i] = s0
        sy[i] = s1
    for r in range(2 if twice else 1):
        a = around if r == 0 else around2
        b = ahead if r == 0 else ahead2
        too = ahead_too if r == 0 else ahead2_too
        _means(s[r, 0], g[r, 2], a[0], b[0], too)
        _means(s[r, 1], g[r, 3], a[1], b[1], too)
        _counts(g[r, 2], g[r, 3], a[2], b[2], too)


@inline
def _means(s: np.ndarray, n: np.ndarray, around: np.ndarray, ahead: np.ndarray,
           ahead_too: bool) -> None:
    """A row's window means of one gradient (:func:`_windows`): ``around[x] = (s[x+6] -
    s[x]) / max(count, 1)``, the count ``n[x] + ... + n[x+5]`` (exact), and with
    ``ahead_too`` ``ahead[x]`` of ``s[x+3]`` and ``n[x+3] + ... + n[x+5]``."""
    one = np.float32(1.0)
    if ahead_too:
        for x in range(around.shape[0]):
            c = n[x + 3] + n[x + 4] + n[x + 5]
            ahead[x] = np.divide(s[x + 6] - s[x + 3], max(c, one))
            c += n[x] + n[x + 1] + n[x + 2]
            around[x] = np.divide(s[x + 6] - s[x], max(c, one))
    else:
        for x in range(around.shape[0]):
            c = n[x] + n[x + 1] + n[x + 2] + n[x + 3] + n[x + 4] + n[x + 5]
            around[x] = np.divide(s[x + 6] - s[x], max(c, one))


@inline
def _counts(nx: np.ndarray, ny: np.ndarray, around: np.ndarray, ahead: np.ndarray,
            ahead_too: bool) -> None:
    """A row's window counts (:func:`_windows`): the smaller of the two gradients'."""
    for x in range(around.shape[0]):
        cx = nx[x] + nx[x + 1] + nx[x + 2] + nx[x + 3] + nx[x + 4] + nx[x + 5]
        cy = ny[x] + ny[x + 1] + ny[x + 2] + ny[x + 3] + ny[x + 4] + ny[x + 5]
        around[x] = min(cx, cy)
    if ahead_too:
        for x in range(around.shape[0]):
            cx = nx[x + 3] + nx[x + 4] + nx[x + 5]
            cy = ny[x + 3] + ny[x + 4] + ny[x + 5]
            ahead[x] = min(cx, cy)


@inline
def _row_states(p: np.ndarray, v: np.ndarray, nz: np.ndarray, cut32: np.float32, pos: bool,
                st: np.ndarray, raw: np.ndarray, back: np.ndarray) -> None:
    """The states of a row's horizontal links, ``st[x+1]`` for the link between ``x`` and
    ``x+1`` (``st[0]``, ``st[W]``: 0): 0 not between two valid pixels, 1 connects, 2 a wrap
    whose phase falls along the phase's direction (``pos``: +1), 3 one whose phase rises, 4
    cut (a step above ``cut32``, or a run of links against the phase's direction that
    falls by more than ``max(0.15, 4 sigma)``, ``sigma`` ``sqrt(2)`` times the larger
    noise ``nz`` of a link's ends). ``raw``, ``back``: scratch rows (``back`` padded to a
    multiple of 8 bytes, 0 from ``W-1``)."""
    w = p.shape[0]
    zero = np.float32(0.0)
    # the difference along the phase's direction, times +-1 rather than chosen by ``pos``
    # (a select on a flag left the loops around scalar): ``p[x] - p[x+1]`` but for the
    # sign of a zero, which nothing reads
    along = np.float32(1.0) if pos else np.float32(-1.0)
    for x in range(w - 1):  # a vector loop
        ok = (v[x] & v[x + 1]) != 0
        r = (p[x + 1] - p[x]) * along
        raw[x] = r
        a = abs(r)
        s = np.uint8(3) if r > zero else np.uint8(2)
        s = s if a > PI32 else (np.uint8(4) if a > cut32 else np.uint8(1))
        st[x + 1] = s if ok else np.uint8(0)
    st[0] = 0
    st[w] = 0
    for x in range(w - 1):  # links that connect against the phase's direction
        back[x] = (st[x + 1] == 1) & (raw[x] < zero)
    sqrt2 = math.sqrt(2.0)
    words = back.view(np.uint64)
    x = 0
    while x < w - 1:  # their runs (eight links at a time skipped where there is none)
        if (x & 7) == 0 and words[x >> 3] == 0:
            x += 8
            continue
        if not back[x]:
            x += 1
            continue
        start = x
        fall = 0.0
        spread = 0.0
        while x < w - 1 and back[x]:
            fall += -np.float64(raw[x])
            spread = max(spread, sqrt2 * np.float64(max(nz[x], nz[x + 1])))
            x += 1
        if fall > max(0.15, 4.0 * spread):
            for k in range(start, x):
                st[k + 1] = 4


@called
def _link_rows(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, cut: float, sign: int,
               relative: float, cut_v: np.ndarray, cut_h: np.ndarray, cuts: bool, y0: int,
               y1: int, out: np.ndarray) -> None:
    """:func:`link_bits` of rows ``y0 .. y1-1`` (``valid``, ``cut_v``, ``cut_h`` as uint8):
    the windows of rows ``y0-1 .. y1`` (the links across the tile's edges are made on
    both sides), each row's link states in short loops over row buffers."""
    h, w = phi.shape
    cut32 = np.float32(cut)
    rel = np.float32(relative)
    fhalf = np.float32(HALF)
    pos = sign > 0
    inv3 = np.float32(1.0) / np.float32(math.sqrt(3.0))  # 1/sqrt(a window's count): 3 to
    inv4 = np.float32(0.5)  # 6 where it may cut (scalars, not an array: one pointer
    inv5 = np.float32(1.0) / np.float32(math.sqrt(5.0))  # fewer for LLVM's overlap checks)
    inv6 = np.float32(1.0) / np.float32(math.sqrt(6.0))
    wl = np.uint8(2) if pos else np.uint8(3)  # the wrap state that drops a link's left end
    wr = np.uint8(5) - wl  # ... and the one that drops its right end
    g = np.zeros((2, 4, w + 6), np.float32)  # the gradients of two rows (``_gradients``)
    sums = np.zeros((2, 2, w + 7), np.float32)  # their running sums
    around = np.zeros((4, 3, w), np.float32)  # windows of rows y-1, y, y+1, at y % 4
    ahead = np.zeros((2, 3, w), np.float32)  # ... of rows y, y+1, at y % 2
    raw = np.zeros(w, np.float32)
    st = np.zeros(w + 1, np.uint8)  # horizontal link states (``_row_states``)
    vs = np.zeros(w, np.uint8)  # vertical link states, the same codes (2: the upper end)
    padded = (w + 7) // 8 * 8  # flags scanned eight at a time: 0 past the row's links
    back = np.zeros(padded, np.uint8)
    maybe_h = np.zeros(padded, np.uint8)
    maybe_v = np.zeros(padded, np.uint8)
    words_h = maybe_h.view(np.uint64)
    words_v = maybe_v.view(np.uint64)
    hconn = np.zeros((2, w), np.uint8)
    drop = np.zeros((2, w), np.uint8)
    first = max(y0 - 1, 0)
    last = min(y1 + 1, h)
    for y in range(first, last):
        cur = y & 1
        prv = cur ^ 1
        p = phi[y]
        v = valid[y]
        nz = noise[y]
        inside = y0 <= y < y1
        if (y - first) & 1 == 0:  # the windows of rows y and y+1
            for r in range(2 if y + 1 < last else 1):
                yr = y + r
                below = yr < h - 1
                _gradients(phi[yr], valid[yr], phi[yr + 1] if below else p,
                           valid[yr + 1] if below else v, below, g[r])
            _windows(g, sums, y + 1 < last, around[y & 3], ahead[y & 1], inside,
                     around[(y + 1) & 3], ahead[(y + 1) & 1], y0 <= y + 1 < y1)
        if inside:  # the horizontal links of row y
            _row_states(p, v, nz, cut32, pos, st, raw, back)
            if cuts:
                ch = cut_h[y]
                for x in range(w - 1):
                    s = st[x + 1]
                    st[x + 1] = np.uint8(4) if (s == 1) & (ch[x] != 0) else s
            # the period jumps of links x = i+3, left window [i, i+3) against right window
            # [i+4, i+7): the counts and cheap forms of the first two tests for every link
            # in a vector loop, the test itself where they pass (indices a loop counter
            # from 0 plus a constant: a negative index would wrap, and its test keeps the
            # loop scalar)
            a0 = ahead[cur, 0]
            a1 = ahead[cur, 1]
            a2 = ahead[cur, 2]
            many = 0
            for i in range(w - 1 - HALF):
                j = i + HALF + 1
                m = ((st[j] == 1) & (a2[i] >= fhalf) & (a2[j] >= fhalf)
                     & _steep(a0[i], a1[i], a0[j], a1[j], rel))
                maybe_h[i] = m
                many += m
            if many * 32 > w:  # (the second where many pass the first: fine fringes)
                for i in range(w - 1 - HALF):  # (a window of 3 counts 3 where it may cut)
                    j = i + HALF + 1
                    maybe_h[i] &= _loud(a0[i], a1[i], a0[j], a1[j], nz[i + HALF], nz[j],
                                        inv3, inv3)
            for k in range(words_h.shape[0]):
                if words_h[k] == 0:  # (most words)
                    continue
                for i in range(8 * k, 8 * k + 8):
                    if maybe_h[i] and _jump(a0[i], a1[i], a2[i], a0[i + HALF + 1],
                                            a1[i + HALF + 1], a2[i + HALF + 1], nz[i + HALF],
                                            nz[i + HALF + 1], rel, fhalf):
                        st[i + HALF + 1] = 4
            hb = hconn[cur]
            dr = drop[cur]
            for x in range(w):
                left = st[x]
                right = st[x + 1]
                hb[x] = right == 1
                dr[x] = (right == 4) | (right == wl) | (left == 4) | (left == wr)
        if y == first:
            continue
        # the vertical links between rows y-1 and y
        pa = phi[y - 1]
        va = valid[y - 1]
        na = noise[y - 1]
        for x in range(w):
            ok = (va[x] & v[x]) != 0
            r = p[x] - pa[x]
            a = abs(r)
            s = np.uint8(3) if r > np.float32(0.0) else np.uint8(2)
            s = s if a > PI32 else (np.uint8(4) if a > cut32 else np.uint8(1))
            vs[x] = s if ok else np.uint8(0)
        if cuts:
            cv = cut_v[y - 1]
            for x in range(w):
                s = vs[x]
                vs[x] = np.uint8(4) if (s == 1) & (cv[x] != 0) else s
        b = around[(y - 1) & 3]
        c = around[y & 3]
        b0 = b[0]
        b1 = b[1]
        b2 = b[2]
        c0 = c[0]
        c1 = c[1]
        c2 = c[2]
        many = 0
        for x in range(w):  # (two loops: fewer arrays a loop, see _gradients)
            m = ((vs[x] == 1) & (b2[x] >= fhalf) & (c2[x] >= fhalf)
                 & _steep(b0[x], b1[x], c0[x], c1[x], rel))
            maybe_v[x] = m
            many += m
        if many * 32 > w:
            for x in range(w):
                maybe_v[x] &= _loud(b0[x], b1[x], c0[x], c1[x], na[x], nz[x],
                                    _inverse_root(b2[x], inv3, inv4, inv5, inv6),
                                    _inverse_root(c2[x], inv3, inv4, inv5, inv6))
        for k in range(words_v.shape[0]):
            if words_v[k] == 0:
                continue
            for x in range(8 * k, 8 * k + 8):
                if maybe_v[x] and _jump(b0[x], b1[x], b2[x], c0[x], c1[x], c2[x], na[x], nz[x],
                                        rel, fhalf):
                    vs[x] = 4
        dp = drop[prv]
        dc = drop[cur]
        for x in range(w):
            s = vs[x]
            dp[x] |= (s == 4) | (s == 2)
            dc[x] |= (s == 4) | (s == 3)
        if y - 1 >= y0:  # row y-1 is complete
            o = out[y - 1]
            hb = hconn[prv]
            for x in range(w):
                o[x] = (hb[x] | (np.uint8(vs[x] == 1) << 1)
                        | ((va[x] & (dp[x] ^ np.uint8(1))) << 2) | (va[x] << 3))
    if y1 == h:  # the last row: no link below
        o = out[h - 1]
        hb = hconn[(h - 1) & 1]
        dl = drop[(h - 1) & 1]
        vl = valid[h - 1]
        for x in range(w):
            o[x] = hb[x] | ((vl[x] & (dl[x] ^ np.uint8(1))) << 2) | (vl[x] << 3)


@kernel(parallel=True)
def link_bits(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, cut: float, sign: int,
              relative: float, cut_v: np.ndarray, cut_h: np.ndarray, cuts: bool
              ) -> np.ndarray:
    """The links of the fringe regions, one byte a pixel: ``LINK_RIGHT`` (1) where the link
    to the right neighbour connects, ``LINK_DOWN`` (2) where the link to the one below
    does, ``KEPT`` (4) for a valid pixel that no cut link dropped, ``VALID`` (8).

    A link between two valid pixels is cut at a wrap (``|difference| > pi``: its high-phase
    end is dropped), at a step above ``cut``, where the fringes' spacing or slant jumps
    (``tests/support/reference.py:period_jumps``, windows of 3 gradients, ``relative``), at a
    cut the codec gives (``cut_v``, ``cut_h`` with ``cuts``) and, along the rows, in a run
    of links against the phase's direction ``sign`` whose fall exceeds
    ``max(0.15, 4 sigma)`` (``sigma``: ``sqrt(2)`` times the larger phase noise of a link's
    ends, ``noise``); all but a wrap drop both ends. One pass over tiles of ``TILE`` rows
    on every core, float32 in the order of the NumPy formulation: the same links, bit for
    bit, as the period-jump and link passes it replaced.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels to link.
    noise : (H, W) float32 array
        Per-pixel phase noise in radians.
    cut : float
        Phase step (radians) above which a link is cut (compared in float32).
    sign : int
        +1 or -1, the phase's direction along the rows.
    relative : float
        Share of the larger mean gradient by which a period jump's two windows differ.
    cut_v, cut_h : (H-1, W) and (H, W-1) bool arrays
        Vertical and horizontal links the codec cuts (read only with ``cuts``; else any
        array, e.g. ``NO_CUTS``).
    cuts : bool
        Whether ``cut_v`` and ``cut_h`` are given.

    Returns
    -------
    (H, W) uint8 array
        The bits of each pixel.

    Examples
    --------
    >>> x = np.arange(40, dtype=np.float32)
    >>> phi = np.tile(np.where(x < 20, 0.2 * x, 0.6 * x) % np.float32(2 * np.pi), (3, 1))
    >>> bits = link_bits(phi, np.ones(phi.shape, bool), np.full(phi.shape, 0.01, np.float32),
    ...                  2.0, 1, 0.3, NO_CUTS, NO_CUTS, False)
    >>> np.flatnonzero(~bits[0, :-1] & LINK_RIGHT).tolist()  # the period jump; a wrap at 31
    [16, 17, 18, 19, 20, 21, 22, 31]
    >>> bool((bits[:2] & LINK_DOWN).all()), int(bits[2, 0])  # the last row: no link below
    (True, 13)
    """
    h, w = phi.shape
    out = np.empty((h, w), np.uint8)
    valid8 = valid.view(np.uint8)
    cut_v8 = cut_v.view(np.uint8)
    cut_h8 = cut_h.view(np.uint8)
    for t in prange((h + TILE - 1) // TILE):
        _link_rows(phi, valid8, noise, cut, sign, relative, cut_v8, cut_h8, cuts, t * TILE,
                   min(t * TILE + TILE, h), out)
    return out


@kernel(parallel=True)
def valid_changes(bits: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """The rows where :func:`link_bits`' ``VALID`` bits differ from ``valid``.

    Parameters
    ----------
    bits : (H, W) uint8 array
        :func:`link_bits` of some mask.
    valid : (H, W) bool array
        Another mask.

    Returns
    -------
    (H,) uint8 array
        1 where a pixel of the row differs.

    Examples
    --------
    >>> valid_changes(np.uint8([[8, 0], [8, 8]]), np.array([[True, False], [True, False]]))
    array([0, 1], dtype=uint8)
    """
    h, w = bits.shape
    valid8 = valid.view(np.uint8)
    changed = np.zeros(h, np.uint8)
    for y in prange(h):
        b = bits[y]
        v = valid8[y]
        d = np.uint8(0)
        for x in range(w):
            d |= ((b[x] >> 3) & np.uint8(1)) ^ v[x]
        changed[y] = d
    return changed


@kernel(parallel=True)
def relink(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, cut: float, sign: int,
           relative: float, bits: np.ndarray, changed: np.ndarray) -> int:
    """:func:`link_bits` (without a codec's cuts) of a ``valid`` mask, in place of the bytes
    ``bits`` it gave for another mask of the same ``phi``, ``noise``, ``cut`` and ``sign``:
    only the rows whose inputs changed (the bytes of row ``y`` read rows ``y-1 .. y+2``;
    ``changed``: :func:`valid_changes`), in runs of up to ``TILE`` rows. The same bytes,
    bit for bit, as :func:`link_bits` of ``valid``.

    Parameters
    ----------
    phi, valid, noise, cut, sign, relative
        As :func:`link_bits`.
    bits : (H, W) uint8 array
        :func:`link_bits` of the same arguments but another mask (and no cuts), changed
        in place.
    changed : (H,) uint8 array
        The rows whose validity changed.

    Returns
    -------
    int
        The rows made again.

    Examples
    --------
    >>> x = np.arange(64, dtype=np.float32)
    >>> phi = np.tile(x * np.float32(0.3) % np.float32(2 * np.pi), (70, 1))
    >>> noise = np.full(phi.shape, 0.02, np.float32)
    >>> ok = np.ones(phi.shape, bool)
    >>> bits = link_bits(phi, ok, noise, 1.0, 1, 0.3, NO_CUTS, NO_CUTS, False)
    >>> ok[40, 5] = False  # rows 38 to 41 read row 40
    >>> relink(phi, ok, noise, 1.0, 1, 0.3, bits, valid_changes(bits, ok))
    4
    >>> np.array_equal(bits, link_bits(phi, ok, noise, 1.0, 1, 0.3, NO_CUTS, NO_CUTS, False))
    True
    """
    h, w = phi.shape
    valid8 = valid.view(np.uint8)
    starts = np.empty(h, np.int64)  # runs of rows to make again, each up to TILE rows
    ends = np.empty(h, np.int64)
    runs = 0
    made = 0
    y = 0
    while y < h:
        hit = False
        for r in range(max(y - 1, 0), min(y + 3, h)):
            hit |= changed[r] != 0
        if hit:
            if runs > 0 and ends[runs - 1] == y and y - starts[runs - 1] < TILE:
                ends[runs - 1] = y + 1
            else:
                starts[runs] = y
                ends[runs] = y + 1
                runs += 1
            made += 1
        y += 1
    none = np.zeros((0, 0), np.uint8)
    for i in prange(runs):
        _link_rows(phi, valid8, noise, cut, sign, relative, none, none, False, starts[i],
                   ends[i], bits)
    return made


