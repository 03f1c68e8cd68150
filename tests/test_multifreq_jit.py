"""The multi-frequency decoder's compiled passes (bistair.codecs.multifreq_jit: unwrap_chain
and agreed_orders) give exactly what the NumPy they replaced gave, on random phases with
NaN, tiny images, single rows and columns, and with one thread or all."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from bistair.codecs.multifreq_jit import agreed_orders, unwrap_chain
from bistair.core.jit import set_threads
from bistair.core.phase import TWO_PI

RNG = np.random.default_rng(11)
SHAPES = [(1, 1), (1, 9), (9, 1), (3, 4), (41, 57), (160, 130)]


def _unwrap_before(phases, periods, length, phi, valid):
    absolute = phases[0].astype(np.float64)
    fold = absolute * (periods[0] / TWO_PI) >= 0.5 * (length + periods[0])
    absolute = np.where(fold, absolute - TWO_PI, absolute)
    worst = 0.0
    last = 0.0
    for coarse, fine, p in zip(periods[:-1], periods[1:], phases[1:], strict=True):
        ref = absolute * (coarse / fine)
        k = np.rint((ref - p.astype(np.float64)) * (1.0 / TWO_PI))
        last = (ref - p.astype(np.float64)) / TWO_PI - k
        worst = np.maximum(worst, np.abs(last))
        absolute = p.astype(np.float64) + TWO_PI * k
    order = np.rint((absolute - phi) * (1.0 / TWO_PI))
    code = np.where(valid & np.isfinite(order), order, -1).astype(np.int32)
    return code, worst, last


def _agreed_before(code, worst, valid, phi):
    agree = worst < 0.25
    lit = valid.sum()
    share = float((agree & valid).sum() / max(lit, 1))
    ok = valid & agree & (code >= 0)
    order = np.where(ok, code, -1).astype(np.int32)
    sub = np.where(ok[::4], phi[::4] + TWO_PI * code[::4], np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices
        slope = np.nanmedian(np.diff(sub, axis=1)) if ok.sum() > 100 else 0.0
    return order, int(lit), share, bool(slope < 0)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("periods", [(1920.0, 240.0, 30.0), (300.0, 30.0),
                                     (1920.0, 480.0, 120.0, 30.0)])
@pytest.mark.parametrize("threads", [1, None])
def test_unwrap_chain_is_numpys(shape, periods, threads):
    length = int(periods[0])
    x = RNG.uniform(-5, length + 5, shape)
    phases = tuple(((TWO_PI * x / t + RNG.normal(0, 0.4, shape)) % TWO_PI).astype(np.float32)
                   for t in periods)
    phases[1][RNG.random(shape) < 0.05] = np.nan
    phases[0][RNG.random(shape) < 0.02] = np.inf
    valid = RNG.random(shape) < 0.9
    with np.errstate(invalid="ignore"):
        expected = _unwrap_before(phases, periods, length, phases[-1], valid)
    try:
        set_threads(threads)
        got = unwrap_chain(phases, periods, length, phases[-1], valid)
    finally:
        set_threads(None)
    assert np.array_equal(got[0], expected[0])
    worst, last = (np.broadcast_to(e, shape) for e in expected[1:])
    assert got[1].dtype == got[2].dtype == np.float32
    assert np.array_equal(got[1], _toward_zero(worst), equal_nan=True)
    assert np.array_equal(got[2], last.astype(np.float32), equal_nan=True)
    with np.errstate(invalid="ignore"):  # the float32 miss passes 0.25 where float64's does
        assert np.array_equal(got[1] < 0.25, worst < 0.25)


def _toward_zero(values):
    """Float64 ``values`` (non-negative or NaN) as float32, rounded toward zero."""
    rounded = values.astype(np.float32)
    with np.errstate(invalid="ignore"):
        return np.where(rounded > values, np.nextafter(rounded, np.float32(0)), rounded)


def test_worst_miss_keeps_its_side_of_the_limit():
    # float64 misses a hair under and over 0.25 (float32 rounds the first to 0.25)
    worst = np.array([0.25 - 1e-12, 0.25, 0.25 + 1e-12, 0.1, 0.0])
    assert (_toward_zero(worst) < 0.25).tolist() == [True, False, False, True, True]
    # a pixel whose float64 miss is 0.2499999975, which float32 rounds to 0.25
    fine = np.array([[1054589079]], np.uint32).view(np.float32)  # 0.42920372 rad
    phases = (np.full((1, 1), 0.2, np.float32), fine)
    miss = abs((np.float64(phases[0][0, 0]) * 10 - np.float64(fine[0, 0])) / TWO_PI)
    assert miss < 0.25 and np.float32(miss) == 0.25
    got = unwrap_chain(phases, (300.0, 30.0), 300, fine, np.ones((1, 1), bool))[1]
    assert got.dtype == np.float32 and bool(got[0, 0] < 0.25)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("direction", [1, -1, 0])
def test_agreed_orders_are_numpys(shape, direction):
    h, w = shape
    for trial in range(6):
        x = np.arange(w) * (direction or 1)
        phase = (TWO_PI * x / 7.0)[None] + RNG.normal(0, 2.5 if direction == 0 else 0.3,
                                                     shape)
        code = np.floor(phase / TWO_PI).astype(np.int32) + 20
        phi = (phase - TWO_PI * (code - 20)).astype(np.float32)
        if trial == 1:  # ties: whole steps of 2*pi
            phi[:] = 0.5
        if trial == 2:
            phi[RNG.random(shape) < 0.1] = np.nan
        code[RNG.random(shape) < 0.1] = -1
        worst = RNG.uniform(0, 0.3, shape)
        worst[RNG.random(shape) < 0.05] = np.nan
        valid = RNG.random(shape) < (0.02 if trial == 3 else 0.9)
        if trial == 4:
            valid[:] = False
        order, lit, share, falling = _agreed_before(code, worst, valid, phi)
        got = agreed_orders(code, worst, valid, phi)
        assert np.array_equal(got[0], order)
        assert got[1] == lit
        assert float(np.int64(got[2]) / max(got[1], 1)) == share
        assert got[3] == falling


def test_agreed_orders_even_middle():
    """An even number of steps with half of them falling: the two middle ones' mean."""
    for a, b in ((-1.0, 0.5), (-0.5, 1.0), (-0.25, 0.25)):
        # one row of 101 kept pixels: 100 steps, 50 falling
        steps = np.r_[np.full(50, a), np.full(50, b)]
        RNG.shuffle(steps)
        phase = np.r_[0.0, np.cumsum(steps)] + 100.0
        code = np.int32(np.floor(phase / TWO_PI))[None]
        phi = (phase - TWO_PI * code[0]).astype(np.float32)[None]
        worst = np.zeros(code.shape)
        valid = np.ones(code.shape, bool)
        assert agreed_orders(code, worst, valid, phi)[3] == _agreed_before(
            code, worst, valid, phi)[3]
