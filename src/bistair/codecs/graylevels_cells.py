"""The multi-level Gray code read a code cell at a time (:mod:`bistair.codecs.graylevels`).

A fringe region (one phase cycle of one surface, :func:`~bistair.core.regions.fringe_regions`)
lies within one fringe, so every pixel of it shares every digit of the code. Read pixel by
pixel (or over a few rows), the levels that crowd together under an uncompensated
projector gamma (0, 1/3, 2/3, 1 reach the camera at about 0, 0.09, 0.41, 1 of its range)
drown in the read noise; averaged over a *cell* (the region's pixels within ``CELL_ROWS``
rows along the fringe, at least ``EDGE_ZONE`` from the code's edges where the camera blur
mixes two cells) the noise of the mean falls by the root of its hundreds of pixels and the
levels stand many sigmas apart. A cell is read where it holds ``CELL_MIN`` such pixels and
their spread is what one level and the noise explain (a cell that mixes two cells' digits,
where a region's labelling ran across two fringes, spreads wider and is not read).

Examples
--------
>>> import numpy as np
>>> labels = np.int32([[1, 1, 2, 2]] * 4)
>>> cid, n = cell_ids(labels, 2)
>>> cid.tolist()[0], cid.tolist()[2], n
([2, 2, 4, 4], [3, 3, 5, 5], 6)
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

# a cell: a fringe region's pixels within CELL_ROWS rows (along the fringe), read where it
# holds CELL_MIN pixels away from the code's edges whose spread in v is at most MIXED
# times the variance the noise explains (measured on renders: docs/guide/methods.md)
CELL_ROWS = 32
CELL_MIN = 30
MIXED = 4.0


def cell_ids(labels: np.ndarray, rows: int = CELL_ROWS) -> tuple[np.ndarray, int]:
    """Each pixel's cell: ``label * blocks + y // rows`` (0 where the label is 0), and the
    number of cell ids.

    Parameters
    ----------
    labels : (H, W) int array
        Fringe-region labels, 0 outside any region.
    rows : int
        Rows of a cell along the fringe.

    Returns
    -------
    cid : (H, W) int64
    n : int
        One past the largest id.
    """
    h = labels.shape[0]
    blocks = -(-h // rows)
    block = (np.arange(h, dtype=np.int64) // rows)[:, None]
    cid = np.where(labels > 0, labels.astype(np.int64) * blocks + block, 0)
    return cid, int((int(labels.max(initial=0)) + 1) * blocks)


def cell_means(v: np.ndarray, noise_v: np.ndarray, inner: np.ndarray, cid: np.ndarray,
               n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each cell's mean of ``v`` per code frame over its ``inner`` pixels, their count, the
    sigma of each mean and how far each frame's spread exceeds the noise's.

    Parameters
    ----------
    v : (D, H, W) float array
        Each code frame's ``(I - A) / B``.
    noise_v : (H, W) float array
        The noise sigma of each pixel's ``v``.
    inner : (H, W) bool
        The pixels a cell is read on.
    cid : (H, W) int64
        Cell ids (:func:`cell_ids`).
    n : int
        One past the largest id.

    Returns
    -------
    mean : (D, n) float64
    count : (n,) int64
    sigma : (D, n) float64
        The sigma of each mean: the larger of the spread seen and the noise's, over the
        root of the count.
    excess : (n,) float64
        The largest spread seen over the noise's variance among the frames.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> v = rng.normal(0.3, 0.1, (1, 1, 400)); cid = np.ones((1, 400), np.int64)
    >>> mean, count, sigma, excess = cell_means(v, np.full((1, 400), 0.1), cid > 0, cid, 2)
    >>> round(float(mean[0, 1]), 2), int(count[1]), round(float(sigma[0, 1]), 3)
    (0.3, 400, 0.005)
    >>> bool(0.8 < excess[1] < 1.2)
    True
    """
    ids = cid[inner]
    count = np.bincount(ids, minlength=n)
    c = np.maximum(count, 1).astype(np.float64)
    expect = np.bincount(ids, weights=(noise_v[inner].astype(np.float64)) ** 2,
                         minlength=n) / c
    mean = np.empty((v.shape[0], n))
    sigma = np.empty((v.shape[0], n))
    excess = np.zeros(n)
    for i, frame in enumerate(v):
        x = frame[inner].astype(np.float64)
        m = np.bincount(ids, weights=x, minlength=n) / c
        var = np.maximum(np.bincount(ids, weights=x * x, minlength=n) / c - m * m, 0.0)
        mean[i] = m
        sigma[i] = np.sqrt(np.maximum(var, expect) / c)
        excess = np.maximum(excess, var / np.maximum(expect, 1e-12))
    return mean, count, sigma, excess


