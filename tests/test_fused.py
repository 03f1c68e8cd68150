"""The fused per-pixel kernels (bistair.core.fused) give, bit for bit, what the NumPy
expressions they replaced gave (written out here), on random data and on the values where
roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from bistair.codecs.bidirectional import edge_runs
from bistair.codecs.graycode import gray_to_binary
from bistair.core import fused, fused_checks, fused_codes
from bistair.core.captures import ScaledStack
from bistair.core.kernels import quantize32, set_threads
from bistair.core.measure import _chi2_median, noise_level
from bistair.core.phase import (
    TWO_PI,
    phase_shift_patterns,
    residuals,
    shifts_of,
    wrap,
    wrapped_phase,
)

RNG = np.random.default_rng(7)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal dtype, shape and bits (NaN equal to NaN, -0.0 not equal to 0.0)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    if a.dtype.kind == "f":
        a, b = (np.where(np.isnan(x), np.inf, x).view(f"i{x.itemsize}") for x in (a, b))
    return bool(np.array_equal(a, b))


def _floats(shape: tuple[int, ...], dtype=np.float32) -> np.ndarray:
    scale = RNG.choice([1.0, 1e-3, 1e-7, 10.0], shape)
    return (RNG.standard_normal(shape) * scale).astype(dtype)


@pytest.mark.parametrize("steps", [3, 4, 7])
@pytest.mark.parametrize("offset", [0.0, 0.4])
def test_finish_phase_is_numpys(steps, offset):
    num, den = _floats((60, 70)), _floats((60, 70))
    num[0, :8], den[0, :8] = 0.0, [0, -0.0, 1e-30, -1e-30, 0, 0, 2, -2]
    phi = np.arctan2(num, den)
    if offset:
        phi = (phi - np.float32(offset)) % np.float32(TWO_PI)
    old_phi = phi.copy()
    np.add(old_phi, np.float32(TWO_PI), out=old_phi, where=old_phi < 0)
    old_phi[old_phi >= np.float32(TWO_PI)] = 0.0
    old_mod = np.hypot(num, den) * np.float32(2.0 / steps)
    mod = fused.finish_phase(phi, num, den, steps)
    assert _same(phi, old_phi) and _same(mod, old_mod)


def test_pixel_validity_is_numpys():
    shape = (50, 64)
    mod = RNG.uniform(0, 0.05, shape).astype(np.float32)
    avg = RNG.uniform(0.9, 1.0, shape).astype(np.float32)
    lowest, threshold = 0.0123, 0.0311
    mod.flat[:4] = [np.float32(lowest), np.float32(threshold), np.nextafter(np.float32(lowest), 0),
                    np.float32(1.02) - avg.flat[3]]
    clipped = RNG.random(shape) < 0.5
    white = RNG.uniform(0, 1, shape).astype(np.float32)
    black = (white - RNG.uniform(0, 0.05, shape)).astype(np.float32)
    for contrast in (False, True):
        valid = (mod >= lowest) & ~(clipped & (avg + mod > 1.02))
        if contrast:
            valid &= (white - black) >= 2.0 * lowest
        strong = valid & (mod >= threshold)
        got = fused.pixel_validity(mod, avg, clipped, lowest, threshold,
                                   *((white, black) if contrast else ()))
        assert _same(got[0], valid) and _same(got[1], strong)
        assert got[2] == int((valid & ~strong).sum())


def test_noise_maps_are_numpys():
    mod = np.abs(_floats((40, 50)))
    mod.flat[:3] = [0.0, 1e-6, np.float32(1e-6)]
    for steps in (3, 4, 12):
        old = (0.013 / (np.maximum(mod, 1e-6) * np.sqrt(steps / 2.0))).astype(np.float32)
        assert _same(fused.phase_noise(mod, 0.013, steps), old)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float64])
def test_pair_phase_is_stair_phase(dtype):
    top = 1.0 if dtype == np.float64 else np.iinfo(dtype).max
    raw = (RNG.uniform(0, 1, (5, 30, 40)) * top).astype(dtype)
    raw[3, 0, :3] = raw[4, 0, :3] = 0
    frames = ScaledStack(raw, 1.0 / top)
    avg = RNG.uniform(0, 1, (30, 40)).astype(np.float32)
    c, s = frames[3] - avg, frames[4] - avg
    theta, mod = fused.pair_phase(raw, 3, np.float32(1.0 / top), avg)
    assert _same(theta, _arctan2_rounded(s, c)) and _same(mod, np.hypot(s, c))


def _arctan2_rounded(y, x):
    """The correctly rounded float32 arctangent: float64 ``arctan2`` rounded once."""
    return np.arctan2(y.astype(np.float64), x.astype(np.float64)).astype(np.float32)


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
        got = fused.arctan2_32(y, x)
    finally:
        set_threads(None)
    expected = _arctan2_rounded(y, x)
    finite = np.isfinite(x) & np.isfinite(y)
    assert np.array_equal(got[finite], expected[finite], equal_nan=True)
    assert np.array_equal(np.signbit(got[finite]), np.signbit(expected[finite]))
    # infinities: the same angle to within a unit in the last place (or both NaN)
    assert np.allclose(got[~finite], expected[~finite], rtol=2e-7, atol=0, equal_nan=True)


@pytest.mark.parametrize(("stairs", "partitions"), [(8, 8), (4, 3), (2, 32)])
def test_stair_agreement_is_numpys(stairs, partitions):
    shape = (40, 50)
    levels = RNG.integers(-1, stairs, shape).astype(np.int32)
    theta = RNG.uniform(-np.pi, np.pi, shape).astype(np.float32)
    theta.flat[:3] = [np.float32(np.pi), -np.float32(np.pi), np.nextafter(np.float32(np.pi), 0)]
    order = RNG.integers(-3 * stairs, 2 * stairs * partitions, shape)
    part = quantize32(theta, partitions, np.ones(shape, bool))
    old = (levels == order % stairs) | (part == order // stairs)
    assert _same(fused_codes.stair_agreement(levels, theta, order, stairs, partitions), old)


def test_code_steps_and_sample_are_numpys():
    phi = RNG.uniform(0, TWO_PI, (30, 41)).astype(np.float32)
    code = np.repeat(RNG.integers(-1, 5, (30, 21)), 2, axis=1)[:, :41].astype(np.int32)
    valid = RNG.random(phi.shape) < 0.9
    e = np.where(valid, code, -1)
    a0, a, b, b1 = e[:, :-3], e[:, 1:-2], e[:, 2:-1], e[:, 3:]
    ok = (a >= 0) & (b >= 0) & (a != b) & (a0 == a) & (b1 == b)
    pa, pb, step = fused_checks.code_steps(phi, code, valid)
    assert _same(pa, phi[:, 1:-2][ok].astype(np.float64))
    assert _same(pb, phi[:, 2:-1][ok].astype(np.float64))
    assert _same(step, (b - a)[ok].astype(np.int64))
    for samples in (1, 7, 100, 10**6):
        idx = np.flatnonzero(valid & (code >= 0))
        assert _same(fused_checks.decoded_sample(valid, code, samples),
                     idx[::max(1, idx.size // samples)])


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
        got = fused_checks.assemble(phi, order, period, length if bounded else None, valid)
        assert _same(got[0], phase) and _same(got[1], phase * np.float32(period / TWO_PI))
        assert _same(got[2], out) and _same(got[4], mask) and got[5] == outside
        assert _same(got[3], np.where(valid, phi, np.float32(np.nan)))


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
            assert (fused_checks.wrap_step_counts(phi, order, valid, every, reach)
                    == _wrap_steps(phi, order, valid, every, reach))


def test_unwrap_chain_is_numpys():
    periods, length = (1920.0, 240.0, 30.0), 1920
    x = RNG.uniform(-5, 1925, (40, 50))
    phases = tuple(((TWO_PI * x / t + RNG.normal(0, 0.3, x.shape)) % TWO_PI).astype(np.float32)
                   for t in periods)
    valid = RNG.random(x.shape) < 0.9
    absolute = phases[0].astype(np.float64)
    fold = absolute * (periods[0] / TWO_PI) >= 0.5 * (length + periods[0])
    absolute = np.where(fold, absolute - TWO_PI, absolute)
    worst = 0.0
    for coarse, fine, phi in zip(periods[:-1], periods[1:], phases[1:], strict=True):
        ref = absolute * (coarse / fine)
        k = np.rint((ref - phi.astype(np.float64)) * (1.0 / TWO_PI))
        last = (ref - phi.astype(np.float64)) / TWO_PI - k
        worst = np.maximum(worst, np.abs(last))
        absolute = phi.astype(np.float64) + TWO_PI * k
    order = np.rint((absolute - phases[-1]) * (1.0 / TWO_PI))
    code = np.where(valid & np.isfinite(order), order, -1).astype(np.int32)
    got = fused_codes.unwrap_chain(phases, periods, length, phases[-1], valid)
    assert _same(got[0], code) and _same(got[2], last.astype(np.float32))
    assert np.allclose(got[1], worst, rtol=2.0 ** -23, atol=0) and np.all(got[1] <= worst)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_wrap_is_numpys(dtype):
    special = np.array([np.pi, -np.pi, 3 * np.pi, -3 * np.pi, 0.0, -0.0, np.nan, np.inf, 1e30,
                        -1e30, TWO_PI, -TWO_PI, 2 * TWO_PI], dtype)
    angles = np.concatenate([special, np.nextafter(special, dtype(0)),
                             np.nextafter(special, dtype(100)),
                             RNG.uniform(-2 * TWO_PI, 2 * TWO_PI, 20000).astype(dtype)])
    with np.errstate(invalid="ignore"):
        assert _same(wrap(angles), (angles + np.pi) % TWO_PI - np.pi)
        strided = angles[:16000].reshape(-1, 2)[:, ::2]  # not contiguous
        assert _same(wrap(strided), (strided + np.pi) % TWO_PI - np.pi)


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
        assert _same(fused_codes.code_bits(raw, 2, 3, np.float32(1 / 255), avg, inverse), gray)


def test_edge_runs_are_scipys_morphology():
    """OpenCV's erosion with an empty outside and anchors matching scipy's reflected
    elements: the same pixels as scipy.ndimage, at the borders too."""
    for _ in range(400):
        shape = tuple(RNG.integers(1, 30, 2))
        edge = RNG.random(shape) < RNG.choice([0.1, 0.5, 0.9])
        for reach in (0, 1, 12):
            wide = ndimage.binary_dilation(edge, np.ones((1, 3), bool))
            old = edge & ndimage.binary_opening(wide, np.ones((4, 1), bool))
            if reach > 0 and old.any():
                old = ndimage.binary_dilation(old, np.ones((2 * reach + 1, 1), bool))
            assert _same(edge_runs(edge, reach), old)


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
        code, got_edges, beyond = fused_codes.gray_orders(gray, phi, valid, mode, fringes)
        assert _same(code, np.where(ok, k, -1).astype(np.int32))
        assert _same(got_edges, np.where(valid, edges, -1).astype(np.int32))
        assert beyond == int(np.count_nonzero(valid & (k >= fringes)))


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
        assert all(_same(a, b) for a, b in zip(_nstep_sums(*args), fused.nstep_sums(*args),
                                               strict=True))


def _noise_before(frames, phi, avg, mod, shift_sign, phase_offset):
    """The NumPy ``noise_level`` (N >= 4): its sample of fit-residual differences."""
    top = (slice(None), slice(0, -1, 4), slice(None, None, 4))
    low = (slice(None), slice(1, None, 4), slice(None, None, 4))
    n_rows = min(len(range(frames.shape[1])[top[1]]), len(range(frames.shape[1])[low[1]]))
    pair = []
    for sub in (top, low):
        f = frames[sub][:, :n_rows]
        p, a, m = (v[sub[1:]][:n_rows] for v in (phi, avg, mod))
        pair.append((residuals(f, p, a, m, shift_sign, phase_offset),
                     (f.min(axis=0) > 0.0) & (f.max(axis=0) < 1.0)))
    (r0, ok0), (r1, ok1) = pair
    return ((r1 - r0) ** 2).sum(axis=0), ok0 & ok1


@pytest.mark.parametrize("steps", [4, 5, 8])
@pytest.mark.parametrize("convention", [(1, 0.0), (-1, 0.7)])
@pytest.mark.parametrize("shape", [(2, 1), (9, 13), (120, 97)])
def test_fit_residual_energy_is_numpys(steps, convention, shape):
    shift_sign, offset = convention
    x = np.tile(np.arange(shape[1], dtype=np.float64), (shape[0], 1))
    clean = phase_shift_patterns(x, 17, steps, amplitude=0.45, phase_offset=offset,
                                 shift_sign=shift_sign)
    raw = np.clip(np.round(255 * (clean + RNG.normal(0, 0.01, clean.shape))), 0, 255
                  ).astype(np.uint8)  # some pixels clip at 0 and 255
    frames = ScaledStack(raw, 1 / 255)
    phi, avg, mod = wrapped_phase(frames[...], shift_sign=shift_sign, phase_offset=offset)
    energy, ok = fused.fit_residual_energy(raw, 0, steps, np.float32(1 / 255), phi, avg, mod,
                                           shifts_of(steps, shift_sign, offset))
    expected, expected_ok = _noise_before(frames, phi, avg, mod, shift_sign, offset)
    # the same but for the cosine's last bit (the C library's cosf against NumPy's)
    assert np.array_equal(ok, expected_ok)
    np.testing.assert_allclose(energy, expected, rtol=1e-4, atol=1e-9)
    if expected.size >= 100:
        got = noise_level(frames, phi, avg, mod, shift_sign, offset)
        want = float(np.sqrt(np.median(expected[expected_ok] if expected_ok.sum() >= 100
                                       else expected.ravel()) / (2.0 * _chi2_median(steps - 3))))
        assert got == pytest.approx(want, rel=1e-5)
