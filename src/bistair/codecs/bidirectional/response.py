"""Where the stair levels read in a capture, the stair phase read there, and how well.

A projector response the patterns do not pre-compensate (its gamma) moves each stair level's
reading by its own amount, the same everywhere in the image: with a gamma of 2.2 by up to
0.38 rad, past half the gap between two of 10 or more levels, so that a level read nearer
its neighbour than itself and whole partitions took their neighbour's order (the paper
scene at 11 x 11 and 640 x 512, hard optics: 12-24% of its pixels). :func:`linear_stair`
fits the response exponent to a grid of the capture's own stair phases
(:func:`~bistair.core.stair.fit_level_response`) and, where it moves the readings, maps the
stair phase so that each level reads where the patterns put it
(:func:`~bistair.core.stair.level_table`); the band rows are then read against the levels
as before. :func:`level_offsets` says how well they read: a level whose rows read far from
it (where the response squeezes levels together its noise counts for more) is doubtful, and
a region that reads one decides nothing alone (:func:`doubtful_regions`): it takes its
order from its neighbours or stays undecided; band rows that as a whole read as far from
the levels as at random (``UNREADABLE``) are refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...core.measure import FringeSet
from ...core.phase import TWO_PI, wrap
from ...core.stair import (
    fit_level_response,
    half_gaps,
    level_readings,
    level_table,
    relinearize_levels,
)
from .bands import Runs, union_levels
from .profiles import RowProfiles
from .response_jit import level_shares, weighted_medians

if TYPE_CHECKING:
    from . import BidirectionalSpec

SAMPLES = 5000  # a quarter of the grid of pixels the response is fitted to
MIN_SHIFT = 0.2  # readings moved less than this share of a half gap: read as they are
MAX_RATIO = 0.95  # the fit must bring the phases this much nearer the readings than the levels


@dataclass(frozen=True)
class LinearStair:
    """The stair phase read where a capture's response puts the levels.

    Attributes
    ----------
    theta : (H, W) float32 stair phase, mapped so that the levels read where the patterns
        put them (the capture's own where not mapped).
    ks : (H, W) int32 its local stair level per pixel, -1 where not valid.
    exponent : the fitted response exponent, 1.0 where the phase was not mapped.
    readings : (L,) where the union levels read in the capture's own stair phase (None
        where not mapped).
    """

    theta: np.ndarray
    ks: np.ndarray
    exponent: float = 1.0
    readings: np.ndarray | None = None


def linear_stair(fs: FringeSet, theta: np.ndarray, stair_mod: np.ndarray, ks: np.ndarray,
                 spec: BidirectionalSpec) -> LinearStair:
    """The stair phase and its local levels, mapped so that the levels read where the
    patterns put them, the response exponent that moved them and where they read.

    The exponent is fitted to the valid pixels of a grid of about 20000 (every few pixels of
    every few rows) away from the fringe edges whose stair phase noise is under 0.3 rad (at
    least 500). The phase is mapped only where that
    exponent moves some level's reading by at least ``MIN_SHIFT`` of the way to halfway,
    fits the phases better than the levels do (mean clipped squared distance at most
    ``MAX_RATIO`` of theirs) and is not at an end of the range searched (0.4 to 4: there no
    power law fits the capture, say a sine frame brighter than the cosine frame): a
    compensated projector decodes exactly as before. On the
    rendered scenes (every preset, 6 x 6 to 12 x 12 levels, 1% and 3% noise, 640 x 512)
    the compensated captures fit exponents of 0.79-1.17 to their noise (moving a level up to
    0.33 of the way) that fit no better than 0.988 of the levels; under a gamma of 2.2 left
    uncompensated, 2.06-2.45, at least 0.66 of the way, at most 0.881.

    Parameters
    ----------
    fs : FringeSet
        Stage 1, column layout (validity, wrapped phase, camera noise).
    theta : numpy.ndarray
        (H, W) float32 stair phase in radians.
    stair_mod : numpy.ndarray
        (H, W) modulation of the stair pair.
    ks : numpy.ndarray
        (H, W) int32 local stair level per pixel (-1 where not valid).
    spec : BidirectionalSpec
        The spec (partitions, stairs, offset, amplitude).

    Returns
    -------
    LinearStair
        The (mapped) stair phase, its local levels, the exponent and the readings.

    Examples
    --------
    Patterns of 12 x 12 levels through a projector gamma of 2.2 the spec does not
    compensate: levels 0 and 2 read nearer level 1 than themselves, until mapped.

    >>> from bistair.codecs import encode, make_spec
    >>> from bistair.codecs.base import measure_shifts
    >>> from bistair.codecs.bidirectional import code_columns
    >>> from bistair.core.captures import prepare
    >>> spec = make_spec("bidirectional", width=480, height=96, period=4, partitions=12,
    ...                  stairs=12, group_rows=16, local_rows=10)
    >>> cols = prepare(encode(spec) ** 2.2, spec.frame_count, spec.method)
    >>> fs = measure_shifts(cols, spec)
    >>> code = code_columns(cols, spec, fs)
    >>> theta, smod = code.maps["stair_phase"], code.maps["stair_modulation"]
    >>> code.code[0, 2:12:4].tolist()  # fringes 0, 1, 2: local levels 0, 1, 2
    [1, 1, 1]
    >>> lin = linear_stair(fs, theta, smod, code.code, spec)
    >>> lin.ks[0, 2:12:4].tolist(), round(lin.exponent, 1)
    ([0, 1, 2], 2.2)
    """
    levels = union_levels(spec.partitions, spec.stairs)
    # every step-th pixel of every step-th row: about 4 * SAMPLES pixels, without a pass
    # over the image
    step = max(1, math.isqrt(theta.size // (4 * SAMPLES)))
    grid = (slice(None, None, step), slice(None, None, step))
    sigma = fs.noise * math.sqrt(2.0) / np.maximum(stair_mod[grid], 1e-6)
    phi = fs.phi[grid]
    keep = fs.valid[grid] & (sigma < 0.3) & (phi > 0.5) & (phi < TWO_PI - 0.5)
    if keep.sum() < 500 or levels.size < 3:
        return LinearStair(theta, ks)
    exponent, ratio = fit_level_response(theta[grid][keep], levels, spec.offset,
                                         spec.amplitude)
    read = level_readings(levels, exponent, spec.offset, spec.amplitude)
    shift = float(np.max(np.abs(wrap(read - levels)) / half_gaps(levels)))
    if ratio > MAX_RATIO or shift < MIN_SHIFT or not 0.42 < exponent < 3.8:
        return LinearStair(theta, ks)  # no better, too little, or no power law (its range's end)
    try:
        table = level_table(read, levels)
    except ValueError:  # readings out of the levels' order: no power law explains them
        return LinearStair(theta, ks)
    mapped, local = relinearize_levels(theta, table, spec.stairs, fs.valid)
    return LinearStair(mapped, local, exponent, read)


def level_offsets(prof: RowProfiles, levels: np.ndarray) -> tuple[float, np.ndarray]:
    """How far the band rows of the regions read from the nearest stair level: the weighted
    median distance, as a share of half the gap to the next level (0 on the levels, 1
    halfway between two), over all of them and over those nearest each level. The rows of
    band cores only (stair-pair modulation at least 0.7 of the fringes').

    On the rendered scenes (every preset, 6 x 6 to 12 x 12 levels, 1% and 3% noise, 640 x
    512) the band rows of a decode read at most 0.304 from their levels, its worst level's
    at most 0.317 where the projector's gamma is compensated and up to 0.53 where it is not
    (the response squeezes some levels together: their noise counts for more); rows that
    read at random between the levels, a coin toss, would read 0.5. A region reading a level
    at least ``LEVEL_DOUBT`` decides nothing alone (:func:`doubtful_regions`); rows at least
    ``UNREADABLE`` as a whole are refused.

    Parameters
    ----------
    prof : RowProfiles
        The regions' row profiles.
    levels : numpy.ndarray
        (L,) nominal level phases (:func:`~.bands.union_levels`).

    Returns
    -------
    offset : float
        The median share over all band rows (0.0 with none).
    per_level : numpy.ndarray
        (L,) float64 the median share of the rows nearest each level (0.0 for a level no
        row reads).

    Examples
    --------
    >>> from bistair.codecs.bidirectional.profiles import RowProfiles
    >>> levels = union_levels(4, 4)
    >>> theta = levels[[0, 1, 2, 3]] + np.array([0.0, 0.1, -0.1, 0.2])
    >>> one = np.ones(4)
    >>> prof = RowProfiles(one, one, np.cos(theta), np.sin(theta), one, one, one, one)
    >>> offset, per_level = level_offsets(prof, levels)
    >>> round(offset, 3), per_level.round(3).tolist()
    (0.127, [0.0, 0.127, 0.127, 0.255])
    """
    theta = np.arctan2(prof.sin, prof.cos)
    weight = np.where(np.asarray(prof.level) >= 0.7, prof.weight, 0.0).astype(np.float64)
    if theta.size == 0 or not weight.sum() > 0:
        return 0.0, np.zeros(levels.size)
    # compiled (response_jit): the nearest levels and shares, then the medians of the rows
    # in NumPy's sort of the shares; the NumPy they replaced is tests/support's oracle
    levels = np.asarray(levels, np.float64)
    nearest, share = level_shares(np.asarray(theta, np.float64), levels, half_gaps(levels))
    offset, per_level = weighted_medians(np.argsort(share), share, nearest, weight,
                                         levels.size)
    return float(offset), per_level


def doubtful_regions(runs: Runs, n_regions: int, doubtful: np.ndarray) -> np.ndarray:
    """The regions whose band runs read a doubtful level (:func:`level_offsets` at least
    ``LEVEL_DOUBT``) in at least ``DOUBT_SHARE`` of their weight: their own reading cannot
    tell that level from its neighbours, so their evidence is to be faint, whichever order
    it favours (doubting the orders of a doubtful level instead favours the orders of the
    levels beside it, which a region misreading that level reads as: a whole fringe of the
    paper scene at 12 x 12 went two partitions off so).

    Parameters
    ----------
    runs : Runs
        The band runs (:func:`~.bands.row_runs`).
    n_regions : int
        The highest region label.
    doubtful : numpy.ndarray
        (L,) bool, the doubtful levels (indexing ``runs.uid``).

    Returns
    -------
    numpy.ndarray
        (n_regions + 1,) bool.

    Examples
    --------
    >>> from bistair.codecs.bidirectional.bands import Runs
    >>> one = np.ones(4)
    >>> runs = Runs(region=np.array([1, 1, 2, 2]), y0=one, y1=one, length=one, theta=one,
    ...             weight=np.array([10.0, 5.0, 10.0, 1.0]), uid=np.array([0, 2, 0, 2]),
    ...             top_ok=one > 0, bottom_ok=one > 0, misfit=one)
    >>> doubtful_regions(runs, 2, np.array([False, False, True])).tolist()
    [False, True, False]
    """
    weight = np.asarray(runs.weight, np.float64)
    total = np.bincount(runs.region, weight, n_regions + 1)
    doubted = np.bincount(runs.region, weight * np.asarray(doubtful)[runs.uid], n_regions + 1)
    return doubted > DOUBT_SHARE * total


LEVEL_DOUBT = 0.3  # a level whose rows read this far from it (median) decides no region alone
DOUBT_SHARE = 0.2  # the share of a region's band weight on doubtful levels that makes it faint
UNREADABLE = 0.4  # band rows this far from their levels (median; 0.5 at random): refused
