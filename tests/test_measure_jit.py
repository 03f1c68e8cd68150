"""The measure stage's compiled passes (bistair.core.measure_jit: pass 1 of a decode, the
phase noise, the noise sample, the coherent dim pixels) and pass 0's
(bistair.core.sample_jit) give what their NumPy references give: pass 1 every map bit for
bit, the sample the full pass's bits at its pixels, the noise the fitted residual's figure
(to 1e-5), on random data and on the values where roundings and thresholds bite."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import angle_np, floats, phase_np, same

from bistair.core.captures import ScaledStack, prepare
from bistair.core.measure import along_fringe_noise, noise_level
from bistair.core.measure_jit import (
    fit_residual_energy,
    front_end,
    keep_coherent,
    phase_noise,
)
from bistair.core.phase import (
    phase_shift_patterns,
    residuals,
    shifts_of,
    wrapped_phase,
)
from bistair.core.phase_jit import offset_parts, shift_weights
from bistair.core.sample import (
    chi2_median,
    clip_level,
    judge,
    kernel_view,
    sample_grid,
    set_noise,
    take_sample,
)
from bistair.core.sample_jit import masked_median

RNG = np.random.default_rng(7)


def test_noise_maps_are_numpys():
    mod = np.abs(floats(RNG, (40, 50)))
    mod.flat[:3] = [0.0, 1e-6, np.float32(1e-6)]
    for steps in (3, 4, 12):
        old = (0.013 / (np.maximum(mod, 1e-6) * np.sqrt(steps / 2.0))).astype(np.float32)
        assert same(phase_noise(mod, 0.013, steps), old)



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
    energy, ok = fit_residual_energy(raw, 0, steps, np.float32(1 / 255), phi, avg, mod,
                                           shifts_of(steps, shift_sign, offset))
    expected, expected_ok = _noise_before(frames, phi, avg, mod, shift_sign, offset)
    # the same but for the cosine's last bit (the C library's cosf against NumPy's)
    assert np.array_equal(ok, expected_ok)
    np.testing.assert_allclose(energy, expected, rtol=1e-4, atol=1e-9)
    if expected.size >= 100:
        got = noise_level(frames, phi, avg, mod, shift_sign, offset)
        want = float(np.sqrt(np.median(expected[expected_ok] if expected_ok.sum() >= 100
                                       else expected.ravel()) / (2.0 * chi2_median(steps - 3))))
        assert got == pytest.approx(want, rel=1e-5)


def _keep_coherent_numpy(region, strong, min_strong, min_size, min_region):
    size = np.bincount(region.ravel())
    bright = np.bincount(region.ravel(), weights=strong.ravel(), minlength=size.size)
    keep = ((bright >= min_strong) | (size >= min_size)) & (size >= min_region)
    keep[0] = False
    return strong | keep[region]


@pytest.mark.parametrize("shape", [(1, 1), (7, 33), (300, 41), (1100, 90)])
def test_keep_coherent_is_numpys(shape):
    """Regions given as provisional labels and their roots, counted by the labelling: the
    pixels of the NumPy formula on the regions."""
    weak = RNG.random(shape) < 0.7
    strong = weak & (RNG.random(shape) < 0.3)
    n, ids = 40, 300
    roots = np.concatenate([[0], RNG.integers(1, n + 1, ids)]).astype(np.int32)
    roots[1:n + 1] = np.arange(1, n + 1)  # every region has an id
    # runs of one label along the rows, as fringe regions have, and single pixels
    labels = np.repeat(RNG.integers(1, ids + 1, (shape[0], shape[1] // 5 + 1)), 5, axis=1)
    labels = labels[:, :shape[1]].astype(np.int32)
    labels[RNG.random(shape) < 0.1] = RNG.integers(1, ids + 1)
    labels[~weak] = 0  # regions of the weak mask
    region = roots[labels]
    size = np.bincount(region.ravel(), minlength=n + 1)
    size[0] = 0
    bright = np.bincount(region[strong], minlength=n + 1)
    k = int(np.argsort(size[1:])[n // 2]) + 1  # thresholds on a region's own counts too
    for thresholds in [(10, 100, 20), (1, 10**9, 1), (3, 20, 2), (10**9, 10**9, 0),
                       (bright[k], size[k], size[k]), (bright[k] + 1, size[k] + 1, 1),
                       (bright[k], 10**9, 1)]:
        thresholds = tuple(int(t) for t in thresholds)
        got = keep_coherent(labels, roots, size, bright, strong, *thresholds)
        assert np.array_equal(got, _keep_coherent_numpy(region, strong, *thresholds))


def _stack(steps: int, dtype, pair: bool, seed: int = 0, sign: int = 1,
           offset: float = 0.0) -> np.ndarray:
    """An N-step set (and a stair pair) on a tilted surface, with noise, dark and blown
    pixels; ``dtype``'s full range."""
    rng = np.random.default_rng(seed)
    h, w = 53, 71
    x = np.arange(w)[None, :] * 1.3 + np.arange(h)[:, None] * 0.2
    amp = np.clip(rng.uniform(-0.05, 0.55, (h, w)), 0, None)
    set_ = phase_shift_patterns(x, 17, steps, offset=0.5, amplitude=1.0, phase_offset=offset,
                                shift_sign=sign) * amp[None] + 0.5 * (1 - amp[None])
    frames = [set_]
    if pair:
        theta = rng.uniform(-np.pi, np.pi, (h, w))
        frames.append(np.stack([0.5 + amp * np.cos(theta), 0.5 + amp * np.sin(theta)]))
    f = np.concatenate(frames) * rng.uniform(0.5, 1.3, (1, h, w))
    f = np.clip(f + rng.normal(0, 0.01, f.shape), 0, 1)
    if np.issubdtype(dtype, np.integer):
        return np.round(f * np.iinfo(dtype).max).astype(dtype)
    return f.astype(dtype)


