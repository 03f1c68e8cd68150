"""The stair phase's compiled pass (bistair.core.stair_jit.pair_phase) gives what the NumPy
reference, bistair.core.stair.stair_phase, gives."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import arctan2_rounded, same

from bistair.core.captures import ScaledStack
from bistair.core.stair_jit import pair_phase

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
