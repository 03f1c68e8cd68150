"""Shared building blocks: N-step phase, stair levels and quantisation, regions, orders."""

import numpy as np
import pytest
from support.reference import stair_phase

from bistair.core.phase import TWO_PI, phase_shift_patterns, residuals, wrapped_phase
from bistair.core.regions import fill_orders, fringe_regions, region_links
from bistair.core.stair import quantize, stair_level_phase, stair_pair


@pytest.mark.parametrize("steps", [3, 4, 5, 8, 12])
def test_wrapped_phase_is_exact_for_any_n(steps):
    x = np.linspace(0, 300, 2001)
    frames = 0.2 + 0.3 * phase_shift_patterns(x, 40, steps, offset=0.0, amplitude=1.0)
    phi, avg, mod = wrapped_phase(frames[:, None, :])
    truth = (TWO_PI * x / 40) % TWO_PI
    err = np.angle(np.exp(1j * (phi[0] - truth)))
    assert np.abs(err).max() < 1e-5
    assert np.allclose(avg, 0.2, atol=1e-6) and np.allclose(mod, 0.3, atol=1e-6)
    assert phi.min() >= 0 and phi.max() < TWO_PI


def test_noise_estimate_tracks_added_noise():
    rng = np.random.default_rng(3)
    x = np.tile(np.arange(400.0), (200, 1))
    frames = phase_shift_patterns(x, 30, 4) + rng.normal(0, 0.01, (4, 200, 400))
    phi, avg, mod = wrapped_phase(frames)
    res = np.sqrt((residuals(frames, phi, avg, mod) ** 2).sum(axis=0))  # N - 3 = 1 dof
    # One redundant sample of four: the residual's median is about 0.67 sigma.
    assert 0.005 < np.median(res) < 0.012


def test_stair_quantisation_wraps_the_top_level():
    for levels in (2, 3, 6, 8, 12):
        theta = stair_level_phase(np.arange(levels), levels)
        assert quantize(theta, levels).tolist() == list(range(levels))
        half = np.pi / levels
        # Up to just under half a step of error either way still reads the same level,
        # including across the +-pi wrap next to the top level.
        for d in (-0.99 * half, 0.99 * half):
            noisy = np.angle(np.exp(1j * (theta + d)))
            assert quantize(noisy, levels).tolist() == list(range(levels))


def test_stair_pair_decodes_with_the_fringe_average():
    theta = stair_level_phase(np.arange(6), 6)
    pair = 0.1 + 0.6 * (stair_pair(theta, 0.5, 0.5))  # camera gain 0.6, ambient 0.1
    dec, mod = stair_phase(pair[0], pair[1], np.full(6, 0.1 + 0.6 * 0.5, np.float32))
    assert np.allclose(np.angle(np.exp(1j * (dec - theta))), 0, atol=1e-5)
    assert np.allclose(mod, 0.3, atol=1e-5)


def _ramp(width=150, height=40, period=30.0, tilt=0.0):
    y, x = np.mgrid[0:height, 0:width].astype(float)
    coord = x + tilt * y + 0.0137  # no pixel exactly on a fringe edge
    return ((TWO_PI * coord / period) % TWO_PI).astype(np.float32), coord


def test_fringe_regions_split_at_wraps_and_link_with_steps():
    phi, coord = _ramp(tilt=0.3)
    labels, n = fringe_regions(phi, np.ones(phi.shape, bool), min_size=1)
    k = np.floor(coord / 30).astype(int)
    # Every region holds exactly one order.
    for r in range(1, n + 1):
        assert np.unique(k[labels == r]).size == 1
    links = region_links(phi, labels)
    order_of = {r: int(k[labels == r][0]) for r in range(1, n + 1)}
    for s, d, st in zip(links.src, links.dst, links.step, strict=True):
        assert order_of[int(d)] - order_of[int(s)] == st


def test_fringe_regions_cut_a_phase_step_and_invalid_pixels():
    phi, _ = _ramp()
    phi[:, 70:] = (phi[:, 70:] + 2.0) % TWO_PI  # a depth step of 2 rad
    valid = np.ones(phi.shape, bool)
    valid[:, 100] = False
    labels, _ = fringe_regions(phi, valid, min_size=1)
    assert labels[5, 65] != labels[5, 75]  # cut at the step
    assert labels[5, 95] != labels[5, 105]  # cut at the invalid column... and wraps
    assert labels[5, 100] == 0


def test_fill_orders_uses_the_nearest_absolute_phase():
    phi, coord = _ramp()
    orders = np.floor(coord / 30).astype(np.int32)
    known = orders.copy()
    known[10:12, 28:33] = -1  # a hole across a wrap
    filled = fill_orders(phi, known, known < 0, max_distance=3)
    assert np.array_equal(filled, orders)
