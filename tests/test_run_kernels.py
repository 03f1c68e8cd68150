"""The band analysis's compiled passes (bistair.core.run_kernels) give what the NumPy they
replaced gave: ``bands.row_runs`` exactly the same runs, levels, lengths and sums on random
row profiles (zero weights, one entry, no band row, several level sets, profiles out of
order); ``evidence.region_evidence`` the evidence of its loop over regions to 1e-12 (sums
taken in order rather than pairwise, the C library's log), on random runs and a decode's."""

from __future__ import annotations

from dataclasses import astuple

import numpy as np
import pytest

from bistair.codecs import make_spec
from bistair.codecs.bidirectional.bands import (
    RowProfiles,
    Runs,
    _drop_transitions,
    nearest_level,
    observed_levels,
    row_runs,
    union_levels,
)
from bistair.codecs.bidirectional.evidence import BandLayout, region_evidence
from bistair.core.phase import TWO_PI, wrap
from bistair.core.region_kernels import group_percentiles, region_quantile
from bistair.core.stair import level_misfit, quantize
from bistair.sim.warp import WarpScene, render_warp

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


def _region_evidence_before(runs, n_regions, heights, layout):
    """``region_evidence`` as its loop over regions in NumPy computed it."""
    S, P = layout.stairs, layout.partitions
    ks = np.arange(S * P)
    a_of_k, b_of_k = ks % S, ks // S
    ev = np.zeros((n_regions + 1, S * P))
    if runs.uid.size == 0:
        return ev
    order = np.argsort(runs.region, kind="stable")
    runs = runs.take(order)
    bounds = np.flatnonzero(np.r_[True, runs.region[1:] != runs.region[:-1], True])
    f_loc, f_par = layout.local_share, 1.0 - layout.local_share
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        r = int(runs.region[lo])
        uid, wgt, length = runs.uid[lo:hi], runs.weight[lo:hi], runs.length[lo:hi]
        complete = runs.top_ok[lo:hi] & runs.bottom_ok[lo:hi]
        h = heights[r] if np.isfinite(heights[r]) else layout.default_height
        total = wgt.sum()
        row_weight = total / max(length.sum(), 1.0)
        if (runs.misfit[lo:hi] * wgt).sum() > 0.32 * total:
            continue  # rows read between levels: the bands are blurred together, no order
        vals, inv = np.unique(uid, return_inverse=True)
        cls_w = np.bincount(inv, wgt)
        rank = np.argsort(cls_w)[::-1]
        x = rank[0]
        y = rank[1] if vals.size > 1 else -1
        if y >= 0 and (cls_w[y] < 0.05 * total or length[inv == y].max() < 2):
            y = -1
        # A class's level is the one its rows were read as (against the levels observed in
        # this capture); its nominal phase says which stair index that is.
        th_x = layout.levels[vals[x]]
        if y < 0:
            a, b = quantize(th_x, S), quantize(th_x, P)
            if length.max() >= 1.3 * max(f_loc, f_par) * h:
                fit = level_misfit(th_x, a, S) + level_misfit(th_x, b, P)
                ev[r, a + S * b] = cls_w[x] / total - 0.5 * fit
            else:
                share = 0.4 * cls_w[x] / total
                ev[r, a_of_k == a] = share
                ev[r, b_of_k == b] = share
            continue
        th_y = layout.levels[vals[y]]
        options = []
        for loc, par in ((x, y), (y, x)):
            th_l, th_p = (th_x, th_y) if loc == x else (th_y, th_x)
            a, b = quantize(th_l, S), quantize(th_p, P)
            expect = np.where(inv == loc, f_loc * h, np.where(inv == par, f_par * h, np.nan))
            cost = _length_cost(length, expect, complete)
            fit = level_misfit(th_l, a, S) + level_misfit(th_p, b, P)
            # A class seen in 3 or more rows' worth of pixels is certain; a match counts +1,
            # a mismatch -1, each weighted by how certain its class is.
            e_l, e_p = np.minimum(1.0, cls_w[[loc, par]] / (3.0 * row_weight))
            hits = e_l * np.where(a_of_k == a, 1.0, -1.0) + e_p * np.where(b_of_k == b, 1.0, -1.0)
            options.append((hits / (e_l + e_p) - 0.5 * fit, cost))
        # Band lengths decide which value is the local one: the worse-fitting reading
        # loses up to 0.5, the better one nothing (its absolute fit depends on h).
        low = min(cost for _, cost in options)
        ev[r] = np.max([score - 0.5 * min(1.0, cost - low) for score, cost in options], axis=0)
    return ev


