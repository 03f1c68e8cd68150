"""The band analysis's compiled passes (bistair.codecs.bidirectional.bands_jit) give what the
NumPy they replaced gave: ``bands.row_runs`` exactly the same runs, levels, lengths and sums
on random row profiles (zero weights, one entry, no band row, several level sets, profiles
out of order); the nearest levels, region quantiles and group percentiles exactly, with ties
and tiny regions."""

from __future__ import annotations

from dataclasses import astuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bistair.codecs.bidirectional.bands import (
    Runs,
    _drop_transitions,
    nearest_level,
    observed_levels,
    row_runs,
    union_levels,
)
from bistair.codecs.bidirectional.bands_jit import (
    group_percentiles,
    nearest_levels,
    region_quantile,
)
from bistair.codecs.bidirectional.profiles import RowProfiles
from bistair.core.phase import TWO_PI, wrap

RNG = np.random.default_rng(5)


def _row_runs_before(prof, levels):
    """``row_runs`` as NumPy computed it (profiles sorted by region, then row: the region
    quantiles from ``region_quantile``, as it took them for sorted profiles)."""
    c, s, wsum = prof.cos, prof.sin, prof.weight
    region, row = prof.region, prof.row
    row_theta = np.arctan2(s, c)
    core = prof.level >= 0.7 * region_quantile(region, prof.level, 0.8)
    levels = observed_levels(row_theta[core], wsum[core], levels)
    read = nearest_level(row_theta, levels)
    expected = group_percentiles(read[core], prof.level[core].astype(np.float64), levels.size,
                                 0.8)
    expected[np.bincount(read[core], minlength=levels.size) == 0] = 1.0
    level = prof.level / np.maximum(expected[read], 1e-6)
    kept = level >= 0.7 * region_quantile(region, level, 0.8)
    dropped_before = np.cumsum(~kept) - (~kept)
    idx = np.flatnonzero(kept)
    if idx.size == 0:
        return None
    region_k, row_k, uid = region[idx], row[idx], read[idx]
    same = np.zeros(idx.size, bool)
    same[1:] = region_k[1:] == region_k[:-1]
    gap = np.zeros(idx.size, np.int64)
    gap[1:] = row_k[1:] - row_k[:-1] - 1
    between = np.zeros(idx.size, np.int64)
    between[1:] = dropped_before[idx[1:]] - dropped_before[idx[:-1]]
    soft = same & (gap == between) & (gap <= 3)
    changed = np.ones(idx.size, bool)
    changed[1:] = uid[1:] != uid[:-1]
    start = ~soft | changed
    start[0] = True
    run_id = np.cumsum(start) - 1
    first = np.flatnonzero(start)
    last = np.r_[first[1:] - 1, idx.size - 1]
    top_ok = soft[first] & changed[first]
    bottom_ok = np.r_[top_ok[1:], False]
    half_top = np.where(top_ok, gap[first] / 2.0, 0.0)
    half_bottom = np.zeros(first.size)
    half_bottom[:-1] = np.where(bottom_ok[:-1], gap[first[1:]] / 2.0, 0.0)
    gaps = np.abs(wrap(levels[:, None] - levels[None, :])) + np.eye(levels.size) * TWO_PI
    off = np.abs(wrap(row_theta[idx] - levels[uid])) / (0.5 * gaps.min(axis=1)[uid])
    misfit = np.bincount(run_id, off * wsum[idx]) / np.maximum(np.bincount(run_id, wsum[idx]),
                                                               1e-12)
    return _drop_transitions(Runs(
        region=region_k[first], y0=row_k[first], y1=row_k[last],
        length=(row_k[last] - row_k[first] + 1) + half_top + half_bottom,
        theta=np.arctan2(np.bincount(run_id, s[idx]), np.bincount(run_id, c[idx])),
        weight=np.bincount(run_id, wsum[idx]), uid=uid[first], top_ok=top_ok,
        bottom_ok=bottom_ok, misfit=misfit))


