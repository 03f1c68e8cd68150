"""The band evidence's compiled passes (bistair.codecs.bidirectional.evidence_jit) give what
the NumPy they replaced gave: region_evidence the evidence of its loop over regions to 1e-12
(sums taken in order rather than pairwise, the C library's log), on random runs and a
decode's; the heights and band splits exactly."""

from __future__ import annotations

import numpy as np
import pytest
from support.reference import level_misfit

from bistair.codecs import make_spec
from bistair.codecs.bidirectional.bands import (
    Runs,
)
from bistair.codecs.bidirectional.evidence import (
    BandLayout,
    _own_heights,
    band_splits,
    region_evidence,
)
from bistair.core.stair import quantize
from bistair.sim.warp import WarpScene, render_warp

RNG = np.random.default_rng(5)


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


def _own_heights_before(region, uid, length, n_regions):
    own = np.full(n_regions + 1, np.nan)
    for r in np.unique(region):
        sel = region == r
        vals, inv, counts = np.unique(uid[sel], return_inverse=True, return_counts=True)
        if vals.size < 2:
            continue
        top_two = np.argsort(counts)[-2:]
        own[r] = sum(np.median(length[sel][inv == v]) for v in top_two)
    return own



def _band_splits_before(runs, heights, local_share):
    splits = []
    if runs.uid.size < 2:
        return splits
    uid, reg, length = runs.uid, runs.region, runs.length
    solid = length >= 2.0
    h = np.asarray(heights, float)[reg]
    merged = np.isfinite(h) & (length >= 1.3 * max(local_share, 1 - local_share) * h)

    def same(*idx):
        return all(0 <= j < uid.size and reg[j] == reg[idx[0]] and solid[j] for j in idx)

    for i in range(1, uid.size):
        if not same(i - 1, i) or uid[i] == uid[i - 1]:
            continue
        if same(i - 2, i - 1, i) and not merged[i - 1] and uid[i] != uid[i - 2]:
            confirmed = ((same(i, i + 2) and uid[i + 2] == uid[i])
                         or (same(i, i + 1) and uid[i + 1] not in (uid[i - 1], uid[i - 2]))
                         or merged[i])
        elif merged[i - 1]:
            confirmed = same(i, i + 2) and uid[i + 2] == uid[i] and not merged[i]
        else:
            confirmed = False
        if not confirmed and merged[i] and same(i - 2, i - 1, i) and not merged[i - 1] \
                and uid[i - 2] == uid[i]:
            confirmed = True
        if confirmed and (not splits or splits[-1][0] != reg[i] or splits[-1][1] < runs.y0[i - 1]):
            splits.append((int(reg[i]), int(runs.y0[i])))
    return splits



def test_own_heights():
    rng = np.random.default_rng(4)
    for _ in range(300):
        n = int(rng.integers(1, 80))
        region = np.sort(rng.integers(1, int(rng.integers(2, 12)), n))
        uid = rng.integers(0, int(rng.integers(1, 6)), n)  # few values: count ties
        length = rng.integers(2, 20, n) + rng.choice([0.0, 0.5], n)
        got = _own_heights(region, uid, length, 12)
        want = _own_heights_before(region, uid, length, 12)
        assert np.array_equal(got, want, equal_nan=True)



def test_band_splits():
    rng = np.random.default_rng(5)
    for _ in range(300):
        n = int(rng.integers(0, 60))
        region = np.sort(rng.integers(1, 5, n))
        uid = rng.integers(0, 4, n)
        length = rng.choice([1.0, 2.0, 6.0, 10.0, 16.0, 30.0], n)
        y0 = np.cumsum(rng.integers(1, 12, n))
        runs = Runs(region, y0, y0 + length.astype(int), length, np.zeros(n), np.ones(n), uid,
                    np.ones(n, bool), np.ones(n, bool), np.zeros(n))
        heights = np.r_[np.nan, rng.choice([np.nan, 16.0, 20.0], 5)]
        assert band_splits(runs, heights, 10 / 16) == _band_splits_before(runs, heights,
                                                                          10 / 16)
