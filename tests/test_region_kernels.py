"""The region stage's compiled statistics give exactly what the NumPy code they replaced
gave: the same nearest levels, order statistics, percentiles, medians and band splits, on
random data with ties and tiny regions."""

from __future__ import annotations

import numpy as np
import pytest

from bistair.codecs.bidirectional.bands import Runs, union_levels
from bistair.codecs.bidirectional.evidence import _own_heights, band_splits
from bistair.core.kernels import period_jump_links, set_threads
from bistair.core.phase import wrap
from bistair.core.region_kernels import (
    group_percentiles,
    nearest_levels,
    region_quantile,
)
from bistair.core.region_maps import dense_tile, window_seeds
from bistair.core.regions import period_jumps


def _nearest_before(theta, levels):
    d = np.abs(wrap(np.asarray(theta)[:, None] - levels[None, :]))
    return d.argmin(axis=1).astype(np.int32)


def _quantile_before(region, values, q):
    order = np.lexsort((values, region))
    starts = np.flatnonzero(np.r_[True, region[order][1:] != region[order][:-1]])
    counts = np.diff(np.r_[starts, region.size])
    pick = values[order][starts + np.floor(q * (counts - 1)).astype(np.int64)]
    return np.repeat(pick, counts)[np.argsort(order, kind="stable")]


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


@pytest.mark.parametrize("levels", [union_levels(8, 8), union_levels(3, 4), np.array([0.5]),
                                    np.array([2.0, -1.0, 0.3])])
def test_nearest_levels(levels):
    rng = np.random.default_rng(1)
    theta = np.r_[rng.uniform(-np.pi, np.pi, 20000), rng.uniform(-12, 12, 2000), levels,
                  -levels, (levels[:, None] + levels[None, :]).ravel() / 2,  # ties
                  [np.pi, -np.pi, 0.0, -0.0, 2 * np.pi, -3 * np.pi, np.nan]]
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


def _dense_before(bad, decided, share, block=8):
    pad = ((0, -bad.shape[0] % block), (0, -bad.shape[1] % block))
    tiles = ((bad.shape[0] + pad[0][1]) // block, block, (bad.shape[1] + pad[1][1]) // block,
             block)
    nbad = np.pad(bad, pad).reshape(tiles).sum(axis=(1, 3))
    ndec = np.pad(decided, pad).reshape(tiles).sum(axis=(1, 3))
    return bool((nbad > 0.9 * share * np.maximum(ndec, 1)).any())


def test_disagreeing_windows():
    from scipy import ndimage

    rng = np.random.default_rng(6)
    for _ in range(200):
        h, w = (int(v) for v in rng.integers(7, 40, 2))
        decided = rng.random((h, w)) < rng.uniform(0.3, 1.0)
        bad = decided & (rng.random((h, w)) < rng.uniform(0.1, 0.9))
        for share in (0.7, 0.5):
            assert dense_tile(bad, decided, share, 8) == _dense_before(bad, decided, share)
            seeds, close = window_seeds(bad, decided, 7, share)
            num = ndimage.uniform_filter(bad.astype(np.float32), 7)
            den = ndimage.uniform_filter(decided.astype(np.float32), 7)
            want = bad & (num > share * den)
            if not close:
                assert np.array_equal(seeds, want)


def test_median_sign():
    from bistair.core.regions import _median_sign

    rng = np.random.default_rng(8)
    for _ in range(2000):
        n = int(rng.integers(1, 12))
        values = rng.choice([-2.0, -1e-45, -0.0, 0.0, 1e-45, 0.5, 2.0], n).astype(np.float32)
        if rng.random() < 0.3:
            values = rng.normal(size=n).astype(np.float32)
        want, got = np.median(values), _median_sign(values)
        assert (want >= 0) == (got >= 0)


