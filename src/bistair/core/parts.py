"""Parts of fringe regions whose pixels' own codes contradict their region's order, detached
as regions of their own: over the whole image, or (for an agreement marked :func:`windowed`)
detected on a 2 x 2 sample and split at full resolution inside each flagged part's box.

Where two surfaces meet with a phase step close to a whole number of fringes, a fringe of
one joins a fringe of the other into one region, and the larger part's order wins; the
smaller part's codes then disagree with it. :func:`split_disagreeing` finds such parts over
the whole image (the reference); :func:`split_parts`, what the decoders run, finds them
from a sample and the full-resolution pixels of a few boxes
(:func:`sample_boxes`, :func:`split_in_boxes`) for an agreement marked :func:`windowed`,
and over the whole image for any other. No codec marks its agreement so: the sample (every
second row and column) missed a part 5 rows tall on the README's sphere-on-plane render and
left its pixels an order 7 fringes off (``tests/test_parts.py``).

Examples
--------
>>> import numpy as np
>>> labels = np.ones((80, 120), np.int32)
>>> truth = np.where(np.arange(120) < 90, 3, 5)[None].repeat(80, axis=0)
>>> @windowed
... def agrees(k, at=ALL):
...     return k == truth[at]
>>> new, n, detached = split_parts(labels, 1, np.array([-1, 3]), agrees)
>>> n, detached, np.unique(new[:, :90]).tolist(), np.unique(new[:, 90:]).tolist()
(2, 1, [1], [2])
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
from scipy import ndimage

from .resolve_jit import dense_tile, pixel_orders, window_seeds

Agreement = Callable[..., np.ndarray]
ALL = (slice(None), slice(None))  # the whole image, as ``at``
STEP = 2  # the sample: every STEP-th row and column
SAMPLE_WINDOW = 4  # the sample's neighbourhood, in sample pixels
TILE = 8  # the sample's seeds are gathered in tiles of TILE x TILE sample pixels
SAMPLE_SHARE = 0.45  # flags a part on the sample: more than this share of the decided pixels bad
Box = tuple[int, int, int, int]  # y0, y1, x0, x1 (ends excluded)


def split_disagreeing(labels: np.ndarray, n: int, k_reg: np.ndarray, agrees: Agreement,
                      window: int = 7, share: float = 0.7, min_size: int = 30
                      ) -> tuple[np.ndarray, int, int]:
    """Detach the parts of regions whose pixels' codes contradict the region's order.

    Where two surfaces meet with a phase step close to a whole number of fringes, a fringe
    of one joins a fringe of the other into one region, and the larger part's order wins.
    The smaller part's codes then disagree with it: pixels in a neighbourhood
    (``window`` x ``window``) where more than ``share`` of the decided pixels disagree seed a
    part, which grows over the region's other disagreeing pixels. Parts of at least
    ``min_size`` pixels become regions of their own; smaller ones are left undecided.
    Returns ``(labels, n, parts detached)``.

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions, 0 outside any.
    n : int
        Number of regions.
    k_reg : (n+1,) int array
        The order per region, -1 where undecided.
    agrees : callable
        ``agrees(order) -> bool array``: the pixels whose own codes fit a per-pixel order
        (-1 where undecided).
    window : int
        Side of the neighbourhood, in pixels.
    share : float
        Share of a neighbourhood's decided pixels that must disagree to seed a part.
    min_size : int
        Smallest part made a region, in pixels.

    Returns
    -------
    labels : (H, W) array
        The labels with the detached parts numbered from ``n + 1`` and the parts too small
        set to 0 (a new array once a part is found, else the input itself).
    n : int
        The new number of regions.
    detached : int
        Parts made regions.

    Examples
    --------
    >>> labels = np.ones((20, 40), np.int32)
    >>> truth = np.where(np.arange(40) < 30, 3, 5)[None].repeat(20, axis=0)
    >>> new, n, detached = split_disagreeing(labels, 1, np.array([-1, 3]), lambda k: k == truth)
    >>> n, detached, np.unique(new[:, :30]).tolist(), np.unique(new[:, 30:]).tolist()
    (2, 1, [1], [2])
    """
    k_pix = pixel_orders(labels, np.asarray(k_reg))
    bad = np.asarray(agrees(k_pix), bool)  # a new array (changed in place below)
    decided = k_pix >= 0
    del k_pix
    bad = np.logical_not(bad, out=bad if bad.flags.writeable else None)
    bad &= decided
    if not dense_tile(bad, decided, share, 8):  # a cheap test: no part anywhere
        return labels, n, 0
    # the window shares only matter at bad pixels: count them in their bounding box, with a
    # margin the window cannot see past
    ys, xs = np.flatnonzero(bad.any(axis=1)), np.flatnonzero(bad.any(axis=0))
    m = 2 * window
    box = (slice(max(ys[0] - m, 0), ys[-1] + m + 1), slice(max(xs[0] - m, 0), xs[-1] + m + 1))
    seeds = np.zeros(bad.shape, bool)
    close = min(bad[box].shape) < window
    if not close:
        seeds[box], close = window_seeds(bad[box], decided[box], window, share)
    if close:  # a share at the limit: decide as the float32 window means always did
        num = ndimage.uniform_filter(bad[box].astype(np.float32), window)
        den = ndimage.uniform_filter(decided[box].astype(np.float32), window)
        seeds[box] = bad[box] & (num > share * den)
    if not seeds.any():
        return labels, n, 0
    del decided
    _, parts = cv2.connectedComponents(bad.view(np.uint8), connectivity=4, ltype=cv2.CV_32S)
    del bad
    seeded = np.zeros(int(parts.max()) + 1, bool)
    seeded[parts[seeds]] = True
    seeded[0] = False
    del seeds
    grown = seeded[parts]  # the bad pixels connected to a seed
    del parts  # (one label image at a time: 4 bytes a pixel each)
    _, parts = cv2.connectedComponents(grown.view(np.uint8), connectivity=4,
                                       ltype=cv2.CV_32S)
    key = parts[grown].astype(np.int64) * (n + 1) + labels[grown]
    del parts
    uniq, inv, size = np.unique(key, return_inverse=True, return_counts=True)
    new = np.where(size >= min_size, n + 1 + np.cumsum(size >= min_size) - 1, 0)
    labels = labels.copy()
    labels[grown] = new[inv]
    return labels, n + int((size >= min_size).sum()), int((size >= min_size).sum())


def windowed(agrees: Agreement) -> Agreement:
    """Mark ``agrees(order, at)`` as an agreement that can judge a part of the image: given
    the orders of the pixels ``image[at]`` (``at``: a tuple of two slices, :data:`ALL` for
    the whole image), it returns which of those pixels' own codes fit them. Such an agreement
    lets :func:`split_parts` work from a sample; any other is judged on the whole image.

    Parameters
    ----------
    agrees : callable
        ``agrees(order, at=ALL) -> bool array`` of ``order``'s shape (-1: undecided).

    Returns
    -------
    callable
        ``agrees`` itself, marked.

    Examples
    --------
    >>> codes = np.arange(12).reshape(3, 4)
    >>> @windowed
    ... def agrees(k, at=ALL):
    ...     return k == codes[at]
    >>> agrees(codes[::2, 1:3], (slice(None, None, 2), slice(1, 3))).all(), agrees.windowed
    (np.True_, True)
    """
    agrees.windowed = True  # type: ignore[attr-defined]
    return agrees


def split_parts(labels: np.ndarray, n: int, k_reg: np.ndarray, agrees: Agreement,
                window: int = 7, share: float = 0.7, min_size: int = 30
                ) -> tuple[np.ndarray, int, int]:
    """:func:`split_disagreeing` from a sample: the parts are flagged on every second row
    and column (:func:`sample_boxes`), then found and detached at full resolution inside
    each flagged part's box alone (:func:`split_in_boxes`), with the same labels, numbering
    and counts as :func:`split_disagreeing` gives whenever every seed of a part lies in a
    box (measured: every rendered scene of ``benchmarks/sampled_parts.py`` and every real
    capture in ../shared/data; ``tests/test_parts.py``).

    An agreement not marked :func:`windowed`, an image under ``8 * window`` pixels on a
    side, a bad share within rounding of ``share`` in a box, or seeds in boxes without a
    dense tile there (where the whole image decides) go to :func:`split_disagreeing`.

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions, 0 outside any.
    n : int
        Number of regions.
    k_reg : (n+1,) int array
        The order per region, -1 where undecided.
    agrees : callable
        ``agrees(order, at)`` (:func:`windowed`), or ``agrees(order)`` for the whole image.
    window, share, min_size
        As :func:`split_disagreeing`.

    Returns
    -------
    labels, n, detached
        As :func:`split_disagreeing`.

    Examples
    --------
    >>> labels = np.ones((60, 100), np.int32)
    >>> truth = np.where(np.arange(100) < 70, 3, 5)[None].repeat(60, axis=0)
    >>> new, n, detached = split_parts(labels, 1, np.array([-1, 3]),
    ...                                windowed(lambda k, at=ALL: k == truth[at]))
    >>> n, detached, np.unique(new[:, 70:]).tolist()
    (2, 1, [2])
    """
    if not getattr(agrees, "windowed", False) or min(labels.shape) < 8 * window:
        return split_disagreeing(labels, n, k_reg, agrees, window, share, min_size)
    boxes = sample_boxes(labels, k_reg, agrees, window)
    if not boxes:
        return labels, n, 0
    found = split_in_boxes(labels, n, k_reg, agrees, boxes, window, share, min_size)
    if found is None:
        return split_disagreeing(labels, n, k_reg, agrees, window, share, min_size)
    return found


def _bad(labels: np.ndarray, k_reg: np.ndarray, agrees: Agreement,
         at: tuple[slice, slice]) -> tuple[np.ndarray, np.ndarray]:
    """The decided pixels of ``labels[at]`` and those whose codes disagree with their
    region's order."""
    k = pixel_orders(np.ascontiguousarray(labels[at]), np.asarray(k_reg))  # (faster so)
    decided = k >= 0
    bad = np.asarray(agrees(k, at), bool)
    bad = np.logical_not(bad, out=bad if bad.flags.writeable else None)
    bad &= decided
    return bad, decided


