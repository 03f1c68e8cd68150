"""Fringe regions: 2-D connected areas of valid pixels between wrapped-phase jumps.

Two 4-neighbours belong to the same fringe when the wrapped phase is continuous between them:
the link is cut where the phase wraps (raw difference above pi) or jumps by more than the
cut threshold (a depth step or a noisy bridge). Every region then holds one fringe order,
and neighbouring regions across a wrap differ by exactly one order.

Examples
--------
>>> import numpy as np
>>> x = np.arange(90.0) + 0.5
>>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (20, 1)).astype(np.float32)
>>> labels, n = fringe_regions(phi, np.ones(phi.shape, bool), min_size=1)
>>> n, labels[0, [0, 29, 30, 89]].tolist()
(3, [1, 1, 2, 3])
>>> links = region_links(phi, labels)
>>> links.src.tolist(), links.dst.tolist(), links.step.tolist()
([1, 2], [2, 3], [1, 1])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .phase import TWO_PI, order_from_reference, wrap
from .regions_cuts_jit import band_links, cut_links, cut_medians
from .regions_jit import NO_CUTS, TILE, link_bits, relink, valid_changes
from .regions_labels_jit import label_kept, relabel, wrap_links

MIN_REGION = 20  # pixels: smaller fringe regions are noise islands, never votes


def fringe_direction(phi: np.ndarray, valid: np.ndarray) -> int:
    """+1 if the phase mostly grows along rows (left to right), -1 if it falls.

    Along the coded axis the phase of one lit surface is monotonic (the projector and camera
    see its points in the same order); a reversal marks where two surfaces meet.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts (every eighth row is looked at).

    Returns
    -------
    int
        +1 or -1 (+1 when no pair of valid neighbours is found): the sign of the median
        wrapped phase difference along the rows.

    Examples
    --------
    >>> phi = np.tile(np.arange(40.0) * 0.3 % (2 * np.pi), (4, 1))
    >>> ok = np.ones(phi.shape, bool)
    >>> fringe_direction(phi, ok), fringe_direction(phi[:, ::-1], ok)
    (1, -1)
    """
    a, b = phi[::8, :-1], phi[::8, 1:]
    ok = valid[::8, :-1] & valid[::8, 1:]
    diff = wrap((b - a)[ok])  # (diff + pi) % 2pi - pi, compiled
    return 1 if diff.size == 0 or _median_sign(diff) >= 0 else -1


def _median_sign(values: np.ndarray) -> float:
    """A number with the sign of ``np.median(values)`` (NaN if it is NaN), from counts: the
    middle values themselves only where the negatives are exactly half."""
    n = values.size
    neg = np.count_nonzero(values < 0)
    if np.isnan(values).any():
        return np.nan
    if n % 2 == 1 or neg != n // 2:
        return -1.0 if neg > (n - 1) // 2 else 1.0
    pair = np.array([values[values < 0].max(), values[values >= 0].min()], values.dtype)
    return float(np.mean(pair))  # as np.median averages its two middle values


def default_cut(phi: np.ndarray, valid: np.ndarray) -> float:
    """Cut threshold for phase steps: three times the median phase gradient, in [0.6, 2.2].

    The gradient is the hypotenuse of the median absolute wrapped neighbour differences
    along the rows and down the columns, on every fourth row and column. A float32 phase
    has its medians taken in one compiled pass
    (:func:`~bistair.core.regions_cuts_jit.cut_medians`): the same threshold, bit for bit, as
    :func:`cut_reference`.

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts.

    Returns
    -------
    float
        The threshold in radians; 1.5 when no pair of valid neighbours is found.

    Examples
    --------
    >>> phi = np.tile(2 * np.pi * np.arange(40.0) / 10 % (2 * np.pi), (8, 1))
    >>> round(default_cut(phi, np.ones(phi.shape, bool)), 3), default_cut(phi, phi < 0)
    (1.885, 1.5)
    >>> default_cut(phi.astype(np.float32), np.ones(phi.shape, bool)) == cut_reference(
    ...     phi.astype(np.float32), np.ones(phi.shape, bool))
    True
    """
    if phi.dtype != np.float32 or phi.ndim != 2:
        return cut_reference(phi, valid)
    meds, counts, ok = cut_medians(np.ascontiguousarray(phi),
                                   np.ascontiguousarray(valid, dtype=bool))
    if not ok:  # NaN (or differences of 4 and more): NumPy's median decides
        return cut_reference(phi, valid)
    if counts[0] + counts[1] == 0:
        return 1.5
    grad = np.hypot(meds[0], meds[1])  # float32, as the reference's (a median absent: 0)
    return float(np.clip(3.0 * grad, 0.6, 2.2))


def cut_reference(phi: np.ndarray, valid: np.ndarray) -> float:
    """NumPy reference of :func:`default_cut` (of its compiled medians,
    :func:`~bistair.core.regions_cuts_jit.cut_medians`): three times the hypotenuse of the
    median wrapped neighbour differences on every fourth row and column, in [0.6, 2.2].

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels whose phase counts.

    Returns
    -------
    float
        The threshold in radians; 1.5 when no pair of valid neighbours is found.

    Examples
    --------
    >>> phi = np.tile(2 * np.pi * np.arange(40.0) / 10 % (2 * np.pi), (8, 1))
    >>> round(cut_reference(phi, np.ones(phi.shape, bool)), 3)
    1.885
    """
    # Neighbour differences on every fourth row and column: plenty for a median.
    a, va = phi[::4, ::4], valid[::4, ::4]
    gx = np.abs(phi[::4, 1::4][:, :a.shape[1]] - a[:, :phi[::4, 1::4].shape[1]])
    gx = np.minimum(gx, TWO_PI - gx)[va[:, :gx.shape[1]] & valid[::4, 1::4][:, :gx.shape[1]]]
    gy = np.abs(phi[1::4, ::4][:a.shape[0]] - a[:phi[1::4, ::4].shape[0]])
    gy = np.minimum(gy, TWO_PI - gy)[va[:gy.shape[0]] & valid[1::4, ::4][:gy.shape[0]]]
    if gx.size + gy.size == 0:
        return 1.5
    grad = np.hypot(np.median(gx) if gx.size else 0.0, np.median(gy) if gy.size else 0.0)
    return float(np.clip(3.0 * grad, 0.6, 2.2))


@dataclass(eq=False)
class Links:
    """The links a labelling made (:func:`~bistair.core.regions_jit.link_bits`), handed to
    the next labelling of the same phase and phase noise (a decode labels its phase twice:
    its coherent dim pixels on the weak mask, :func:`bistair.core.measure.coherent_pixels`,
    then its regions on the valid pixels with its own cuts; ``FringeSet.links`` carries
    them from one to the other). Taken over once: :func:`label_fringes` empties ``bits``
    (it changes them in place).
    """

    phi: np.ndarray  # the phase they link (the same array must be labelled again)
    phase_noise: np.ndarray  # its phase noise (the same array)
    bits: np.ndarray | None  # (H, W) uint8 link bits; None once taken
    cut: float  # the cut threshold they were made with
    sign: int  # the phase's direction along the rows


@dataclass(frozen=True)
class Labelling:
    """Fringe regions as :func:`label_fringes` leaves them: provisional labels and the
    region of each, before their final numbering (:func:`fringe_regions` numbers them;
    :func:`~bistair.core.measure.coherent_pixels` reads them as they are).

    The region of pixel ``(y, x)`` is ``roots[labels[y, x]]`` (0: none); regions are
    numbered ``1..n`` in raster order of their first kept pixel.
    """

    labels: np.ndarray  # (H, W) int32 provisional ids, 0 outside any region
    roots: np.ndarray  # int32: the region of each id (defined at the ids in use)
    n: int  # regions
    size: np.ndarray  # (n+1,) int64 pixels per region, the reattached ones included
    strong: np.ndarray  # (n+1,) int64 pixels of the ``strong`` mask per region (0 without)
    links: Links | None = None  # its links, to hand on (``share``)


def label_fringes(phi: np.ndarray, valid: np.ndarray, cut: float | None = None,
                  phase_noise: np.ndarray | None = None,
                  boundaries: tuple[np.ndarray, np.ndarray] | None = None,
                  sign: int | None = None, strong: np.ndarray | None = None,
                  share: bool = False, links: Links | None = None) -> Labelling:
    """The fringe regions of :func:`fringe_regions` before small ones are dropped and the
    labels numbered: the links (:func:`~bistair.core.regions_jit.link_bits`), then the kept
    pixels labelled and the dropped ones reattached, with per-region counts
    (:func:`~bistair.core.regions_labels_jit.label_kept`).

    With ``share``, the links are handed on in ``Labelling.links`` (:class:`Links`) for
    the next labelling of the same ``phi`` and ``phase_noise`` (the same arrays): given
    them as ``links`` (a decode labels its phase twice: the coherent dim pixels on the
    weak mask, then its regions on the valid pixels with its own cuts), that labelling
    takes them over, makes again only the rows that read a row whose validity changed
    (:func:`~bistair.core.regions_jit.relink`; where those are at most three quarters of
    the rows) and adds its cuts (:func:`~bistair.core.regions_cuts_jit.cut_links`), where its
    direction is the first one's and no link's step lies between the two cut thresholds
    (:func:`~bistair.core.regions_cuts_jit.band_links`). The same links, bit for bit, as its
    own pass; they are taken over once (a later labelling given them makes its own).

    Parameters
    ----------
    phi, valid, cut, phase_noise, boundaries, sign
        As :func:`fringe_regions`.
    strong : (H, W) bool array, optional
        A mask whose pixels are counted per region (``Labelling.strong``).
    share : bool
        Hand the links on (``Labelling.links``; without ``boundaries`` only).
    links : Links, optional
        The links a labelling of the same ``phi`` and ``phase_noise`` handed on, to take
        over.

    Returns
    -------
    Labelling
        The provisional labels, their regions and the counts per region.

    Examples
    --------
    >>> x = np.arange(60.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (4, 1)).astype(np.float32)
    >>> lab = label_fringes(phi, np.ones(phi.shape, bool), strong=phi > 3)
    >>> lab.n, lab.size.tolist(), lab.strong.tolist()
    (2, [0, 120, 120], [0, 64, 64])
    >>> lab.roots[lab.labels[0, [0, 29, 30, 59]]].tolist()
    [1, 1, 2, 2]
    """
    valid = np.ascontiguousarray(valid, dtype=bool)
    h, w = phi.shape
    noise = (np.full((h, w), 0.02, np.float32) if phase_noise is None
             else np.ascontiguousarray(phase_noise, dtype=np.float32))
    cut_v, cut_h = NO_CUTS, NO_CUTS
    if boundaries is not None:
        cut_v, cut_h = (np.ascontiguousarray(b, dtype=bool) for b in boundaries)
    bits, cut, sign = _shared_links(links, phi, valid, noise, cut, sign, phase_noise)
    shared = None
    if bits is not None:
        if boundaries is not None:
            bits = cut_links(bits, cut_v, cut_h)
    else:
        if cut is None:
            cut = default_cut(phi, valid)
        if sign is None:
            sign = fringe_direction(phi, valid)
        bits = link_bits(np.ascontiguousarray(phi, dtype=np.float32), valid, noise,
                         float(np.float32(cut)), int(sign), 0.3, cut_v, cut_h,
                         boundaries is not None)
        if share and boundaries is None and phase_noise is not None:
            shared = Links(phi, phase_noise, bits, cut, sign)
    del noise
    counted = strong is not None
    mask = np.ascontiguousarray(strong, dtype=bool) if counted else NO_CUTS
    # the pixels dropped beside a cut link (thin lines along the wraps) join the region
    # they still link to: three rounds
    labels, roots, n, size, lit = label_kept(bits, mask, counted, TILE, 3)
    return Labelling(labels, roots, int(n), size, lit, shared)


def _shared_links(links: Links | None, phi: np.ndarray, valid: np.ndarray,
                  noise: np.ndarray, cut: float | None, sign: int | None,
                  phase_noise: np.ndarray | None
                  ) -> tuple[np.ndarray | None, float | None, int | None]:
    """The ``links`` another labelling handed on for this ``phi`` and ``phase_noise``,
    taken over and made for ``valid`` (``None`` where there are none, or where their
    direction is not this labelling's or their cut threshold cuts a link otherwise), with
    the cut and the direction; they are taken over once."""
    if links is None or links.bits is None or phase_noise is None:
        return None, cut, sign
    bits, cut0, sign0 = links.bits, links.cut, links.sign
    if links.phi is not phi or links.phase_noise is not phase_noise or \
            bits.shape != phi.shape:
        return None, cut, sign
    links.bits = None
    changed = valid_changes(bits, valid)
    reread = np.convolve(changed, np.ones(4, np.uint8))[2:2 + changed.size]  # rows y-1..y+2
    if np.count_nonzero(reread) * 4 > 3 * changed.size:  # most rows: its own pass is cheaper
        return None, cut, sign
    if changed.any():
        if cut is None:  # the mask changed: its own threshold and direction
            cut = default_cut(phi, valid)
        if sign is None:
            sign = fringe_direction(phi, valid)
    cut = cut0 if cut is None else cut
    sign = sign0 if sign is None else sign
    if int(sign) != int(sign0):
        return None, cut, sign
    low, high = sorted((float(np.float32(cut)), float(np.float32(cut0))))
    if low != high and band_links(phi, valid, low, high) > 0:
        return None, cut, sign  # (the two thresholds cut some link differently)
    relink(np.ascontiguousarray(phi, dtype=np.float32), valid, noise,
           float(np.float32(cut)), int(sign), 0.3, bits, changed)
    return bits, cut, sign


def fringe_regions(phi: np.ndarray, valid: np.ndarray, cut: float | None = None,
                   min_size: int = MIN_REGION, phase_noise: np.ndarray | None = None,
                   boundaries: tuple[np.ndarray, np.ndarray] | None = None,
                   sign: int | None = None, links: Links | None = None
                   ) -> tuple[np.ndarray, int]:
    """Label fringe regions of ``phi`` (wrapped, in ``[0, 2*pi)``) over the ``valid`` mask.

    Links are cut at wraps, at steps above ``cut``, where the fringe period jumps
    (``tests/support/reference.py:period_jumps``) and, along the rows, where the phase runs
    backwards (against :func:`fringe_direction`) by more than noise explains
    (``phase_noise``: per-pixel phase noise in radians, 0.02 when not given): that is where
    one surface meets another.
    ``boundaries`` adds links to cut that a codec found itself (vertical links (H-1, W),
    horizontal links (H, W-1)). A link cut at a wrap drops its high-phase pixel, any
    other cut both; the pixels kept are labelled (4-connected), then the dropped ones join
    a region they still link to (:func:`label_fringes`).

    Returns ``(labels, n)``: int32 labels 1..n in raster order of each region's first
    kept pixel, 0 outside any region. Regions smaller than ``min_size`` pixels are dropped
    (left 0, the others numbered on) so that noise islands never vote.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Pixels to label.
    cut : float, optional
        Phase step (radians) above which a link is cut; :func:`default_cut` when not given.
    min_size : int
        Smallest region kept, in pixels.
    phase_noise : (H, W) float array, optional
        Per-pixel phase noise in radians.
    boundaries : tuple of (H-1, W) and (H, W-1) bool arrays, optional
        Vertical and horizontal links to cut as well.
    sign : int, optional
        The phase's direction along the rows, when the caller has it already:
        ``fringe_direction(phi, valid)``.
    links : Links, optional
        The links a labelling of the same ``phi`` and ``phase_noise`` handed on
        (``FringeSet.links``), taken over (:func:`label_fringes`).

    Returns
    -------
    labels : (H, W) int32 array
        Region labels 1..n, 0 outside any region.
    n : int
        Number of regions.

    Examples
    --------
    >>> x = np.arange(60.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (12, 1)).astype(np.float32)
    >>> ok = np.ones(phi.shape, bool)
    >>> labels, n = fringe_regions(phi, ok)
    >>> n, labels[0, [0, 9, 10, 29, 30]].tolist()
    (2, [1, 1, 1, 1, 2])
    >>> horiz = np.zeros((12, 59), bool)
    >>> horiz[:, 9] = True  # a boundary between columns 9 and 10
    >>> labels, n = fringe_regions(phi, ok, boundaries=(np.zeros((11, 60), bool), horiz))
    >>> n, labels[0, [0, 9, 10, 29, 30]].tolist()
    (3, [1, 1, 2, 2, 3])
    """
    lab = label_fringes(phi, valid, cut, phase_noise, boundaries, sign, links=links)
    remap, n = kept_regions(lab, min_size)
    relabel(lab.labels, lab.roots, remap)
    return lab.labels, n


def kept_regions(lab: Labelling, min_size: int = MIN_REGION) -> tuple[np.ndarray, int]:
    """The final number of each region of :func:`label_fringes`: regions of at least
    ``min_size`` pixels numbered ``1..n`` in their order, the others 0 (what
    :func:`fringe_regions` writes through :func:`~bistair.core.regions_labels_jit.relabel`).

    Parameters
    ----------
    lab : Labelling
        From :func:`label_fringes`.
    min_size : int
        Smallest region kept, in pixels.

    Returns
    -------
    remap : (lab.n + 1,) int32 array
        The final number of each region (0: dropped).
    n : int
        Regions kept.

    Examples
    --------
    >>> x = np.arange(50.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (4, 1)).astype(np.float32)
    >>> lab = label_fringes(phi, np.ones(phi.shape, bool))
    >>> lab.size.tolist(), [a.tolist() if hasattr(a, "tolist") else a
    ...                     for a in kept_regions(lab, 100)]
    ([0, 120, 80], [[0, 1, 0], 1])
    """
    n = lab.n
    if min_size <= 1:  # (every region has a pixel)
        return np.arange(n + 1, dtype=np.int32), n
    kept = lab.size >= min_size
    kept[0] = False
    return np.where(kept, np.cumsum(kept), 0).astype(np.int32), int(kept.sum())


def core_weight(phi: np.ndarray) -> np.ndarray:
    """How far a pixel sits from its fringe's edges, as a vote weight in [0.1, 1].

    Codes change at the fringe edges, where the wrapped phase jumps; blur and the half-pixel
    offset of a projector's stair edge put a neighbouring fringe's code on the first and last
    pixels of a fringe, so those vote least.

    Parameters
    ----------
    phi : ndarray
        Wrapped phase in ``[0, 2*pi)``.

    Returns
    -------
    ndarray
        ``min(phi, 2*pi - phi) / (pi/2)`` clipped to [0.1, 1], same shape.

    Examples
    --------
    >>> core_weight(np.array([0.0, np.pi / 4, np.pi, 6.0])).round(3).tolist()
    [0.1, 0.5, 1.0, 0.18]
    """
    weight = np.minimum(phi, TWO_PI - phi)  # in place from here: one temporary
    weight /= np.pi / 2
    return np.clip(weight, 0.1, 1.0, out=weight)


@dataclass(frozen=True)
class RegionLinks:
    """Wrap links between regions: going from ``src`` to ``dst`` the order changes by ``step``.

    ``count`` is the number of pixel pairs that support the link.
    """

    src: np.ndarray
    dst: np.ndarray
    step: np.ndarray
    count: np.ndarray


def region_links(phi: np.ndarray, labels: np.ndarray, direction: int | None = None
                 ) -> RegionLinks:
    """Pairs of regions that touch across a phase wrap, with the expected order step.

    Walking from a pixel to its right or lower neighbour, a wrap from high to low phase means
    the order grows by one, a wrap from low to high that it falls by one. Along the rows, a
    wrap against the phase's direction (:func:`fringe_direction`) joins two surfaces, not two
    fringes, and is left out. Each touching pair is reported once per direction of walk
    (``src`` before ``dst``). ``direction`` is :func:`fringe_direction`, computed if not given.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    labels : (H, W) int32 array
        Fringe regions (:func:`fringe_regions`), 0 outside any.
    direction : int, optional
        +1 or -1, the phase's direction along the rows.

    Returns
    -------
    RegionLinks
        Int64 arrays ``src``, ``dst``, ``step`` (+1 or -1) and ``count`` (the pixel pairs
        behind each link), sorted by ``(src, dst)``.

    Examples
    --------
    >>> x = np.arange(60.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (5, 1)).astype(np.float32)
    >>> labels = np.where(x < 30, 1, 2).astype(np.int32)[None].repeat(5, axis=0)
    >>> links = region_links(phi, labels)
    >>> links.src.tolist(), links.dst.tolist(), links.step.tolist(), links.count.tolist()
    ([1], [2], [1], [5])
    """
    sign = fringe_direction(phi, labels > 0) if direction is None else direction
    s, d, st = wrap_links(phi, labels, sign)
    if s.size == 0:
        empty = np.zeros(0, np.int64)
        return RegionLinks(empty, empty, empty, empty)
    n = int(labels.max()) + 1
    key, count = np.unique((s * n + d) * 2 + (st > 0), return_counts=True)
    return RegionLinks(key // 2 // n, key // 2 % n, np.where(key % 2 == 1, 1, -1), count)


FILL_CHUNK = 8192  # fill_orders' targets a chunk: about 7 MB of temporaries at most


def fill_orders(phi: np.ndarray, order: np.ndarray, target: np.ndarray,
                max_distance: float = 3.0, in_place: bool = False) -> np.ndarray:
    """Fringe orders for ``target`` pixels without one (``order < 0``) from the nearest
    pixel that has one: the order that brings the pixel's phase nearest that pixel's
    absolute phase, ``round((phi_near + 2 pi k_near - phi) / 2pi)``. Target pixels farther
    than ``max_distance`` from any order keep -1. Returns a new int32 array, or, with
    ``in_place`` and an int32 ``order``, ``order`` itself filled.

    Only the orders given count as sources (a pixel filled here does not fill another).

    Parameters
    ----------
    phi : (H, W) float array
        Wrapped phase in ``[0, 2*pi)``.
    order : (H, W) int array
        Fringe orders, negative where unknown.
    target : (H, W) bool array
        Pixels to fill.
    max_distance : float
        Farthest source, in pixels (Euclidean).
    in_place : bool
        Fill an int32 ``order`` itself (every source is read before a pixel is filled).

    Returns
    -------
    (H, W) int32 array
        ``order`` with the target pixels filled where a source is near enough.

    Examples
    --------
    >>> phi = np.array([[5.9, 6.2, 0.1, 0.4, 0.7, 1.0]])
    >>> order = np.array([[3, -1, -1, 4, -1, -1]])
    >>> fill_orders(phi, order, np.ones(phi.shape, bool), max_distance=1.5).tolist()
    [[3, 3, 4, 4, 4, -1]]
    """
    out = np.asarray(order, np.int32) if in_place else np.array(order, dtype=np.int32)
    ty, tx = np.nonzero(target & (out < 0))
    if ty.size == 0:
        return out
    r = int(np.floor(max_distance))
    dy, dx = np.mgrid[-r:r + 1, -r:r + 1]
    dist = np.hypot(dy, dx).ravel()
    near = np.argsort(dist, kind="stable")
    near = near[(dist[near] > 0) & (dist[near] <= max_distance)]
    dy, dx = dy.ravel()[near], dx.ravel()[near]
    h, w = out.shape
    # the targets a chunk at a time (each target's candidates take some 30 words: a whole
    # image's at once could take more than the image), every order found before any is
    # written, so that only the orders given are sources
    filled = np.zeros(ty.size, bool)
    found_order = np.empty(ty.size, np.float64)
    for start in range(0, ty.size, FILL_CHUNK):
        cy, cx = ty[start:start + FILL_CHUNK], tx[start:start + FILL_CHUNK]
        yy = np.clip(cy[:, None] + dy[None, :], 0, h - 1)
        xx = np.clip(cx[:, None] + dx[None, :], 0, w - 1)
        cand = order[yy, xx]  # (targets, offsets), nearest offsets first
        found = cand >= 0
        first = found.argmax(axis=1)
        has = found.any(axis=1)
        rows = np.arange(cy.size)
        pick_y, pick_x = yy[rows, first][has], xx[rows, first][has]
        del yy, xx, cand, found
        ref = phi[pick_y, pick_x] + TWO_PI * order[pick_y, pick_x]  # absolute phase, float64
        chunk = slice(start, start + cy.size)
        filled[chunk] = has
        found_order[chunk][has] = order_from_reference(phi[cy[has], cx[has]], ref)
    out[ty[filled], tx[filled]] = found_order[filled]
    return out
