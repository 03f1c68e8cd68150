"""Compiled passes of the fringe regions (:mod:`bistair.core.regions`), their second half:
the kept pixels labelled by union-find over row tiles (with per-region counts gathered in
the same scan), dropped pixels reattached, the final numbering, and the wraps between
regions. The links they label are the first half, :mod:`.regions_jit`.

A decode runs them after :func:`~.regions_jit.link_bits`
(:func:`bistair.core.regions.label_fringes`):

2. :func:`label_kept`: provisional labels of the kept pixels (4-connected), their regions
   numbered ``1..n`` in raster order of each region's first pixel (as
   ``cv2.connectedComponents(kept, connectivity=4)`` numbers them), the valid pixels not
   kept reattached to a region they link to, pixels and pixels of a second mask counted
   per region;
3. :func:`relabel`: the final labels, written row by row in raster order (the hook for
   sums per (region, row): see its docstring).

Each gives exactly what the passes it replaced gave (``cv2.connectedComponents``,
``reattach`` and ``drop_small`` of bistair 0.x, kept in ``tests/support/regions_before.py``
as the tests' oracle).

Examples
--------
>>> import numpy as np
>>> from bistair.core.regions_jit import NO_CUTS, link_bits
>>> x = np.arange(60, dtype=np.float32) + np.float32(0.5)
>>> phi = np.tile(x * np.float32(2 * np.pi / 30) % np.float32(2 * np.pi), (4, 1))
>>> bits = link_bits(phi, np.ones(phi.shape, bool), np.full(phi.shape, 0.02, np.float32),
...                  1.0, 1, 0.3, NO_CUTS, NO_CUTS, False)
>>> labels, roots, n, size, _ = label_kept(bits, NO_CUTS, False, TILE, 3)
>>> n, size.tolist()  # column 29 (dropped by the wrap) reattached
(2, [0, 120, 120])
"""

from __future__ import annotations

import numpy as np

from .jit import PI32, called, inline, kernel
from .regions_jit import KEPT, LINK_DOWN, LINK_RIGHT, TILE, VALID

prange = range  # numba's prange once the first kernel of this module compiles (its helpers too)


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
    >>> from bistair.core.regions_jit import NO_CUTS
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