def test_stair_sums_and_noise_match_the_numpy_values():
    from bistair.codecs.bidirectional.bands import stair_values
    from bistair.core.label_rows import label_row_sums
    from bistair.core.region_maps import label_stair_sums, stair_noise
    from bistair.core.regions import core_weight

    rng = np.random.default_rng(9)
    for shape in [(1, 1), (1, 7), (9, 1), (40, 50), (33, 64), (150, 20)]:
        phi = rng.uniform(0, 2 * np.pi, shape).astype(np.float32)
        theta = rng.uniform(-np.pi, np.pi, shape).astype(np.float32)
        stair_mod = rng.uniform(0, 0.5, shape).astype(np.float32)
        mod = rng.uniform(0, 0.5, shape).astype(np.float32)
        edge = [0.0, np.float32(2 * np.pi) - 1e-7, np.pi, 1e-30, 6.0][:phi.size]
        phi.flat[:len(edge)] = edge
        stair_mod.flat[:3], mod.flat[-2:] = 0.0, 1e-7
        labels = rng.integers(0, 5, shape).astype(np.int32)
        ratio = np.clip(stair_mod / np.maximum(mod, 1e-6), 0.0, 2.0)
        values = stair_values(theta, core_weight(phi) * np.minimum(ratio, 1.0), ratio)
        want = label_row_sums(labels, values, int(labels.max()))
        got = label_stair_sums(labels, phi, theta, stair_mod, mod, int(labels.max()))
        assert all(np.array_equal(a, b) for a, b in zip(want, got, strict=True))
        noise_scale = 0.012 * np.sqrt(2.0)
        want_noise = np.ascontiguousarray(noise_scale / np.maximum(stair_mod, 1e-6), np.float32)
        assert np.array_equal(stair_noise(stair_mod, float(noise_scale)), want_noise)


def test_pixel_orders():
    from bistair.core.region_maps import pixel_orders

    rng = np.random.default_rng(10)
    labels = rng.integers(0, 6, (30, 40)).astype(np.int32)
    k_reg = np.array([7, -1, 0, 63, 5000, 12])
    k_pix = pixel_orders(labels, k_reg)
    assert np.array_equal(k_pix, np.where(labels > 0, k_reg[labels], -1))


def test_split_profiles():
    from bistair.codecs.bidirectional.bands import row_profiles, stair_values
    from bistair.codecs.bidirectional.evidence import split_profiles, split_regions

    rng = np.random.default_rng(11)
    for _ in range(30):
        h, w = (int(v) for v in rng.integers(4, 30, 2))
        labels = rng.integers(0, 5, (h, w)).astype(np.int32)
        values = stair_values(rng.uniform(-3, 3, (h, w)).astype(np.float32),
                              rng.random((h, w)), rng.random((h, w)))
        splits = [(int(r), int(y)) for r, y in zip(rng.integers(1, 5, 3),
                                                   rng.integers(0, h, 3), strict=True)]
        n = int(labels.max())
        want = row_profiles(split_regions(labels, n, splits)[0], values)
        got = split_profiles(row_profiles(labels, values), n, splits)
        for key, value in want.__dict__.items():
            assert np.array_equal(getattr(got, key), value), key