def cell_digits(mean: np.ndarray, sigma: np.ndarray, centres: np.ndarray,
                digit_of: np.ndarray, used: np.ndarray, levels: int, z: float, share: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's order through the base-L reflected Gray code of its nearest levels, and
    whether every digit is clear: outside the middle ``share`` of the gap to the next
    level on its side and ``z`` sigmas of its mean from that gap's middle.

    Parameters
    ----------
    mean, sigma : (D, n) float arrays
        :func:`cell_means`.
    centres, digit_of, used, levels
        As :func:`~bistair.codecs.graylevels_jit.read_levels` takes them.
    z, share : float
        The sigmas and the share of a half-gap a clear digit's margin needs.

    Returns
    -------
    order : (n,) int64
    clear : (n,) bool

    Examples
    --------
    >>> centres = np.float32([[-0.8, -0.6, 0.1, 1.4]])
    >>> order, clear = cell_digits(np.array([[-0.79, -0.7, 1.3]]), np.full((1, 3), 0.01),
    ...                            centres, np.int32([[0, 1, 2, 3]]), np.int32([4]), 4, 3.0, 0.5)
    >>> order.tolist(), clear.tolist()
    ([0, 1, 3], [True, False, True])
    """
    n = mean.shape[1]
    parent = np.zeros(n, np.int64)
    clear = np.ones(n, bool)
    for i in range(mean.shape[0]):
        c = centres[i, :used[i]].astype(np.float64)
        mids = 0.5 * (c[1:] + c[:-1])
        j = np.searchsorted(mids, mean[i], side="right")
        at = c[j]
        up = np.concatenate([(c[1:] - c[:-1]) / 2, [np.inf]])[j]
        down = np.concatenate([[np.inf], (c[1:] - c[:-1]) / 2])[j]
        half = np.where(mean[i] >= at, up, down)
        margin = half - np.abs(mean[i] - at)
        clear &= (margin >= share * half) & (margin >= z * sigma[i])
        g = digit_of[i][j].astype(np.int64)
        parent = parent * levels + np.where(parent % 2 == 0, g, levels - 1 - g)
    return parent, clear


def code_v(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
           mod: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Each code frame's ``v = (I - A) / B`` (0 where not ``ok``), float32 (D, H, W)."""
    safe = np.where(ok, mod, np.float32(1.0))
    out = np.empty((digits, *avg.shape), np.float32)
    for i in range(digits):
        out[i] = np.where(ok, (raw[start + i].astype(np.float32) * np.float32(scale) - avg)
                          / safe, np.float32(0.0))
    return out


def read_cells(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
               mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, labels: np.ndarray,
               noise_d: float, zone: float) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                     np.ndarray, np.ndarray, np.ndarray]:
    """The cells of a capture and their readings before the levels are known.

    Returns ``(cid, mean, count, sigma, excess, usable)``: the pixels' cell ids
    (:func:`cell_ids`), :func:`cell_means` over the valid pixels at least ``zone`` from the
    code's edges, and the cells that may be read (``CELL_MIN`` pixels, spread at most
    ``MIXED`` times the noise's).
    """
    ok = valid & (mod > 0)
    inner = ok & (labels > 0) & (phi >= zone) & (phi <= np.float32(2 * math.pi - zone))
    v = code_v(raw, start, digits, scale, avg, mod, ok)
    cid, n = cell_ids(labels)
    noise_v = np.float32(noise_d) / np.where(ok, mod, np.float32(1.0))
    mean, count, sigma, excess = cell_means(v, noise_v, inner, cid, n)
    usable = (count >= CELL_MIN) & (excess <= MIXED)
    usable[0] = False  # id 0: no region
    return cid, mean, count, sigma, excess, usable


