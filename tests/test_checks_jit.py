"""The checks' compiled passes (bistair.core.checks_jit: code steps, wrap steps, and the
decoded sample) give, bit for bit, what the NumPy expressions they replaced gave (written
out here), on random data and on the values where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
from support.arrays import same

from bistair.codecs.bidirectional.stairs_jit import decoded_sample
from bistair.core.checks_jit import wrap_step_counts
from bistair.core.phase import (
    TWO_PI,
)

RNG = np.random.default_rng(7)


def code_steps(phi, edges, valid):
    """The steps of a code along the rows between runs of at least two equal codes, in raster
    order: the phase before and after each step and the code's change (NumPy)."""
    e = np.where(valid, edges, -1)
    a0, a, b, b1 = e[:, :-3], e[:, 1:-2], e[:, 2:-1], e[:, 3:]
    ok = (a >= 0) & (b >= 0) & (a != b) & (a0 == a) & (b1 == b)
    return (phi[:, 1:-2][ok].astype(np.float64), phi[:, 2:-1][ok].astype(np.float64),
            (b - a)[ok].astype(np.int64))


def test_decoded_sample_is_numpys():
    code = np.repeat(RNG.integers(-1, 5, (30, 21)), 2, axis=1)[:, :41].astype(np.int32)
    valid = RNG.random(code.shape) < 0.9
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


def _edge_alignment_before(phi, edges, valid, edge_phase=0.0, levels=None):
    """checks.edge_alignment as it was: NumPy on the steps' arrays (code_steps)."""
    from bistair.core.checks import EdgeCheck
    from bistair.core.phase import wrap

    pa, pb, step = code_steps(phi, edges, valid)
    if pa.size == 0:
        return EdgeCheck(0, 0.0, 0.0, 0, 0.0)
    mid = np.angle(np.exp(1j * pa) + np.exp(1j * pb))
    z = np.exp(1j * (mid - edge_phase)).mean()
    if levels:
        step = np.where(step % levels < levels / 2, 1, -1)
    against = np.sign(step) != np.sign(wrap(pb - pa))
    return EdgeCheck(int(pa.size), float(wrap(np.angle(z))), float(np.abs(z)), int(pa.size),
                     float(against.mean()))


def test_edge_alignment_sums_in_one_pass_what_numpy_did():
    """The one-pass sums (step_sums) give the counts exactly and the circular mean to 1e-12
    of the NumPy on code_steps' arrays: on random codes, stairs that wrap (levels), reversed
    phases and both edge phases."""
    from bistair.core.checks import edge_alignment

    for trial in range(40):
        h, w = RNG.integers(1, 30), RNG.integers(4, 200)
        period = RNG.uniform(6, 30)
        x = np.arange(w) + RNG.uniform(0, 1)
        phi = (TWO_PI * x / period)[None] + RNG.normal(0, RNG.choice([0.05, 0.8]), (h, w))
        if trial % 3 == 0:
            phi = -phi  # the shifts run the other way
        phi = (phi % TWO_PI).astype(np.float32)
        code = (x // period).astype(np.int32)[None] + RNG.choice([0, 0, 0, 0, 1, -1], (h, w))
        levels = (None, 4, 5)[trial % 3]
        if levels:
            code = code % levels
        code = np.where(RNG.random((h, w)) < 0.05, -1, code).astype(np.int32)
        valid = RNG.random((h, w)) < 0.95
        for edge_phase in (0.0, np.pi):
            new = edge_alignment(phi, code, valid, edge_phase, levels)
            old = _edge_alignment_before(phi, code, valid, edge_phase, levels)
            assert (new.edges, new.wraps) == (old.edges, old.wraps)
            assert new.reversed == old.reversed
            assert abs(new.spread - old.spread) < 1e-12
            assert abs(np.exp(1j * new.crossing) - np.exp(1j * old.crossing)) < 1e-12


def test_stair_misfit_in_one_pass_is_numpys():
    """stair_misfit's compiled distances (level_misfits) give the median NumPy's
    (n, L) distances, argmin and division gave, bit for bit: levels as made and as a
    response moves them, phases on the levels, halfway and at +-pi."""
    from bistair.codecs.bidirectional.bands import union_levels
    from bistair.core.checks import stair_misfit
    from bistair.core.phase import wrap
    from bistair.core.stair import half_gaps

    for partitions, stairs in ((8, 8), (12, 12), (3, 4), (5, 7)):
        levels = union_levels(partitions, stairs)
        for moved in (levels, levels + RNG.normal(0, 0.05, levels.size)):
            theta = RNG.uniform(-np.pi, np.pi, (70, 90)).astype(np.float32)
            theta.flat[:levels.size] = moved
            theta.flat[-3:] = [np.pi, -np.pi, (moved[0] + moved[1]) / 2]
            valid = RNG.random(theta.shape) < 0.8
            t = theta[valid]
            t = t[:: max(1, -(-t.size // 20000))].astype(np.float64)
            d = np.abs(wrap(t[:, None] - moved[None, :]))
            nearest = d.argmin(axis=1)
            want = np.median(d[np.arange(t.size), nearest] / half_gaps(moved)[nearest])
            assert stair_misfit(theta, valid, moved) == want
