"""The stair phase's compiled pass (bistair.core.stair_jit.pair_phase) gives what the NumPy
reference, bistair.core.stair.stair_phase, gives."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import arctan2_rounded, same

from bistair.core.captures import ScaledStack
from bistair.core.stair import level_readings, level_table, relinearize, stair_level_phase
from bistair.core.stair_jit import pair_phase, quantize32, relinearize32

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float64])
def test_pair_phase_is_stair_phase(dtype):
    top = 1.0 if dtype == np.float64 else np.iinfo(dtype).max
    raw = (RNG.uniform(0, 1, (5, 30, 40)) * top).astype(dtype)
    raw[3, 0, :3] = raw[4, 0, :3] = 0
    frames = ScaledStack(raw, 1.0 / top)
    avg = RNG.uniform(0, 1, (30, 40)).astype(np.float32)
    c, s = frames[3] - avg, frames[4] - avg
    theta, mod = pair_phase(raw, 3, np.float32(1.0 / top), avg)
    assert same(theta, arctan2_rounded(s, c)) and same(mod, np.hypot(s, c))


def test_relinearize32_is_relinearize_and_quantize():
    """The compiled map through a level table gives the NumPy reference's phases bit for bit
    and quantize32's levels of them (including phases at the ends of the circle)."""
    levels = stair_level_phase(np.arange(11), 11)
    table = level_table(level_readings(levels, 2.2), levels)
    theta = RNG.uniform(-np.pi, np.pi, (64, 80)).astype(np.float32)
    theta[0, :4] = [-np.pi, np.pi, np.nextafter(np.float32(np.pi), 0), 0.0]
    valid = RNG.uniform(0, 1, theta.shape) < 0.9
    mapped, level = relinearize32(theta, table, 11, valid)
    assert same(mapped, relinearize(theta, table))
    assert np.array_equal(level, quantize32(mapped, 11, valid))
