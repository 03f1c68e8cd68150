"""The compiled passes of binocular matching against exact answers: resampling without
mixing surfaces, where pixels land on the rectified grid (against OpenCV), the row search for
equal phase (against a plain search on random rising rows), its refusals (gaps, steps,
falls, two places), the row-support check, the points, and the smoothing within runs
(against its definition, sample by sample); and the passes issue 32 made cheaper against
the ones they replaced (``tests/support/stereo_before.py``), bit for bit."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from support import stereo_before

from bistair.geometry.stereo_checks import projector_misfits
from bistair.geometry.stereo_jit import (
    cloud_points,
    depth_counts,
    grid_depth,
    grid_points,
    pick_finite,
    rectified_positions,
    remap_valid,
)
from bistair.geometry.stereo_match_jit import (
    ALONE,
    AMBIGUOUS,
    INCONSISTENT,
    MATCHED,
    NOT_MONOTONIC,
    OTHER_AXIS,
    UNMATCHED,
    count_status,
    match_pair,
    smooth_runs,
    supported,
)


def test_remap_interpolates_one_surface_and_never_two():
    rng = np.random.default_rng(0)
    plane = (3.0 * np.arange(40)[None, :] + 0.5 * np.arange(30)[:, None]).astype(np.float32)
    mx = rng.uniform(0, 39, (20, 25)).astype(np.float32)
    my = rng.uniform(0, 29, (20, 25)).astype(np.float32)
    got = remap_valid(plane, mx, my, 10.0)
    np.testing.assert_allclose(got, 3.0 * mx + 0.5 * my, atol=1e-3)  # bilinear is exact
    step = plane.copy()
    step[:, 20:] += 100.0  # a second surface
    got = remap_valid(step, mx, my, 10.0)
    between = (mx > 19) & (mx < 20)
    assert np.isnan(got[between]).all() and np.isfinite(got[~between]).all()
    hole = plane.copy()
    hole[10, 10] = np.nan
    got = remap_valid(hole, np.float32([[10.0, 10.5, 11.0]]), np.float32([[10.0, 10.0, 10.0]]),
                      10.0)
    assert np.isnan(got[0, :2]).all() and got[0, 2] == plane[10, 11]
    off = remap_valid(plane, np.float32([[-0.5, 39.5, 5.0]]), np.float32([[5.0, 5.0, np.nan]]),
                      10.0)
    assert np.isnan(off).all()


def test_rectified_positions_agree_with_opencv():
    K = np.array([[610.0, 0.0, 322.5], [0, 608.0, 241.0], [0, 0, 1]])  # OpenCV: no skew
    dist = np.array([-0.28, 0.11, 0.0012, -0.0008, -0.02])
    rot = cv2.Rodrigues(np.array([0.02, -0.15, 0.01]))[0]
    u, v, rx, ry = rectified_positions(K, dist, rot, 600.0, 330.0, 250.0, (640, 480))
    pix = np.stack(np.meshgrid(np.arange(0, 640, 7.0), np.arange(0, 480, 5.0)), -1).reshape(-1, 2)
    proj = np.array([[600.0, 0, 330.0], [0, 600.0, 250.0], [0, 0, 1]])
    want = cv2.undistortPoints(pix.reshape(-1, 1, 2), K, dist, R=rot, P=proj,
                               criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100,
                                         1e-14)).reshape(-1, 2)
    rows, cols = pix[:, 1].astype(int), pix[:, 0].astype(int)
    np.testing.assert_allclose(u[rows, cols], want[:, 0], atol=2e-3)
    np.testing.assert_allclose(v[rows, cols], want[:, 1], atol=2e-3)
    rays = cv2.undistortPoints(pix.reshape(-1, 1, 2), K, dist, criteria=(
        cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)).reshape(-1, 2)
    np.testing.assert_allclose(rx[rows, cols], rays[:, 0], atol=2e-6)
    np.testing.assert_allclose(ry[rows, cols], rays[:, 1], atol=2e-6)


def rising_row(rng: np.random.Generator, width: int) -> np.ndarray:
    """A strictly rising random row (steps 0.3 to 1.7)."""
    return np.cumsum(rng.uniform(0.3, 1.7, width)).astype(np.float32)


def test_match_pair_finds_every_value_where_a_plain_search_does():
    rng = np.random.default_rng(1)
    h, w = 40, 200
    right = np.stack([rising_row(rng, w) for _ in range(h)])
    left = np.full((h, 120), np.nan, np.float32)
    # where each left value lies on its right row: rising along the row, as on a surface
    truth = np.sort(rng.uniform(5, w - 6, (h, 120)), axis=1)
    for y in range(h):
        left[y] = np.interp(truth[y], np.arange(w), right[y])
    left[:, ::7] = np.nan
    xs = np.arange(120)[None, :]
    d, status = match_pair(left, right, -400.0, 400.0, reach=1)
    ok = np.isfinite(left)
    assert (status[ok] == MATCHED).all() and (status[~ok] == 0).all()
    np.testing.assert_allclose(d[ok], (xs - truth)[ok], atol=2e-3)  # disparity x - x_r


def test_the_line_through_four_samples_on_a_smooth_phase():
    x = np.arange(400.0)
    phase = 0.8 * x + 1e-3 * x**2 + 2.0 * np.sin(x / 40)  # rising, curved as on a surface
    truth = np.linspace(20, 370, 300)
    left = np.interp(truth, x, phase).astype(np.float32)[None, :]  # its values at truth
    d, status = match_pair(left, phase.astype(np.float32)[None, :], -400.0, 400.0)
    assert (status == MATCHED).all()
    exact = np.interp(np.interp(truth, x, phase), phase, x)  # the piecewise-linear answer
    assert np.abs((np.arange(300) - d[0]) - exact).max() < 0.01


@pytest.mark.parametrize("reach", [1, 2])
def test_matches_are_exact_on_linear_rows_and_windows_are_kept(reach):
    x = np.arange(300, dtype=np.float32)
    right = np.tile(0.8 * x + 3.0, (3, 1))
    left = np.tile(0.8 * (x[:100] + 57.25) + 3.0, (3, 1))  # lies 57.25 columns on
    d, status = match_pair(left, right, 0.0, 300.0, shift=2.0, reach=reach)
    assert (status == MATCHED).all()
    np.testing.assert_allclose(d, -57.25 - 2.0, atol=1e-3)
    _, status = match_pair(left, right, 0.0, 50.0, reach=reach)  # outside the window
    assert (status == UNMATCHED).all()


def test_gaps_steps_falls_and_two_places_are_refused():
    nan = math.nan
    right = np.float32([[0, 1, 2, 3, nan, nan, nan, nan, 4, 5, 6]])
    d, status = match_pair(np.float32([[2.5, 3.5, 4.5]]), right, -20.0, 20.0)
    assert status.tolist() == [[MATCHED, UNMATCHED, MATCHED]]  # 3.5 lies in a 5-column gap
    np.testing.assert_allclose(d[0, [0, 2]], [0 - 2.5, 2 - 8.5], atol=1e-6)
    stepped = np.float32([[0, 1, 2, 3, 40, 41, 42, 43]])  # two surfaces, no gap
    for values, want in (([19.5, 20.0], UNMATCHED), ([41.0, 41.5], MATCHED)):
        _, status = match_pair(np.float32([values]), stepped, -20.0, 20.0, jump=5.0)
        assert status[0, 1] == want
    _, status = match_pair(np.float32([[19.5, 20.0]]), stepped, -20.0, 20.0)  # no jump limit
    assert status[0, 1] == MATCHED
    _, status = match_pair(np.float32([[2.0] + [nan] * 4 + [2.5]]), right, -20.0, 20.0)
    assert status[0, [0, 5]].tolist() == [INCONSISTENT] * 2  # no run on the left row
    fall = np.float32([[0, 1, 2, 3, 4, 1, 2, 3, 4, 5]])  # the phase runs back by 3 px
    _, status = match_pair(np.float32([[2.5, 4.5, 4.7]]), fall, -20.0, 20.0)
    assert status[0, :2].tolist() == [NOT_MONOTONIC, MATCHED]
    noisy = np.float32([[0, 1, 2, 1.9, 3, 4, 5]])  # noise: back by a tenth of a step
    _, status = match_pair(np.float32([[1.95, 3.5]]), noisy, -20.0, 20.0, wiggle=1.0)
    assert status.tolist() == [[NOT_MONOTONIC, MATCHED]]  # crossed at 1.95 and 3.05
    d, status = match_pair(np.float32([[1.95, 3.5]]), noisy, -20.0, 20.0, wiggle=1.5)
    assert status.tolist() == [[MATCHED, MATCHED]]
    assert d[0, 0] == pytest.approx(-(1.95 + 3 + 0.05 / 1.1) / 2, abs=1e-6)  # the midpoint
    twice = np.float32([[0, 1, 2, 3, nan, nan, nan, nan, 0, 1, 2, 3]])
    _, status = match_pair(np.float32([[1.5, 1.7]]), twice, -20.0, 20.0)
    assert status[0, 0] == AMBIGUOUS
    _, status = match_pair(np.float32([[1.5, 1.7]]), twice, -20.0, 3.0)  # the window decides
    assert status[0, 0] == MATCHED


def test_the_match_back_and_the_second_coordinate():
    x = np.arange(20, dtype=np.float32)
    right = (x + 100).reshape(1, -1)
    left = np.full((1, 30), np.nan, np.float32)
    left[0, :20] = x + 100
    left[0, 25:27] = [104.0, 104.5]  # the same values again further on the left row
    d, status = match_pair(left, right, -40.0, 40.0)
    assert status[0, 4] == INCONSISTENT and status[0, 3] == MATCHED
    other_l = np.zeros((1, 30), np.float32)
    other_r = np.zeros((1, 20), np.float32)
    other_r[0, 10:] = 5.0  # the second coordinate disagrees from column 10 of the right
    _, status = match_pair(left[:, :20], right, -40.0, 40.0, other=other_l[:, :20],
                           other_right=other_r)
    assert (status[0, 2:9] == MATCHED).all() and (status[0, 11:18] == OTHER_AXIS).all()
    other_r[0, 10:] = np.nan  # not decoded there: nothing to disagree with
    _, status = match_pair(left[:, :20], right, -40.0, 40.0, other=other_l[:, :20],
                           other_right=other_r)
    assert (status[0, 2:18] == MATCHED).all()


def test_a_match_one_row_thin_is_dropped():
    d = np.full((5, 4), 100.0, np.float32)
    d[2, 1] = 160.0  # a lone row of another surface
    d[3:, 3] = np.nan
    d[2, 3] = 130.0
    kept, status = supported(d, np.full((5, 4), MATCHED, np.int8))
    assert np.isnan(kept[2, 1]) and status[2, 1] == ALONE
    assert np.isnan(kept[2, 3]) and status[2, 3] == ALONE  # its only neighbour differs
    assert np.isfinite(np.delete(kept.ravel(), [9, 11, 15, 19])).all()


def test_grid_depth_triangulates_and_turns_back():
    rot = cv2.Rodrigues(np.array([0.0, 0.1, 0.02]))[0]  # camera -> rectified frame
    f, cx, cy, tx = 500.0, 320.0, 240.0, -100.0
    point = np.array([30.0, -20.0, 700.0])  # camera frame
    rect = rot @ point
    u, v = f * rect[0] / rect[2] + cx, f * rect[1] / rect[2] + cy
    d = -f * tx / rect[2]
    disparity = np.full((480, 640), d, np.float32)
    depth, outside = grid_depth(disparity, np.float32([[u, 5.0]]), np.float32([[v, 5.0]]),
                                np.array([[True, False]]), f, cx, cy, tx, rot)
    assert depth[0, 0] == pytest.approx(700.0, abs=2e-3) and np.isnan(depth[0, 1])
    assert outside == 0
    depth, outside = grid_depth(disparity, np.float32([[u]]), np.float32([[v]]),
                                np.ones((1, 1), bool), f, cx, cy, tx, rot, max_depth=600.0)
    assert np.isnan(depth).all() and outside == 1


def _line_through(line: np.ndarray, x: int, radius: int, weights: np.ndarray,
                  jump: float) -> float:
    """The definition of :func:`smooth_runs` at one sample: the weighted least-squares line
    through its neighbours up to ``radius`` away, each side up to the first invalid one or
    step over ``jump``, at the sample."""
    ks = [0]
    for direction in (-1, 1):
        for k in range(1, radius + 1):
            j, prev = x + direction * k, x + direction * (k - 1)
            if not 0 <= j < len(line) or not abs(float(line[j]) - float(line[prev])) <= jump:
                break
            ks.append(direction * k)
    k = np.array(ks, float)
    if len(k) == 1:
        return float(line[x])
    fit = np.polyfit(k, line[x + k.astype(int)].astype(float), 1, w=np.sqrt(weights[
        np.abs(k).astype(int)]))
    return float(fit[1])


@pytest.mark.parametrize("sigma", [0.6, 1.0, 2.0])
def test_smoothing_is_the_least_squares_line_within_each_run(sigma):
    rng = np.random.default_rng(5)
    h, w = 40, 60
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    values = (1.5 * xx + 0.3 * yy + 4 * np.sin(xx / 7)).astype(np.float32)
    values[:, 30:] += 50.0  # a second surface
    values[15:, :] -= 40.0  # and a third
    values += rng.normal(0, 0.05, values.shape).astype(np.float32)
    values[rng.random(values.shape) < 0.04] = np.nan
    values[5:9, 10:14] = np.nan
    jump = 5.0
    got = smooth_runs(values, sigma, jump)
    radius = max(1, math.ceil(3 * sigma))
    weights = np.exp(-0.5 * (np.arange(radius + 1) / sigma) ** 2)
    rows = np.full(values.shape, np.nan)
    for y in range(h):
        for x in range(w):
            if np.isfinite(values[y, x]):
                rows[y, x] = _line_through(values[y], x, radius, weights, jump)
    rows = rows.astype(np.float32)
    want = np.full(values.shape, np.nan)
    for x in range(w):
        for y in range(h):
            if np.isfinite(rows[y, x]):
                want[y, x] = _line_through(rows[:, x], y, radius, weights, jump)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(values))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-4)


def test_a_gap_is_bridged_only_where_the_slope_carries_across_it():
    """Pixels of one surface left out (dim, at a code edge) keep their slope and are
    interpolated across; a gap hiding a step of two surfaces (one object's edge, whose
    strip of background only the other camera sees) is not: the far scene's 249 points off
    by 1.4% (stereo_accuracy.py, default optics) came from such a gap of 3 columns."""
    nan = math.nan
    smooth = np.float32([[0, 1, 2, nan, nan, 5, 6, 7]])
    d, status = match_pair(np.float32([[3.0, 3.5, 4.0]]), smooth, -20.0, 20.0, reach=1)
    assert status[0].tolist() == [MATCHED] * 3 and d[0, 1] == pytest.approx(1 - 3.5)
    # the strip seen by the left camera hidden in the right one's gap: a step of 6 where
    # the slope carries 3 (within the jump limit of 4 a column)
    stepped = np.float32([[0, 1, 2, nan, nan, 8, 9, 10]])
    _, status = match_pair(np.float32([[3.5, 4.5, 5.5]]), stepped, -20.0, 20.0, reach=1,
                           jump=4.0)
    assert status[0].tolist() == [UNMATCHED] * 3
    # within half a column's worth of the slope a column: noise, bridged
    _, status = match_pair(np.float32([[3.0, 3.5, 4.0]]), smooth + np.float32(
        [[0, 0, 0, 0, 0, 1.4, 1.4, 1.4]]), -20.0, 20.0, reach=1)
    assert status[0, 1] == MATCHED


def _surfaces(rng: np.random.Generator, h: int, w: int, slope: float) -> np.ndarray:
    """A rectified coordinate map: three surfaces, blurred steps (kinks), noise, holes."""
    yy, xx = np.mgrid[0:h, 0:w].astype(float)
    values = slope * xx + 0.3 * yy + 4 * np.sin(xx / 7)
    values[:, 30:] += 50.0 * np.sign(slope)
    values[15:, :] -= 40.0
    values[:, 29] = 0.5 * (values[:, 28] + values[:, 31])  # a pixel mixing two surfaces
    values += rng.normal(0, 0.05, values.shape)
    values[rng.random(values.shape) < 0.04] = np.nan
    values[5:9, 10:14] = np.nan
    return values.astype(np.float32)


@pytest.mark.parametrize(("sigma", "negate", "kink"),
                         [(1.0, False, 2.0), (1.0, True, 2.0), (0.6, True, 1.0),
                          (2.0, False, 2.0), (1.0, False, math.inf), (0.0, True, 2.0)])
def test_one_pass_prepares_a_map_as_the_kinks_negation_and_smoothing_did(sigma, negate,
                                                                         kink):
    """Dropping the kinks, negating and smoothing in one pass (``smooth_runs`` with ``kink``
    and ``negate``) gives what the three passes gave, bit for bit."""
    rng = np.random.default_rng(11)
    for trial in range(3):
        values = _surfaces(rng, 34 + trial, 61, -1.5 if negate else 1.5)
        got = smooth_runs(values, sigma, 5.0, kink, 1, negate=negate)
        want = stereo_before.prepared(values, sigma, 5.0, kink, 1, negate)
        np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32))


def test_the_points_counts_and_sample_are_those_of_the_whole_image_passes():
    """``depth_counts`` gives ``grid_depth``'s depth with its mask, counts per row and the
    decoded pixels; ``pick_finite`` the misfit check's sample that ``np.nonzero`` of every
    point gave; ``count_status`` ``np.bincount``'s counts."""
    rng = np.random.default_rng(3)
    h, w = 90, 120
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    disparity = (16.0 + 0.05 * xx + 0.02 * yy + rng.normal(0, 0.1, (h, w))).astype(np.float32)
    disparity[:, 100:] -= 3.0  # beyond the depth range
    disparity[rng.random((h, w)) < 0.05] = np.nan
    disparity[40:50] = np.nan  # rows without a point
    u = xx + rng.uniform(-1, 1, (h, w)).astype(np.float32)
    v = yy + rng.uniform(-1, 1, (h, w)).astype(np.float32)
    coord = rng.uniform(0, 100, (h, w)).astype(np.float32)
    coord[rng.random((h, w)) < 0.1] = np.nan
    rot = cv2.Rodrigues(np.array([0.01, -0.02, 0.005]))[0]
    args = (100.0, 60.0, 45.0, -80.0, rot, 380.0, 520.0)
    depth, mask, outside, per_row, decoded = depth_counts(disparity, u, v, coord, *args)
    want, want_outside = grid_depth(disparity, u, v, np.isfinite(coord), *args)
    np.testing.assert_array_equal(depth.view(np.uint32), want.view(np.uint32))
    np.testing.assert_array_equal(mask, np.isfinite(want))
    assert outside == want_outside > 0 and decoded == np.isfinite(coord).sum()
    assert 0.5 * decoded < mask.sum() < decoded and (per_row == 0).any()
    np.testing.assert_array_equal(per_row, np.isfinite(want).sum(axis=1))
    for count in (0, 1, 7, int(mask.sum()) // 3, int(mask.sum())):
        pick = np.linspace(0, mask.sum() - 1, count).astype(np.int64)
        rows, cols = np.nonzero(mask)
        got = pick_finite(depth, per_row, pick)
        np.testing.assert_array_equal(got[0], rows[pick])
        np.testing.assert_array_equal(got[1], cols[pick])
    status = rng.integers(0, 8, (h, w)).astype(np.int8)
    np.testing.assert_array_equal(count_status(status), np.bincount(status.ravel(),
                                                                    minlength=8))


def test_the_misfit_share_is_the_one_the_copies_gave():
    """``projector_misfits`` with its cubic's powers made once and its first fit on the
    arrays themselves: the share of misfits the old one gave, exactly."""
    rng = np.random.default_rng(8)
    for n, moved in ((40000, 0), (40000, 1500), (12000, 900), (30000, 2500)):
        pts = rng.uniform([-100, -80, 500], [100, 80, 700], (n, 3))
        coord = 960 + 2000 * (pts[:, 0] - 100) / pts[:, 2] + rng.normal(0, 0.3, n)
        rows = np.floor(240 + 600 * pts[:, 1] / pts[:, 2])
        pts[:moved, 2] *= rng.uniform(1.01, 1.2, moved)
        want = stereo_before.projector_misfits(pts, coord, rows)
        assert projector_misfits(pts, coord, rows) == want
        assert (want > 0) == (moved > 0)


def test_the_points_and_the_cloud_are_those_of_the_numpy_expressions():
    """``grid_points`` and ``cloud_points`` (one pass each) give the points and the cloud
    that ``StereoResult`` made with NumPy, bit for bit, in row-major order."""
    rng = np.random.default_rng(4)
    depth = rng.uniform(400, 900, (70, 90)).astype(np.float32)
    depth[rng.random(depth.shape) < 0.3] = np.nan
    depth[20:30] = np.nan
    rx, ry = (rng.uniform(-0.6, 0.6, depth.shape).astype(np.float32) for _ in range(2))
    grey = rng.integers(0, 256, depth.shape).astype(np.uint8)
    want = np.stack([depth * rx, depth * ry, depth], axis=-1)
    got = grid_points(depth, rx, ry)
    np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32))
    mask = np.isfinite(depth)
    pts, rgb = cloud_points(depth, rx, ry, grey, mask)
    want = np.column_stack([depth[mask] * rx[mask], depth[mask] * ry[mask], depth[mask]])
    assert pts.dtype == np.float32 and rgb.dtype == np.uint8
    np.testing.assert_array_equal(pts.view(np.uint32), want.view(np.uint32))
    np.testing.assert_array_equal(rgb, np.repeat(grey[mask][:, None], 3, axis=1))
