"""Compiled passes of the fringe regions (:mod:`bistair.core.regions`): the links between
neighbouring pixels that a labelling cuts (wrapped-phase steps, fringe period jumps), pixels
reattached to their regions, the wraps between regions and the small regions dropped.

Each gives exactly what the NumPy formulation gives (:func:`bistair.core.regions.period_jumps`
is the reference of :func:`period_jump_links`).

Examples
--------
>>> import numpy as np
>>> x = np.arange(40, dtype=np.float32)
>>> phi = np.tile(np.where(x < 20, 0.2 * x, 0.6 * x) % np.float32(2 * np.pi), (6, 1))
>>> vert, horiz = period_jump_links(phi, np.ones(phi.shape, bool),
...                                 np.full(phi.shape, 0.01, np.float32), 3, 0.3)
>>> np.flatnonzero(horiz[0]).tolist(), bool(vert.any())
([16, 17, 18, 19, 21, 22], False)
"""

from __future__ import annotations

import math

import numpy as np

from .jit import PI32, _numba_called, _numba_inline, _wrapped, kernel

prange = range  # numba's prange once the first kernel of this module compiles


@_numba_inline
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



@_numba_inline
def _steep(px: np.float32, py: np.float32, qx: np.float32, qy: np.float32,
           rel: np.float32) -> bool:
    """Not clearly below ``rel`` of the larger gradient: :func:`_jump`'s first test, which
    most links fail (True for NaN)."""
    dx, dy = px - qx, py - qy
    return not (dx * dx + dy * dy < rel * rel * max(px * px + py * py, qx * qx + qy * qy)
                * np.float32(0.9999))



@_numba_inline
def _gradient_windows(phi: np.ndarray, valid: np.ndarray, y: int, half: int,
                      sums: np.ndarray, around: np.ndarray, ahead: np.ndarray) -> None:
    """Row ``y``'s mean wrapped gradients (x, y) and their sample counts over the columns
    ``[x-half, x+half)`` (``around``, for the vertical links) and ``[x, x+half)``
    (``ahead``, for the horizontal ones), each (3, W) and clipped to the image (the means
    only where the count reaches ``half``: :func:`_jump` reads them only there); ``sums``
    (4, W+1) is scratch for the running sums."""
    h, w = phi.shape
    one = np.float32(1.0)
    # the running sums in registers, stored as they grow (adding to the sum just stored
    # waited on the store: about 1.5 ms of 14 at 1.3 MP on one thread)
    s0 = np.float32(0.0)
    s1 = np.float32(0.0)
    s2 = np.float32(0.0)
    s3 = np.float32(0.0)
    for x in range(w):
        gx = np.float32(0.0)
        nx = np.float32(0.0)
        if x < w - 1 and valid[y, x] and valid[y, x + 1]:
            gx = _wrapped(phi[y, x + 1] - phi[y, x])
            nx = one
        gy = np.float32(0.0)
        ny = np.float32(0.0)
        if y < h - 1 and valid[y, x] and valid[y + 1, x]:
            gy = _wrapped(phi[y + 1, x] - phi[y, x])
            ny = one
        s0 += gx
        s1 += nx
        s2 += gy
        s3 += ny
        sums[0, x + 1] = s0
        sums[1, x + 1] = s1
        sums[2, x + 1] = s2
        sums[3, x + 1] = s3
    few = np.float32(half)
    for x in range(w):  # a window of under ``half`` samples never cuts: no means needed
        hi = min(x + half, w)
        lo = max(x - half, 0)
        nxs = sums[1, hi] - sums[1, lo]
        nys = sums[3, hi] - sums[3, lo]
        around[2, x] = min(nxs, nys)
        if around[2, x] >= few:
            around[0, x] = (sums[0, hi] - sums[0, lo]) / max(nxs, one)
            around[1, x] = (sums[2, hi] - sums[2, lo]) / max(nys, one)
        nxs = sums[1, hi] - sums[1, x]
        nys = sums[3, hi] - sums[3, x]
        ahead[2, x] = min(nxs, nys)
        if ahead[2, x] >= few:
            ahead[0, x] = (sums[0, hi] - sums[0, x]) / max(nxs, one)
            ahead[1, x] = (sums[2, hi] - sums[2, x]) / max(nys, one)



