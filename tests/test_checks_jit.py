"""The checks' compiled passes (bistair.core.checks_jit: code steps, wrap steps, and the
decoded sample) give, bit for bit, what the NumPy expressions they replaced gave (written
out here), on random data and on the values where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
from support.arrays import same

from bistair.codecs.bidirectional.stairs_jit import decoded_sample
from bistair.core.checks_jit import code_steps, wrap_step_counts
from bistair.core.phase import (
    TWO_PI,
)

RNG = np.random.default_rng(7)


def test_code_steps_and_sample_are_numpys():
    phi = RNG.uniform(0, TWO_PI, (30, 41)).astype(np.float32)
    code = np.repeat(RNG.integers(-1, 5, (30, 21)), 2, axis=1)[:, :41].astype(np.int32)
    valid = RNG.random(phi.shape) < 0.9
    e = np.where(valid, code, -1)
    a0, a, b, b1 = e[:, :-3], e[:, 1:-2], e[:, 2:-1], e[:, 3:]
    ok = (a >= 0) & (b >= 0) & (a != b) & (a0 == a) & (b1 == b)
    pa, pb, step = code_steps(phi, code, valid)
    assert same(pa, phi[:, 1:-2][ok].astype(np.float64))
    assert same(pb, phi[:, 2:-1][ok].astype(np.float64))
    assert same(step, (b - a)[ok].astype(np.int64))
    for samples in (1, 7, 100, 10**6):
        idx = np.flatnonzero(valid & (code >= 0))
        assert same(decoded_sample(valid, code, samples),
                     idx[::max(1, idx.size // samples)])



def _wrap_steps(phi, order, valid, every, reach):
    """checks.wrap_steps as NumPy computed it."""
    p, k = phi[::every].astype(np.float32), order[::every]
    ok = valid[::every] & (k >= 0)
    width = p.shape[1]
    if width < 2 * reach + 2:
        return 0, 0, 0
    d = p[:, 1:] - p[:, :-1]
    wraps = np.abs(d) > np.pi
    clean = ok[:, 1:] & ok[:, :-1] & (np.abs(d - TWO_PI * np.round(d / TWO_PI)) < 0.6)
    zero = np.zeros((p.shape[0], 1), np.int32)
    bad_sum = np.concatenate([zero, np.cumsum(~clean, axis=1, dtype=np.int32)], axis=1)
    wrap_sum = np.concatenate([zero, np.cumsum(wraps & clean, axis=1, dtype=np.int32)], axis=1)
    span = 2 * reach + 1
    bad_in = bad_sum[:, span:] - bad_sum[:, :-span]
    wraps_in = wrap_sum[:, span:] - wrap_sum[:, :-span]
    judged = wraps[:, reach:width - 1 - reach] & (bad_in == 0) & (wraps_in == 1)
    want = np.where(d[:, reach:width - 1 - reach] > 0, -1, 1)
    off = np.abs(k[:, span:].astype(np.int64) - k[:, :-span] - want)[judged]
    return int(np.count_nonzero(off)), int(np.count_nonzero(off >= 2)), int(judged.sum())



def test_wrap_steps_are_numpys():
    for _ in range(60):
        h, w = RNG.integers(1, 20), RNG.integers(1, 60)
        period = RNG.uniform(3, 20)
        x = np.arange(w) + RNG.uniform(0, 1)
        phi = ((TWO_PI * x / period)[None] + RNG.normal(0, RNG.choice([0.01, 0.3]), (h, w)))
        phi = (phi % TWO_PI).astype(np.float32)
        order = (x // period).astype(np.int32)[None] + RNG.choice([0, 0, 0, 1, -2], (h, w))
        valid = RNG.random((h, w)) < 0.95
        for every, reach in ((1, 3), (2, 3), (3, 1)):
            assert (wrap_step_counts(phi, order, valid, every, reach)
                    == _wrap_steps(phi, order, valid, every, reach))
