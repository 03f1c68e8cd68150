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
from scipy import ndimage

from .phase import TWO_PI


def _link_cuts(phi: np.ndarray, valid: np.ndarray, axis: int,
               cut: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For links between pixel i and i+1 along ``axis``: (connected, wrap, step_cut)."""
    a = phi.take(np.arange(phi.shape[axis] - 1), axis=axis)
    b = phi.take(np.arange(1, phi.shape[axis]), axis=axis)
    va = valid.take(np.arange(phi.shape[axis] - 1), axis=axis)
    vb = valid.take(np.arange(1, phi.shape[axis]), axis=axis)
    raw = b - a
    wrap = np.abs(raw) > np.pi
    step_cut = ~wrap & (np.abs(raw) > cut)
    connected = va & vb & ~wrap & ~step_cut
    return connected, wrap & va & vb, step_cut & va & vb


def default_cut(phi: np.ndarray, valid: np.ndarray) -> float:
    """Cut threshold for phase steps: three times the median phase gradient, in [0.6, 2.2]."""
    gx = np.abs(np.diff(phi, axis=1))
    gx = np.minimum(gx, TWO_PI - gx)[valid[:, 1:] & valid[:, :-1]]
    gy = np.abs(np.diff(phi, axis=0))
    gy = np.minimum(gy, TWO_PI - gy)[valid[1:] & valid[:-1]]
    if gx.size + gy.size == 0:
        return 1.5
    grad = np.hypot(np.median(gx) if gx.size else 0.0, np.median(gy) if gy.size else 0.0)
    return float(np.clip(3.0 * grad, 0.6, 2.2))


def fringe_regions(phi: np.ndarray, valid: np.ndarray, cut: float | None = None,
                   min_size: int = 20) -> tuple[np.ndarray, int]:
    """Label fringe regions of ``phi`` (wrapped, in ``[0, 2*pi)``) over the ``valid`` mask.

    Returns ``(labels, n)``: int32 labels 1..n, 0 outside any region. Regions smaller than
    ``min_size`` pixels are dropped (left 0) so that noise islands never vote.
    """
    valid = np.asarray(valid, dtype=bool)
    if cut is None:
        cut = default_cut(phi, valid)
    keep = valid.copy()
    links = []
    for axis in (0, 1):
        connected, wrap, step = _link_cuts(phi, valid, axis, cut)
        links.append(connected)
        lo = [slice(None)] * 2
        hi = [slice(None)] * 2
        lo[axis] = slice(0, -1)
        hi[axis] = slice(1, None)
        a, b = phi[tuple(lo)], phi[tuple(hi)]
        # Remove one endpoint of each wrap link (the high-phase side) and both ends of a step,
        # so that 4-connected components of what is kept never cross a cut link.
        keep[tuple(lo)] &= ~((wrap & (a >= b)) | step)
        keep[tuple(hi)] &= ~((wrap & (b > a)) | step)
    labels, n = ndimage.label(keep)
    labels = labels.astype(np.int32)
    # Reattach the removed pixels through links that are not cut.
    for _ in range(3):
        todo = valid & (labels == 0)
        if not todo.any():
            break
        vert, horiz = links
        cand = np.zeros_like(labels)
        cand[:-1][vert & todo[:-1]] = labels[1:][vert & todo[:-1]]
        cand[1:][vert & todo[1:] & (cand[1:] == 0)] = labels[:-1][vert & todo[1:] & (cand[1:] == 0)]
        sel = horiz & todo[:, :-1] & (cand[:, :-1] == 0)
        cand[:, :-1][sel] = labels[:, 1:][sel]
        sel = horiz & todo[:, 1:] & (cand[:, 1:] == 0)
        cand[:, 1:][sel] = labels[:, :-1][sel]
        grow = todo & (cand > 0)
        if not grow.any():
            break
        labels[grow] = cand[grow]
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    small = sizes < min_size
    small[0] = False
    if small.any():
        remap = np.cumsum(~small) - 1
        remap[small] = 0
        remap[0] = 0
        labels = remap[labels].astype(np.int32)
        n = int(remap.max())
    return labels, int(n)


@dataclass(frozen=True)
class RegionLinks:
    """Wrap links between regions: going from ``src`` to ``dst`` the order changes by ``step``.

    ``count`` is the number of pixel pairs that support the link.
    """

    src: np.ndarray
    dst: np.ndarray
    step: np.ndarray
    count: np.ndarray


def region_links(phi: np.ndarray, labels: np.ndarray) -> RegionLinks:
    """Pairs of regions that touch across a phase wrap, with the expected order step.

    Walking from a pixel to its right or lower neighbour, a wrap from high to low phase means
    the order grows by one, a wrap from low to high that it falls by one. Each touching pair
    is reported once per direction of walk (``src`` before ``dst``).
    """
    src, dst, step = [], [], []
    for axis in (0, 1):
        n = phi.shape[axis]
        a = phi.take(np.arange(n - 1), axis=axis)
        b = phi.take(np.arange(1, n), axis=axis)
        la = labels.take(np.arange(n - 1), axis=axis)
        lb = labels.take(np.arange(1, n), axis=axis)
        sel = (la > 0) & (lb > 0) & (la != lb) & (np.abs(b - a) > np.pi)
        src.append(la[sel])
        dst.append(lb[sel])
        step.append(np.where(a[sel] > b[sel], 1, -1))
    s, d, st = (np.concatenate(v).astype(np.int64) for v in (src, dst, step))
    if s.size == 0:
        empty = np.zeros(0, np.int64)
        return RegionLinks(empty, empty, empty, empty)
    key = np.stack([s, d, st])
    uniq, count = np.unique(key, axis=1, return_counts=True)
    return RegionLinks(uniq[0], uniq[1], uniq[2], count)


def fill_from_neighbours(phi: np.ndarray, abs_phase: np.ndarray, target: np.ndarray,
                         max_distance: float = 3.0) -> np.ndarray:
    """Absolute phase for ``target`` pixels from the nearest pixel that has one.

    The fringe order is ``round((Phi_near - phi) / 2pi)``; target pixels farther than
    ``max_distance`` from any absolute phase stay NaN.
    """
    known = np.isfinite(abs_phase)
    out = abs_phase.copy()
    if not known.any() or not target.any():
        return out
    dist, (iy, ix) = ndimage.distance_transform_edt(~known, return_indices=True)
    sel = target & ~known & (dist <= max_distance)
    ref = abs_phase[iy[sel], ix[sel]]
    k = np.round((ref - phi[sel]) / TWO_PI)
    out[sel] = phi[sel] + TWO_PI * k
    return out