def _reference(prepared, steps, pair, sign, offset, lowest, threshold, noise):
    """Pass 1 in NumPy: the sums in frame order, the arctangent emulated, float32 throughout."""
    raw = prepared.raw
    f = [raw[n].astype(np.float32) * prepared.scale for n in range(steps)]
    sin_w, cos_w = shift_weights(steps, sign)
    s = c = a = np.zeros(raw.shape[1:], np.float32)
    for n in range(steps):
        s, c, a = s + sin_w[n] * f[n], c + cos_w[n] * f[n], a + f[n]
    num, a = -s, a / np.float32(steps)
    phi = phase_np(num, c, offset)
    mod = np.sqrt(num * num + c * c) * (np.float32(2.0) / np.float32(steps))
    used = raw[:steps + (2 if pair is not None else 0)]
    clipped = used.max(axis=0).astype(np.float32) >= np.float32(clip_level(prepared))
    valid, strong = judge(mod, a, clipped, lowest, threshold, prepared.white, prepared.black)
    sigma = np.float32(noise / np.sqrt(steps / 2.0)) / np.maximum(mod, np.float32(1e-6))
    out = [phi, mod, a, valid, strong, sigma]
    if pair is not None:
        cc = raw[pair].astype(np.float32) * prepared.scale - a
        ss = raw[pair + 1].astype(np.float32) * prepared.scale - a
        out += [angle_np(ss, cc), np.sqrt(cc * cc + ss * ss)]
    return out


CONVENTIONS = [(1, 0.0), (-1, 0.0), (1, -2 * np.pi / 3), (-1, 2.5)]


@pytest.mark.parametrize("steps", [3, 4, 5, 12])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32, np.float64])
@pytest.mark.parametrize("pair", [None, "pair"])
@pytest.mark.parametrize("convention", CONVENTIONS, ids=str)
def test_front_end_is_numpys(steps, dtype, pair, convention):
    """Every map of pass 1, bit for bit (four quarter-turn shifts take their own path)."""
    sign, offset = convention
    raw = _stack(steps, dtype, pair is not None, steps, sign, offset)
    frames = raw.shape[0]
    white = black = None
    if steps == 5:  # white and black frames: their contrast judged too
        white = np.random.default_rng(1).uniform(0, 1, raw.shape[1:]).astype(np.float32)
        black = (white * np.float32(0.9)).astype(np.float32)
    prepared = prepare(raw, frames, "demo")
    prepared = type(prepared)(prepared.raw, prepared.full_scale, white, black)
    at = None if pair is None else steps
    lowest, threshold, noise = 0.02, 0.05, 0.011
    kraw, first, cos_frame = kernel_view(prepared, 0, steps, at)
    none = np.zeros((1, 1), np.float32)
    got = front_end(kraw, first, steps, cos_frame, float(prepared.scale),
                    *shift_weights(steps, sign), *offset_parts(offset), clip_level(prepared),
                    lowest, threshold, np.float32(noise / np.sqrt(steps / 2.0)),
                    none if white is None else white, none if black is None else black,
                    white is not None)
    want = _reference(prepared, steps, at, sign, offset, lowest, threshold, noise)
    maps = got[:6] + (got[6:8] if pair is not None else ())
    names = ("phi", "mod", "avg", "valid", "strong", "sigma", "theta", "smod")[:len(maps)]
    for name, a, b in zip(names, maps, want, strict=True):
        assert same(a, b), name
    assert got[8] == int((want[3] & ~want[4]).sum())
    assert 0 < want[4].sum() < want[3].sum() < want[3].size  # the thresholds bite


