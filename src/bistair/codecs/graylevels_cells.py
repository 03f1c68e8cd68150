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
where a region's labelling ran across two fringes, spreads wider and is not read:
:func:`narrow`).

Examples
--------
>>> import numpy as np
>>> mean, sigma, spread, excess = cell_stats(np.array([[0.0, 12.0]]), np.array([[0.0, 1.5]]),
...                                  np.array([0.0, 0.1]), np.array([0, 100]))
>>> mean.tolist(), sigma.round(3).tolist(), excess.round(2).tolist()
([[0.0, 0.12]], [[0.0, 0.003]], [0.0, 0.6])
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .graylevels_jit import cell_sums

# a cell: a fringe region's pixels within CELL_ROWS rows (along the fringe), read where it
# holds CELL_MIN pixels away from the code's edges whose variance in v is at most MIXED
# times the noise's (the levels are estimated on those) or, in every frame, whose spread
# beyond the noise is at most SPREAD of the gap from its level to the nearer neighbour (a
# cell mixing two cells' digits spreads wider)
CELL_ROWS = 32
CELL_MIN = 30
MIXED = 4.0
SPREAD = 0.25


def cell_stats(total: np.ndarray, square: np.ndarray, expect: np.ndarray, count: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each cell's mean ``v`` per code frame, the sigma of each mean (the larger of the
    spread seen and the noise's, over the root of the count), the spread (sigma) beyond the
    noise's per frame and how far the widest frame's variance exceeds the noise's, from
    the sums of
    :func:`~bistair.codecs.graylevels_jit.cell_sums`.

    Parameters
    ----------
    total, square : (D, n) float
        Sums of ``v`` and ``v**2`` per frame and cell.
    expect : (n,) float
        Sums of the noise variance of ``v``.
    count : (n,) int
        Pixels summed.

    Returns
    -------
    mean, sigma, spread : (D, n) float64
    excess : (n,) float64

    Examples
    --------
    >>> mean, sigma, spread, excess = cell_stats(
    ...     np.array([[40.0]]), np.array([[20.0]]), np.array([0.5]), np.array([100]))
    >>> mean.tolist(), sigma.round(3).tolist(), spread.round(3).tolist(), excess.round(1).tolist()
    ([[0.4]], [[0.02]], [[0.187]], [8.0])
    """
    c = np.maximum(count, 1).astype(np.float64)
    mean = total / c
    var = np.maximum(square / c - mean * mean, 0.0)
    noise = expect / c
    sigma = np.sqrt(np.maximum(var, noise) / c)
    # (a noise floor of 0.001 in v: about the 8-bit step of a well modulated pixel)
    excess = np.max(var / np.maximum(noise, 1e-6), axis=0) if len(total) else np.zeros(c.size)
    return mean, sigma, np.sqrt(np.maximum(var - noise, 0.0)), excess


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


def read_cells(raw: np.ndarray, start: int, digits: int, scale: float, avg: np.ndarray,
               mod: np.ndarray, valid: np.ndarray, phi: np.ndarray, labels: np.ndarray,
               noise_d: float, zone: float) -> tuple[np.ndarray, ...]:
    """The cells of a capture and their readings before the levels are known.

    Parameters
    ----------
    raw, start, digits, scale, avg, mod, valid, phi
        As :func:`~bistair.codecs.graylevels_jit.read_levels` takes them.
    labels : (H, W) int array
        Fringe regions, 0 outside any.
    noise_d : float
        The noise of ``I - A``.
    zone : float
        Radians from the code's edges left out of the means.

    Returns
    -------
    tuple
        ``(cid, mean, count, sigma, spread, period, clean)``: the pixels' cells (``label *
        blocks + y // CELL_ROWS``, 0 outside any region), :func:`cell_stats` over the valid
        pixels at least ``zone`` from the code's edges, each cell's fringe period along the
        rows in pixels (``2 pi`` over its mean phase step, ``inf`` where it has none) and
        the cells whose variance is at most ``MIXED`` times the noise's.

    Examples
    --------
    >>> raw = np.float32(np.repeat([0.25, 0.5, 0.75], 20))[None, None].repeat(40, 1)
    >>> ones = np.ones((40, 60), np.float32)
    >>> phi = np.tile(np.float32(np.arange(60) % 20 * 0.3), (40, 1))
    >>> labels = np.repeat(np.int32([1, 2, 3]), 20)[None].repeat(40, 0)
    >>> cid, mean, count, sigma, spread, period, clean = read_cells(
    ...     raw, 0, 1, 1.0, ones * 0.5, ones * 0.5, ones > 0, phi, labels, 0.01, 1.0)
    >>> mean[0, count > 0].tolist(), period[count > 0].round(1).tolist()
    ([-0.5, -0.5, 0.0, 0.0, 0.5, 0.5], [20.9, 20.9, 20.9, 20.9, 20.9, 20.9])
    """
    cid, total, square, expect, count, step, steps = cell_sums(
        raw, start, digits, scale, avg, mod, valid, phi, labels, CELL_ROWS, zone, noise_d)
    mean, sigma, spread, excess = cell_stats(total, square, expect, count)
    rate = np.abs(step) / np.maximum(steps, 1)
    period = np.where(rate > 0, 2 * math.pi / np.where(rate > 0, rate, 1.0), np.inf)
    return cid, mean, count, sigma, spread, period, excess <= MIXED


def fit_blur(mean: np.ndarray, count: np.ndarray, usable: np.ndarray, period: np.ndarray,
             centres_of: Callable, times: np.ndarray | None = None, rounds: int = 2
             ) -> float:
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
    times : (n,) int, optional
        How many times each cell's mean counts there (its pixels, the default, where
        usable, else 0).
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
    times = np.where(usable, count, 0) if times is None else times
    c = 0.0
    for _ in range(rounds):
        corrected = mean * np.exp(-c * x)
        centres = centres_of([np.repeat(m, times) for m in corrected])
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


def narrow(spread: np.ndarray, mean: np.ndarray, centres: np.ndarray, used: np.ndarray
           ) -> np.ndarray:
    """The cells whose spread beyond the noise is at most ``SPREAD`` of the gap between
    their level and its nearer neighbour, in every frame (two levels mixed spread by a
    share of the gap between them).

    Parameters
    ----------
    spread, mean : (D, n) float
        :func:`cell_stats`.
    centres : (D, L) float
        The levels, the first ``used[i]`` of row ``i`` set, increasing.
    used : (D,) int
        Levels per frame.

    Returns
    -------
    (n,) bool

    Examples
    --------
    >>> centres = np.array([[-1.5, 0.0, 0.4]])
    >>> narrow(np.array([[0.2, 0.2, 0.05]]), np.array([[-1.5, 0.4, 0.0]]), centres,
    ...        np.array([3])).tolist()
    [True, False, True]
    """
    ok = np.ones(spread.shape[1], bool)
    for i, s in enumerate(spread):
        c = centres[i, :used[i]].astype(np.float64)
        if c.size < 2:
            continue
        gaps = np.diff(c)
        nearest = np.searchsorted(0.5 * (c[1:] + c[:-1]), mean[i])
        gap = np.minimum(np.concatenate([[np.inf], gaps])[nearest],
                         np.concatenate([gaps, [np.inf]])[nearest])
        ok &= s <= SPREAD * gap
    return ok
