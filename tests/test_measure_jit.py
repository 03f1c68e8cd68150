"""The measure stage's compiled passes (bistair.core.measure_jit: validity, phase noise, the
noise sample, the coherent dim pixels) give, bit for bit, what the NumPy expressions they
replaced gave (written out here), on random data and on the values where roundings and
thresholds bite."""

from __future__ import annotations

import numpy as np
import pytest
from support.arrays import floats, same

from bistair.core.captures import ScaledStack
from bistair.core.measure import _chi2_median, noise_level
from bistair.core.measure_jit import (
    fit_residual_energy,
    keep_coherent,
    phase_noise,
    pixel_validity,
)
from bistair.core.phase import (
    phase_shift_patterns,
    residuals,
    shifts_of,
    wrapped_phase,
)

RNG = np.random.default_rng(7)


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
        got = pixel_validity(mod, avg, clipped, lowest, threshold,
                                   *((white, black) if contrast else ()))
        assert same(got[0], valid) and same(got[1], strong)
        assert got[2] == int((valid & ~strong).sum())



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
                                       else expected.ravel()) / (2.0 * _chi2_median(steps - 3))))
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
