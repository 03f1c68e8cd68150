"""The wrapped phase's compiled passes (bistair.core.phase_jit) give, bit for bit, what the
NumPy expressions they replaced gave (written out here), on random data and on the values
where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import arctan2_rounded, floats, same

from bistair.core.jit import set_threads
from bistair.core.phase import (
    TWO_PI,
    wrap,
)
from bistair.core.phase_jit import arctan2_32, finish_phase, nstep_sums

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("steps", [3, 4, 7])
@pytest.mark.parametrize("offset", [0.0, 0.4])
def test_finish_phase_is_numpys(steps, offset):
    num, den = floats(RNG, (60, 70)), floats(RNG, (60, 70))
    num[0, :8], den[0, :8] = 0.0, [0, -0.0, 1e-30, -1e-30, 0, 0, 2, -2]
    phi = np.arctan2(num, den)
    if offset:
        phi = (phi - np.float32(offset)) % np.float32(TWO_PI)
    old_phi = phi.copy()
    np.add(old_phi, np.float32(TWO_PI), out=old_phi, where=old_phi < 0)
    old_phi[old_phi >= np.float32(TWO_PI)] = 0.0
    old_mod = np.hypot(num, den) * np.float32(2.0 / steps)
    mod = finish_phase(phi, num, den, steps)
    assert same(phi, old_phi) and same(mod, old_mod)






@pytest.mark.parametrize("threads", [1, None])
def test_arctan2_32_is_correctly_rounded(threads):
    # every scale, both signs, zeros of both signs, infinities and NaN
    n = 400_000
    y = (RNG.standard_normal(n) * 10.0 ** RNG.uniform(-30, 30, n)).astype(np.float32)
    x = (RNG.standard_normal(n) * 10.0 ** RNG.uniform(-30, 30, n)).astype(np.float32)
    special = np.float32([0.0, -0.0, 1.0, -1.0, np.inf, -np.inf, np.nan, 1e-45, 3e38])
    y = np.concatenate([y, np.repeat(special, special.size)])
    x = np.concatenate([x, np.tile(special, special.size)])
    y[:1000] = x[:1000] * np.float32(0.41421357)  # at the reduction's switch, tan(pi/8)
    try:
        set_threads(threads)
        got = arctan2_32(y, x)
    finally:
        set_threads(None)
    expected = arctan2_rounded(y, x)
    finite = np.isfinite(x) & np.isfinite(y)
    assert np.array_equal(got[finite], expected[finite], equal_nan=True)
    assert np.array_equal(np.signbit(got[finite]), np.signbit(expected[finite]))
    # infinities: the same angle to within a unit in the last place (or both NaN)
    assert np.allclose(got[~finite], expected[~finite], rtol=2e-7, atol=0, equal_nan=True)



@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_wrap_is_numpys(dtype):
    special = np.array([np.pi, -np.pi, 3 * np.pi, -3 * np.pi, 0.0, -0.0, np.nan, np.inf, 1e30,
                        -1e30, TWO_PI, -TWO_PI, 2 * TWO_PI], dtype)
    angles = np.concatenate([special, np.nextafter(special, dtype(0)),
                             np.nextafter(special, dtype(100)),
                             RNG.uniform(-2 * TWO_PI, 2 * TWO_PI, 20000).astype(dtype)])
    with np.errstate(invalid="ignore"):
        assert same(wrap(angles), (angles + np.pi) % TWO_PI - np.pi)
        strided = angles[:16000].reshape(-1, 2)[:, ::2]  # not contiguous
        assert same(wrap(strided), (strided + np.pi) % TWO_PI - np.pi)



def _nstep_sums(raw, start, steps, scale, sin_w, cos_w):
    """The N-step sums in NumPy, float32, summed in frame order."""
    s32 = np.float32(scale)
    s = c = total = np.zeros(raw.shape[1:], np.float32)
    for n in range(steps):
        f = raw[start + n].astype(np.float32) * s32
        s, c, total = s + sin_w[n] * f, c + cos_w[n] * f, total + f
    return -s, c, total / np.float32(steps)



@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float64])
def test_nstep_sums_are_numpys(dtype):
    top = 1.0 if dtype == np.float64 else np.iinfo(dtype).max
    raw = (RNG.uniform(0, 1, (7, 20, 33)) * top).astype(dtype)
    for start, steps, sign in ((0, 4, 1), (1, 3, -1), (2, 5, 1)):
        d = sign * TWO_PI * np.arange(steps) / steps
        args = (raw, start, steps, 1.0 / top, np.sin(d).astype(np.float32),
                np.cos(d).astype(np.float32))
        assert all(same(a, b) for a, b in zip(_nstep_sums(*args), nstep_sums(*args),
                                               strict=True))
