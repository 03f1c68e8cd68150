"""The result's compiled pass (bistair.core.result_jit.assemble) gives, bit for bit, what the
NumPy expressions they replaced gave (written out here), on random data and on the values
where roundings and thresholds bite."""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
from support.arrays import same

from bistair.core.phase import (
    TWO_PI,
)
from bistair.core.result import (
    PIXEL_FIELDS,
    DecodeResult,
    code_dtype,
    make_result,
    narrow_code,
    transpose_own,
)
from bistair.core.result_jit import assemble, coord_factor

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
        wrapped = np.where(valid, phi, np.float32(np.nan))
        for reuse in (False, True):
            given_phi, given_order = phi.copy(), order.astype(np.int32)
            got = assemble(given_phi, given_order, period, length if bounded else None, valid,
                           reuse=reuse)
            assert same(got[0], phase) and same(got[1], out) and same(got[3], mask)
            assert same(got[2], wrapped) and got[4] == outside
            # written over when given up, left as they were when not
            assert (got[2] is given_phi and got[1] is given_order) == reuse
            assert reuse or (same(given_phi, phi) and same(given_order, order.astype(np.int32)))


def test_assemble_copies_what_it_cannot_write_over():
    """int64 orders, float64 or read-only phases are copied even when given up."""
    phi = np.full((2, 3), 1.0)
    order = np.zeros((2, 3), np.int64)
    frozen = np.ones((2, 3), np.float32)
    frozen.flags.writeable = False
    for p, k in ((phi, order), (frozen, order.astype(np.int32))):
        got = assemble(p, k, 30.0, valid=np.zeros((2, 3), bool), reuse=True)
        assert got[2] is not p and np.isnan(got[2]).all() and not np.isnan(p).any()


def test_coord_is_the_phase_times_the_factor_as_before():
    """The coordinate computed from the phase is, bit for bit with its NaNs, what the pass
    wrote before (``phase * float32(period / 2pi)`` in float32, NaN where invalid)."""
    phi = RNG.uniform(0, TWO_PI, (30, 40)).astype(np.float32)
    order = RNG.integers(-1, 66, phi.shape)
    for period in (30.0, 1920 / 58, 7.0):
        res = make_result("demo", phi, order, period, np.ones_like(phi))
        before = np.where(res.mask, res.phase * np.float32(period / TWO_PI),
                          np.float32(np.nan)).astype(np.float32)
        assert res.coord.dtype == np.float32
        assert res.coord.tobytes() == before.tobytes()
        assert coord_factor(period) == np.float32(period / TWO_PI)
        # a coordinate given to the constructor is the one returned, also transposed
        given = DecodeResult(res.phase, before + 1, res.order, res.wrapped, res.modulation,
                             res.average, res.mask, res.code, period, "demo")
        assert same(given.coord, before + 1) and same(given.transposed().coord, (before + 1).T)
        assert same(res.transposed().coord, res.coord.T)
        # the dataclass's replace and pickling keep it (the field stands where it stood)
        assert same(dataclasses.replace(res, method="x").coord, res.coord)
        assert same(pickle.loads(pickle.dumps(res)).coord, res.coord)


def test_code_words_are_narrowed_never_cut():
    """The code in the smallest dtype that holds the spec's words, wider where a word is
    larger than the spec allows; every word kept."""
    words = np.int32([[-1, 0, 63, 127]])
    assert narrow_code(words, 127).dtype == np.int8
    assert narrow_code(words, 128).dtype == np.int16
    for big in (128, 40000, -300):
        got = narrow_code(np.int32([[-1, 5, big]]), 127)
        assert got.tolist() == [[-1, 5, big]] and got.dtype == code_dtype(abs(big))


def test_transpose_own_turns_every_array_as_transposed_does():
    """The rows decode's in-place turn gives what ``transposed`` gives, every array."""
    phi = RNG.uniform(0, TWO_PI, (30, 40)).astype(np.float32)
    order = RNG.integers(-1, 66, phi.shape)
    res = make_result("demo", phi, order, 30.0, RNG.random(phi.shape), RNG.random(phi.shape),
                      code=RNG.integers(-1, 64, phi.shape).astype(np.int8))
    want = res.transposed()
    got = transpose_own(res)
    assert got is res
    for name in PIXEL_FIELDS:
        a, b = getattr(got, name), getattr(want, name)
        assert same(a, b) and a.shape == (40, 30) and a.flags.c_contiguous, name
