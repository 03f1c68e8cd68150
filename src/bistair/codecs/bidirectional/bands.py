"""Band analysis of a bidirectional stair code inside fringe regions (the default decoder).

Inside one fringe region the fringe order ``k`` is constant, so the stair phase takes only
two values: ``k mod S`` on the local-order rows and ``k // S`` on the partition rows, in
horizontal bands that alternate down the region. Averaging the stair phase over each row of
a region (across the fringe) gives a clean 1-D profile; its runs are the bands, their
lengths tell the local bands (``L`` of every ``G`` projector rows) from the partition bands
(``G - L``), and together they give the region's order. Where a region is too small to
tell, the evidence says so and the neighbours decide (see
:func:`bistair.core.resolve.resolve_regions`).
"""

from __future__ import annotations

from dataclasses import astuple, dataclass
from functools import lru_cache

import numpy as np

from ...core.phase import TWO_PI, wrap
from ...core.stair import half_gaps, stair_level_phase
from .bands_jit import band_reads, band_runs, band_sums, nearest_levels, transitions
from .profiles import RowProfiles


@dataclass
class Runs:
    """Vertical runs of one stair value in the row profiles of fringe regions."""

    region: np.ndarray
    y0: np.ndarray
    y1: np.ndarray
    length: np.ndarray  # rows, including half of the blurred transitions on each side
    theta: np.ndarray  # circular mean stair phase
    weight: np.ndarray
    uid: np.ndarray  # stair level (on the union of both stairs' levels)
    top_ok: np.ndarray  # bounded above by another run of the same region
    bottom_ok: np.ndarray
    misfit: np.ndarray  # mean distance of its rows' phases from its level, in half steps

    def take(self, sel: np.ndarray) -> Runs:
        return Runs(**{k: v[sel] for k, v in self.__dict__.items()})


@lru_cache(maxsize=32)
def union_levels(partitions: int, stairs: int) -> np.ndarray:
    """Phases of all stair levels of both stairs, near-coincident ones merged (read-only).

    Levels closer than a quarter of the finer stair's step are one level (the first in
    ascending order is kept).

    Parameters
    ----------
    partitions : int
        Partition stair levels ``P``.
    stairs : int
        Local stair levels ``S``.

    Returns
    -------
    numpy.ndarray
        (levels,) float64 phases in radians, ascending in [-pi, pi), not writeable (the
        result is cached).

    Examples
    --------
    >>> union_levels(6, 6).round(3).tolist()
    [-2.618, -1.571, -0.524, 0.524, 1.571, 2.618]
    >>> levels = union_levels(3, 4)  # level 0 of both stairs merged
    >>> levels.size, levels.flags.writeable
    (5, False)
    """
    phases = np.concatenate([stair_level_phase(np.arange(stairs), stairs),
                             stair_level_phase(np.arange(partitions), partitions)])
    phases = np.sort(wrap(phases))
    tol = 0.25 * TWO_PI / max(partitions, stairs)
    keep = [phases[0]]
    for p in phases[1:]:
        if abs(wrap(p - keep[-1])) > tol:
            keep.append(p)
    if len(keep) > 1 and abs(wrap(keep[0] - keep[-1])) <= tol:
        keep.pop()
    out = np.array(keep)
    out.flags.writeable = False
    return out