def _profiles(n, regions, steps, zero_weights=False):
    """Random profiles: bands of stair levels down each region, noisy, some rows missing."""
    region = np.sort(RNG.integers(1, regions + 1, n))
    row = np.zeros(n, np.int64)
    for r in np.unique(region):
        at = region == r
        row[at] = np.sort(RNG.choice(4 * n, at.sum(), replace=False))
    k = (row // RNG.integers(2, 12)) % steps
    theta = -np.pi + (k + 0.5) * TWO_PI / steps + RNG.normal(0, 0.25, n)
    weight = RNG.uniform(0, 3, n)
    if zero_weights:
        weight[RNG.random(n) < 0.2] = 0.0
    return RowProfiles(region.astype(np.int64), row, weight * np.cos(theta),
                       weight * np.sin(theta), weight, RNG.uniform(0, 2, n),
                       RNG.integers(1, 50, n), RNG.uniform(0, 100, n))


def _same(got, expected):
    for name, value in got.__dict__.items():
        other = getattr(expected, name)
        assert value.dtype == other.dtype, name
        assert np.array_equal(value, other, equal_nan=True), name


@pytest.mark.parametrize("n", [1, 2, 7, 60, 900])
@pytest.mark.parametrize("levels", [(6, 6), (3, 4), (8, 8)])
def test_row_runs_are_numpys(n, levels):
    lv = union_levels(*levels)
    for trial in range(8):
        prof = _profiles(n, int(RNG.integers(1, 12)), len(lv), zero_weights=trial % 2 == 1)
        expected = _row_runs_before(prof, lv)
        got = row_runs(prof, lv)
        if expected is None:
            assert got.uid.size == 0
        else:
            _same(got, expected)


def test_row_runs_sort_profiles_given_out_of_order():
    lv = union_levels(6, 6)
    prof = _profiles(300, 5, len(lv))
    order = RNG.permutation(prof.region.size)
    shuffled = RowProfiles(*(v[order] for v in astuple(prof)))
    _same(row_runs(shuffled, lv), row_runs(prof, lv))


def test_no_band_row_gives_no_run():
    lv = union_levels(3, 4)
    prof = _profiles(20, 2, len(lv))
    prof.level[:] = np.nan  # no row reaches its region's band cores
    runs = row_runs(prof, lv)
    assert runs.uid.size == 0 and runs.length.size == 0


def _nearest_before(theta, levels):
    d = np.abs(wrap(np.asarray(theta)[:, None] - levels[None, :]))
    return d.argmin(axis=1).astype(np.int32)



def _quantile_before(region, values, q):
    order = np.lexsort((values, region))
    starts = np.flatnonzero(np.r_[True, region[order][1:] != region[order][:-1]])
    counts = np.diff(np.r_[starts, region.size])
    pick = values[order][starts + np.floor(q * (counts - 1)).astype(np.int64)]
    return np.repeat(pick, counts)[np.argsort(order, kind="stable")]



@pytest.mark.parametrize("levels", [union_levels(8, 8), union_levels(3, 4), np.array([0.5]),
                                    np.array([2.0, -1.0, 0.3])])
def test_nearest_levels(levels):
    rng = np.random.default_rng(1)
    theta = np.r_[rng.uniform(-np.pi, np.pi, 20000), rng.uniform(-12, 12, 2000), levels,
                  -levels, (levels[:, None] + levels[None, :]).ravel() / 2,  # ties
                  [np.pi, -np.pi, 0.0, -0.0, 2 * np.pi, -3 * np.pi, np.nan]]
    theta = np.r_[theta, np.nextafter(theta, 20), np.nextafter(theta, -20)]
    assert np.array_equal(nearest_levels(theta, levels), _nearest_before(theta, levels))



@settings(max_examples=60, deadline=None, derandomize=True, database=None)
@given(seed=st.integers(0, 2**16), m=st.integers(1, 13), gap=st.sampled_from([0.0, 1e-12,
                                                                               1e-9, 0.3]))
def test_nearest_levels_on_a_ring_of_levels(seed, m, gap):
    """Levels ascending in [-pi, pi) (the union levels, the observed ones, one at -pi, two
    close, one near pi: those searched only where they bracket a phase) or not quite (too
    close, unsorted): the nearest level of every phase as ``argmin`` gave it, ties and
    phases out of [-pi, pi] and NaN among them."""
    rng = np.random.default_rng(seed)
    levels = np.sort(rng.uniform(-np.pi, np.pi, m))
    levels[0] = rng.choice([levels[0], -np.pi])
    levels[-1] = rng.choice([levels[-1], np.nextafter(np.pi, 0)]) if m > 1 else levels[-1]
    if m > 2:  # a close pair (the ring holds from 1e-9 apart)
        levels[2] = levels[1] + gap
        levels = levels if rng.random() < 0.8 else rng.permutation(levels)
    mid = (levels[:, None] + levels[None, :]).ravel() / 2
    theta = np.r_[rng.uniform(-np.pi, np.pi, 3000), rng.uniform(-9, 9, 100), levels, mid,
                  mid + np.pi, [np.pi, -np.pi, 0.0, np.nan]]
    theta = np.r_[theta, np.nextafter(theta, 20), np.nextafter(theta, -20)]
    assert np.array_equal(nearest_levels(theta, levels), _nearest_before(theta, levels))


def test_region_quantile():
    rng = np.random.default_rng(2)
    for _ in range(200):
        n = int(rng.integers(1, 120))
        region = np.sort(rng.integers(0, int(rng.integers(1, 30)), n))
        values = rng.uniform(0, 2, n)
        if rng.random() < 0.5:
            values = np.round(values, 1)  # ties
        for q in (0.0, 0.33, 0.5, 0.8, 1.0):
            assert np.array_equal(region_quantile(region, values, q),
                                  _quantile_before(region, values, q))



def test_group_percentiles():
    rng = np.random.default_rng(3)
    for _ in range(300):
        n, groups = int(rng.integers(1, 60)), int(rng.integers(1, 8))
        group = rng.integers(0, groups, n)
        values = rng.exponential(1.0, n)
        if rng.random() < 0.5:
            values = np.round(values, 1)
        got = group_percentiles(group, values, groups, 0.8)
        for g in range(groups):
            want = np.percentile(values[group == g], 80) if (group == g).any() else np.nan
            assert got[g] == want or (np.isnan(want) and np.isnan(got[g]))
