"""Bidirectional's label-space stages as bistair computed them at the branch point of issue
32 part C (main at 5d200cd), in NumPy: the tests' oracles for the compiled passes that
replace them (tests/test_labelspace.py)."""

from __future__ import annotations

import numpy as np

from bistair.codecs.bidirectional.bands import Runs
from bistair.codecs.bidirectional.profiles import stair_values
from bistair.core.phase import wrap
from bistair.core.regions import core_weight


def relabel_then_stair_sums(labels: np.ndarray, roots: np.ndarray, remap: np.ndarray,
                            phi: np.ndarray, theta: np.ndarray, stair_mod: np.ndarray,
                            mod: np.ndarray) -> tuple[np.ndarray, ...]:
    """The final labels ``remap[roots[labels]]`` and, in a scan of its own, the five stair
    values per (label, row) summed by ``np.bincount`` (float64, raster order): ``(final
    labels, keys = label * H + row, counts, sums (5, K))``."""
    final = remap[roots[labels]].astype(np.int32)
    h = final.shape[0]
    ratio = np.clip(stair_mod / np.maximum(mod, np.float32(1e-6)), 0.0, 2.0)
    values = stair_values(theta, core_weight(phi) * np.minimum(ratio, 1.0), ratio)
    inside = final > 0
    key = (final.astype(np.int64) * h + np.arange(h)[:, None])[inside]
    keys, inv = np.unique(key, return_inverse=True)
    counts = np.bincount(inv, minlength=keys.size).astype(np.int64)
    sums = np.stack([np.bincount(inv, v[inside].astype(np.float64), keys.size)
                     for v in values])
    return final, keys, counts, sums


def drop_transitions(runs: Runs) -> Runs:
    """Remove runs that are not bands.

    Squeezed between two different bands, a run of 1-2 rows, or one under 0.4 of both its
    neighbours' lengths whose level lies between theirs, is their blurred transition: the
    stair phase across a band boundary blends the two levels, so it passes the levels in
    between (its rows go half to each neighbour). At the top or bottom end of a region a
    1-2 row run is its ragged edge, and the band next to it is then cut by the edge, not
    bounded by another band.
    """
    n = runs.uid.size
    if n < 2:
        return runs
    prev_uid = np.r_[-1, runs.uid[:-1]]
    next_uid = np.r_[runs.uid[1:], -1]
    prev_len = np.r_[0.0, runs.length[:-1]]
    next_len = np.r_[runs.length[1:], 0.0]
    to_here = wrap(runs.theta - np.r_[runs.theta[:1], runs.theta[:-1]])
    to_next = wrap(np.r_[runs.theta[1:], runs.theta[-1:]] - np.r_[runs.theta[:1],
                                                                 runs.theta[:-1]])
    between = (to_here * to_next > 0) & (np.abs(to_here) < np.abs(to_next))
    short = (runs.length <= 2.0) | (between & (runs.length <= 0.4 * np.minimum(prev_len,
                                                                                next_len)))
    inner = short & runs.top_ok & runs.bottom_ok & (prev_uid != next_uid)
    short = runs.length <= 2.0
    top_end = short & ~runs.top_ok & runs.bottom_ok
    bottom_end = short & runs.top_ok & ~runs.bottom_ok
    drop = inner | top_end | bottom_end
    if not drop.any():
        return runs
    length = runs.length.copy()
    j = np.flatnonzero(inner)
    np.add.at(length, j - 1, runs.length[j] / 2)
    np.add.at(length, j + 1, runs.length[j] / 2)
    runs.length = length
    runs.top_ok = runs.top_ok & ~np.r_[False, top_end[:-1]]
    runs.bottom_ok = runs.bottom_ok & ~np.r_[bottom_end[1:], False]
    return runs.take(~drop)


def level_offsets(prof, levels: np.ndarray) -> tuple[float, np.ndarray]:
    """``response.level_offsets`` in NumPy (main at ec6b88d): the weighted median share of
    half a level gap the band-core rows read from their nearest level, over all of them and
    per level."""
    from bistair.core.stair import half_gaps

    theta = np.arctan2(prof.sin, prof.cos)
    weight = np.where(np.asarray(prof.level) >= 0.7, prof.weight, 0.0)
    per_level = np.zeros(levels.size)
    if theta.size == 0 or not weight.sum() > 0:
        return 0.0, per_level
    nearest = np.abs(wrap(theta[:, None] - levels[None, :])).argmin(axis=1)
    share = np.abs(wrap(theta - levels[nearest])) / half_gaps(levels)[nearest]
    order = np.argsort(share)
    cum = np.cumsum(weight[order])
    offset = float(share[order][np.searchsorted(cum, 0.5 * cum[-1])])
    grouped = order[np.argsort(nearest[order], kind="stable")]
    cum = np.cumsum(weight[grouped])
    first, last = (np.searchsorted(nearest[grouped], np.arange(levels.size), side=side)
                   for side in ("left", "right"))
    before = np.where(first > 0, cum[np.maximum(first - 1, 0)], 0.0)
    total = np.where(last > first, cum[np.maximum(last - 1, 0)], 0.0) - before
    seen = total > 0
    at = np.minimum(np.searchsorted(cum, before + 0.5 * total), last - 1)
    per_level[seen] = share[grouped][at[seen]]
    return offset, per_level


def profile_centroids(prof, n_regions: int) -> np.ndarray:
    """``profiles.profile_centroids`` in NumPy (main at ec6b88d): three bincounts."""
    count = np.maximum(np.bincount(prof.region, prof.count, n_regions + 1), 1)
    rows = np.bincount(prof.region, prof.row * prof.count, n_regions + 1)
    cols = np.bincount(prof.region, prof.col_sum, n_regions + 1)
    return np.c_[rows / count, cols / count]


def split_profiles(prof, n_regions: int, splits: list[tuple[int, int]]):
    """``evidence.split_profiles`` in NumPy (main at ec6b88d): the split tails relabelled,
    then a lexsort by region and row."""
    from bistair.codecs.bidirectional.profiles import RowProfiles

    region = prof.region.copy()
    for old, row in sorted(splits, key=lambda s: (s[0], -s[1])):
        n_regions += 1
        region[(region == old) & (prof.row >= row)] = n_regions
    order = np.lexsort((prof.row, region))
    return RowProfiles(region[order], *(v[order] for k, v in prof.__dict__.items()
                                        if k != "region"))
