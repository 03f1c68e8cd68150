"""Order evidence from the band runs of the fringe regions (:mod:`.bands`): where a region
holds two surfaces (its band values change pair), how tall a group of bands is, and which
fringe orders a region's bands support.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .bands import Runs, union_levels
from .evidence_jit import band_evidence, split_order, value_changes
from .profiles import RowProfiles


def band_splits(runs: Runs, heights: np.ndarray, local_share: float
                ) -> list[tuple[int, int]]:
    """Where a region's band values change pair down its profile: two surfaces (say one
    object above another) joined into one fringe region. Returns ``(region, first row of the
    lower part)`` pairs.

    Down one surface the bands alternate between two values (or, where ``k mod S`` equals
    ``k // S``, form one merged band as long as the surface). A new surface starts at

    - a run whose value is neither of the two before it, if what follows confirms it: the
      run after next repeats its value, the next run is new as well, or the run is a merged
      band;
    - a run of another value after a merged band, if the run after next repeats it;
    - a merged band after alternating bands.

    A merged band is longer than 1.3 times the longer band of a group of the region's
    height (``heights``: camera rows per group, per region; ``local_share``: the local
    band's share of a group). Rows left out between the runs (the blurred edge where one
    surface hides the other) do not matter; runs under two rows long do not count.

    Parameters
    ----------
    runs : Runs
        From :func:`row_runs`.
    heights : numpy.ndarray
        (n_regions + 1,) group height per region in camera rows (NaN where unknown).
    local_share : float
        Local rows over group rows.

    Returns
    -------
    list of tuple of int
        ``(region, first row of the lower part)`` per split.

    Examples
    --------
    >>> from bistair.codecs.bidirectional.bands import row_runs, union_levels
    >>> from bistair.codecs.bidirectional.profiles import (profile_centroids, row_profiles,
    ...     stair_values)
    >>> from bistair.core.stair import stair_level_phase

    One region of 64 rows: order 5 above row 32, order 10 below it.

    >>> y = np.arange(64)[:, None]
    >>> k = np.where(y < 32, 5, 10)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)) * np.ones((1, 8), np.float32)
    >>> labels = np.ones((64, 8), np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> runs = row_runs(prof, union_levels(3, 4))
    >>> band_splits(runs, np.array([np.nan, 16.0]), 10 / 16)
    [(1, 32)]
    """
    splits: list[tuple[int, int]] = []
    if runs.uid.size < 2:
        return splits
    uid, reg, length = runs.uid, runs.region, runs.length
    solid = length >= 2.0
    h = np.asarray(heights, float)[reg]
    merged = np.isfinite(h) & (length >= 1.3 * max(local_share, 1 - local_share) * h)

    regions, rows = value_changes(uid, reg, solid, merged, runs.y0)
    splits.extend(zip(regions.tolist(), rows.tolist(), strict=True))
    return splits


def split_regions(labels: np.ndarray, n_regions: int, splits: list[tuple[int, int]],
                  in_place: bool = False) -> tuple[np.ndarray, int]:
    """Give the rows of a region from each split row down a new label.

    Parameters
    ----------
    labels : numpy.ndarray
        (H, W) int fringe region labels (changed only ``in_place``).
    n_regions : int
        The highest label in use.
    splits : list of tuple of int
        ``(region, row)`` pairs, as from :func:`band_splits`.
    in_place : bool
        Relabel ``labels`` itself rather than a copy.

    Returns
    -------
    labels : numpy.ndarray
        A relabelled copy (or ``labels``): each split's lower part gets a new label above
        ``n_regions``.
    n_regions : int
        The highest label now in use.

    Examples
    --------
    >>> labels = np.ones((6, 2), np.int32)
    >>> new, n = split_regions(labels, 1, [(1, 4)])
    >>> n, new[:, 0].tolist()
    (2, [1, 1, 1, 1, 2, 2])
    """
    labels = labels if in_place else labels.copy()
    for region, row in sorted(splits, key=lambda s: (s[0], -s[1])):
        n_regions += 1
        lower = labels[row:] == region
        labels[row:][lower] = n_regions
    return labels, n_regions


def split_profiles(prof: RowProfiles, n_regions: int,
                   splits: list[tuple[int, int]]) -> RowProfiles:
    """The row profiles of the labels :func:`split_regions` gives, from those before: a
    split moves whole (region, row) entries to the new label, their sums unchanged.

    Parameters
    ----------
    prof : RowProfiles
        From :func:`row_profiles` of the labels before the splits.
    n_regions : int
        The highest label before the splits.
    splits : list of tuple of int
        ``(region, row)`` pairs, as given to :func:`split_regions`.

    Returns
    -------
    RowProfiles
        The same as :func:`row_profiles` of the split labels (sorted by region, then row).

    Examples
    --------
    >>> from bistair.codecs.bidirectional.bands import row_runs, union_levels
    >>> from bistair.codecs.bidirectional.profiles import (profile_centroids, row_profiles,
    ...     stair_values)
    >>> from bistair.core.stair import stair_level_phase
    >>> labels = np.ones((6, 2), np.int32)
    >>> values = stair_values(np.zeros((6, 2), np.float32), np.ones((6, 2)), np.ones((6, 2)))
    >>> prof = split_profiles(row_profiles(labels, values), 1, [(1, 4)])
    >>> prof.region.tolist(), prof.row.tolist()
    ([1, 1, 1, 1, 2, 2], [0, 1, 2, 3, 4, 5])
    """
    region = prof.region.copy()
    for old, row in sorted(splits, key=lambda s: (s[0], -s[1])):  # as split_regions does
        n_regions += 1
        region[(region == old) & (prof.row >= row)] = n_regions
    # compiled: a counting sort by region (rows ascend within each region already)
    order = split_order(region, np.asarray(prof.row), int(n_regions))
    if order.size != region.size:
        order = np.lexsort((prof.row, region))
    return RowProfiles(region[order], *(v[order] for k, v in prof.__dict__.items()
                                        if k != "region"))


def edge_rows(runs: Runs, splits: list[tuple[int, int]], short: float = 3.0
              ) -> list[tuple[int, int]]:
    """Move each split up by one run where the upper surface's last full band was cut short.

    A split starts the lower surface at its first run of a new value, but the run before
    may show a level both surfaces have there (say the shared partition level) and belong
    to the lower one already. When the run before that is shorter than the region's other
    runs of its value above the split by more than ``short`` rows, the surface edge cut it:
    the split moves up to the start of the shared run. Otherwise it stays.

    Parameters
    ----------
    runs : Runs
        From :func:`row_runs`.
    splits : list of tuple of int
        ``(region, row)`` pairs from :func:`band_splits`.
    short : float
        Rows by which the cut band falls short of its value's median length.

    Returns
    -------
    list of tuple of int
        The splits, some moved up.

    Examples
    --------
    Bands of 10 and 5 rows alternating (values 1 and 2) until the band at row 45 is cut to
    5 rows; the shared value 2 follows, then the lower surface's value 3 from row 58.

    >>> y0 = np.array([0, 10, 15, 25, 30, 40, 45, 50, 58])
    >>> y1 = np.array([9, 14, 24, 29, 39, 44, 49, 57, 67])
    >>> uid = np.array([1, 2, 1, 2, 1, 2, 1, 2, 3])
    >>> n = y0.size
    >>> runs = Runs(region=np.ones(n, int), y0=y0, y1=y1, length=(y1 - y0 + 1).astype(float),
    ...             theta=np.zeros(n), weight=np.ones(n), uid=uid, top_ok=np.ones(n, bool),
    ...             bottom_ok=np.ones(n, bool), misfit=np.zeros(n))
    >>> edge_rows(runs, [(1, 58)])
    [(1, 50)]
    >>> runs.length[6] = 10.0  # a full band: the shared run may be either surface's
    >>> edge_rows(runs, [(1, 58)])
    [(1, 58)]
    """
    moved = []
    for region, row in splits:
        own = np.flatnonzero(runs.region == region)
        at = own[runs.y0[own] == row]
        i = int(np.searchsorted(own, at[0])) if at.size else -1
        if i < 3:
            moved.append((region, row))
            continue
        shared, cut, before = own[i - 1], own[i - 2], own[i - 3]
        same = own[:i - 2][runs.uid[own[:i - 2]] == runs.uid[cut]]
        typical = float(np.median(runs.length[same])) if same.size >= 2 else np.nan
        if runs.uid[shared] == runs.uid[before] and runs.length[cut] < typical - short:
            moved.append((region, int(runs.y0[shared])))
        else:
            moved.append((region, row))
    return moved


@dataclass(frozen=True)
class BandLayout:
    """What the decoder knows of the code: stairs ``S``, partitions ``P``, group rows."""

    stairs: int
    partitions: int
    local_share: float  # local rows / group rows
    default_height: float  # group height in camera rows when nothing better is known

    @property
    def levels(self) -> np.ndarray:
        """Nominal phases of the union of both stairs' levels (what run ``uid`` indexes)."""
        return union_levels(self.partitions, self.stairs)


def group_heights(runs: Runs, n_regions: int, centroids: np.ndarray) -> np.ndarray:
    """Group height (camera rows) per region: its own bands where two complete ones show,
    else the median of the nearest regions that have one.

    Parameters
    ----------
    runs : Runs
        From :func:`row_runs`.
    n_regions : int
        The highest region label.
    centroids : numpy.ndarray
        (n_regions + 1, 2) region centroids, from :func:`profile_centroids`.

    Returns
    -------
    numpy.ndarray
        (n_regions + 1,) float64 camera rows per group: the sum of the median lengths of a
        region's two most frequent band values, else the median of up to 7 nearest
        regions' own; NaN for region 0 and where no region has its own.

    Examples
    --------
    >>> from bistair.codecs.bidirectional.bands import row_runs, union_levels
    >>> from bistair.codecs.bidirectional.profiles import (profile_centroids, row_profiles,
    ...     stair_values)
    >>> from bistair.core.stair import stair_level_phase

    A 48 x 16 image of two fringe regions (orders 5 and 6, eight columns each) of a code
    with ``S = 4`` stairs and ``P = 3`` partitions, in groups of 16 rows, 10 of them local:

    >>> y = np.arange(48)[:, None]
    >>> k = np.where(np.arange(16) < 8, 5, 6)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)).astype(np.float32)
    >>> labels = np.tile(np.where(np.arange(16) < 8, 1, 2), (48, 1)).astype(np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> runs = row_runs(prof, union_levels(3, 4))
    >>> group_heights(runs, 2, profile_centroids(prof, 2)).tolist()
    [nan, 16.0, 16.0]
    """
    complete = runs.top_ok & runs.bottom_ok & (runs.length >= 2)
    own = _own_heights(runs.region[complete], runs.uid[complete], runs.length[complete],
                       n_regions)
    have = np.flatnonzero(np.isfinite(own))
    out = own.copy()
    if have.size == 0:
        return out
    tree = cKDTree(centroids[have])
    missing = np.flatnonzero(~np.isfinite(own))
    missing = missing[missing > 0]
    if missing.size:
        k = min(7, have.size)
        _, nn = tree.query(centroids[missing], k=k)
        nn = np.asarray(nn).reshape(missing.size, k)
        out[missing] = np.median(own[have][nn], axis=1)
    return out


def _own_heights(region: np.ndarray, uid: np.ndarray, length: np.ndarray,
                 n_regions: int) -> np.ndarray:
    """Per region, the sum of the median lengths of its two most frequent band values (NaN
    where it shows fewer than two), in one sort of all runs."""
    own = np.full(n_regions + 1, np.nan)
    if region.size == 0:
        return own
    region, uid = region.astype(np.int64), uid.astype(np.int64)
    key = region * (int(uid.max()) + 1) + uid  # (region, value) pairs, in that order
    order = np.lexsort((length, key))
    key, srt = key[order], length[order]
    first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[first, key.size])
    mid = first + count // 2
    # np.median: the middle value, or the mean of the two middle values
    median = np.where(count % 2 == 1, srt[mid], (srt[mid - 1] + srt[mid]) / 2)
    pair_region = region[order][first]
    starts = np.flatnonzero(np.r_[True, pair_region[1:] != pair_region[:-1]])
    n_pairs = np.diff(np.r_[starts, pair_region.size])
    # the two most frequent values: sort each region's pairs by count (ties in value order)
    rank = np.lexsort((count, pair_region))
    ends = starts + n_pairs
    two = n_pairs >= 2
    best, second = rank[ends[two] - 1], rank[ends[two] - 2]
    regions = pair_region[starts[two]]
    own[regions] = median[second] + median[best]
    # a tie for second place: np.argsort decides as the loop over regions did
    third = np.where(n_pairs[two] >= 3, rank[np.maximum(ends[two] - 3, 0)], -1)
    tied = (third >= 0) & (count[np.maximum(third, 0)] == count[second])
    for i in np.flatnonzero(tied):
        lo = starts[two][i]
        pairs = np.arange(lo, lo + n_pairs[two][i])
        top_two = np.argsort(count[pairs])[-2:]
        own[regions[i]] = sum(median[pairs[v]] for v in top_two)
    return own


