"""Compiled passes of the fringe regions (:mod:`bistair.core.regions`): the links between
neighbouring pixels (wraps, phase steps, backward runs, fringe period jumps, a codec's own
cuts) in one pass over row tiles, the kept pixels labelled by union-find over row tiles
(with per-region counts gathered in the same scan), dropped pixels reattached, the final
numbering, and the wraps between regions.

A decode runs them in this order (:func:`bistair.core.regions.label_fringes`):

1. :func:`link_bits`: one byte a pixel, ``LINK_RIGHT | LINK_DOWN | KEPT | VALID`` (or,
   where a labelling takes over the links of an earlier one of the same phase, the
   rows that read a row whose validity changed made again, :func:`valid_changes` and
   :func:`relink`, and the codec's cuts added, :func:`cut_links`);
2. :func:`label_kept`: provisional labels of the kept pixels (4-connected), their regions
   numbered ``1..n`` in raster order of each region's first pixel (as
   ``cv2.connectedComponents(kept, connectivity=4)`` numbers them), the valid pixels not
   kept reattached to a region they link to, pixels and pixels of a second mask counted
   per region;
3. :func:`relabel`: the final labels, written row by row in raster order (the hook for
   sums per (region, row): see its docstring).

Each gives exactly what the passes it replaced gave (``period_jump_links``,
``fringe_links``, ``cv2.connectedComponents``, ``reattach`` and ``drop_small`` of bistair
0.x, kept in ``tests/support/regions_before.py`` as the tests' oracle;
:func:`bistair.core.regions.period_jumps` is the NumPy reference of the period jumps).

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
>>> labels, roots, n, size, _ = label_kept(bits, NO_CUTS, False, TILE, 3)
>>> n, size.tolist()  # column 29 reattached
(2, [0, 120, 120])
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


@called
def _median_bits(vals: np.ndarray, hist: np.ndarray) -> np.float32:
    """The median of ``vals`` (float32 in ``[+0, 4)``, at least one: their bit patterns
    sort as the values do) as :func:`numpy.median` gives it (the middle value, or the
    float32 mean of the two middle values): the values counted by their top 16 bits
    (``hist``: zeros, one bin each, left as found), then the middle ranks selected
    among those of the middle bins. (Compiled on its own: inlined twice into
    :func:`cut_medians` it ran six times slower.)"""
    n = vals.shape[0]
    bins = hist.shape[0]
    bits = vals.view(np.uint32)
    for i in range(n):
        hist[bits[i] >> 16] += 1
    lo_k = (n - 1) // 2  # the two middle ranks (the same for an odd count)
    hi_k = n // 2
    seen = 0
    below = 0  # values in the bins under the lower middle rank's
    lo_bin = bins
    hi_bin = bins - 1
    for b in range(bins):
        c = hist[b]
        if lo_bin == bins and seen + c > lo_k:
            lo_bin = b
            below = seen
        if seen + c > hi_k:
            hi_bin = b
            break
        seen += c
    mid = np.empty(seen + hist[hi_bin] - below, np.float32)
    m = 0
    for i in range(n):
        b = bits[i] >> 16
        if lo_bin <= b <= hi_bin:
            mid[m] = vals[i]
            m += 1
    for i in range(n):
        hist[bits[i] >> 16] = 0
    k = lo_k - below
    mid = np.partition(mid, k)  # (a selection: ties are equal bits)
    a = mid[k]
    return a if hi_k == lo_k else (a + mid[k + 1:].min()) / np.float32(2.0)


@kernel()
def cut_medians(phi: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """The two medians of :func:`bistair.core.regions.default_cut`, bit for bit: of the
    absolute wrapped differences ``min(g, 2pi - g)`` (float32) between valid neighbours
    on every fourth row and column, along the rows (pixel ``(4i, 4j)`` and the one to
    its right) and down the columns (``(4i, 4j)`` and the one below), without NumPy's
    strided copies and sorts.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts.

    Returns
    -------
    meds : (2,) float32 array
        The medians along the rows and down the columns (0 where there is no pair).
    counts : (2,) int64 array
        The pairs behind each.
    ok : bool
        False where a difference is NaN or not below 4 (``meds`` then not to be read:
        NumPy's own median decides).

    Examples
    --------
    >>> phi = np.tile(np.float32(2 * np.pi) * np.arange(40, dtype=np.float32) / 10
    ...               % np.float32(2 * np.pi), (8, 1))
    >>> meds, counts, ok = cut_medians(phi, np.ones(phi.shape, bool))
    >>> [round(float(m), 4) for m in meds], counts.tolist(), ok
    ([0.6283, 0.0], [20, 20], True)
    """
    h, w = phi.shape
    two_pi = TWO_PI32
    rows = (h + 3) // 4
    cols = (w + 3) // 4
    vals = np.empty((2, rows * cols + 1), np.float32)  # (+1: the last write not kept)
    counts = np.zeros(2, np.int64)
    nx = 0
    ny = 0
    for y in range(0, h, 4):  # each value written, kept where its pair is valid (no
        p = phi[y]  # branch on the validity: half of them would be mispredicted)
        v = valid[y].view(np.uint8)
        for x in range(0, w - 1, 4):
            g = abs(p[x + 1] - p[x])
            t = two_pi - g
            vals[0, nx] = t if t < g else g  # (NaN kept)
            nx += v[x] & v[x + 1]
        if y + 1 < h:
            q = phi[y + 1]
            u = valid[y + 1].view(np.uint8)
            for x in range(0, w, 4):
                g = abs(q[x] - p[x])
                t = two_pi - g
                vals[1, ny] = t if t < g else g
                ny += v[x] & u[x]
    counts[0] = nx
    counts[1] = ny
    meds = np.zeros(2, np.float32)
    for r in range(2):  # negative, NaN or 4 and more: not for the bit patterns' order
        bits = vals[r, :counts[r]].view(np.uint32)
        for i in range(bits.shape[0]):
            if bits[i] >= np.uint32(0x40800000):
                return meds, counts, False
    hist = np.zeros(0x4080, np.int32)  # (the top 16 bits of 4.0)
    if nx > 0:
        meds[0] = _median_bits(vals[0, :nx], hist)
    if ny > 0:
        meds[1] = _median_bits(vals[1, :ny], hist)
    return meds, counts, True


@inline
def _jump(px: np.float32, py: np.float32, pn: np.float32, qx: np.float32, qy: np.float32,
          qn: np.float32, noise_p: np.float32, noise_q: np.float32, rel: np.float32,
          half: np.float32) -> bool:
    """Whether two mean gradients differ by more than ``rel`` of the larger and four times
    their noise (float32, as :func:`bistair.core.regions.period_jumps` computes it)."""
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
    (:func:`bistair.core.regions.period_jumps`, windows of 3 gradients, ``relative``), at a
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
def band_links(phi: np.ndarray, valid: np.ndarray, low: float, high: float) -> int:
    """The links between two valid neighbours whose phase step lies in ``(low, high]``
    (float32, as :func:`link_bits` compares a step with its cut): where none does, a cut
    threshold of ``low`` and one of ``high`` make the same links.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels to link.
    low, high : float
        The two thresholds (compared in float32).

    Returns
    -------
    int
        Links, along the rows and down the columns.

    Examples
    --------
    >>> phi = np.float32([[0.0, 1.0, 1.5], [0.0, 0.2, 3.0]])
    >>> band_links(phi, np.ones(phi.shape, bool), 0.9, 1.0)  # the step of 1.0 only
    1
    """
    h, w = phi.shape
    lo = np.float32(low)
    hi = np.float32(high)
    valid8 = valid.view(np.uint8)
    count = np.zeros(h, np.int64)
    for y in prange(h):
        p = phi[y]
        v = valid8[y]
        c = 0
        for x in range(w - 1):
            a = abs(p[x + 1] - p[x])
            c += (v[x] & v[x + 1]) & ((a > lo) & (a <= hi))
        if y + 1 < h:
            q = phi[y + 1]
            u = valid8[y + 1]
            for x in range(w):
                a = abs(q[x] - p[x])
                c += (v[x] & u[x]) & ((a > lo) & (a <= hi))
        count[y] = c
    return int(count.sum())


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


@kernel(parallel=True)
def cut_links(bits: np.ndarray, cut_v: np.ndarray, cut_h: np.ndarray) -> np.ndarray:
    """A codec's cuts added to :func:`link_bits`' bytes made without them: a link that
    connects and is cut connects no more and drops both its pixels. The same bytes, bit
    for bit, as :func:`link_bits` with the cuts (a codec's cut acts only on a link that
    would connect: a wrap, a step, a backward run or a period jump cuts it anyway, and
    the backward runs are found before the codec's cuts).

    Parameters
    ----------
    bits : (H, W) uint8 array
        :func:`link_bits` without cuts.
    cut_v, cut_h : (H-1, W) and (H, W-1) bool arrays
        Vertical and horizontal links the codec cuts.

    Returns
    -------
    (H, W) uint8 array
        The bytes with the cuts.

    Examples
    --------
    >>> bits = np.full((2, 3), LINK_RIGHT | LINK_DOWN | KEPT | VALID, np.uint8)
    >>> bits[:, 2] &= ~np.uint8(LINK_RIGHT)
    >>> bits[1] &= ~np.uint8(LINK_DOWN)
    >>> cut_links(bits, np.zeros((1, 3), bool),
    ...           np.array([[False, True], [False, False]])).tolist()
    [[15, 10, 10], [13, 13, 12]]
    """
    h, w = bits.shape
    out = np.empty((h, w), np.uint8)
    cv = cut_v.view(np.uint8)
    ch = cut_h.view(np.uint8)
    right = np.uint8(LINK_RIGHT)
    down = np.uint8(LINK_DOWN)
    every = np.uint8(255)
    no_right = np.uint8(255 - LINK_RIGHT - KEPT)  # masks: the bits a cut leaves
    no_down = np.uint8(255 - LINK_DOWN - KEPT)
    no_kept = np.uint8(255 - KEPT)
    for t in prange((h + TILE - 1) // TILE):
        for y in range(t * TILE, min(t * TILE + TILE, h)):
            b = bits[y]
            o = out[y]
            c = ch[y]
            for x in range(w):  # a link cut where it connects: selects, a vector loop
                o[x] = b[x]
            for x in range(w - 1):
                cr = (c[x] != 0) & ((b[x] & right) != 0)
                o[x] &= no_right if cr else every
            for x in range(1, w):
                cl = (c[x - 1] != 0) & ((b[x - 1] & right) != 0)
                o[x] &= no_kept if cl else every
            if y < h - 1:
                d = cv[y]
                for x in range(w):
                    cd = (d[x] != 0) & ((b[x] & down) != 0)
                    o[x] &= no_down if cd else every
            if y > 0:
                u = cv[y - 1]
                a = bits[y - 1]
                for x in range(w):
                    cu = (u[x] != 0) & ((a[x] & down) != 0)
                    o[x] &= no_kept if cu else every
    return out


@inline
def _find(parent: np.ndarray, a: np.int32) -> np.int32:
    """The root of ``a`` (paths halved on the way)."""
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@inline
def _union(parent: np.ndarray, a: np.int32, b: np.int32) -> None:
    """Join the trees of ``a`` and ``b`` under the smaller root: a root is always its
    tree's smallest id (``parent[i] <= i``)."""
    a = _find(parent, a)
    b = _find(parent, b)
    if a < b:
        parent[b] = a
    elif b < a:
        parent[a] = b


@called
def _label_rows(bits: np.ndarray, strong: np.ndarray, count_strong: bool, y0: int, y1: int,
                base: int, labels: np.ndarray, parent: np.ndarray, size: np.ndarray,
                bright: np.ndarray, dropped: np.ndarray) -> tuple[int, int]:
    """Label the kept pixels of rows ``y0 .. y1-1`` by runs along the rows (a run takes the
    label of the pixel above its first pixel, or a new id from ``base``; the labels above
    the rest of the run are joined to it), counting each id's pixels (``size``) and
    ``strong`` pixels (``bright``, with ``count_strong``), and list the valid pixels not
    kept (``dropped``: ``(y - y0) * W + x``, in raster order). Returns the ids made and the
    pixels listed. The rows above ``y0`` are not looked at."""
    w = bits.shape[1]
    nxt = base
    listed = 0
    for y in range(y0, y1):
        b = bits[y]
        lab = labels[y]
        for x in range(w):
            lab[x] = 0
        up = labels[y - 1] if y > y0 else lab  # (the zeros of this row: no label above)
        s = strong[y] if count_strong else b  # (uint8 rows)
        row = (y - y0) * w
        x = 0
        while x < w:
            if not b[x] & KEPT:
                if b[x] & VALID:
                    dropped[listed] = row + x
                    listed += 1
                x += 1
                continue
            start = x
            last = up[x]
            if last != 0:
                cur = last
            else:
                cur = np.int32(nxt)
                parent[nxt] = nxt
                size[nxt] = 0
                bright[nxt] = 0
                nxt += 1
            lit = 0
            while x < w and b[x] & KEPT:
                u = up[x]
                if u != last:
                    if u != 0 and u != cur:
                        _union(parent, cur, u)
                    last = u
                lab[x] = cur
                if count_strong:
                    lit += s[x] != 0
                x += 1
            size[cur] += x - start
            bright[cur] += lit
    return nxt - base, listed


@called
def _reattach(labels: np.ndarray, bits: np.ndarray, ty: np.ndarray, tx: np.ndarray,
              roots: np.ndarray, size: np.ndarray, bright: np.ndarray, strong: np.ndarray,
              count_strong: bool, passes: int) -> None:
    """Give the pixels ``(ty, tx)`` (valid, not kept, label 0) the label of a neighbour
    they are linked to (below, above, right, left: the first labelled one), ``passes``
    times; each pass reads the labels the previous one left. A pixel takes its
    neighbour's label as it is (a provisional id, or 0), so the regions ``roots[labels]``
    are those of the same reattachment on final labels; the counts per region follow."""
    n = ty.shape[0]
    got = np.zeros(n, np.int32)
    for _ in range(passes):
        if n == 0:
            break
        for i in range(n):
            y = ty[i]
            x = tx[i]
            g = np.int32(0)
            if bits[y, x] & LINK_DOWN:
                g = labels[y + 1, x]
            if g == 0 and y > 0 and bits[y - 1, x] & LINK_DOWN:
                g = labels[y - 1, x]
            if g == 0 and bits[y, x] & LINK_RIGHT:
                g = labels[y, x + 1]
            if g == 0 and x > 0 and bits[y, x - 1] & LINK_RIGHT:
                g = labels[y, x - 1]
            got[i] = g
        m = 0
        for i in range(n):
            g = got[i]
            labels[ty[i], tx[i]] = g
            if g == 0:
                ty[m] = ty[i]
                tx[m] = tx[i]
                m += 1
            else:
                r = roots[g]
                size[r] += 1
                if count_strong:
                    bright[r] += strong[ty[i], tx[i]] != 0
        n = m


@kernel(parallel=True)
def label_kept(bits: np.ndarray, strong: np.ndarray, count_strong: bool, tile: int,
               passes: int) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray]:
    """The fringe regions of :func:`link_bits`' bytes, before their final numbering:
    4-connected regions of the ``KEPT`` pixels, numbered ``1..n`` in raster order of each
    region's first pixel (the numbering of ``cv2.connectedComponents(kept,
    connectivity=4)``), then the valid pixels that were not kept given the label of a
    neighbour they still link to (below, above, right, left: the first labelled one,
    ``passes`` rounds, each reading the labels the last one left); per region its pixels
    and, with ``count_strong``, its ``strong`` pixels, gathered in the same scan.

    Tiles of ``tile`` rows are labelled on every core (union-find by runs along the rows,
    the ids of tile ``t`` from ``t * cap + 1``, ``cap`` the most runs a tile can hold),
    joined across their boundary rows, then the roots (each tree's smallest id: the id of
    its region's first pixel) numbered in id order. The final labels are
    ``roots[labels]`` (:func:`relabel`).

    Parameters
    ----------
    bits : (H, W) uint8 array
        :func:`link_bits`.
    strong : (H, W) bool array
        A second mask whose pixels are counted per region (read only with
        ``count_strong``; else any array, e.g. ``NO_CUTS``).
    count_strong : bool
        Count ``strong``.
    tile : int
        Rows a task labels (the result does not depend on it).
    passes : int
        Rounds of reattachment (0: none).

    Returns
    -------
    labels : (H, W) int32 array
        Provisional ids, 0 outside the regions.
    roots : (ids,) int32 array
        The region of each id (defined at the ids in use and at 0, which is 0).
    n : int
        Number of regions.
    size : (n+1,) int64 array
        Pixels per region (``size[0]`` 0).
    bright : (n+1,) int64 array
        ``strong`` pixels per region (zeros without ``count_strong``).

    Examples
    --------
    >>> bits = np.uint8([[4, 4, 0, 4], [8, 4, 0, 4], [4, 0, 4, 4]])
    >>> labels, roots, n, size, _ = label_kept(bits, NO_CUTS, False, 1, 0)
    >>> n, roots[labels].tolist(), size.tolist()
    (3, [[1, 1, 0, 2], [0, 1, 0, 2], [3, 0, 2, 2]], [0, 3, 4, 1])
    >>> bits[1, 0] |= LINK_RIGHT  # the valid pixel not kept links to its right
    >>> labels, roots, n, size, _ = label_kept(bits, NO_CUTS, False, 1, 3)
    >>> roots[labels].tolist()[1], size.tolist()
    ([1, 1, 0, 2], [0, 4, 4, 1])
    """
    h, w = bits.shape
    tiles = (h + tile - 1) // tile
    cap = tile * ((w + 1) // 2)  # runs of kept pixels a tile can hold: ids it may make
    labels = np.empty((h, w), np.int32)
    parent = np.empty(tiles * cap + 1, np.int32)  # these three touched only where used
    size = np.empty(tiles * cap + 1, np.int32)
    bright = np.empty(tiles * cap + 1, np.int32)
    dropped = np.empty(tiles * tile * w, np.int32)
    made = np.zeros(tiles, np.int64)
    listed = np.zeros(tiles, np.int64)
    strong8 = strong.view(np.uint8)
    for t in prange(tiles):
        made[t], listed[t] = _label_rows(bits, strong8, count_strong, t * tile,
                                         min(t * tile + tile, h), t * cap + 1, labels,
                                         parent, size, bright, dropped[t * tile * w:])
    for t in range(1, tiles):  # join the tiles across their boundary rows
        below = labels[t * tile]
        above = labels[t * tile - 1]
        last_a = np.int32(0)
        last_b = np.int32(0)
        for x in range(w):
            a = above[x]
            b = below[x]
            if a != 0 and b != 0 and (a != last_a or b != last_b):
                _union(parent, a, b)
                last_a = a
                last_b = b
    # number the roots in id order; ``parent[i] < i`` is numbered before ``i``: the tree
    # of ``i`` is its region (``parent`` becomes ``roots`` in place)
    n = 0
    parent[0] = 0
    for t in range(tiles):
        for i in range(t * cap + 1, t * cap + 1 + made[t]):
            if parent[i] == i:
                n += 1
                parent[i] = n
            else:
                parent[i] = parent[parent[i]]
    region_size = np.zeros(n + 1, np.int64)
    region_bright = np.zeros(n + 1, np.int64)
    for t in range(tiles):
        for i in range(t * cap + 1, t * cap + 1 + made[t]):
            r = parent[i]
            region_size[r] += size[i]
            region_bright[r] += bright[i]
    if passes > 0:
        ty = np.empty(listed.sum(), np.int64)
        tx = np.empty(listed.sum(), np.int64)
        k = 0
        for t in range(tiles):
            for i in range(t * tile * w, t * tile * w + listed[t]):
                ty[k] = t * tile + dropped[i] // w
                tx[k] = dropped[i] % w
                k += 1
        _reattach(labels, bits, ty, tx, parent, region_size, region_bright, strong8,
                  count_strong, passes)
    return labels, parent, n, region_size, region_bright


@called
def _relabel_rows(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray, y0: int,
                  y1: int) -> None:
    """:func:`relabel` of rows ``y0 .. y1-1`` (a run of one label looked up once)."""
    for y in range(y0, y1):
        row = labels[y]
        last = np.int32(0)
        final = np.int32(0)
        for x in range(row.shape[0]):
            lab = row[x]
            if lab != last:
                last = lab
                final = remap[roots[lab]]
            row[x] = final


@kernel(parallel=True)
def relabel(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray) -> None:
    """The final labels in place: ``remap[roots[labels]]`` (``remap``: the number each
    region keeps, 0 for one dropped), row by row on every core.

    **The hook for sums per (region, row)** (bidirectional's stair sums are gathered
    there: :func:`bistair.codecs.bidirectional.profiles_jit.relabel_sums`, which writes
    the final labels as this does, tile by tile): this is the last pass over the labels, and
    it visits each row's pixels in raster order with their final label. A kernel that
    wants per-(label, row) sums of other per-pixel values runs its own loop over tiles of
    rows, calls :func:`_relabel_rows` for the tile, then adds its values pixel by pixel
    into one slot per (label, row) while the rows are in cache: the same float64 sums, bit
    for bit, as a scan of the final labels (pixels added in raster order), and no scan of
    its own. The entries per row are known from the rows' runs of one label.

    Parameters
    ----------
    labels : (H, W) int32 array
        Labels (0: none; ``roots[0]`` and ``remap[0]`` are 0), changed in place.
    roots : int32 array
        The region of each label (:func:`label_kept`).
    remap : (n+1,) int32 array
        The final number of each region.

    Examples
    --------
    >>> labels = np.int32([[5, 5, 0, 7]])
    >>> roots = np.zeros(8, np.int32)
    >>> roots[5], roots[7] = 1, 2
    >>> relabel(labels, roots, np.int32([0, 0, 1]))  # region 1 dropped
    >>> labels.tolist()
    [[0, 0, 0, 1]]
    """
    h = labels.shape[0]
    for t in prange((h + TILE - 1) // TILE):
        _relabel_rows(labels, roots, remap, t * TILE, min(t * TILE + TILE, h))


@kernel()
def wrap_links(phi: np.ndarray, labels: np.ndarray, sign: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Neighbour pairs of different regions across a phase wrap, walking down the columns
    and along the rows (a wrap along a row against the phase's direction ``sign`` is left
    out): ``(src, dst, step)``, step +1 where the phase falls from ``src`` to ``dst``.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    labels : (H, W) int32 array
        Region labels, 0 outside any.
    sign : int
        +1 or -1, the phase's direction along the rows.

    Returns
    -------
    src, dst : int64 arrays
        Labels of the first and second pixel of each pair (one entry per pixel pair).
    step : int64 array
        +1 where the phase falls across the wrap (from near 2*pi to near 0), else -1.

    Examples
    --------
    >>> phi = np.float32([[5.0, 6.0, 0.5, 1.5]])
    >>> labels = np.int32([[1, 1, 2, 2]])
    >>> [a.tolist() for a in wrap_links(phi, labels, 1)]
    [[1], [2], [1]]
    >>> [a.tolist() for a in wrap_links(phi, labels, -1)]  # against the phase's direction
    [[], [], []]
    """
    h, w = phi.shape
    src = []
    dst = []
    step = []
    for y in range(h):
        for x in range(w):
            la = labels[y, x]
            if la <= 0:
                continue
            if y + 1 < h:
                lb = labels[y + 1, x]
                if lb > 0 and lb != la and abs(phi[y + 1, x] - phi[y, x]) > PI32:
                    src.append(la)
                    dst.append(lb)
                    step.append(1 if phi[y, x] > phi[y + 1, x] else -1)
            if x + 1 < w:
                lb = labels[y, x + 1]
                if lb > 0 and lb != la and abs(phi[y, x + 1] - phi[y, x]) > PI32:
                    st = 1 if phi[y, x] > phi[y, x + 1] else -1
                    if st == sign:
                        src.append(la)
                        dst.append(lb)
                        step.append(st)
    return (np.array(src, np.int64), np.array(dst, np.int64), np.array(step, np.int64))