def _length_cost(length, expect, complete):
    ok = np.isfinite(expect)
    if not ok.any():
        return 0.0
    ratio = np.log(np.maximum(length[ok], 0.5) / expect[ok])
    over = np.maximum(ratio - np.log(1.25), 0.0)
    terms = np.where(complete[ok], ratio**2, over**2)
    return float(terms.sum())


def _runs(n, regions, layout, rng):
    """Random runs: bands of one to four levels per region, some short, some cut."""
    region = np.sort(rng.integers(1, regions + 1, n))
    uid = np.zeros(n, np.int64)
    for r in np.unique(region):
        at = np.flatnonzero(region == r)
        choices = rng.choice(layout.levels.size, int(rng.integers(1, 5)))
        uid[at] = choices[np.arange(at.size) % choices.size] if rng.random() < 0.7 else \
            rng.choice(choices, at.size)
    return Runs(region=region.astype(np.int64), y0=np.zeros(n, np.int64),
                y1=np.zeros(n, np.int64), length=rng.uniform(0.5, 40, n),
                theta=np.zeros(n), weight=rng.uniform(0, 50, n), uid=uid.astype(np.int32),
                top_ok=rng.random(n) < 0.8, bottom_ok=rng.random(n) < 0.8,
                misfit=rng.uniform(0, 0.5, n) * (rng.random(n) < 0.5))


@pytest.mark.parametrize("n", [1, 2, 9, 80, 700])
@pytest.mark.parametrize("stairs", [(6, 6), (3, 4), (8, 8)])
def test_region_evidence_is_the_loops(n, stairs):
    rng = np.random.default_rng(n)
    for trial in range(6):
        layout = BandLayout(stairs[1], stairs[0], 0.6 + 0.1 * (trial % 3), 16.0)
        regions = int(rng.integers(1, 30))
        runs = _runs(n, regions, layout, rng)
        heights = rng.uniform(8, 30, regions + 3)
        heights[rng.random(heights.size) < 0.3] = np.nan
        expected = _region_evidence_before(runs, regions + 2, heights, layout)
        got = region_evidence(runs, regions + 2, heights, layout)
        assert got.shape == expected.shape
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_region_evidence_of_a_decode_is_the_loops():
    # the runs and heights the default decoder reads on a rendered scene
    captured = []

    def keep(runs, n, heights, layout):
        captured.append((runs, n, heights, layout))
        return region_evidence(runs, n, heights, layout)

    import bistair.codecs.bidirectional as bidirectional

    spec = make_spec("bidirectional", width=480, height=300, period=20, partitions=5,
                     stairs=5)
    frames, _ = render_warp(spec, WarpScene(size=(240, 320), noise=0.02, seed=3))
    original = bidirectional.region_evidence
    bidirectional.region_evidence = keep
    try:
        bidirectional.CODEC.decode(frames, spec)
    finally:
        bidirectional.region_evidence = original
    assert captured and captured[0][0].uid.size > 50
    for runs, n, heights, layout in captured:
        np.testing.assert_allclose(region_evidence(runs, n, heights, layout),
                                   _region_evidence_before(runs, n, heights, layout),
                                   rtol=1e-12, atol=1e-12)
