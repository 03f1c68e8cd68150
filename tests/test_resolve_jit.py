"""The order resolution's compiled passes (bistair.core.resolve_jit, and those of its parts:
bistair.core.parts_jit) give exactly what the
NumPy code they replaced gave: dense patches of wrong steps, each region's order on its
pixels, messages between regions, votes per region and code, and the in-place fills and
splits."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from bistair.core.parts_jit import dense_tile, window_seeds


def _dense_before(bad, decided, share, block=8):
    pad = ((0, -bad.shape[0] % block), (0, -bad.shape[1] % block))
    tiles = ((bad.shape[0] + pad[0][1]) // block, block, (bad.shape[1] + pad[1][1]) // block,
             block)
    nbad = np.pad(bad, pad).reshape(tiles).sum(axis=(1, 3))
    ndec = np.pad(decided, pad).reshape(tiles).sum(axis=(1, 3))
    return bool((nbad > 0.9 * share * np.maximum(ndec, 1)).any())



def test_disagreeing_windows():

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



def test_pixel_orders():
    from bistair.core.parts_jit import pixel_orders

    rng = np.random.default_rng(10)
    labels = rng.integers(0, 6, (30, 40)).astype(np.int32)
    k_reg = np.array([7, -1, 0, 63, 5000, 12])
    k_pix = pixel_orders(labels, k_reg)
    assert np.array_equal(k_pix, np.where(labels > 0, k_reg[labels], -1))



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