def nearest_level(theta: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """The index of the level nearest each phase, on the circle.

    Parameters
    ----------
    theta : numpy.ndarray
        (n,) phases in radians (a 1-D array).
    levels : numpy.ndarray
        (levels,) level phases in radians, e.g. :func:`union_levels`.

    Returns
    -------
    numpy.ndarray
        (n,) int32 indices into ``levels``.

    Examples
    --------
    >>> levels = union_levels(6, 6)
    >>> nearest_level(np.array([0.5, -3.1, 3.1]), levels).tolist()  # both ends: level 0 or 5
    [3, 0, 5]
    """
    return nearest_levels(np.asarray(theta, np.float64), np.asarray(levels, np.float64))


def observed_levels(theta: np.ndarray, weight: np.ndarray, levels: np.ndarray) -> np.ndarray:
    """Where the stair levels actually read in this capture.

    A projector's nonlinearity (an uncompensated gamma) moves every level's decoded phase
    by the same amount everywhere in the image; each level's observed phase is the weighted
    circular mean of the rows read nearest to it (levels seen in under 1% of the weight keep
    their nominal phase), so band rows are read and judged against it rather than the
    nominal one.

    Parameters
    ----------
    theta : numpy.ndarray
        (n,) stair phases in radians.
    weight : numpy.ndarray
        (n,) their weights.
    levels : numpy.ndarray
        (levels,) nominal level phases in radians (:func:`union_levels`).

    Returns
    -------
    numpy.ndarray
        (levels,) float64 observed phase of each level, radians.

    Examples
    --------
    >>> levels = union_levels(6, 6)
    >>> theta = levels[[0, 1, 1, 2]] + 0.1  # three levels read 0.1 rad off
    >>> observed_levels(theta, np.ones(4), levels).round(3).tolist()
    [-2.518, -1.471, -0.424, 0.524, 1.571, 2.618]
    """
    uid = nearest_level(theta, levels)
    c = np.bincount(uid, weight * np.cos(theta), levels.size)
    s = np.bincount(uid, weight * np.sin(theta), levels.size)
    seen = np.bincount(uid, weight, levels.size) > 0.01 * weight.sum()
    return np.where(seen, np.arctan2(s, c), levels)


def row_runs(prof: RowProfiles, levels: np.ndarray) -> Runs:
    """Runs of constant stair level in the row profiles of every region.

    Rows where the stair pair's modulation (over the fringes', which takes out albedo and
    shading) falls below 0.7 of the region's band cores (its 80th percentile row) are
    blurred band transitions and are skipped: two band phasors mixed cancel in part, and
    their mixed phase would read as a stair level in between. Each row's modulation is
    taken relative to what its level shows across the capture (its 80th percentile), as
    an uncompensated projector gamma gives some levels less modulation than others.

    Parameters
    ----------
    prof : RowProfiles
        From :func:`row_profiles`.
    levels : numpy.ndarray
        (levels,) nominal level phases in radians (:func:`union_levels`).

    Returns
    -------
    Runs
        The runs sorted by region, then row: ``uid`` indexes ``levels``; ``length`` is in
        camera rows; blurred transitions and ragged ends are dropped (empty when no band
        row is left).

    Examples
    --------
    A 48 x 16 image of two fringe regions (orders 5 and 6, eight columns each) of a code
    with ``S = 4`` stairs and ``P = 3`` partitions, in groups of 16 rows, 10 of them local:

    >>> from bistair.codecs.bidirectional.profiles import row_profiles, stair_values
    >>> y = np.arange(48)[:, None]
    >>> k = np.where(np.arange(16) < 8, 5, 6)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)).astype(np.float32)
    >>> labels = np.tile(np.where(np.arange(16) < 8, 1, 2), (48, 1)).astype(np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> runs = row_runs(prof, union_levels(3, 4))
    >>> runs.region.tolist(), runs.uid.tolist()
    ([1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2], [1, 2, 1, 2, 1, 2, 3, 2, 3, 2, 3, 2])
    >>> runs.y0[:6].tolist(), runs.length[:6].tolist()
    ([0, 10, 16, 26, 32, 42], [10.0, 6.0, 10.0, 6.0, 10.0, 6.0])
    """
    if prof.region.size > 1 and not (np.all(prof.region[1:] >= prof.region[:-1])
                                     and np.all((prof.row[1:] > prof.row[:-1])
                                                | (prof.region[1:] != prof.region[:-1]))):
        prof = RowProfiles(*(v[np.lexsort((prof.row, prof.region))]
                             for v in astuple(prof)))  # by region, then row
    region, row, level = prof.region, prof.row, np.asarray(prof.level, np.float64)
    row_theta = np.arctan2(prof.sin, prof.cos)
    core, c, s, w = band_sums(region, level, row_theta, prof.weight, levels)
    # levels no core row reads keep their nominal phase (as observed_levels)
    levels = np.where(w > 0.01 * prof.weight[core].sum(), np.arctan2(s, c), levels)
    read, kept = band_reads(region, level, row_theta, core, levels)
    if not kept.any():  # no band row left (tiny or pure-noise captures)
        empty = np.zeros(0)
        return Runs(*(empty.astype(np.int64),) * 3, empty, empty, empty,
                    empty.astype(np.int64), empty.astype(bool), empty.astype(bool), empty)
    # distance of the rows from their level, in half the distance to the nearest other level
    # (where a reading would change level): blur mixing two bands puts rows in between
    reg, y0, y1, length, cw, sw, weight, misfit, uid, top_ok, bottom_ok = band_runs(
        region, row, read, kept, prof.cos, prof.sin, prof.weight, row_theta, levels,
        half_gaps(levels))
    runs = Runs(region=reg, y0=y0, y1=y1, length=length, theta=np.arctan2(sw, cw),
                weight=weight, uid=uid, top_ok=top_ok,
                bottom_ok=bottom_ok, misfit=misfit)
    return _drop_transitions(runs)


def _drop_transitions(runs: Runs) -> Runs:
    """Remove runs that are not bands.

    Squeezed between two different bands, a run of 1-2 rows, or one under 0.4 of both its
    neighbours' lengths whose level lies between theirs, is their blurred transition: the
    stair phase across a band boundary blends the two levels, so it passes the levels in
    between (its rows go half to each neighbour). At the top or bottom end of a region a
    1-2 row run is its ragged edge, and the band next to it is then cut by the edge, not
    bounded by another band.
    """
    if runs.uid.size < 2:
        return runs
    # compiled (bands_jit.transitions): the NumPy it replaced is tests/support's oracle
    drop, length, top_ok, bottom_ok, some = transitions(runs.uid, runs.length, runs.theta,
                                                        runs.top_ok, runs.bottom_ok)
    if not some:
        return runs
    runs.length, runs.top_ok, runs.bottom_ok = length, top_ok, bottom_ok
    return runs.take(~drop)