@kernel(parallel=True)
def period_jump_links(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, half: int,
                      relative: float) -> tuple[np.ndarray, np.ndarray]:
    """The links across which the fringes' spacing or slant jumps (see
    :func:`bistair.core.regions.period_jumps`): ``(vertical (H-1, W), horizontal (H, W-1))``.

    Gradients are wrapped phase differences along the row (``x``) and down the column
    (``y``), averaged over windows of columns: ``[x-half, x+half)`` around a pixel (for the
    vertical links), ``[x-half, x)`` and ``[x+1, x+1+half)`` either side of a horizontal
    link. Float32 throughout, in the order of the NumPy formulation. Only links between
    two valid pixels are judged (no other link joins a region). Rows are taken in blocks of
    32 (on every core), each row's windows kept only until the next row's links are made.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts.
    noise : (H, W) float32 array
        Per-pixel phase noise in radians.
    half : int
        Window length in pixels (each window also needs ``half`` valid gradients).
    relative : float
        Share of the larger mean gradient by which the two must differ.

    Returns
    -------
    vert : (H-1, W) bool array
        Links between each pixel and the one below it to cut.
    horiz : (H, W-1) bool array
        Links between each pixel and the one to its right to cut.

    Examples
    --------
    >>> x = np.arange(40, dtype=np.float32)
    >>> phi = np.tile(np.where(x < 20, 0.2 * x, 0.6 * x) % np.float32(2 * np.pi), (6, 1))
    >>> vert, horiz = period_jump_links(phi, np.ones(phi.shape, bool),
    ...                                 np.full(phi.shape, 0.01, np.float32), 3, 0.3)
    >>> np.flatnonzero(horiz[0]).tolist(), bool(vert.any())
    ([16, 17, 18, 19, 21, 22], False)
    """
    h, w = phi.shape
    horiz = np.zeros((h, w - 1), np.bool_)
    vert = np.zeros((h - 1, w), np.bool_)
    block = 32
    for b in prange((h + block - 1) // block):
        _jump_rows(phi, valid, noise, half, relative, b * block, min(b * block + block, h),
                   vert, horiz)
    return vert, horiz



@_numba_called
def _jump_rows(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, half: int,
               relative: float, y0: int, y1: int, vert: np.ndarray, horiz: np.ndarray
               ) -> None:
    """:func:`period_jump_links` for rows ``y0 .. y1-1`` (and the links from row ``y0-1``)."""
    h, w = phi.shape
    rel = np.float32(relative)
    fhalf = np.float32(half)
    sums = np.zeros((4, w + 1), np.float32)
    ahead = np.zeros((3, w), np.float32)
    rows = np.zeros((2, 3, w), np.float32)  # ``around`` of rows y-1 and y (at y % 2)
    maybe = np.zeros(w, np.bool_)  # links that pass _jump's first test
    if y0 > 0:
        _gradient_windows(phi, valid, y0 - 1, half, sums, rows[(y0 - 1) % 2], ahead)
    for y in range(y0, y1):
        lit = False
        for x in range(w):
            lit = lit or valid[y, x]
        if not lit:  # no link of this row joins two valid pixels
            continue
        around = rows[y % 2]
        _gradient_windows(phi, valid, y, half, sums, around, ahead)
        # left of link x the window [x-half, x) is ``ahead`` of x-half; nearer the image's
        # left edge it holds under ``half`` samples and no link is cut. Most links fail
        # _jump's first test: it runs for every link in one vector loop, the rest only
        # where it passes.
        for x in range(half, w - 1):
            lo = x - half
            maybe[x] = _steep(ahead[0, lo], ahead[1, lo], ahead[0, x + 1], ahead[1, x + 1],
                              rel)
        for x in range(half, w - 1):
            if maybe[x] and valid[y, x] and valid[y, x + 1]:
                lo = x - half
                horiz[y, x] = _jump(ahead[0, lo], ahead[1, lo], ahead[2, lo],
                                    ahead[0, x + 1], ahead[1, x + 1], ahead[2, x + 1],
                                    noise[y, x], noise[y, x + 1], rel, fhalf)
        if y > 0:
            above = rows[(y - 1) % 2]
            for x in range(w):
                maybe[x] = _steep(above[0, x], above[1, x], around[0, x], around[1, x], rel)
            for x in range(w):
                if maybe[x] and valid[y - 1, x] and valid[y, x]:
                    vert[y - 1, x] = _jump(above[0, x], above[1, x], above[2, x],
                                           around[0, x], around[1, x], around[2, x],
                                           noise[y - 1, x], noise[y, x], rel, fhalf)



@kernel(parallel=True)
def fringe_links(phi: np.ndarray, valid: np.ndarray, cut: float, sign: int,
                 noise: np.ndarray, jump_v: np.ndarray, jump_h: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The links of :func:`bistair.core.regions.fringe_regions`: ``(vertical links kept
    (H-1, W), horizontal links kept (H, W-1), pixels kept (H, W))``.

    A link between two valid pixels is cut at a wrap (its high-phase end is dropped), at a
    step above ``cut`` or a cut given in ``jump_v``/``jump_h`` (both ends dropped), and,
    along the rows, in a run of links against the phase's direction ``sign`` whose fall
    exceeds ``max(0.15, 4 sigma)`` (``sigma``: ``sqrt(2)`` times the larger per-pixel phase
    noise of a link, ``noise``; both ends dropped).

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels to link.
    cut : float
        Phase step (radians) above which a link is cut.
    sign : int
        +1 or -1, the phase's direction along the rows.
    noise : (H, W) float32 array
        Per-pixel phase noise in radians.
    jump_v, jump_h : (H-1, W) and (H, W-1) bool arrays
        Vertical and horizontal links to cut as well.

    Returns
    -------
    vert : (H-1, W) bool array
        Links between each pixel and the one below it that connect.
    horiz : (H, W-1) bool array
        Links between each pixel and the one to its right that connect.
    keep : (H, W) bool array
        Valid pixels that no cut link dropped.

    Examples
    --------
    >>> x = np.arange(60.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (3, 1)).astype(np.float32)
    >>> vert, horiz, keep = fringe_links(phi, np.ones(phi.shape, bool), 1.0, 1,
    ...                                  np.full(phi.shape, 0.02, np.float32),
    ...                                  np.zeros((2, 60), bool), np.zeros((3, 59), bool))
    >>> keep[0, 28:32].tolist(), horiz[0, 27:31].tolist(), bool(vert.all())  # a wrap at 29|30
    ([True, False, True, True], [True, True, False, True], True)
    """
    h, w = phi.shape
    cut32 = np.float32(cut)
    sqrt2 = math.sqrt(2.0)
    vert = np.zeros((h - 1, w), np.bool_)
    drop_up = np.zeros((h - 1, w), np.bool_)
    drop_down = np.zeros((h - 1, w), np.bool_)
    for y in prange(h - 1):
        for x in range(w):
            if not (valid[y, x] and valid[y + 1, x]):
                continue
            raw = phi[y + 1, x] - phi[y, x]
            if abs(raw) > PI32:
                if raw <= 0:
                    drop_up[y, x] = True
                else:
                    drop_down[y, x] = True
            elif abs(raw) > cut32 or jump_v[y, x]:
                drop_up[y, x] = True
                drop_down[y, x] = True
            else:
                vert[y, x] = True
    horiz = np.zeros((h, w - 1), np.bool_)
    keep = np.zeros((h, w), np.bool_)
    for y in prange(h):
        raw = np.zeros(w - 1, np.float32)
        state = np.zeros(w - 1, np.int8)  # 0 none, 1 ok, 2 wrap high-a, 3 wrap high-b, 4 cut
        for x in range(w - 1):
            if not (valid[y, x] and valid[y, x + 1]):
                continue
            r = (phi[y, x + 1] - phi[y, x]) if sign > 0 else (phi[y, x] - phi[y, x + 1])
            raw[x] = r
            if abs(r) > PI32:
                state[x] = 2 if r <= 0 else 3
            elif abs(r) > cut32:
                state[x] = 4
            else:
                state[x] = 1
        x = 0
        while x < w - 1:  # runs of ok links against the phase's direction
            if not (state[x] == 1 and raw[x] < 0):
                x += 1
                continue
            start = x
            fall = 0.0
            spread = 0.0
            while x < w - 1 and state[x] == 1 and raw[x] < 0:
                fall += -np.float64(raw[x])
                spread = max(spread, sqrt2 * np.float64(max(noise[y, x], noise[y, x + 1])))
                x += 1
            if fall > max(0.15, 4.0 * spread):
                for k in range(start, x):
                    state[k] = 4
        drop_lo = np.zeros(w, np.bool_)  # dropped by a link on the pixel's low-x side...
        for x in range(w - 1):
            s = state[x]
            if s == 1 and jump_h[y, x]:
                s = 4
            if s == 1:
                horiz[y, x] = True
            elif s == 4:
                drop_lo[x] = True
                drop_lo[x + 1] = True
            elif s == 2:  # raw <= 0: the first pixel along the walk is the high end
                if sign > 0:
                    drop_lo[x] = True
                else:
                    drop_lo[x + 1] = True
            elif s == 3:
                if sign > 0:
                    drop_lo[x + 1] = True
                else:
                    drop_lo[x] = True
        for x in range(w):
            k = valid[y, x] and not drop_lo[x]
            if y < h - 1 and drop_up[y, x]:
                k = False
            if y > 0 and drop_down[y - 1, x]:
                k = False
            keep[y, x] = k
    return vert, horiz, keep



@kernel()
def reattach(labels: np.ndarray, valid: np.ndarray, keep: np.ndarray, vert: np.ndarray,
             horiz: np.ndarray, passes: int) -> None:
    """Give valid pixels that were dropped the label of a neighbour they are linked to
    (below, above, right, left: the first labelled one), ``passes`` times, in place; each
    pass reads the labels the previous one left.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels (0: none), changed in place.
    valid : (H, W) bool array
        Valid pixels.
    keep : (H, W) bool array
        Pixels that kept their label (the others, if valid, are reattached).
    vert : (H-1, W) bool array
        Links between each pixel and the one below it that connect.
    horiz : (H, W-1) bool array
        Links between each pixel and the one to its right that connect.
    passes : int
        Rounds of reattachment.

    Examples
    --------
    >>> labels = np.array([[1, 0, 2], [1, 1, 2]], np.int32)
    >>> keep = np.array([[True, False, True], [True, True, True]])
    >>> vert = np.array([[False, True, False]])
    >>> horiz = np.array([[False, True], [True, True]])
    >>> reattach(labels, np.ones((2, 3), bool), keep, vert, horiz, 1)
    >>> labels.tolist()  # linked right and below: the one below wins
    [[1, 1, 2], [1, 1, 2]]
    """
    h, w = labels.shape
    ys = []
    xs = []
    for y in range(h):
        for x in range(w):
            if valid[y, x] and not keep[y, x]:
                ys.append(y)
                xs.append(x)
    n = len(ys)
    ty = np.array(ys, np.int64)
    tx = np.array(xs, np.int64)
    got = np.zeros(n, np.int32)
    for _ in range(passes):
        if n == 0:
            break
        for i in range(n):
            y, x = ty[i], tx[i]
            g = 0
            if y + 1 < h and vert[y, x]:
                g = labels[y + 1, x]
            if g == 0 and y > 0 and vert[y - 1, x]:
                g = labels[y - 1, x]
            if g == 0 and x + 1 < w and horiz[y, x]:
                g = labels[y, x + 1]
            if g == 0 and x > 0 and horiz[y, x - 1]:
                g = labels[y, x - 1]
            got[i] = g
        m = 0
        for i in range(n):
            labels[ty[i], tx[i]] = got[i]
            if got[i] == 0:
                ty[m] = ty[i]
                tx[m] = tx[i]
                m += 1
        n = m



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


@kernel()
def drop_small(labels: np.ndarray, n: int, min_size: int) -> int:
    """Set the labels of regions under ``min_size`` pixels to 0 and number the others
    ``1..`` in their order, in place; returns how many are left.

    Parameters
    ----------
    labels : (H, W) int32 array
        Region labels ``0..n`` (0: none), changed in place.
    n : int
        Highest label.
    min_size : int
        Smallest region kept, in pixels.

    Returns
    -------
    int
        The number of regions kept.

    Examples
    --------
    >>> labels = np.array([[1, 1, 2, 3, 3, 3]], np.int32)
    >>> drop_small(labels, 3, 2), labels.tolist()
    (2, [[1, 1, 0, 2, 2, 2]])
    """
    h, w = labels.shape
    size = np.zeros(n + 1, np.int64)
    for y in range(h):
        x = 0
        while x < w:  # by runs of one label
            lab = labels[y, x]
            x1 = x + 1
            while x1 < w and labels[y, x1] == lab:
                x1 += 1
            size[lab] += x1 - x
            x = x1
    remap = np.zeros(n + 1, np.int32)
    kept = 0
    for lab in range(1, n + 1):
        if size[lab] >= min_size:
            kept += 1
            remap[lab] = kept
    if kept < n:
        for y in range(h):
            for x in range(w):
                labels[y, x] = remap[labels[y, x]]
    return kept
