"""The result's compiled pass (bistair.core.result_jit.assemble) gives, bit for bit, what the
NumPy expressions they replaced gave (written out here), on random data and on the values
where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
from support.arrays import same

from bistair.core.phase import (
    TWO_PI,
)
from bistair.core.result_jit import assemble

RNG = np.random.default_rng(7)


def test_assemble_is_make_results_numpy():
    phi = RNG.uniform(0, TWO_PI, (30, 40)).astype(np.float32)
    phi.flat[:2] = np.nan, np.float32(TWO_PI) - np.float32(1e-6)
    order = RNG.integers(-1, 66, phi.shape)
    valid = RNG.random(phi.shape) < 0.8
    period, length = 30.0, 1920
    for bounded in (False, True):
        out = order.astype(np.int32)
        mask = (out >= 0) & np.isfinite(phi)
        outside = 0
        if bounded:
            top = np.floor(np.float32(length) / np.float32(period)).astype(np.int32)
            inside = (out < top) | ((out == top) & (
                phi * np.float32(period / TWO_PI) < np.float32(length - top * period)))
            outside = int((mask & ~inside).sum())
            mask &= inside
        out[~mask] = -1
        phase = phi + np.float32(TWO_PI) * out.astype(np.float32)
        phase[~mask] = np.nan
        got = assemble(phi, order, period, length if bounded else None, valid)
        assert same(got[0], phase) and same(got[1], phase * np.float32(period / TWO_PI))
        assert same(got[2], out) and same(got[4], mask) and got[5] == outside
        assert same(got[3], np.where(valid, phi, np.float32(np.nan)))