def test_resolve_regions_messages():
    from bistair.core.regions import RegionLinks
    from bistair.core.resolve import resolve_regions

    def before(evidence, links, link_weight=0.5, iterations=12, cap=2.0):
        n_k = evidence.shape[1]
        src = np.concatenate([links.src, links.dst])
        dst = np.concatenate([links.dst, links.src])
        step = np.concatenate([links.step, -links.step])
        strength = link_weight * np.minimum(1.0, np.concatenate([links.count,
                                                                 links.count]) / 10.0)
        n_e = src.size
        reverse = np.r_[np.arange(n_e // 2, n_e), np.arange(n_e // 2)]
        msgs = np.zeros((n_e, n_k))
        belief = evidence.copy()
        ks = np.arange(n_k)
        for _ in range(iterations if n_e else 0):
            without = belief[src] - msgs[reverse]
            prev_k = ks[None, :] - step[:, None]
            ok = (prev_k >= 0) & (prev_k < n_k)
            shifted = np.take_along_axis(without, np.clip(prev_k, 0, n_k - 1), axis=1)
            new = np.where(ok, strength[:, None] * np.clip(shifted, 0.0, cap), 0.0)
            msgs = 0.5 * msgs + 0.5 * new
            belief = evidence.copy()
            np.add.at(belief, dst, msgs)
        order = belief.argmax(axis=1)
        top2 = np.sort(belief, axis=1)[:, -2:]
        order[top2[:, 1] <= 0] = -1
        return order, top2[:, 1], top2[:, 1] - top2[:, 0]

    rng = np.random.default_rng(12)
    for _ in range(50):
        n, k, e = int(rng.integers(2, 30)), int(rng.integers(2, 12)), int(rng.integers(0, 60))
        evidence = np.round(rng.uniform(-0.5, 1.0, (n + 1, k)), 2)
        src, dst = rng.integers(1, n + 1, e), rng.integers(1, n + 1, e)
        links = RegionLinks(src, dst, rng.choice([-1, 1], e), rng.integers(1, 30, e))
        for got, want in zip(resolve_regions(evidence, links), before(evidence, links),
                             strict=True):
            assert np.array_equal(got, want)


def test_label_row_sums_match_bincount():
    from bistair.core.label_rows import label_row_sums

    rng = np.random.default_rng(12)
    for shape, n in [((1, 1), 1), ((5, 1), 3), ((1, 9), 4), ((70, 40), 3), ((64, 33), 900)]:
        labels = rng.integers(0, n + 1, shape).astype(np.int32)
        labels[rng.random(shape) < 0.3] = 0
        if shape[0] > 3:
            labels[2] = 0  # a row without labels
        values = rng.normal(size=(3, *shape)).astype(np.float32)
        h = shape[0]
        key = (labels.astype(np.int64) * h + np.arange(h)[:, None])[labels > 0]
        want_keys, inv = np.unique(key, return_inverse=True)
        keys, counts, sums = label_row_sums(labels, values, int(labels.max()))
        assert np.array_equal(keys, want_keys)
        assert np.array_equal(counts, np.bincount(inv, minlength=want_keys.size))
        for v in range(3):
            want = np.bincount(inv, values[v][labels > 0].astype(np.float64), want_keys.size)
            assert np.array_equal(sums[v], want)


def test_code_evidence_matches_bincount():
    from bistair.core.resolve import code_evidence

    rng = np.random.default_rng(13)
    for shape, n, c in [((1, 1), 1, 1), ((6, 1), 3, 4), ((40, 30), 20, 7), ((25, 64), 300, 64)]:
        labels = rng.integers(0, n + 1, shape).astype(np.int32)
        codes = rng.integers(-1, c, shape).astype(np.int32)
        weights = rng.uniform(0.1, 1, shape).astype(np.float32)
        for w in (None, weights):
            flat, cc = labels.ravel(), codes.ravel()
            sel = (flat > 0) & (cc >= 0)
            ww = None if w is None else w.ravel()[sel]
            votes = np.bincount(flat[sel].astype(np.int64) * c + cc[sel], ww,
                                (n + 1) * c).reshape(n + 1, c)
            total = np.bincount(flat[sel], ww, n + 1)
            want = votes / np.maximum(total, 1e-12)[:, None]
            assert np.array_equal(code_evidence(labels, n, codes, c, w), want)


def test_in_place_fills_and_splits_equal_the_copies():
    from bistair.codecs.bidirectional.evidence import split_regions
    from bistair.core.regions import fill_orders

    rng = np.random.default_rng(14)
    phi = rng.uniform(0, 2 * np.pi, (30, 40)).astype(np.float32)
    order = rng.integers(-1, 5, (30, 40)).astype(np.int32)
    target = rng.random((30, 40)) < 0.5
    want = fill_orders(phi, order, target)
    given = order.copy()
    got = fill_orders(phi, given, target, in_place=True)
    assert got is given and np.array_equal(got, want)
    assert not np.array_equal(want, order)  # the copy left the input alone

    labels = rng.integers(0, 4, (30, 40)).astype(np.int32)
    splits = [(1, 10), (2, 5), (1, 20)]
    want, n = split_regions(labels, 3, splits)
    given = labels.copy()
    got, m = split_regions(given, 3, splits, in_place=True)
    assert got is given and m == n and np.array_equal(got, want)
    assert not np.array_equal(want, labels)


@pytest.mark.parametrize("shape", [(1, 1), (1, 9), (9, 1), (2, 5), (37, 41), (70, 1200)])
@pytest.mark.parametrize("half", [1, 3, 5])
@pytest.mark.parametrize("threads", [1, None])
def test_period_jump_links_are_numpys(shape, half, threads):
    # fringes whose period and slant change from place to place, noise, invalid pixels
    h, w = shape
    rng = np.random.default_rng(h * w + half)
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    period = np.where((x // 37 + y // 23) % 2 == 0, 20.0, 33.0)
    phi = ((2 * np.pi * (x + 0.3 * y) / period + rng.normal(0, 0.05, shape)) % (2 * np.pi)
           ).astype(np.float32)
    valid = rng.random(shape) > 0.15
    noise = rng.uniform(0.001, 0.05, shape).astype(np.float32)
    expected = period_jumps(phi, valid, noise, 0.3, half)
    try:
        set_threads(threads)
        got = period_jump_links(phi, valid, noise, half, 0.3)
    finally:
        set_threads(None)
    assert np.array_equal(got[0], expected[0]) and np.array_equal(got[1], expected[1])
    assert got[1].any() or w < 2 * half + 2 or h * w < 1000
