"""The row profiles' compiled passes (bistair.codecs.bidirectional.profiles_jit) give exactly
what np.bincount and the NumPy profiles give."""

from __future__ import annotations

import numpy as np


def test_split_profiles():
    from bistair.codecs.bidirectional.evidence import split_profiles, split_regions
    from bistair.codecs.bidirectional.profiles import row_profiles, stair_values

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



def test_label_row_sums_match_bincount():
    from bistair.codecs.bidirectional.profiles_jit import label_row_sums

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
