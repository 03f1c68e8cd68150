"""The bidirectional stair checks' compiled passes (bistair.codecs.bidirectional.stairs_jit:
stair agreement, stair noise) and the OpenCV morphology of the stair edges give, bit for
bit, what the NumPy expressions they replaced gave (written out here), on random data and on
the values where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from support.arrays import same

from bistair.codecs.bidirectional.stairs import edge_runs
from bistair.codecs.bidirectional.stairs_jit import stair_agreement
from bistair.core.stair_jit import quantize32

RNG = np.random.default_rng(7)


@pytest.mark.parametrize(("stairs", "partitions"), [(8, 8), (4, 3), (2, 32)])
def test_stair_agreement_is_numpys(stairs, partitions):
    shape = (40, 50)
    levels = RNG.integers(-1, stairs, shape).astype(np.int32)
    theta = RNG.uniform(-np.pi, np.pi, shape).astype(np.float32)
    theta.flat[:3] = [np.float32(np.pi), -np.float32(np.pi), np.nextafter(np.float32(np.pi), 0)]
    order = RNG.integers(-3 * stairs, 2 * stairs * partitions, shape)
    part = quantize32(theta, partitions, np.ones(shape, bool))
    old = (levels == order % stairs) | (part == order // stairs)
    assert same(stair_agreement(levels, theta, order, stairs, partitions), old)



def test_edge_runs_are_scipys_morphology():
    """OpenCV's erosion with an empty outside and anchors matching scipy's reflected
    elements: the same pixels as scipy.ndimage, at the borders too."""
    for _ in range(400):
        shape = tuple(RNG.integers(1, 30, 2))
        edge = RNG.random(shape) < RNG.choice([0.1, 0.5, 0.9])
        for reach in (0, 1, 12):
            wide = ndimage.binary_dilation(edge, np.ones((1, 3), bool))
            old = edge & ndimage.binary_opening(wide, np.ones((4, 1), bool))
            if reach > 0 and old.any():
                old = ndimage.binary_dilation(old, np.ones((2 * reach + 1, 1), bool))
            assert same(edge_runs(edge, reach), old)


def test_stair_sums_and_noise_match_the_numpy_values():
    from bistair.codecs.bidirectional.profiles import stair_values
    from bistair.codecs.bidirectional.profiles_jit import label_row_sums, label_stair_sums
    from bistair.codecs.bidirectional.stairs_jit import stair_noise
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
