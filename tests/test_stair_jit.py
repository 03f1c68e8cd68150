"""The stair phase's compiled passes (bistair.core.stair_jit) give what the NumPy
references (bistair.core.stair) give, bit for bit: the pair's phase and modulation (the
float32 arctangent, held to its NumPy emulation) and its quantisation."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import angle_np, same
from support.reference import relinearize, stair_phase

from bistair.core.captures import ScaledStack
from bistair.core.stair import level_readings, level_table, quantize, stair_level_phase
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
    want = stair_phase(frames[3], frames[4], avg)
    assert same(theta, want[0]) and same(mod, want[1])
    assert same(theta, angle_np(s, c)) and same(mod, np.sqrt(c * c + s * s))


@pytest.mark.parametrize("levels", [2, 6, 64])
def test_quantize32_is_quantize(levels):
    theta = np.concatenate([RNG.uniform(-np.pi, np.pi, 5000),
                            RNG.uniform(-30, 30, 500)]).astype(np.float32).reshape(50, 110)
    theta.flat[:4] = [np.pi, -np.pi, np.float32(np.pi), -np.float32(np.pi)]
    valid = RNG.random(theta.shape) < 0.9
    assert same(quantize32(theta, levels, valid),
                np.where(valid, quantize(theta, levels), -1).astype(np.int32))


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
