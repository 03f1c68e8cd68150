"""Compiled passes of the fringe regions (:mod:`bistair.core.regions`) about the cuts: the
two medians behind a labelling's own cut threshold (:func:`cut_medians`), whether two
thresholds make the same links (:func:`band_links`), and a codec's own cuts added to the
links a labelling takes over (:func:`cut_links`). The links themselves are made in
:mod:`.regions_jit`, labelled in :mod:`.regions_labels_jit`.

Each gives exactly what the NumPy it replaced gave (the medians: ``np.median`` of the
strided differences, :func:`bistair.core.regions.cut_reference`; the cuts: what
:func:`~.regions_jit.link_bits` makes with them).

Examples
--------
>>> import numpy as np
>>> phi = np.float32([[0.0, 1.0, 2.0, 2.5]])
>>> band_links(phi, np.ones(phi.shape, bool), 0.6, 1.0)  # two steps of 1.0
2
"""

from __future__ import annotations

import numpy as np

from .jit import TWO_PI32, called, kernel
from .regions_jit import KEPT, LINK_DOWN, LINK_RIGHT, TILE

prange = range  # numba's prange once the first kernel of this module compiles (its helpers too)


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
    >>> from bistair.core.regions_jit import VALID
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