@pytest.mark.parametrize("steps", [3, 4, 12])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32, np.float64])
def test_the_sample_is_the_full_pass_there(steps, dtype):
    """Pass 0's pixels carry pass 1's bits: phase, modulation, average, stair pair,
    validity; and every frame's raw values."""
    raw = _stack(steps, dtype, True, 7, -1, 0.4)
    prepared = prepare(raw, raw.shape[0], "demo")
    lowest, threshold = 0.02, 0.05
    sample = take_sample(prepared, 0, steps, steps, lowest, threshold, -1, 0.4)
    kraw, first, cos_frame = kernel_view(prepared, 0, steps, steps)
    none = np.zeros((1, 1), np.float32)
    full = front_end(kraw, first, steps, cos_frame, float(prepared.scale),
                     *shift_weights(steps, -1), *offset_parts(0.4), clip_level(prepared),
                     lowest, threshold, np.float32(0.01), none, none, False)
    at = np.ix_(sample.rows, sample.cols)
    for name, a, b in (("phi", sample.phi, full[0]), ("mod", sample.mod, full[1]),
                       ("avg", sample.avg, full[2]), ("valid", sample.valid, full[3]),
                       ("strong", sample.strong, full[4]), ("theta", sample.theta, full[6]),
                       ("smod", sample.stair_mod, full[7])):
        assert same(a, b[at]), name
    assert same(sample.values, raw[:, sample.rows][:, :, sample.cols])
    blocks = sample.blocks(sample.values)
    assert blocks.shape[-3:] == (3, sample.cols.size // 2, 2)
    assert same(blocks[0, 0, 1, 0, 1], raw[0, sample.rows[1], sample.cols[1]])


def test_the_sample_grid():
    for h, w in [(8, 8), (9, 13), (480, 640), (1024, 1280)]:
        rows, cols = sample_grid(h, w)
        assert rows.size % 3 == 0 and cols.size % 2 == 0 and rows.max() < h and cols.max() < w
        assert (np.diff(rows.reshape(-1, 3), axis=1) == 1).all()
        assert (np.diff(cols.reshape(-1, 2), axis=1) == 1).all()
    rows, cols = sample_grid(1024, 1280)
    assert rows.size * cols.size == 192 * 320  # 3/64 of the pixels


def _fitted_noise(frames, steps, sign, offset):
    """The fitted residual's noise (noise_level, the reference) of a float32 set."""
    stack = ScaledStack(frames[:steps], 1.0)
    return noise_level(stack, *wrapped_phase(stack[...], sign, offset), sign, offset)


@pytest.mark.parametrize("steps", [4, 5, 8, 12])
@pytest.mark.parametrize("convention", CONVENTIONS, ids=str)
def test_set_noise_is_the_fitted_residuals(steps, convention):
    """Pass 0's noise without fitting agrees with the fitted residual's: the same sample,
    the residual the fit's projection."""
    sign, offset = convention
    rng = np.random.default_rng(steps)
    x = np.tile(np.arange(197.0), (150, 1)) + np.arange(150.0)[:, None] * 0.3
    clean = phase_shift_patterns(x, 23, steps, amplitude=0.35, phase_offset=offset,
                                 shift_sign=sign) ** 1.3  # a gamma: harmonics
    frames = np.clip(clean + rng.normal(0, 0.012, clean.shape), 0, 1).astype(np.float32)
    got = set_noise(prepare(frames, steps, "demo"), 0, steps)
    assert got == pytest.approx(_fitted_noise(frames, steps, sign, offset), rel=1e-5)
    assert got == pytest.approx(0.012, rel=0.1)  # (the gamma's harmonics add a little)


def test_set_noise_of_three_steps_is_along_the_fringes():
    """N = 3: along_fringe_noise's figure, on the sample grid's runs of rows (every second
    column)."""
    rng = np.random.default_rng(3)
    x = np.tile(np.arange(640.0), (480, 1))
    clean = phase_shift_patterns(x, 29, 3, amplitude=0.3)
    frames = np.clip(clean + rng.normal(0, 0.01, clean.shape), 0, 1).astype(np.float32)
    frames[:, :, :20] = 1.0  # clipped: left out
    rows = sample_grid(*frames.shape[1:])[0]
    runs = frames[:, rows, ::2].reshape(3, -1, 3, 320)
    d2 = np.abs(runs[:, :, 0] - 2 * runs[:, :, 1] + runs[:, :, 2])
    ok = (runs.min(axis=(0, 2)) > 0) & (runs.max(axis=(0, 2)) < 1)
    want = np.median(d2[:, ok].astype(np.float64)) / (0.6745 * np.sqrt(6.0))
    got = set_noise(prepare(frames, 3, "demo"), 0, 3)
    assert got == pytest.approx(want, rel=1e-12)
    # the sample's median against the full one (every fourth column, every row): 28,800
    # values against 230,400, about 0.7% apart at one standard error
    assert got == pytest.approx(along_fringe_noise(frames), rel=0.02)


@pytest.mark.parametrize("n", [1, 2, 5, 100, 2001])
def test_masked_median_is_numpys(n):
    for kind in range(3):
        values = [RNG.random(n), RNG.normal(size=n), RNG.integers(0, 5, n) ** 2][kind]
        values = values.astype(np.float32)
        ok = RNG.random(n) < 0.7
        want = np.median(values[ok].astype(np.float64)) if ok.sum() >= 3 else \
            np.median(values.astype(np.float64))
        assert masked_median(values, ok, 3) == want
    assert np.isnan(masked_median(np.zeros(0, np.float32), np.zeros(0, bool), 1))