def cell_periods(phi: np.ndarray, cid: np.ndarray, n: int) -> np.ndarray:
    """Each cell's fringe period along the rows in pixels, ``2 pi`` over its mean phase
    step between neighbouring pixels (wraps and steps over 1 radian left out); ``inf``
    where a cell has none.

    Examples
    --------
    >>> phi = np.tile(np.float32(np.arange(8) * 0.5), (2, 1))
    >>> cell_periods(phi, np.ones((2, 8), np.int64), 2)[1].round(2)
    np.float64(12.57)
    """
    step = np.diff(phi.astype(np.float64), axis=1)
    a, b = cid[:, :-1], cid[:, 1:]
    keep = (a > 0) & (a == b) & (np.abs(step) < 1.0)
    total = np.bincount(a[keep], weights=step[keep], minlength=n)
    count = np.bincount(a[keep], minlength=n)
    mean = np.abs(total) / np.maximum(count, 1)
    return np.where(mean > 0, 2 * math.pi / np.where(mean > 0, mean, 1.0), np.inf)


def fit_blur(mean: np.ndarray, count: np.ndarray, usable: np.ndarray, period: np.ndarray,
             centres_of: Callable, rounds: int = 3) -> float:
    """The blur constant ``c`` of the fringes' modulation against the code's flat levels:
    blur leaves a flat level as it is and takes the fringes' modulation down by the optics'
    transfer at the fringe's frequency, about ``exp(-c / P**2)`` (a Gaussian blur of sigma
    ``s`` pixels: ``c = 2 pi**2 s**2``), so a level's ``v`` sits ``exp(c / P**2)`` times
    further out where the fringes are denser. ``c`` is fitted as the common slope of
    ``log |v|`` over ``1 / P**2`` within each level well away from 0 (levels from
    ``centres_of`` of the corrected means, refitted ``rounds`` times), at least 0.

    Parameters
    ----------
    mean : (D, n) float
        Cell means of ``v``.
    count : (n,) int
        Their pixels (the weights).
    usable : (n,) bool
        The cells read.
    period : (n,) float
        :func:`cell_periods`.
    centres_of : callable
        ``centres_of(list of per-frame pixel-weighted values) -> (D, L) centres``.
    rounds : int
        Refits.

    Returns
    -------
    float

    Examples
    --------
    >>> p = np.repeat([12.0, 16.0, 24.0, 40.0], 3)
    >>> v = np.array([[-0.8, -0.6, 1.4] * 4]) * np.exp(38 / p ** 2)
    >>> fixed = lambda s: np.array([[-0.8, -0.6, 0.1, 1.4]])
    >>> round(fit_blur(v, np.full(12, 100), np.ones(12, bool), p, fixed), 1)
    38.0
    """
    x = np.where(np.isfinite(period), 1.0 / period ** 2, 0.0)
    use = usable & np.isfinite(period)
    c = 0.0
    for _ in range(rounds):
        corrected = mean * np.exp(-c * x)
        centres = centres_of([np.repeat(m[use], count[use]) for m in corrected])
        sxy = sxx = 0.0
        for i, m in enumerate(corrected):
            levels = centres[i][np.isfinite(centres[i])]
            nearest = np.argmin(np.abs(m[:, None] - levels[None]), axis=1)
            for j, level in enumerate(levels):
                s = use & (nearest == j)
                if np.count_nonzero(s) < 3 or abs(level) < 0.2:
                    continue  # (log |v| of a level near 0 is noise)
                w = count[s].astype(np.float64)
                xs = x[s] - np.average(x[s], weights=w)
                ys = np.log(np.maximum(np.abs(mean[i][s]), 1e-6))
                ys = ys - np.average(ys, weights=w)
                sxy += float(np.sum(w * xs * ys))
                sxx += float(np.sum(w * xs * xs))
        c = max(sxy / sxx, 0.0) if sxx > 0 else 0.0
    return c