def region_evidence(runs: Runs, n_regions: int, heights: np.ndarray,
                    layout: BandLayout) -> np.ndarray:
    """Evidence for every fringe order per region, shape (n_regions + 1, P*S).

    A region whose bands show both values gets close to 1 for its order (and less for the
    orders that share only one of its values, the less the surer both values are); a region
    that shows a single band value gets
    0.4 for every order compatible with it (its neighbours decide), unless the band is far
    longer than a band can be, which is the merged case ``k mod S == k // S``.

    Parameters
    ----------
    runs : Runs
        From :func:`row_runs`.
    n_regions : int
        The highest region label.
    heights : numpy.ndarray
        (n_regions + 1,) group height per region in camera rows (NaN where unknown), from
        :func:`group_heights`.
    layout : BandLayout
        The code's stairs, partitions, local share and default group height.

    Returns
    -------
    numpy.ndarray
        (n_regions + 1, P*S) float64 evidence per region and order (row 0 and regions whose
        bands are blurred together stay 0).

    Examples
    --------
    >>> from bistair.codecs.bidirectional.bands import row_runs, union_levels
    >>> from bistair.codecs.bidirectional.profiles import (profile_centroids, row_profiles,
    ...     stair_values)
    >>> from bistair.core.stair import stair_level_phase

    A 48 x 16 image of two fringe regions (orders 5 and 6, eight columns each) of a code
    with ``S = 4`` stairs and ``P = 3`` partitions, in groups of 16 rows, 10 of them local:

    >>> y = np.arange(48)[:, None]
    >>> k = np.where(np.arange(16) < 8, 5, 6)
    >>> theta = np.where(y % 16 < 10, stair_level_phase(k % 4, 4),
    ...                  stair_level_phase(k // 4, 3)).astype(np.float32)
    >>> labels = np.tile(np.where(np.arange(16) < 8, 1, 2), (48, 1)).astype(np.int32)
    >>> ones = np.ones(theta.shape, np.float32)
    >>> prof = row_profiles(labels, stair_values(theta, ones, ones))
    >>> runs = row_runs(prof, union_levels(3, 4))
    >>> heights = group_heights(runs, 2, profile_centroids(prof, 2))
    >>> ev = region_evidence(runs, 2, heights, BandLayout(4, 3, 10 / 16, 16.0))
    >>> ev.shape, ev[1:].argmax(axis=1).tolist(), ev[1:].max(axis=1).round(2).tolist()
    ((3, 12), [5, 6], [1.0, 1.0])
    """
    if runs.uid.size == 0:
        return np.zeros((n_regions + 1, layout.stairs * layout.partitions))
    order = np.argsort(runs.region, kind="stable")  # (row_runs gives them in this order)
    runs = runs.take(order)
    return band_evidence(runs.region, runs.uid, np.asarray(runs.weight, np.float64),
                         np.asarray(runs.length, np.float64),
                         np.asarray(runs.misfit, np.float64), runs.top_ok & runs.bottom_ok,
                         np.asarray(heights, np.float64), np.asarray(layout.levels),
                         layout.stairs, layout.partitions, float(layout.local_share),
                         float(layout.default_height), int(n_regions))
