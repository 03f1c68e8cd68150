"""The fringe-region passes of bistair before issue 32 (02b6580), kept as the oracle of their
replacements in bistair.core.regions_jit: ``period_jump_links`` + ``fringe_links`` (the
links), ``cv2.connectedComponents`` + ``reattach`` + ``drop_small`` (the regions) and
``keep_coherent`` (the coherent dim pixels), compiled here with plain ``numba.njit`` (not
bistair's kernel cache: nothing here is compiled at install time)."""

from __future__ import annotations

import math

import cv2
import numba
import numpy as np
from numba import prange

from bistair.core.jit import PI32, TWO_PI32
from bistair.core.regions import cut_reference as default_cut
from bistair.core.regions import fringe_direction


@numba.njit(inline="always", cache=True, error_model="numpy")
def _wrapped(raw):
    d = raw + PI32
    if d >= TWO_PI32:
        d = d - TWO_PI32
    elif d < 0:
        d = d + TWO_PI32
    return d - PI32


@numba.njit(inline="always", cache=True, error_model="numpy")
def _jump(px: np.float32, py: np.float32, pn: np.float32, qx: np.float32, qy: np.float32,
          qn: np.float32, noise_p: np.float32, noise_q: np.float32, rel: np.float32,
          half: np.float32) -> bool:
    """Whether two mean gradients differ by more than ``rel`` of the larger and four times
    their noise (float32, as :func:`support.reference.period_jumps` computes it)."""
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



@numba.njit(inline="always", cache=True, error_model="numpy")
def _steep(px: np.float32, py: np.float32, qx: np.float32, qy: np.float32,
           rel: np.float32) -> bool:
    """Not clearly below ``rel`` of the larger gradient: :func:`_jump`'s first test, which
    most links fail (True for NaN)."""
    dx, dy = px - qx, py - qy
    return not (dx * dx + dy * dy < rel * rel * max(px * px + py * py, qx * qx + qy * qy)
                * np.float32(0.9999))



@numba.njit(inline="always", cache=True, error_model="numpy")
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




