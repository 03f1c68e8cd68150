"""The wrapped phase's compiled passes (bistair.core.phase_jit): the float32 arctangent
every phase of a decode comes from is within its documented bound of float64 arctan2,
gives the bits of its NumPy float32 emulation (the same operations in the same order, so
the same bits on every x86 machine) and is compiled without fused multiply-adds; the
other passes give what the NumPy expressions they replaced gave."""

from __future__ import annotations

import hashlib
import re

import numpy as np
import pytest
from support.arrays import angle_np, phase_np, same

from bistair.core.jit import dispatcher, set_threads
from bistair.core.phase import TWO_PI, wrap
from bistair.core.phase_jit import (
    ATAN_ERROR,
    _phase_of_sums,
    arctan2_32,
    offset_parts,
    phase_of_sums32,
    shift_weights,
)

RNG = np.random.default_rng(7)
OFFSETS = [0.0, 0.7, -2 * np.pi / 3, 3.0, np.pi, 40.0]


def _pairs() -> tuple[np.ndarray, np.ndarray]:
    """Every pair of whole numbers in [-512, 512] (sums of 8-bit frames), 2 million random
    pairs over five decades, and the places where the reduction switches or values vanish."""
    g = np.arange(-512, 513, dtype=np.float32)
    gy, gx = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    n = 2_000_000
    ang, rad = RNG.uniform(-np.pi, np.pi, n), 10.0 ** RNG.uniform(-4, 1, n)
    tiny = np.float32([0.0, -0.0, 1e-30, -1e-30, 1e-9, -1e-9, 3e-8, -3e-8, 1.0, -1.0])
    ty, tx = np.repeat(tiny, tiny.size), np.tile(tiny[::-1] + np.float32(0.5), tiny.size)
    sx = RNG.uniform(-1, 1, 1000).astype(np.float32)
    return (np.concatenate([gy, (rad * np.sin(ang)).astype(np.float32), ty,
                            sx * np.float32(0.41421357), sx * np.float32(2.4142137)]),
            np.concatenate([gx, (rad * np.cos(ang)).astype(np.float32), tx, sx, sx]))


Y, X = _pairs()


@pytest.mark.parametrize("offset", OFFSETS)
def test_phase_is_within_the_bound(offset):
    phi, mod = phase_of_sums32(Y, X, 2, offset)
    exact = (np.arctan2(Y.astype(np.float64), X.astype(np.float64)) - offset) % TWO_PI
    err = np.abs(phi - exact)
    err = np.minimum(err, TWO_PI - err)
    assert err.max() < ATAN_ERROR  # measured 2.8e-7 to 3.1e-7
    assert phi.min() >= 0 and phi.max() < np.float32(TWO_PI) and not np.signbit(phi).any()
    assert np.allclose(mod, np.hypot(Y, X), rtol=2e-7, atol=0)


@pytest.mark.parametrize("threads", [1, None])
def test_arctangent_is_within_the_bound(threads):
    try:
        set_threads(threads)
        got = arctan2_32(Y, X)
    finally:
        set_threads(None)
    exact = np.arctan2(Y.astype(np.float64), X.astype(np.float64))
    err = np.abs(got - exact)
    err = np.minimum(err, TWO_PI - err)  # (-0.0, x < 0): pi here, -pi for arctan2
    assert err.max() < ATAN_ERROR and np.abs(got).max() <= np.float32(np.pi)


@pytest.mark.parametrize("offset", OFFSETS)
def test_arctangent_is_its_numpy_emulation(offset):
    """The same float32 operations in the same order: the same bits. NumPy rounds every
    operation, so a compiled kernel that fused a multiply-add or reordered a sum would
    differ here (and on another machine)."""
    assert same(phase_of_sums32(Y, X, 2, offset)[0], phase_np(Y, X, offset))
    assert same(arctan2_32(Y, X), angle_np(Y, X))


def test_kernels_have_no_fused_multiply_add():
    """Compiled with the kernels' own options (no fastmath), the phase pass holds no
    instruction that fuses a multiply and an add (whose single rounding would give other
    bits than a machine without FMA). Compiled afresh: cached code cannot be inspected.
    (The other kernels' arithmetic is held to its NumPy emulation, bit for bit, by their
    tests: tests/test_measure_jit.py, tests/test_stair_jit.py.)"""
    from numba.core.caching import NullCache

    from bistair.core import jit

    phase_of_sums32(Y[:10], X[:10], 4)
    fresh = jit._dispatcher(_phase_of_sums.py_func, _phase_of_sums.parallel)
    fresh._cache = NullCache()
    for sig in dispatcher(_phase_of_sums).signatures:
        fresh.compile(sig)
        asm = fresh.inspect_asm(sig)
        assert "vdivps" in asm or "divss" in asm  # (the code of the arctangent itself)
        assert not re.search(r"\bv?f(n)?m(add|sub)\w*", asm)


def test_phases_are_pinned():
    """The bits of the phases of fixed sums (exact inputs: every pair of whole numbers in
    [-512, 512] and of multiples of 2**-20 below 2**-9), the same on every x86 machine: a
    change to the arithmetic changes this hash, and the decode's phases with it."""
    g = np.arange(-512, 513, dtype=np.float32)
    gy, gx = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    y = np.concatenate([gy, gy * np.float32(2.0 ** -20)])
    x = np.concatenate([gx, gx[::-1] * np.float32(2.0 ** -20)])
    phi, mod = phase_of_sums32(y, x, 4, -2 * np.pi / 3)
    digest = hashlib.sha256(phi.tobytes() + mod.tobytes() + arctan2_32(y, x).tobytes())
    assert digest.hexdigest() == PINNED


PINNED = "a24e0b4ea0f06c43e15643a4d8cc1599360f48f4b3b2c70bfadc42a869e6b7d8"


def test_offset_parts():
    for offset in OFFSETS + [-1e-9, 1e-9, 1e6]:
        hi, lo = offset_parts(offset)
        assert float(hi) * 4096 % 1 == 0 and abs(float(lo)) <= 2.0 ** -13
        assert abs((float(hi) + float(lo)) - offset % TWO_PI) < 1e-9


@pytest.mark.parametrize("steps", [3, 4, 5, 8, 12])
@pytest.mark.parametrize("sign", [1, -1])
def test_shift_weights(steps, sign):
    sin_w, cos_w = shift_weights(steps, sign)
    d = sign * TWO_PI * np.arange(steps) / steps
    assert np.allclose(sin_w, np.sin(d), atol=1e-7) and np.allclose(cos_w, np.cos(d), atol=1e-7)
    near = np.isclose(np.abs(np.sin(d)), np.round(np.abs(np.sin(d))), atol=1e-12)
    assert np.all(np.abs(sin_w[near]) == np.round(np.abs(np.sin(d[near]))))
    assert not np.signbit(sin_w[sin_w == 0]).any()


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
