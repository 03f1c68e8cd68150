"""The Gray code's compiled passes (bistair.codecs.graycode_jit: code bits, orders) give, bit
for bit, what the NumPy expressions they replaced gave (written out here), on random data
and on the values where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
from support.arrays import same

from bistair.codecs.graycode import gray_to_binary
from bistair.codecs.graycode_jit import code_bits, gray_orders
from bistair.core.captures import ScaledStack
from bistair.core.phase import (
    TWO_PI,
)

RNG = np.random.default_rng(7)


def test_code_bits_are_numpys():
    raw = RNG.integers(0, 256, (9, 20, 30)).astype(np.uint8)
    frames = ScaledStack(raw, 1 / 255)
    avg = RNG.uniform(0, 1, (20, 30)).astype(np.float32)
    avg.flat[:3] = frames[2].flat[:3]  # a frame equal to its threshold reads 0
    for inverse in (False, True):
        ref = frames[5:8] if inverse else avg[None].repeat(3, axis=0)
        gray = np.zeros(avg.shape, np.int32)
        for frame, against in zip(frames[2:5], ref, strict=True):
            gray <<= 1
            gray |= frame > against
        assert same(code_bits(raw, 2, 3, np.float32(1 / 255), avg, inverse), gray)



def test_gray_orders_are_numpys():
    gray = RNG.integers(0, 2**8, (30, 40)).astype(np.int32)
    phi = RNG.uniform(0, TWO_PI, gray.shape).astype(np.float32)
    phi.flat[:4] = [np.nan, np.float32(np.pi / 2), np.float32(1.5 * np.pi), np.float32(np.pi)]
    valid = RNG.random(gray.shape) < 0.9
    for mode, fringes in ((0, 200), (1, 100), (2, 200)):
        if mode == 1:
            k1 = gray_to_binary(gray >> 1)
            k2 = (gray_to_binary(gray) + 1) // 2
            k = np.where(phi < np.pi / 2, k2, np.where(phi >= 1.5 * np.pi, k2 - 1, k1))
            edges = k1
        elif mode == 2:
            edges = gray_to_binary(gray)
            k = np.where(phi < np.pi, edges, edges - 1)
        else:
            k = edges = gray_to_binary(gray)
        ok = valid & (k >= 0) & (k < fringes)
        code, got_edges, beyond = gray_orders(gray, phi, valid, mode, fringes)
        assert same(code, np.where(ok, k, -1).astype(np.int32))
        assert same(got_edges, np.where(valid, edges, -1).astype(np.int32))
        assert beyond == int(np.count_nonzero(valid & (k >= fringes)))
