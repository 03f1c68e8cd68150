"""The paper decoder's compiled column scan (bistair.codecs.bidirectional.paper_jit) gives
exactly what the SciPy and NumPy code it replaced gave: the same column medians, runs, run
sums, modes and orders, on random codes with invalid pixels, tiny images, single rows and
columns."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from support.reference import mode_by_label

from bistair.codecs import make_spec
from bistair.codecs.base import measure_shifts
from bistair.codecs.bidirectional import code_columns
from bistair.codecs.bidirectional.bands import nearest_level, union_levels
from bistair.codecs.bidirectional.paper import _pixel_median, paper_orders
from bistair.codecs.bidirectional.paper_jit import (
    column_median,
    column_runs,
    paint_labels,
    run_label_modes,
)
from bistair.core.captures import prepare
from bistair.core.jit import set_threads
from bistair.core.regions import fringe_regions
from bistair.core.stair import quantize
from bistair.sim.warp import WarpScene, render_warp

SHAPES = [(1, 1), (1, 7), (9, 1), (2, 3), (37, 23), (130, 70)]


def _codes(rng, shape, levels=4, invalid=0.1, stay=0.7):
    """Random codes that often repeat the pixel above (runs), some invalid (-1)."""
    h, w = shape
    code = rng.integers(-1, levels, shape).astype(np.int32)
    for y in range(1, h):
        same = rng.random(w) < stay
        code[y, same] = code[y - 1, same]
    code[rng.random(shape) < invalid] = -1
    return code


def _runs_before(code, t, min_run):
    """The NumPy column scan paper_orders used: runs, lengths, stretch starts, sums."""
    h, w = code.shape
    v = (code >= 0).T.ravel()
    q = code.T.ravel()
    t = t.T.ravel()
    col_start = np.zeros(v.size, bool)
    col_start[::h] = True
    seg_start = v & (col_start | ~np.r_[False, v[:-1]])
    start = seg_start | (v & np.r_[True, q[1:] != q[:-1]])
    pix = np.flatnonzero(v)
    run_of = np.cumsum(start)[pix] - 1
    length = np.bincount(run_of)
    first_pix = np.flatnonzero(start)
    keep = (length >= min_run) | seg_start[first_pix]
    owner = np.maximum.accumulate(np.where(keep, np.arange(keep.size), 0))
    owner = np.where(keep | seg_start[first_pix], np.arange(keep.size), owner)
    segment = np.cumsum(seg_start[first_pix]) - 1
    owner = np.where(segment[owner] == segment, owner, np.arange(keep.size))
    run_of = owner[run_of]
    runs = np.flatnonzero(keep | (owner == np.arange(keep.size)))
    remap = np.full(keep.size, -1)
    remap[runs] = np.arange(runs.size)
    run_of = remap[run_of]
    c_len = np.bincount(run_of, minlength=runs.size)
    sum_sin = np.bincount(run_of, np.sin(t[pix]), runs.size)
    sum_cos = np.bincount(run_of, np.cos(t[pix]), runs.size)
    first = seg_start[first_pix[runs]]
    order_of = np.full(v.size, -1, np.int64)
    order_of[pix] = run_of
    return c_len, first, sum_sin, sum_cos, first_pix[runs], order_of.reshape(w, h).T


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("size", [1, 2, 3, 4, 5, 7])
def test_column_median_is_scipys(shape, size):
    rng = np.random.default_rng(size * 100 + shape[0])
    code = _codes(rng, shape, levels=6)
    valid = rng.random(shape) > 0.2
    expected = np.where(valid, ndimage.median_filter(code, size=(size, 1), mode="nearest"),
                        -1)
    got = column_median(code, valid, size)
    assert got.dtype == code.dtype
    assert np.array_equal(got, expected)


def test_median_of_five_every_order():
    """The min/max network against every ordering of five values with ties."""
    vals = np.array(np.meshgrid(*[np.arange(5)] * 5, indexing="ij")).reshape(5, -1)
    code = np.ascontiguousarray(vals.astype(np.int32))  # each column one 5-tuple
    got = column_median(code, np.ones(code.shape, bool), 5)[2]
    assert np.array_equal(got, np.median(vals, axis=0).astype(np.int32))


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("min_run", [0, 1, 2, 3, 5])
@pytest.mark.parametrize("invalid", [0.0, 0.1, 1.0])
def test_column_runs_are_the_numpy_scan(shape, min_run, invalid):
    rng = np.random.default_rng(min_run * 7 + shape[1])
    code = _codes(rng, shape, invalid=invalid)
    t = rng.uniform(-np.pi, np.pi, shape).astype(np.float32)
    runs = column_runs(code, np.sin(t), np.cos(t), min_run)
    c_len, first, sum_sin, sum_cos, first_pix, run_of = _runs_before(code, t, min_run)
    h = shape[0]
    assert np.array_equal(runs.length, c_len)
    assert np.array_equal(runs.first, first)
    assert np.array_equal(runs.col * h + runs.start, first_pix)
    assert np.array_equal(runs.sum_sin, sum_sin)  # bit for bit: same order of addition
    assert np.array_equal(runs.sum_cos, sum_cos)
    assert runs.offsets[-1] == c_len.size
    # each run covers its pixels: rows start .. start + length - 1 of its column
    painted = np.full(shape, -1, np.int64)
    for i, (x, y0, n) in enumerate(zip(runs.col, runs.start, runs.length, strict=True)):
        painted[y0:y0 + n, x] = i
    assert np.array_equal(painted, run_of)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("n_labels", [0, 1, 5, 40])
def test_run_label_modes_are_mode_by_label(shape, n_labels):
    rng = np.random.default_rng(n_labels + shape[0] * 3)
    code = _codes(rng, shape)
    t = rng.uniform(-np.pi, np.pi, shape).astype(np.float32)
    runs = column_runs(code, np.sin(t), np.cos(t), 2)
    value = rng.integers(-1, 6, runs.length.size)
    labels = rng.integers(0, n_labels + 1, shape).astype(np.int32)
    image = np.full(shape, -1, np.int64)
    for x, y0, n, k in zip(runs.col, runs.start, runs.length, value, strict=True):
        image[y0:y0 + n, x] = k
    expected = mode_by_label(labels, image, n_labels, 6)
    for chunks in (1, 3, 8):
        mode, support = run_label_modes(labels, runs, value, n_labels, 6, chunks)
        assert np.array_equal(mode, expected[0])
        assert np.array_equal(support, expected[1])
    table = np.r_[-7, mode[1:]]
    assert np.array_equal(paint_labels(labels, table), np.where(labels > 0, table[labels], -1))


def test_pixel_median_is_numpys():
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 10, 101):
        length = rng.integers(1, 30, n)
        assert _pixel_median(length) == np.median(np.repeat(length, length))


@pytest.mark.parametrize(("partitions", "stairs", "median"), [(4, 4, 5), (3, 4, 5),
                                                               (4, 4, 1), (4, 4, 3)])
def test_paper_orders_as_before_on_a_noisy_code(partitions, stairs, median):
    """The whole scan against the NumPy paper_orders on a rendered capture with noise."""
    spec = make_spec("bidirectional", width=240, height=200, period=20,
                     partitions=partitions, stairs=stairs)
    images, _ = render_warp(spec, WarpScene(size=(150, 240), noise=0.03, seed=1))
    cols = prepare(images, spec.frame_count, spec.method)
    fs = measure_shifts(cols, spec)
    code = code_columns(cols, spec, fs)
    ks, theta = code.code, code.maps["stair_phase"]
    got = paper_orders(ks, theta, fs, spec, median=median)
    # the NumPy formulation, step by step
    S, P = stairs, partitions
    if P != S:
        ks = np.where(fs.valid, nearest_level(theta.ravel(), union_levels(P, S)).reshape(
            ks.shape), -1)
    if median > 1:
        ks = np.where(fs.valid, ndimage.median_filter(ks, size=(median, 1), mode="nearest"),
                      -1)
    scanned = np.where(fs.valid & (ks >= 0), ks, -1)
    c_len, first, ss, cc, _, run_of = _runs_before(scanned, theta, 3)
    run_theta = np.arctan2(ss, cc)
    new_group = first.copy()
    new_group[1:] |= c_len[1:] > c_len[:-1]
    merged = c_len > 1.4 * np.median(np.repeat(c_len, c_len))
    new_group[1:] |= merged[:-1]
    group = np.cumsum(new_group) - 1
    g_first = np.flatnonzero(new_group)
    g_second = g_first + 1
    ok = g_second < c_len.size
    has_second = np.zeros(g_first.size, bool)
    has_second[ok] = group[g_second[ok]] == group[g_first[ok]]
    has_second &= ~merged[g_first]
    second = np.where(has_second, run_theta[np.minimum(g_second, c_len.size - 1)],
                      run_theta[g_first])
    local_first = 2 * spec.local_rows > spec.group_rows
    lt, pt = (run_theta[g_first], second) if local_first else (second, run_theta[g_first])
    k_group = quantize(lt, S) + S * quantize(pt, P)
    order = np.where(run_of >= 0, k_group[group[np.maximum(run_of, 0)]], -1)
    fringes, n = fringe_regions(fs.phi, fs.valid, min_size=1, phase_noise=fs.phase_noise)
    mode, _ = mode_by_label(fringes, order, n, S * P)
    assert np.array_equal(got, np.where(fringes > 0, mode[fringes], -1))
    assert (got >= 0).mean() > 0.5


def test_one_thread_gives_the_same_runs_and_modes():
    """The passes split columns over threads; the result must not depend on how many."""
    rng = np.random.default_rng(8)
    code = _codes(rng, (300, 517), levels=6)
    valid = rng.random(code.shape) > 0.1
    t = rng.uniform(-np.pi, np.pi, code.shape).astype(np.float32)
    labels = rng.integers(0, 30, code.shape).astype(np.int32)

    def everything():
        med = column_median(code, valid, 5)
        runs = column_runs(med, np.sin(t), np.cos(t), 3)
        value = np.arange(runs.length.size) % 7
        mode, support = run_label_modes(labels, runs, value, 29, 7)
        return (med, *runs, mode, support, paint_labels(labels, mode))

    many = everything()
    try:
        assert set_threads(1) == 1
        one = everything()
    finally:
        set_threads(None)
    assert all(np.array_equal(a, b) for a, b in zip(one, many, strict=True))