@numba.njit(parallel=True, cache=True, error_model="numpy", nogil=True)
def period_jump_links(phi: np.ndarray, valid: np.ndarray, noise: np.ndarray, half: int,
                      relative: float) -> tuple[np.ndarray, np.ndarray]:
    """The links across which the fringes' spacing or slant jumps (see
    :func:`support.reference.period_jumps`): ``(vertical (H-1, W), horizontal (H, W-1))``.

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
    """
    h, w = phi.shape
    horiz = np.zeros((h, w - 1), np.bool_)
    vert = np.zeros((h - 1, w), np.bool_)
    block = 32
    for b in prange((h + block - 1) // block):
        _jump_rows(phi, valid, noise, half, relative, b * block, min(b * block + block, h),
                   vert, horiz)
    return vert, horiz



@numba.njit(cache=True, error_model="numpy", nogil=True)
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



@numba.njit(parallel=True, cache=True, error_model="numpy", nogil=True)
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



@numba.njit(cache=True, error_model="numpy", nogil=True)
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




@numba.njit(cache=True, error_model="numpy", nogil=True)
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

@numba.njit(parallel=True, cache=True, error_model="numpy", nogil=True)
def keep_coherent(labels: np.ndarray, weak: np.ndarray, strong: np.ndarray, n: int,
                  min_strong: int, min_size: int, min_region: int) -> np.ndarray:
    """``strong | (weak & region kept)``, a region kept when it holds ``min_region`` pixels
    and ``min_strong`` strong pixels or ``min_size`` pixels (see
    :func:`bistair.core.measure.coherent_pixels`; ``min_region``: the regions
    :func:`bistair.core.regions.fringe_regions` would drop as too small).

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions of the weak mask, 0 outside any (never kept).
    weak : (H, W) bool array
        Pixels with at least the lower modulation threshold.
    strong : (H, W) bool array
        Pixels with at least the full modulation threshold.
    n : int
        Highest label.
    min_strong : int
        Strong pixels that keep a region.
    min_size : int
        Pixels in all that keep a region.
    min_region : int
        Pixels a region needs to be kept at all.

    Returns
    -------
    (H, W) bool array
        The pixels to count as valid.
    """
    h, w = labels.shape
    # counted in blocks of rows (each its own counts: as many as leave them under 8 MB),
    # a run of one label along a row at a time; pixels outside the weak mask are label 0
    blocks = min(16, max(1, h // 256), max(1, (1 << 20) // (n + 1)))
    size = np.zeros((blocks, n + 1), np.int32)
    bright = np.zeros((blocks, n + 1), np.int32)
    for b in prange(blocks):
        sizes = size[b]
        brights = bright[b]
        for y in range(b * h // blocks, (b + 1) * h // blocks):
            run = 0
            run_size = 0
            run_bright = 0
            for x in range(w):
                lab = labels[y, x] if weak[y, x] else 0
                if lab != run:
                    sizes[run] += run_size
                    brights[run] += run_bright
                    run = lab
                    run_size = 0
                    run_bright = 0
                run_size += 1
                run_bright += strong[y, x]
            sizes[run] += run_size
            brights[run] += run_bright
    keep = np.zeros(n + 1, np.bool_)
    for i in range(1, n + 1):
        total = 0
        lit = 0
        for b in range(blocks):
            total += size[b, i]
            lit += bright[b, i]
        keep[i] = (lit >= min_strong or total >= min_size) and total >= min_region
    out = np.empty((h, w), np.bool_)
    for y in prange(h):
        for x in range(w):
            out[y, x] = strong[y, x] or (weak[y, x] and keep[labels[y, x]])
    return out




def links_before(phi, valid, cut, sign, noise, boundaries=None):
    """``(vert, horiz, keep)`` of the fringe regions as bistair 02b6580 made them."""
    jump_v, jump_h = period_jump_links(phi, valid, noise, 3, 0.3)
    if boundaries is not None:
        jump_v |= boundaries[0]
        jump_h |= boundaries[1]
    return fringe_links(phi, valid, float(np.float32(cut)), sign, noise, jump_v, jump_h)


def regions_before(phi, valid, cut=None, min_size=20, phase_noise=None, boundaries=None,
                   sign=None):
    """``bistair.core.regions.fringe_regions`` of 02b6580: ``(labels, n)``."""
    valid = np.asarray(valid, dtype=bool)
    if cut is None:
        cut = default_cut(phi, valid)
    h, w = phi.shape
    noise = (np.full((h, w), 0.02, np.float32) if phase_noise is None
             else np.ascontiguousarray(phase_noise, dtype=np.float32))
    if sign is None:
        sign = fringe_direction(phi, valid)
    vert, horiz, keep = links_before(phi, valid, cut, sign, noise, boundaries)
    n, labels = cv2.connectedComponents(keep.view(np.uint8), connectivity=4,
                                        ltype=cv2.CV_32S)
    n -= 1
    reattach(labels, valid, keep, vert, horiz, 3)
    if min_size > 1:
        n = drop_small(labels, n, min_size)
    return labels, int(n)


def coherent_before(phi, weak, strong, phase_noise, min_strong=10, min_size=100):
    """``bistair.core.measure.coherent_pixels`` of 02b6580."""
    labels, n = regions_before(phi, weak, min_size=1, phase_noise=phase_noise)
    return keep_coherent(labels, weak, strong, n, min_strong, min_size, 20)


class Watch:
    """While open (``with Watch() as seen``), every fringe-region labelling a decode runs
    is checked against the passes above on the same arguments: the links of each
    ``link_bits`` call and of the links a labelling takes over from another
    (``links_before``), the labels of each ``fringe_regions`` call
    (``regions_before``) and the pixels of each ``coherent_pixels`` call
    (``coherent_before``). ``seen`` counts the calls per kind; ``differ`` lists the calls
    that did not give the same (a decode goes on with the new result)."""

    def __init__(self) -> None:
        self.seen = {"link_bits": 0, "fringe_regions": 0, "coherent_pixels": 0,
                     "codec cuts": 0, "shared links": 0}
        self.differ: list[str] = []
        self._undo: list[tuple] = []

    def __enter__(self) -> Watch:
        import sys

        from bistair.core import measure, regions

        def links(phi, valid, noise, cut, sign, relative, cut_v, cut_h, cuts):
            bits = link_bits(phi, valid, noise, cut, sign, relative, cut_v, cut_h, cuts)
            vert, horiz, keep = links_before(phi, valid, cut, sign, noise,
                                             (cut_v, cut_h) if cuts else None)
            self.seen["link_bits"] += 1
            self.seen["codec cuts"] += int(cuts and (cut_v.any() or cut_h.any()))
            if not same_links(bits, vert, horiz, keep, valid):
                self.differ.append(f"link_bits {phi.shape}")
            return bits

        def fringes(phi, valid, cut=None, min_size=20, phase_noise=None, boundaries=None,
                    sign=None, links=None):
            labels, n = fringe_regions(phi, valid, cut, min_size, phase_noise, boundaries,
                                       sign, links)
            want, n_want = regions_before(phi, valid, cut, min_size, phase_noise, boundaries,
                                          sign)
            self.seen["fringe_regions"] += 1
            if n != n_want or not np.array_equal(labels, want) or labels.dtype != want.dtype:
                self.differ.append(f"fringe_regions {phi.shape} min_size {min_size}")
            return labels, n

        def coherent(phi, weak, strong, phase_noise, min_strong=10, min_size=100):
            got, links = coherent_pixels(phi, weak, strong, phase_noise, min_strong,
                                         min_size)
            self.seen["coherent_pixels"] += 1
            if not np.array_equal(got, coherent_before(phi, weak, strong, phase_noise,
                                                       min_strong, min_size)):
                self.differ.append(f"coherent_pixels {phi.shape}")
            return got, links

        def shared(links, phi, valid, noise, cut, sign, phase_noise):
            bits, cut, sign = shared_links(links, phi, valid, noise, cut, sign, phase_noise)
            if bits is not None:  # links taken over: those of the labelling's own pass
                self.seen["shared links"] += 1
                self.seen["link_bits"] += 1
                vert, horiz, keep = links_before(phi, valid, cut, sign, noise, None)
                if not same_links(bits, vert, horiz, keep, valid):
                    self.differ.append(f"shared links {phi.shape}")
            return bits, cut, sign

        def cuts_added(bits, cut_v, cut_h):
            self.seen["codec cuts"] += int(cut_v.any() or cut_h.any())
            return cut_links(bits, cut_v, cut_h)

        link_bits = regions.link_bits
        fringe_regions = regions.fringe_regions
        coherent_pixels = measure.coherent_pixels
        shared_links = regions._shared_links
        cut_links = regions.cut_links
        self._patch(regions, "link_bits", links)
        self._patch(regions, "_shared_links", shared)
        self._patch(regions, "cut_links", cuts_added)
        for module in list(sys.modules.values()):  # where the codecs imported it
            if getattr(module, "__name__", "").startswith("bistair.") and \
                    getattr(module, "fringe_regions", None) is fringe_regions:
                self._patch(module, "fringe_regions", fringes)
        self._patch(measure, "coherent_pixels", coherent)
        return self

    def _patch(self, module, name: str, value) -> None:
        self._undo.append((module, name, getattr(module, name)))
        setattr(module, name, value)

    def __exit__(self, *exc) -> None:
        for module, name, value in reversed(self._undo):
            setattr(module, name, value)


def same_links(bits, vert, horiz, keep, valid) -> bool:
    """Whether the bytes of ``link_bits`` say what the three masks and the validity say
    (and no link leaves the image)."""
    from bistair.core.regions_jit import KEPT, LINK_DOWN, LINK_RIGHT, VALID

    return (np.array_equal((bits & KEPT) > 0, keep)
            and np.array_equal((bits & VALID) > 0, valid)
            and np.array_equal((bits[:, :-1] & LINK_RIGHT) > 0, horiz)
            and np.array_equal((bits[:-1] & LINK_DOWN) > 0, vert)
            and not (bits[:, -1] & LINK_RIGHT).any() and not (bits[-1] & LINK_DOWN).any()
            and not (bits & ~np.uint8(15)).any())
