"""Fringe-order resolution shared by the codecs.

* :func:`orders_from_regions`: the region decoders' entry: fringe orders per pixel from
  fringe regions and each region's evidence for every order (a codec's own,
  e.g. :func:`code_evidence`: the votes of its pixels' codes);
* :func:`resolve_regions`: pick one order per fringe region from its own evidence and the
  rule that orders step by exactly one across each wrap (max-sum message passing);
* :func:`jump_violations`: how many wrap links break that rule.

Examples
--------
>>> import numpy as np
>>> from bistair.core.regions import fringe_regions
>>> x = np.arange(60.0) + 0.5
>>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (8, 1)).astype(np.float32)
>>> ok = np.ones(phi.shape, bool)
>>> code = np.tile((x // 30).astype(np.int64), (8, 1))
>>> def evidence_of(labels, n):
...     return labels, n, code_evidence(labels, n, code, 2)
>>> orders_from_regions(phi, ok, fringe_regions(phi, ok)[0], evidence_of)[0, ::15].tolist()
[0, 0, 1, 1]
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from .parts import Agreement, split_disagreeing
from .regions import RegionLinks, fill_orders, fringe_direction, region_links
from .resolve_jit import (
    label_code_votes,
    label_orders,
    pass_messages,
)
from .split import adopt_demanded, contradicted_regions, split_contradicted


def resolve_regions(evidence: np.ndarray, links: RegionLinks, link_weight: float = 0.5,
                    iterations: int = 12, cap: float = 2.0
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One order per region from ``evidence`` (shape (n+1, K), row 0 unused) and wrap links.

    Max-sum message passing on the region graph: across a link with step ``s`` the
    neighbour's belief in order ``k - s`` supports order ``k``, scaled by ``link_weight`` and
    by how many pixel pairs make the link (full weight from 10), and capped at ``cap`` so that
    a long chain of fringes backs a region without drowning what the region itself shows.
    Returns ``(order, belief, margin)`` per region: the chosen order (-1 where nothing
    supports one), its belief and how far it leads the runner-up.

    Parameters
    ----------
    evidence : (n+1, K) float array
        Each region's support for each of the K orders (e.g. :func:`code_evidence`).
    links : RegionLinks
        Wrap links between the regions (:func:`~bistair.core.regions.region_links`).
    link_weight : float
        Weight of a link's message (of one made by at least 10 pixel pairs).
    iterations : int
        Rounds of message passing.
    cap : float
        Largest belief a message carries over.

    Returns
    -------
    order : (n+1,) int array
        The chosen order per region, -1 where no order has a positive belief.
    belief : (n+1,) float array
        The chosen order's belief.
    margin : (n+1,) float array
        How far it leads the runner-up.

    Examples
    --------
    >>> from bistair.core.regions import RegionLinks
    >>> evidence = np.array([[0, 0, 0, 0], [0.6, 0.4, 0, 0], [0, 0.3, 0.35, 0],
    ...                      [0, 0, 0.1, 0.9]])
    >>> links = RegionLinks(np.array([1, 2]), np.array([2, 3]), np.array([1, 1]),
    ...                     np.array([20, 20]))
    >>> order, belief, margin = resolve_regions(evidence, links)
    >>> order.tolist(), belief.round(3).tolist(), margin.round(3).tolist()
    ([-1, 1, 2, 3], [0.0, 0.799, 1.0, 1.175], [0.0, 0.024, 0.35, 0.775])
    """
    n_reg, n_k = evidence.shape
    # Each touching pair is linked both ways: k_dst = k_src + step.
    src = np.concatenate([links.src, links.dst])
    dst = np.concatenate([links.dst, links.src])
    step = np.concatenate([links.step, -links.step])
    strength = link_weight * np.minimum(1.0, np.concatenate([links.count, links.count]) / 10.0)
    n_e = src.size
    reverse = np.r_[np.arange(n_e // 2, n_e), np.arange(n_e // 2)]
    # Each round: the belief of the source without what the destination told it, shifted
    # by the step, clipped, weighted and averaged with the last message (compiled).
    belief = pass_messages(np.ascontiguousarray(evidence, np.float64), src, dst, step,
                           np.asarray(strength, np.float64), reverse, iterations, float(cap))
    order = belief.argmax(axis=1)
    top2 = np.sort(belief, axis=1)[:, -2:] if n_k > 1 else np.c_[belief * 0, belief]
    order[top2[:, 1] <= 0] = -1
    return order, top2[:, 1], top2[:, 1] - top2[:, 0]


def jump_violations(links: RegionLinks, region_order: np.ndarray) -> tuple[int, int]:
    """Count wrap links (in pixel pairs) whose orders do not step by the expected one.

    Parameters
    ----------
    links : RegionLinks
        Wrap links between regions (:func:`~bistair.core.regions.region_links`).
    region_order : (n+1,) int array
        The order per region, -1 where undecided (links to such regions are not counted).

    Returns
    -------
    violations : int
        Pixel pairs of links between decided regions whose orders do not differ by the
        link's step.
    total : int
        Pixel pairs of all links between decided regions.

    Examples
    --------
    >>> from bistair.core.regions import RegionLinks
    >>> links = RegionLinks(np.array([1, 2]), np.array([2, 3]), np.array([1, 1]),
    ...                     np.array([20, 20]))
    >>> jump_violations(links, np.array([-1, 0, 1, 3]))
    (20, 40)
    >>> jump_violations(links, np.array([-1, 0, 1, -1]))  # region 3 undecided
    (0, 20)
    """
    ks, kd = region_order[links.src], region_order[links.dst]
    both = (ks >= 0) & (kd >= 0)
    bad = both & (kd - ks != links.step)
    return int(links.count[bad].sum()), int(links.count[both].sum())


Evidence = Callable[[np.ndarray, int], tuple[np.ndarray, int, np.ndarray]]


def orders_from_regions(phi: np.ndarray, valid: np.ndarray, labels: np.ndarray,
                        evidence_of: Evidence, agrees: Agreement | None = None,
                        info: dict | None = None, min_score: float = 0.45,
                        min_margin: float = 0.1, phase_noise: np.ndarray | None = None,
                        direction: int | None = None) -> np.ndarray:
    """Fringe orders (int32, -1 where undecided) from fringe regions and each region's
    evidence for every order.

    ``evidence_of(labels, n)`` returns ``(labels, n, evidence)``, the codec's evidence for
    every order per region (it may refine the labels). Regions are resolved with their wrap
    links (:func:`resolve_regions`); a region whose best order scores below ``min_score`` or
    leads the runner-up by less than ``min_margin`` stays invalid. With ``agrees`` (which
    pixels' own codes fit a given per-pixel order), parts of regions whose codes contradict
    their region's order are detached and decoded on their own
    (:func:`~bistair.core.parts.split_disagreeing`).
    With ``phase_noise``, an undecided region whose decided neighbours demand different
    orders across its wraps is cut in two where its fringe period jumps
    (:func:`~bistair.core.split.split_contradicted`): two surfaces side by side whose phase
    runs on across the edge, each piece then taking the order its own side demands; and an
    undecided region whose decided neighbours all demand one order its own code does not
    deny takes it (:func:`~bistair.core.split.adopt_demanded`).
    Valid pixels outside any region (cut off at a wrap, or in a noise island) take the order
    that makes their phase continuous with the nearest decoded pixel within 3 px. ``info``
    receives the counts and the wrap-consistency check.

    Parameters
    ----------
    phi : (H, W) float32 array
        Wrapped phase in ``[0, 2*pi)``.
    valid : (H, W) bool array
        Valid pixels.
    labels : (H, W) int32 array
        Fringe regions (:func:`~bistair.core.regions.fringe_regions`), 0 outside any.
    evidence_of : callable
        ``evidence_of(labels, n) -> (labels, n, evidence)``, ``evidence`` of shape (n+1, K).
    agrees : callable, optional
        ``agrees(order) -> bool array``: the pixels whose own codes fit a per-pixel order
        (-1 where undecided).
    info : dict, optional
        Receives ``regions``, ``regions_decoded``, ``regions_detached``, ``regions_cut``,
        ``jump_violations`` and ``jump_links``.
    min_score : float
        Belief the best order of a region needs.
    min_margin : float
        Lead over the runner-up the best order needs.
    phase_noise : (H, W) float array, optional
        Per-pixel phase noise in radians. Without it no region is cut and no undecided
        region adopts its neighbours' order. The bidirectional decoder passes it; Lv and
        phase coding do not (measured: their cut pieces took wrong orders on mugs-on-wall,
        phase coding 0.26% -> 1.7% wrong, and with 121 levels its adopted regions raised
        its errors from 0.56% to 2.3%).
    direction : int, optional
        The phase's direction along the rows, when the caller has it already:
        ``fringe_direction(phi, valid)``.

    Returns
    -------
    (H, W) int32 array
        Fringe order per pixel, -1 where undecided.

    Examples
    --------
    >>> from bistair.core.regions import fringe_regions
    >>> x = np.arange(90.0) + 0.5
    >>> phi = np.tile((2 * np.pi * x / 30) % (2 * np.pi), (12, 1)).astype(np.float32)
    >>> ok = np.ones(phi.shape, bool)
    >>> code = np.tile((x // 30).astype(np.int64), (12, 1))
    >>> code[:, 35:45] = 2  # a third of fringe 1 misread
    >>> def evidence_of(labels, n):
    ...     return labels, n, code_evidence(labels, n, code, 3)
    >>> info = {}
    >>> order = orders_from_regions(phi, ok, fringe_regions(phi, ok)[0], evidence_of, info=info)
    >>> order[0, ::10].tolist(), info["regions_decoded"], info["jump_violations"]
    ([0, 0, 0, 1, 1, 1, 2, 2, 2], 3, 0)
    """
    if direction is None:
        direction = fringe_direction(phi, valid)
    labels, n, evidence = evidence_of(labels, int(labels.max()))
    links = region_links(phi, labels, direction)
    k_reg = _decide(evidence, links, min_score, min_margin)
    detached = cut = 0
    if phase_noise is not None:
        before = n
        faint = evidence.max(axis=1) < min_score  # decided by the neighbours alone
        labels, n, cut = split_contradicted(phi, phase_noise, labels, n,
                                            contradicted_regions(links, k_reg, faint=faint))
        k_reg = np.concatenate([k_reg, np.full(n - before, -1, k_reg.dtype)])
    if agrees is not None:
        labels, n, detached = split_disagreeing(labels, n, k_reg, agrees)
    if detached or cut:
        labels, n, evidence = evidence_of(labels, n)
        links = region_links(phi, labels, direction)
        k_reg = _decide(evidence, links, min_score, min_margin)
    if info is not None:
        bad, total = jump_violations(links, k_reg)
        info.update(regions=n, regions_decoded=int((k_reg[1:] >= 0).sum()),
                    regions_detached=detached, regions_cut=cut, jump_violations=bad,
                    jump_links=total)
    adopted = 0
    if phase_noise is not None:
        k_reg, adopted = adopt_demanded(links, k_reg, evidence)
        k_reg, dropped = settle(links, k_reg, _faint(evidence, min_score, min_margin))
    else:
        k_reg, dropped = drop_contradicted(links, k_reg)
    if info is not None:
        info.update(regions_adopted=adopted, regions_contradicted=dropped)
    order, outside = label_orders(labels, k_reg.astype(np.int32), valid)
    return fill_orders(phi, order, outside, max_distance=3.0, in_place=True)


def drop_contradicted(links: RegionLinks, region_order: np.ndarray,
                      min_pairs: int = 3, say: np.ndarray | None = None
                      ) -> tuple[np.ndarray, int]:
    """Undecide the regions whose orders contradict their neighbours' more than they agree.

    A decided region whose wrap links to decided neighbours do not step as the links say
    for more pixel pairs than they do (and for at least ``min_pairs``) holds an order its
    surroundings deny: it is made undecided (-1) rather than kept as a guess. The most
    contradicted region goes first and the others are judged again without it, so the
    right neighbours of one wrong region stay.

    Parameters
    ----------
    links : RegionLinks
        Wrap links between regions (:func:`~bistair.core.regions.region_links`).
    region_order : (n+1,) int array
        Order per region label, -1 where undecided (label 0: outside any region).
    min_pairs : int
        Contradicting pixel pairs below which a region is kept.
    say : (n+1,) float array, optional
        How much each region's order counts when it agrees with or denies a neighbour's
        (1 everywhere by default; less for regions whose own code did not decide them, so
        that a chain of them cannot outvote a region that decides itself).

    Returns
    -------
    (orders, dropped) : ((n+1,) int array, int)
        The orders with the contradicted regions at -1, and how many there were.

    Examples
    --------
    >>> from bistair.core.regions import RegionLinks
    >>> links = RegionLinks(np.array([1, 2]), np.array([2, 3]), np.array([1, 1]),
    ...                     np.array([20, 20]))
    >>> k, dropped = drop_contradicted(links, np.array([-1, 0, 9, 2]))  # region 2 is off
    >>> k.tolist(), dropped
    ([-1, 0, -1, 2], 1)
    """
    k = np.array(region_order, copy=True)
    count = links.count.astype(np.float64)
    dropped = 0
    while True:  # the most contradicted region first: its neighbours may be right
        ks, kd = k[links.src], k[links.dst]
        both = (ks >= 0) & (kd >= 0)
        good = both & (kd - ks == links.step)
        bad = both & ~good
        # each side of a link hears the other: its pairs, weighted by what the other says
        to_src = count if say is None else count * say[links.dst]
        to_dst = count if say is None else count * say[links.src]
        agree = (np.bincount(links.src[good], to_src[good], k.size)
                 + np.bincount(links.dst[good], to_dst[good], k.size))
        deny = (np.bincount(links.src[bad], to_src[bad], k.size)
                + np.bincount(links.dst[bad], to_dst[bad], k.size))
        worse = np.where((deny > agree) & (deny >= min_pairs) & (k >= 0), deny - agree, 0.0)
        worse[0] = 0.0
        worst = int(np.argmax(worse))
        if worse[worst] <= 0:
            return k, dropped
        k[worst] = -1
        dropped += 1


def settle(links: RegionLinks, region_order: np.ndarray, faint: np.ndarray,
           faint_say: float = 0.2) -> tuple[np.ndarray, int]:
    """Undecide the regions whose orders their surroundings do not bear out, until none is
    left: contradicted regions (:func:`drop_contradicted`, where a region its own code did
    not decide counts ``faint_say`` of one that did), faint regions whose neighbours demand
    two orders (:func:`~bistair.core.split.contradicted_regions`: two surfaces in one
    region) and faint regions that no chain of agreeing links ties to a region its own code
    decided (:func:`unanchored`): an order a region cannot show is never a guess.

    Parameters
    ----------
    links : RegionLinks
        Wrap links between regions.
    region_order : (n+1,) int array
        Order per region label, -1 where undecided.
    faint : (n+1,) bool array
        Regions whose own evidence does not decide them.
    faint_say : float
        How much a faint region's order counts against a neighbour's.

    Returns
    -------
    (orders, dropped) : ((n+1,) int array, int)
        The orders left and how many regions were undecided.

    Examples
    --------
    Regions 1-2 decide themselves (orders 0, 1); regions 3-4 are faint and agree only with
    each other (orders 7, 8): they are undecided, the others kept.

    >>> from bistair.core.regions import RegionLinks
    >>> links = RegionLinks(np.array([1, 2, 3]), np.array([2, 3, 4]), np.array([1, 1, 1]),
    ...                     np.array([20, 5, 20]))
    >>> faint = np.array([False, False, False, True, True])
    >>> k, dropped = settle(links, np.array([-1, 0, 1, 7, 8]), faint)
    >>> k.tolist(), dropped
    ([-1, 0, 1, -1, -1], 2)
    """
    say = np.where(faint, faint_say, 1.0)
    k, dropped = drop_contradicted(links, region_order, say=say)
    while True:
        doubt = (contradicted_regions(links, k, faint=faint) | unanchored(links, k, faint)) \
            & (k >= 0)
        if not doubt.any():
            return k, dropped
        k[doubt] = -1
        k, more = drop_contradicted(links, k, say=say)
        dropped += int(doubt.sum()) + more


def unanchored(links: RegionLinks, region_order: np.ndarray, faint: np.ndarray) -> np.ndarray:
    """Decided faint regions that no chain of agreeing links (both ends decided, orders
    stepping as the link says) ties to a decided region that is not faint.

    Parameters
    ----------
    links : RegionLinks
        Wrap links between regions.
    region_order : (n+1,) int array
        Order per region label, -1 where undecided.
    faint : (n+1,) bool array
        Regions whose own evidence does not decide them.

    Returns
    -------
    (n+1,) bool array

    Examples
    --------
    >>> from bistair.core.regions import RegionLinks
    >>> links = RegionLinks(np.array([1, 3]), np.array([2, 4]), np.array([1, 1]),
    ...                     np.array([20, 20]))
    >>> faint = np.array([False, False, True, True, True])
    >>> unanchored(links, np.array([-1, 0, 1, 5, 6]), faint).tolist()
    [False, False, False, True, True]
    """
    k = np.asarray(region_order)
    n = k.size
    ks, kd = k[links.src], k[links.dst]
    good = (ks >= 0) & (kd >= 0) & (kd - ks == links.step)
    graph = sparse.coo_matrix((np.ones(int(good.sum())), (links.src[good], links.dst[good])),
                              shape=(n, n))
    _, comp = csgraph.connected_components(graph, directed=False)
    anchored = np.zeros(n, bool)
    anchored[np.unique(comp[(k >= 0) & ~faint])] = True
    return (k >= 0) & faint & ~anchored[comp]


def _faint(evidence: np.ndarray, min_score: float, min_margin: float) -> np.ndarray:
    """Regions whose own evidence does not decide them: no order scores ``min_score``, or
    the best leads the runner-up by less than ``min_margin``."""
    if evidence.shape[1] < 2:
        return evidence.max(axis=1, initial=0.0) < min_score
    top2 = np.sort(evidence, axis=1)[:, -2:]
    return (top2[:, 1] < min_score) | (top2[:, 1] - top2[:, 0] < min_margin)


def _decide(evidence: np.ndarray, links: RegionLinks, min_score: float,
            min_margin: float) -> np.ndarray:
    k_reg, score, margin = resolve_regions(evidence, links)
    k_reg[(score < min_score) | (margin < min_margin)] = -1
    k_reg[0] = -1
    return k_reg


def code_evidence(labels: np.ndarray, n_regions: int, codes: np.ndarray, n_codes: int,
                  weights: np.ndarray | None = None) -> np.ndarray:
    """Each region's weighted share of pixels voting for each code (codes < 0 abstain).

    Parameters
    ----------
    labels : (H, W) int array
        Fringe regions, 0 outside any.
    n_regions : int
        Highest label.
    codes : (H, W) int array
        Code per pixel, 0 .. n_codes-1, negative to abstain.
    n_codes : int
        Number of codes.
    weights : (H, W) float array, optional
        Vote weight per pixel (e.g. :func:`~bistair.core.regions.core_weight`).

    Returns
    -------
    (n_regions + 1, n_codes) float64 array
        The share of each region's (weighted) votes per code; rows sum to 1 for regions
        with votes, 0 otherwise (row 0 is unused).

    Examples
    --------
    >>> labels = np.array([[1, 1, 1, 2, 2, 0]])
    >>> codes = np.array([[0, 0, 1, 2, -1, 1]])
    >>> code_evidence(labels, 2, codes, 3).round(3).tolist()
    [[0.0, 0.0, 0.0], [0.667, 0.333, 0.0], [0.0, 0.0, 1.0]]
    """
    shape = labels.shape if labels.ndim == 2 else (1, labels.size)
    votes, total = label_code_votes(
        np.ascontiguousarray(labels).reshape(shape), np.ascontiguousarray(codes).reshape(shape),
        np.empty((0, 0)) if weights is None else np.ascontiguousarray(weights).reshape(shape),
        int(n_regions), int(n_codes))
    return votes / np.maximum(total, 1e-12)[:, None]
