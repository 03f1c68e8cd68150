"""Parts of fringe regions whose pixels' own codes contradict their region's order, detached
as regions of their own, over the whole image.

Where two surfaces meet with a phase step close to a whole number of fringes, a fringe of
one joins a fringe of the other into one region, and the larger part's order wins; the
smaller part's codes then disagree with it. :func:`split_disagreeing` finds such parts over
the whole image. A split flagged on a 2 x 2 sample and made at full resolution only inside
each flagged part's box was cheaper (2.5 against 8.2 ms at 1.3 MP) but missed a part 5 rows
tall on the README's sphere-on-plane render and left its pixels an order 7 fringes off
(``tests/test_parts.py``): it is kept, as the prototype that measures it, in
``benchmarks/sampled_parts.py``.

Examples
--------
>>> import numpy as np
>>> labels = np.ones((80, 120), np.int32)
>>> truth = np.where(np.arange(120) < 90, 3, 5)[None].repeat(80, axis=0)
>>> new, n, detached = split_disagreeing(labels, 1, np.array([-1, 3]), lambda k: k == truth)
>>> n, detached, np.unique(new[:, :90]).tolist(), np.unique(new[:, 90:]).tolist()
(2, 1, [1], [2])
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
from scipy import ndimage

from .parts_jit import dense_tile, pixel_orders, window_seeds

Agreement = Callable[[np.ndarray], np.ndarray]


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