def sample_boxes(labels: np.ndarray, k_reg: np.ndarray, agrees: Agreement,
                 window: int = 7) -> list[Box]:
    """Boxes of the image around the parts that disagree on a sample: every
    :data:`STEP`-th row and column, where more than :data:`SAMPLE_SHARE` of a
    :data:`SAMPLE_WINDOW`-pixel neighbourhood's decided pixels disagree (a part of 30 px
    still shows about 7 pixels there; at 0.5, 5 of 400 drawn scenes of ``tests/test_parts.py``
    lost a part 3 px wide along the image's edge, none at 0.45). The flagged pixels' tiles
    of :data:`TILE` x :data:`TILE` sample pixels, each widened by one tile (at least
    ``2 * window`` full-resolution pixels), give a box per cluster of tiles (8-connected);
    boxes that overlap are merged.

    Parameters
    ----------
    labels : (H, W) int32 array
        Fringe regions, 0 outside any.
    k_reg : (n+1,) int array
        The order per region, -1 where undecided.
    agrees : callable
        A :func:`windowed` agreement.
    window : int
        The full-resolution neighbourhood (the margin must reach ``2 * window``).

    Returns
    -------
    list of (y0, y1, x0, x1)
        Full-resolution boxes (ends excluded), none overlapping; empty when no part shows.

    Examples
    --------
    >>> labels = np.ones((64, 96), np.int32)
    >>> truth = np.full(labels.shape, 3)
    >>> truth[8:20, 16:28] = truth[40:50, 70:80] = 5
    >>> sample_boxes(labels, np.array([-1, 3]), windowed(lambda k, at=ALL: k == truth[at]))
    [(0, 64, 0, 96)]
    """
    h, w = labels.shape
    bad, decided = _bad(labels, k_reg, agrees, (slice(None, None, STEP),) * 2)
    if min(bad.shape) < SAMPLE_WINDOW:
        return [(0, h, 0, w)]
    seeds, _ = window_seeds(bad, decided, SAMPLE_WINDOW, SAMPLE_SHARE)
    # the seeds' tiles of TILE x TILE sample pixels, each widened by a tile (2 * TILE full
    # pixels, at least 2 * window): each cluster of those (8-connected) gives a box; a part
    # seeded in several is made whole at full resolution (split_in_boxes)
    rows = np.flatnonzero(seeds.any(axis=1))  # (seeds are few: found row by row)
    if rows.size == 0:
        return []
    ry, rx = np.nonzero(seeds[rows])
    tiles = np.zeros((-(-seeds.shape[0] // TILE), -(-seeds.shape[1] // TILE)), np.uint8)
    tiles[rows[ry] // TILE, rx // TILE] = 1
    tiles = cv2.dilate(tiles, np.ones((3, 3), np.uint8))
    count, _, stats, _ = cv2.connectedComponentsWithStats(tiles, connectivity=8)
    full = STEP * TILE
    boxes = [(ty * full, min((ty + bh) * full, h), tx * full, min((tx + bw) * full, w))
             for tx, ty, bw, bh in (stats[c, :4].tolist() for c in range(1, count))]
    return merge_boxes(boxes)


def merge_boxes(boxes: list[Box], reach: int = 0) -> list[Box]:
    """Boxes that overlap once each is widened by ``reach`` pixels on every side, merged
    into their bounding box until none do; sorted.

    Parameters
    ----------
    boxes : list of (y0, y1, x0, x1)
        Boxes, ends excluded.
    reach : int
        How far apart two boxes may lie and still be merged (each widened by it).

    Returns
    -------
    list of (y0, y1, x0, x1)

    Examples
    --------
    >>> merge_boxes([(0, 5, 0, 5), (4, 9, 4, 9), (20, 30, 0, 3)])
    [(0, 9, 0, 9), (20, 30, 0, 3)]
    >>> merge_boxes([(0, 5, 0, 5), (8, 9, 0, 5)], reach=2)
    [(0, 9, 0, 5)]
    """
    boxes = sorted(boxes)
    merged = True
    while merged:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                if (a[0] < b[1] + 2 * reach and b[0] < a[1] + 2 * reach
                        and a[2] < b[3] + 2 * reach and b[2] < a[3] + 2 * reach):
                    boxes[i] = (min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]),
                                max(a[3], b[3]))
                    del boxes[j]
                    merged = True
                    break
            if merged:
                break
    return sorted(boxes)


def _outer(box: Box, window: int, h: int, w: int, tile: int = 8) -> Box:
    """``box`` widened by ``window`` pixels on every side, out to the ``tile``-pixel grid
    from the image's top left (the grid of ``dense_tile``), within the image."""
    y0, y1, x0, x1 = box
    return ((max(y0 - window, 0) // tile) * tile, min(-(-(y1 + window) // tile) * tile, h),
            (max(x0 - window, 0) // tile) * tile, min(-(-(x1 + window) // tile) * tile, w))


def split_in_boxes(labels: np.ndarray, n: int, k_reg: np.ndarray, agrees: Agreement,
                   boxes: list[Box], window: int = 7, share: float = 0.7,
                   min_size: int = 30) -> tuple[np.ndarray, int, int] | None:
    """:func:`split_disagreeing` with its seeds taken inside ``boxes`` alone: at full
    resolution, in each box widened by ``window`` (so that every window around a pixel of
    the box counts what it counts in the whole image), the seeds of the box grow over their
    disagreeing pixels; a part that reaches the widened box's edge widens the box and the
    boxes are judged again, so that every part is whole. The parts are numbered as
    :func:`split_disagreeing` numbers them (by their first pixel in raster order, then the
    region).

    Parameters
    ----------
    labels, n, k_reg, agrees, window, share, min_size
        As :func:`split_parts`.
    boxes : list of (y0, y1, x0, x1)
        Where seeds may lie (:func:`sample_boxes`).

    Returns
    -------
    (labels, n, detached) or None
        As :func:`split_disagreeing` (the input labels when no seed lies in a box), or
        ``None`` when a box cannot decide alone: a neighbourhood's bad share within
        rounding of ``share``, or seeds without an 8 x 8 tile dense enough in any box
        (the whole image's test that :func:`split_disagreeing` applies first).

    Examples
    --------
    >>> labels = np.ones((64, 96), np.int32)
    >>> truth = np.full(labels.shape, 3)
    >>> truth[8:20, 16:28] = truth[40:50, 70:80] = 5
    >>> agrees = windowed(lambda k, at=ALL: k == truth[at])
    >>> new, n, detached = split_in_boxes(labels, 1, np.array([-1, 3]), agrees,
    ...                                   [(5, 25, 15, 35)])  # the first part's box alone
    >>> n, detached, int((new == 2).sum())
    (2, 1, 144)
    """
    h, w = labels.shape
    widened = True
    while widened:  # until no part runs on past its widened box
        boxes = merge_boxes(boxes, window + 8)  # their widened boxes apart
        widened, dense = False, False
        flats, ids, firsts, judged = [], [], [], []
        for box in boxes:
            oy0, oy1, ox0, ox1 = _outer(box, window, h, w)
            at = (slice(oy0, oy1), slice(ox0, ox1))
            bad, decided = _bad(labels, k_reg, agrees, at)
            if min(bad.shape) < window:
                return None
            seeds, close = window_seeds(bad, decided, window, share)
            if close:
                return None
            inner = np.zeros(bad.shape, bool)
            inner[box[0] - oy0:box[1] - oy0, box[2] - ox0:box[3] - ox0] = True
            seeds &= inner
            judged.append(box)
            if not seeds.any():
                continue
            dense = dense or dense_tile(bad, decided, share, 8)
            _, parts = cv2.connectedComponents(bad.view(np.uint8), connectivity=4,
                                               ltype=cv2.CV_32S)
            seeded = np.zeros(int(parts.max()) + 1, bool)
            seeded[parts[seeds]] = True
            seeded[0] = False
            grown = seeded[parts]
            ys, xs = np.nonzero(grown)
            if ((oy0 > 0 and grown[0].any()) or (oy1 < h and grown[-1].any())
                    or (ox0 > 0 and grown[:, 0].any()) or (ox1 < w and grown[:, -1].any())):
                # a part runs on past the widened box: the box takes it in, judged again
                judged[-1] = (min(box[0], oy0 + int(ys.min())),
                              max(box[1], oy0 + int(ys.max()) + 1),
                              min(box[2], ox0 + int(xs.min())),
                              max(box[3], ox0 + int(xs.max()) + 1))
                widened = True
                continue
            part = parts[ys, xs]
            uniq, first = np.unique(part, return_index=True)
            flat = (ys + oy0).astype(np.int64) * w + (xs + ox0)
            ids.append(np.searchsorted(uniq, part) + sum(f.size for f in firsts))
            flats.append(flat)
            firsts.append(flat[first])
        boxes = judged
    if not flats:
        return labels, n, 0
    if not dense:
        return None
    flat, part = np.concatenate(flats), np.concatenate(ids)
    rank = np.argsort(np.argsort(np.concatenate(firsts)))  # parts in raster order
    key = rank[part].astype(np.int64) * (n + 1) + labels.ravel()[flat]
    uniq, inv, size = np.unique(key, return_inverse=True, return_counts=True)
    new = np.where(size >= min_size, n + 1 + np.cumsum(size >= min_size) - 1, 0)
    labels = labels.copy()
    labels.ravel()[flat] = new[inv]
    return labels, n + int((size >= min_size).sum()), int((size >= min_size).sum())
