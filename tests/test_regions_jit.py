"""The fringe regions' compiled passes (bistair.core.regions_jit) give exactly what the NumPy
formulation gives: the period-jump links of bistair.core.regions.period_jumps, and the
fringe direction."""

from __future__ import annotations

import numpy as np
import pytest

from bistair.core.jit import set_threads
from bistair.core.regions import period_jumps
from bistair.core.regions_jit import period_jump_links


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
