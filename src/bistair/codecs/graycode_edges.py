"""The orders of a shifted Gray code's pixels beside its edges, from their fringe region.

A shifted Gray code (``gray_offset 0.5``, cyclic or not) has its edges mid-fringe, where the
wrapped phase is near pi and continuous: blur and noise read the code one level off there,
which per pixel gives the order one off (``k + 1`` where ``phi < pi``, ``k - 1`` where
``phi >= pi``; across the cyclic code's wrap, modulo the fringes). SLMaster's decoder
(``computeFloorMap``) takes those pixels' orders by the side of their row's phase wrap; here
each fringe region (the pixels between two phase wraps, cut where the phase jumps:
:func:`~bistair.core.regions.fringe_regions`) is settled by its pixels far from the code's
edges (phase in the outer thirds, where the code is read mid-cell), and a pixel beside the
edge (phase in the middle third) that reads the region's order, or the order one off on
the side its phase says, takes the region's order. A pixel that reads anything else, or
whose region is not settled, keeps what its own evidence gave it.

Examples
--------
>>> import numpy as np
>>> from bistair.codecs import encode, make_spec
>>> from bistair.codecs.base import measure_shifts
>>> from bistair.codecs.graycode import code_columns
>>> from bistair.core.captures import prepare
>>> spec = make_spec("graycode", width=240, height=32, period=30, gray_offset=0.5)
>>> cols = prepare(encode(spec), spec.frame_count, spec.method)
>>> fs = measure_shifts(cols, spec)
>>> read = code_columns(cols, spec, fs).code
>>> read[:, 44] = 2  # beside the edge of fringe 1's code (phase just under pi): one off
>>> orders = read.copy()
>>> orders[:, 44] = -1
>>> out, taken = edge_orders(fs, read, orders, spec.fringes)
>>> int(taken), out[0, 40:48].tolist()
(32, [1, 1, 1, 1, 1, 1, 1, 1])
"""

from __future__ import annotations

import numpy as np

from ..core.measure import FringeSet
from ..core.regions import fringe_regions
from ..core.resolve import code_evidence

# beside the code's edge: the phase within EDGE_BAND of pi (the middle third, SLMaster's)
EDGE_BAND = np.pi / 3
# a region is settled where over SETTLED of at least MIN_FAR of its far pixels agree
SETTLED = 0.95
MIN_FAR = 20


def edge_orders(fs: FringeSet, read: np.ndarray, orders: np.ndarray, fringes: int,
                cyclic: bool = False, regions: tuple[np.ndarray, int] | None = None,
                settled: float = SETTLED, min_far: int = MIN_FAR
                ) -> tuple[np.ndarray, int]:
    """The orders of a shifted Gray code's pixels beside its edges, from their region.

    Parameters
    ----------
    fs : FringeSet
        Stage 1: the wrapped phase, validity and phase noise the regions are cut by.
    read : numpy.ndarray
        (H, W) int32 orders as read from the code (-1 where none).
    orders : numpy.ndarray
        (H, W) int32 orders the pixels' own evidence carries (-1 elsewhere); the far
        pixels among them settle their regions.
    fringes : int
        Fringes across the coded axis.
    cyclic : bool, default False
        The code wraps cyclically (``gray_wrap 1``): one off is taken modulo ``fringes``.
    regions : tuple of (numpy.ndarray, int), optional
        The fringe regions of ``fs`` over the pixels read, if already cut.
    settled : float, default SETTLED
        Share of a region's far pixels that must carry one order.
    min_far : int, default MIN_FAR
        Far pixels a region needs.

    Returns
    -------
    orders : numpy.ndarray
        (H, W) int32: ``orders`` with the pixels beside the edges given their region's.
    taken : int
        The pixels whose order changed.

    Examples
    --------
    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.graycode import code_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("graycode", width=240, height=32, period=30, gray_offset=0.5)
    >>> cols = prepare(encode(spec), spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> read = code_columns(cols, spec, fs).code
    >>> orders = read.copy()
    >>> orders[:, 42:48] = -1  # beside the code's edge at x = 45: left out
    >>> read[:16, 44] = 2  # and misread one up in half the rows
    >>> orders, taken = edge_orders(fs, read, orders, spec.fringes)
    >>> taken, orders[0, 40:50].tolist() == orders[20, 40:50].tolist() == [1] * 10
    (192, True)
    """
    read_any = read >= 0
    near = read_any & (np.abs(fs.phi - np.float32(np.pi)) < np.float32(EDGE_BAND))
    if regions is None:
        regions = fringe_regions(fs.phi, fs.valid & read_any, phase_noise=fs.phase_noise)
    labels, n = regions
    far = np.where(near, -1, orders)
    shares = code_evidence(labels, n, far, fringes)
    count = np.bincount(labels[far >= 0], minlength=n + 1)
    order = np.where((shares.max(axis=1) > settled) & (count >= min_far),
                     shares.argmax(axis=1), -1)
    order[0] = -1
    idx = np.flatnonzero(near | (read_any & (orders < 0)))
    region_k = order[labels.ravel()[idx]]
    k_read = read.ravel()[idx]
    beside = region_k + np.where(fs.phi.ravel()[idx] < np.pi, 1, -1)
    if cyclic:
        beside %= fringes
    take = (region_k >= 0) & ((k_read == region_k) | (near.ravel()[idx] & (k_read == beside)))
    idx, region_k = idx[take], region_k[take]
    out = np.array(orders, dtype=np.int32, order="C")  # a copy
    taken = int(np.count_nonzero(out.ravel()[idx] != region_k))
    out.ravel()[idx] = region_k
    return out, taken
