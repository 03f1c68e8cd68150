"""A depth map for every window of a two-camera stream (issue 34): ``stereo --window N|N+K
--starts`` and :class:`~bistair.geometry.unwrap_stream.StereoStream`, against the renderer's
truth and against the full search of every window."""

import json
import shutil

import numpy as np
import pytest
from conftest import cli_run

from bistair.app.simulate_motion import simulate_motion
from bistair.codecs import make_spec
from bistair.geometry.stereo_calibration import load_stereo_calibration
from bistair.geometry.unwrap_stream import StereoStream
from bistair.io.read import find_spec, read_captures

SIZE = (160, 120)
PERIOD = 48
RANGE = "520:650"  # two-masks lies at 559-633 mm, at 541-614 mm by frame 9
#: An order off moves a point by about a period's depth (86 mm here: 48 projector columns
#: at 1.8 mm each, 600 mm away with the projector 100 mm from the left camera); the noise
#: of a decided point is 0.8 mm (median), 3 mm (99th percentile), at most 8 mm over these
#: windows; a tolerance of 15 mm counts every order off and no noise.
TOLERANCE_MM = 15.0


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    """Ten frames of two-masks (4 steps, period 48, the masks moving 2 mm nearer a frame:
    0.14 rad of phase) seen by two cameras 200 mm apart, the projector halfway."""
    out = tmp_path_factory.mktemp("stereo-stream") / "sim"
    return simulate_motion("two-masks", ["multifreq"], out, "0,0,-2mm", frames=10,
                           continuous=True, cameras=2, camera_size=SIZE, period=PERIOD)


def truth_at(sim, time, name):
    """The left camera's truth ``name`` at ``time`` (the mean of the frames either side),
    NaN where the two frames see different objects."""
    times = sorted({int(np.floor(time)), int(np.ceil(time))})
    folders = [sim / "truth" / "L" / f"frame-{t:04d}" for t in times]
    values = np.stack([np.load(f / f"{name}.npy") for f in folders]).astype(float)
    ids = np.stack([np.load(f / "object_id.npy") for f in folders])
    mean = values.mean(0)
    mean[(ids != ids[0]).any(0)] = np.nan
    return mean


def windows(sim, order, margin):
    """Every window of the stream through the library."""
    left, right = (read_captures(sim / "multifreq" / side) for side in ("L", "R"))
    stream = StereoStream(load_stereo_calibration(sim / "stereo.json"),
                          find_spec(sim / "multifreq" / "L"), 520.0, 650.0, order=order,
                          margin=margin)
    out = [stream.push(a, b) for a, b in zip(left, right, strict=True)]
    return [o for o in out if o is not None], stream.lag


def test_windows_against_truth(sim, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    code, printed, err = cli_run(
        monkeypatch, capsys, "stereo", sim / "multifreq" / "L", sim / "multifreq" / "R",
        "--calibration", sim / "stereo.json", "--depth-range", RANGE, "--window", "4",
        "--out", out)
    assert code == 0, err
    assert "7 depth maps of --window 4" in printed
    folders = sorted(p for p in out.iterdir())
    assert [p.name for p in folders] == [f"{s:04d}" for s in range(7)]
    for folder in folders:
        assert sorted(p.name for p in folder.iterdir()) == ["cloud.ply", "depth.npy",
                                                            "depth.png", "info.json"]
        info = json.loads((folder / "info.json").read_text())
        depth = np.load(folder / "depth.npy")
        decided = np.isfinite(depth)
        assert info["decided"] == int(decided.sum())
        assert info["decided_fraction"] > 0.5
        assert info["frames"] == [info["start"], info["start"] + 3] and info["lag"] == 1.5
        assert info["range_check"]["outside"] < 0.5
        assert np.all((depth[decided] >= 520) & (depth[decided] <= 650))  # NaN elsewhere
        truth = truth_at(sim, info["time"], "depth")
        seen = decided & np.isfinite(truth)
        err = np.abs(depth[seen] - truth[seen])
        assert seen.sum() > 0.95 * decided.sum()
        assert np.sum(err > TOLERANCE_MM) <= 0.001 * decided.sum()  # an order off
        assert np.median(err) < 1.0 and np.percentile(err, 99) < 5.0


def test_orders_and_the_full_search(sim):
    """Where the tracker and the full search of the same window both decide, they decide
    the same disparity, of the right order. Both grow decisions from two agreeing
    neighbours (:func:`~bistair.geometry.unwrap_jit.grow`); without that the tracker decided
    3.9% fewer. It now decides none the full search does not, and at most 0.5% fewer
    (3-19 of about 6700 a window): at an occlusion edge the right grid's narrow search
    decides the near surface where the full search finds both surfaces (two candidates,
    undecided), and a left pixel that it contradicts is an occlusion for the tracker,
    blocking 2 pixels either side along the row. Orders off: at most 0.1% of the decided
    pixels."""
    tracked, lag = windows(sim, 0, 6.0)
    full, _ = windows(sim, 0, 0.0)
    near = 0
    for a, b in zip(tracked, full, strict=True):
        da, db = np.isfinite(a.disparity), np.isfinite(b.disparity)
        both = da & db
        assert np.array_equal(a.disparity[both], b.disparity[both])
        assert np.sum(da & ~db) <= 0.001 * da.sum() and np.sum(db & ~da) <= 0.005 * db.sum(), (
            np.sum(da & ~db), np.sum(db & ~da), db.sum())
        near += a.info["searched_near"]
        truth = truth_at(sim, a.start + lag, "coord_x")
        off = np.abs(a.phase - 2 * np.pi * truth / PERIOD)
        assert np.sum(off[a.mask & np.isfinite(off)] > np.pi) <= 0.001 * a.mask.sum()
        extra = a.mask & ~b.mask & np.isfinite(off)
        assert np.sum(off[extra] > np.pi) <= 0.001 * a.mask.sum()
        assert np.array_equal(a.mask, a.order >= 0)
    assert near > 0.5 * sum(a.info["left_decoded"] for a in tracked[1:])


def ripple(result, sim, lag):
    """The amplitude (radians) of the phase error at twice the fringe frequency."""
    truth = 2 * np.pi * truth_at(sim, result.start + lag, "coord_x") / PERIOD
    ok = result.mask & np.isfinite(truth)
    err, phase = (result.phase - truth)[ok], truth[ok]
    basis = np.column_stack([np.sin(2 * phase), np.cos(2 * phase), np.ones_like(phase)])
    coef = np.linalg.lstsq(basis, err, rcond=None)[0]
    return float(np.hypot(coef[0], coef[1]))


def test_compensation_lowers_the_ripple(sim):
    plain, lag0 = windows(sim, 0, 6.0)
    compensated, lag2 = windows(sim, 2, 6.0)
    before = np.median([ripple(r, sim, lag0) for r in plain])
    after = np.median([ripple(r, sim, lag2) for r in compensated])
    assert before > 0.05 and after < 0.1 * before, (before, after)  # 0.077 and 0.002 rad


def bad_cases(sim, tmp_path):
    """Each bad input: its extra arguments."""
    short = tmp_path / "short"
    shutil.copytree(sim / "multifreq" / "R", short)
    sorted(short.glob("*.png"))[-1].unlink()
    left = read_captures(sim / "multifreq" / "L")
    np.save(tmp_path / "l.npy", left)
    np.save(tmp_path / "r.npy", left[:, :, :150])
    periods = tmp_path / "two.json"
    periods.write_text(make_spec("multifreq", width=1920, height=1080,
                                 periods=(1920, 48)).to_json())
    base = [sim / "multifreq" / "L", sim / "multifreq" / "R"]
    spec = sim / "multifreq" / "L" / "spec.json"
    return {
        "window": (base, ["--window", "3", "--depth-range", RANGE], "--window must be 4"),
        "order": (base, ["--window", "4+0", "--depth-range", RANGE], "--window must be 4"),
        "starts": (base, ["--window", "4+1", "--starts", "0,6", "--depth-range", RANGE],
                   "--starts 6 is beyond the stream"),
        "count": ([base[0], short], ["--window", "4", "--depth-range", RANGE],
                  "LEFT has 10 frames and RIGHT 9"),
        "size": ([tmp_path / "l.npy", tmp_path / "r.npy"],
                 ["--window", "4", "--depth-range", RANGE, "--spec", spec],
                 "left and right frames differ"),
        "spec": (base, ["--window", "4", "--depth-range", RANGE, "--spec", periods],
                 "a stream needs a single-period N-step spec"),
        "range": (base, ["--window", "4"], "needs --depth-range"),
        "wrong range": (base, ["--window", "4", "--depth-range", "700:800"],
                        "correct --depth-range"),
        "starts alone": (base, ["--starts", "0", "--depth-range", RANGE],
                         "--starts needs --window"),
    }


@pytest.mark.parametrize("case", ["window", "order", "starts", "count", "size", "spec",
                                  "range", "wrong range", "starts alone"])
def test_bad_inputs_refused(sim, tmp_path, monkeypatch, capsys, case):
    sides, extra, message = bad_cases(sim, tmp_path)[case]
    out = tmp_path / "out"
    code, printed, err = cli_run(monkeypatch, capsys, "stereo", *sides, "--calibration",
                                 sim / "stereo.json", *extra, "--out", out)
    assert code == 2, err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_starts_and_old_windows(sim, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    args = ["stereo", sim / "multifreq" / "L", sim / "multifreq" / "R", "--calibration",
            sim / "stereo.json", "--depth-range", RANGE, "--out", out]
    assert cli_run(monkeypatch, capsys, *args, "--window", "4")[0] == 0
    code, _, err = cli_run(monkeypatch, capsys, *args, "--window", "4+2", "--starts", "1,4")
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["0001", "0004"]
    info = json.loads((out / "0004" / "info.json").read_text())
    assert (info["window"], info["order"], info["lag"], info["frames"], info["time"]) == (
        "4+2", 2, 2.5, [4, 9], 6.5)


def test_depth_through_a_distorted_projector():
    """The column planes of a projector with radial distortion (k1 = 0.3): the pixel's
    column undistorted at the row its point projects to. Median 0.37 mm off the truth
    (2.5 mm with the distortion ignored)."""
    from bistair.codecs import encode
    from bistair.geometry.stereo_calibration import StereoCalibration
    from bistair.sim import Imaging, expose, preset, trace
    from bistair.sim.stereo import StereoRig

    rig, scene = preset("two-masks", camera_size=SIZE)
    srig = StereoRig.default(camera_size=SIZE, projector_size=rig.projector.size,
                             projector_dist=(0.3, 0, 0, 0, 0))
    spec = make_spec("multifreq", width=rig.projector.size[0], height=rig.projector.size[1],
                     periods=(PERIOD,), steps=4)
    patterns = encode(spec)[np.arange(6) % 4]
    frames, truths = [], []
    for i, side in enumerate(("left", "right")):
        imaging = Imaging(seed=i)
        traced = trace(srig.rig(side), scene, imaging)
        frames.append(expose(traced, patterns, imaging))
        truths.append(traced.truth)
    stream = StereoStream(StereoCalibration.from_rig(srig), spec, 540.0, 650.0)
    results = [stream.push(a, b) for a, b in zip(*frames, strict=True)][3:]
    for result in results:
        err = np.abs(result.depth - truths[0].depth)[result.mask]
        err = err[np.isfinite(err)]
        assert result.info["decided_fraction"] > 0.6
        assert np.median(err) < 1.0 and np.max(err) < TOLERANCE_MM


def _random_phase(rng, shape, period=21.0):
    """A wrapped ramp of ``period`` px along x with 0.05 rad of noise, and a modulation
    uniform in [0, 1) (30% below 0.3: unknown pixels everywhere)."""
    yy, xx = np.mgrid[:shape[0], :shape[1]]
    phi = np.float32((2 * np.pi * xx / period + 0.01 * yy + rng.normal(0, 0.05, xx.shape))
                     % (2 * np.pi))
    return phi, np.float32(rng.uniform(0, 1, phi.shape))


def _wrapped_error(a, b):
    """|a - b| wrapped into [0, pi] (radians)."""
    return np.abs((a.astype(float) - b + np.pi) % (2 * np.pi) - np.pi)


def _crooked_rig():
    """Rectified grids that sample between pixels everywhere: distorted cameras, the right
    one 2 mm higher and rolled half a degree."""
    from bistair.geometry.stereo import rectify
    from bistair.geometry.stereo_calibration import StereoCalibration
    from bistair.sim.stereo import StereoRig

    srig = StereoRig.default(camera_size=SIZE, projector_size=(640, 480),
                             camera_dist=(-0.1, 0.05, 0, 0, 0), right_height=2.0,
                             right_roll_deg=0.5)
    return rectify(StereoCalibration.from_rig(srig))


#: The compiled resampler (the steps between corners unwrapped, averaged bilinearly) and
#: the cosine-sine one (the angle of the averaged unit vectors) part by about ``w (1 - w)
#: (1 - 2 w) d**3 / 6`` between two pixels of weights ``1 - w``, ``w`` and a step ``d``
#: (at most ``0.016 d**3``): 0.3 rad a pixel here, with 0.05 rad of noise (measured
#: 3.0e-3 at most).
COS_SIN_TOLERANCE = 5e-3


def test_resampling_agrees_with_the_cosine_sine_resampler():
    """The compiled resampler against the ``cv2.remap`` of the cosine, sine and validity
    it replaced (``tests/support/reference.py``) on both grids of a rig that samples
    between pixels: within :data:`COS_SIN_TOLERANCE` where both know the phase; the known
    sets differ only beside unknown pixels, on at most 0.5% (none with OpenCV 5's exact
    float weights; OpenCV 4 rounds them to 1/32 px)."""
    from support.reference import rectified_phase_cv2

    from bistair.geometry.unwrap import rectified_phase

    rect = _crooked_rig()
    rng = np.random.default_rng(3)
    for maps in (rect.maps_left, rect.maps_right):
        fractions = maps[0] - np.floor(maps[0])
        assert np.mean((fractions > 0.01) & (fractions < 0.99)) > 0.5  # between pixels
        phi, mod = _random_phase(rng, SIZE[::-1])
        phase = np.where(mod >= 0.3, phi, np.float32(np.nan)).astype(np.float32)
        got, want = rectified_phase(phase, maps), rectified_phase_cv2(phase, maps)
        known, known_cv2 = np.isfinite(got), np.isfinite(want)
        both = known & known_cv2
        assert 0.2 < both.mean() < 0.9  # (both kinds of pixel)
        assert _wrapped_error(got, want)[both].max() <= COS_SIN_TOLERANCE
        differ = known ^ known_cv2
        assert differ.sum() <= 0.005 * known_cv2.sum()
        x0, y0 = (np.floor(m[differ]).astype(int) for m in maps)
        beside = np.zeros(x0.shape, bool)  # an unknown or outside pixel among the four
        for dy in (0, 1):
            for dx in (0, 1):
                yy, xx = y0 + dy, x0 + dx
                inside = (yy >= 0) & (yy < SIZE[1]) & (xx >= 0) & (xx < SIZE[0])
                beside |= ~inside
                beside[inside] |= np.isnan(phase[yy[inside], xx[inside]])
        assert beside.all()


def test_resampling_against_the_truth():
    """The wrapped phase of the renderer's true projector column (two-masks, period 48),
    resampled onto both rectified grids, against that column itself resampled (bilinear,
    where the four pixels of nonzero weight see one surface) and wrapped: within 1e-5 rad
    (float32 rounding; measured 6.6e-7), and known wherever the truth is. The cosine-sine
    resampler is off there by up to 0.19 rad (steps of about a radian between pixels)."""
    from support.reference import rectified_phase_cv2

    from bistair.geometry.stereo import rectify
    from bistair.geometry.stereo_calibration import StereoCalibration
    from bistair.geometry.unwrap import rectified_phase
    from bistair.sim import preset, trace
    from bistair.sim.stereo import StereoRig

    rig, scene = preset("two-masks", camera_size=SIZE)
    srig = StereoRig.default(camera_size=SIZE, projector_size=rig.projector.size,
                             projector_dist=(0.3, 0, 0, 0, 0))
    rect = rectify(StereoCalibration.from_rig(srig))
    for side, maps in (("left", rect.maps_left), ("right", rect.maps_right)):
        truth = trace(srig.rig(side), scene).truth
        column = truth.coord_x.astype(float)
        mx, my = (m.astype(float) for m in maps)
        x0, y0 = np.floor(mx).astype(int), np.floor(my).astype(int)
        want = np.zeros(mx.shape)
        ok = (x0 >= 0) & (y0 >= 0) & (x0 < SIZE[0] - 1) & (y0 < SIZE[1] - 1)
        ids = truth.object_id[np.clip(y0, 0, SIZE[1] - 1), np.clip(x0, 0, SIZE[0] - 1)]
        for dy, dx, w in ((0, 0, (1 - (mx - x0)) * (1 - (my - y0))),
                          (0, 1, (mx - x0) * (1 - (my - y0))),
                          (1, 0, (1 - (mx - x0)) * (my - y0)), (1, 1, (mx - x0) * (my - y0))):
            yy, xx = np.clip(y0 + dy, 0, SIZE[1] - 1), np.clip(x0 + dx, 0, SIZE[0] - 1)
            ok &= np.isfinite(column[yy, xx]) & (truth.object_id[yy, xx] == ids)
            want += w * np.nan_to_num(column[yy, xx])
        want = 2 * np.pi * want / PERIOD
        phase = np.float32(2 * np.pi * column / PERIOD % (2 * np.pi))
        got = rectified_phase(phase, maps)
        assert ok.sum() > 4000 and np.isfinite(got[ok]).all()
        assert _wrapped_error(got, want)[ok].max() < 1e-5
        if side == "right":  # (the old one, for the record: the test tells them apart)
            assert _wrapped_error(rectified_phase_cv2(phase, maps), want)[ok].max() > 0.1


def test_the_stream_resampling_and_rectified_phase_are_one_door():
    """The stream's resampling (``resample_wrapped`` with a modulation: the threshold and
    the resampling in one pass, into reused buffers) gives what the one-set path gives
    (``np.where`` of the threshold, then ``rectified_phase``), bit for bit, on both
    grids: the first window and the later ones read the same numbers; every phase in [0,
    2*pi)."""
    from bistair.geometry.stereo import resample_wrapped
    from bistair.geometry.unwrap import rectified_phase

    rect = _crooked_rig()
    rng = np.random.default_rng(4)
    buffers: dict = {}
    for maps in (rect.maps_left, rect.maps_right):
        for _ in range(2):
            phi, mod = _random_phase(rng, SIZE[::-1])
            want_phase = np.where(mod >= 0.3, phi, np.float32(np.nan)).astype(np.float32)
            want = rectified_phase(want_phase, maps)
            phase, got, valid = resample_wrapped(phi, maps, mod, 0.3, buffers)
            assert valid == int(np.sum(mod >= 0.3))
            assert np.array_equal(phase, want_phase, equal_nan=True)
            assert np.array_equal(got, want, equal_nan=True)
            known = got[np.isfinite(got)]
            assert known.size > 1000 and known.min() >= 0 and known.max() < 2 * np.pi
        assert got is buffers["rectified"]  # (reused)


def test_the_first_window_settles_the_pixel_origin(sim):
    """A calibration that records the wrong pixel origin (its cameras' principal points one
    pixel off, as a MATLAB matrix read 0-based) is checked on the first window as one set
    is, and every later window uses the origin the data fit: the tracked windows' depth
    stays on the truth (one pixel off costs millimetres: the tracker kept the wrong model)."""
    from bistair.geometry.projection_matrices import with_pixel_origin

    left, right = (read_captures(sim / "multifreq" / side) for side in ("L", "R"))
    wrong = with_pixel_origin(load_stereo_calibration(sim / "stereo.json"), 1)
    stream = StereoStream(wrong, find_spec(sim / "multifreq" / "L"), 520.0, 650.0,
                          pixel_origin=1)
    out = [r for r in (stream.push(a, b) for a, b in zip(left, right, strict=True)) if r]
    assert stream.pixel_origin == 0
    assert any("pixel-origin" in w for w in out[0].info["warnings"])
    for result in out:
        decided = np.isfinite(result.depth)
        truth = truth_at(sim, result.start + stream.lag, "depth")
        seen = decided & np.isfinite(truth)
        assert seen.sum() > 0.5 * np.isfinite(truth).sum()
        assert np.median(np.abs(result.depth[seen] - truth[seen])) < 1.0


def test_the_fast_row_search_equals_the_plain_one(sim, monkeypatch):
    """:func:`~bistair.geometry.unwrap_stream_jit.track_rows` tests only the intervals whose
    two ends lie within a phase step of the pixel's phase (a crossing needs it) and its
    candidates' projector column in one division: on every tracked window of the test
    stream, both grids, it gives what the plain scan gives (every interval), and its full
    search (no previous disparity) what :func:`~bistair.geometry.unwrap_jit.unwrap_rows`
    gives, bit for bit."""
    from bistair.geometry import unwrap_stream
    from bistair.geometry.unwrap_jit import unwrap_rows

    calls = []
    plain = unwrap_stream.track_rows

    def recorded(*args, **kwargs):
        copies = [np.copy(a) if isinstance(a, np.ndarray) else a for a in args]
        out = plain(*args, **kwargs)
        calls.append((copies, kwargs, [np.copy(a) for a in out]))  # (its buffers are reused)
        return out

    monkeypatch.setattr(unwrap_stream, "track_rows", recorded)
    windows(sim, 0, 6.0)
    assert len(calls) == 12  # six tracked windows, two grids each
    near = 0
    for args, kwargs, fast in calls:
        slow = plain(*args, **kwargs, skip=False)
        n_in = fast[0]
        assert np.sum(n_in != slow[0]) == 0 and np.array_equal(fast[2], slow[2])
        assert np.array_equal(fast[1], slow[1], equal_nan=True)
        read = np.arange(fast[3].shape[2]) < np.clip(n_in, 0, None)[..., None]
        assert np.array_equal(fast[3][read], slow[3][read])
        near += int(fast[2].sum())
        own, other, previous, margin, *rest = args
        side = {"from_right": kwargs.get("from_right", False)}
        full = plain(own, other, np.full_like(previous, np.nan), margin, *rest, **side)
        want = unwrap_rows(own, other, *rest, **side)
        assert np.sum(full[0] != want[0]) == 0
        assert np.array_equal(full[1], want[1], equal_nan=True)
        assert np.sum(want[0] >= 2) > 0 and np.sum(want[0] == 1) > 1000
    assert near > 10000


def test_the_bounded_row_search_on_rough_rows():
    """The fast search scans only the intervals between two bounds of the row's running
    sums of phase steps (:mod:`~bistair.geometry.unwrap_stream_bounds_jit`, a NaN step
    counted as 4): on rows of random steps (forwards and back, up to 2.5 rad), holes of NaN
    and every phase a pixel may have, with the projector and depth tests wide open (every
    crossing a candidate), it gives what the plain scan gives, bit for bit, narrow and full
    searches, both grids. A search longer than ``LONG`` intervals (every full one here, the
    narrow ones too with a margin of 15 px) scans unbounded, its distances in a pass of
    their own: the same."""
    from bistair.geometry.unwrap_stream_bounds_jit import LONG
    from bistair.geometry.unwrap_stream_jit import track_rows

    rng = np.random.default_rng(7)
    h, w = 60, 160
    other = np.cumsum(rng.uniform(-0.8, 2.5, (h, w)), axis=1) % (2 * np.pi)
    other[rng.random((h, w)) < 0.06] = np.nan
    other[::7, 40:43] = np.nan  # (runs of holes)
    own = rng.uniform(0, 2 * np.pi, (h, w))
    own[rng.random((h, w)) < 0.05] = np.nan
    previous = rng.uniform(2.0, 40.0, (h, w)).astype(np.float32)
    previous[rng.random((h, w)) < 0.2] = np.nan
    k = np.array([[100.0, 0, 5000], [0, 100, 0], [0, 0, 1]])
    rig = (0.0, 100.0, 0.0, 0.0, -100.0, np.eye(3), k, np.zeros(5), np.eye(3),
           np.array([-25.0, 0, 0]), 8.0, np.pi, 1.0, 1e6, 10000)
    assert 2 * 6.0 + 1 <= LONG < 2 * 15.0 < 40.0 - 1.0  # (short narrow, long full searches)
    for side, margin in ((False, 6.0), (True, 6.0), (False, 15.0), (True, 15.0)):
        out = [track_rows(own, other, previous, margin, 1.0, 40.0, *rig, from_right=side,
                          skip=skip) for skip in (True, False)]
        fast, slow = out
        assert np.array_equal(fast[0], slow[0]) and np.array_equal(fast[2], slow[2])
        assert np.array_equal(fast[1], slow[1], equal_nan=True)
        read = np.arange(fast[3].shape[2]) < np.clip(fast[0], 0, None)[..., None]
        assert np.array_equal(fast[3][read], slow[3][read])
        near = fast[2].sum()  # (the wide margin's narrow searches decide fewer)
        assert near > (1000 if margin == 6.0 else 200) and np.sum(fast[0] >= 2) > 1000


def test_every_window_leaves_mixed_pixels_undecided(sim, monkeypatch):
    """Every window, tracked or searched in full, leaves undecided the pixels
    :func:`~bistair.geometry.unwrap.mixed_pixels` finds in its depth (ramps across depth
    steps, spikes), as the one-set ``stereo`` does: NaN depth and phase, order -1, and
    ``info["mixed"]`` counts them. This stream has none (smooth masks at 160 x 120): the
    check here also flags every 50th decided pixel, to see the stream honour what it
    returns (without the stream's call, the tracked windows kept them)."""
    from bistair.geometry import unwrap_stream

    found, real = [], unwrap_stream.mixed_pixels

    def recorded(depth, mask, *args, **kwargs):
        flagged = real(depth, mask, *args, **kwargs)
        flagged.ravel()[np.flatnonzero(mask)[::50]] = True
        found.append(flagged & mask)
        return found[-1]

    monkeypatch.setattr(unwrap_stream, "mixed_pixels", recorded)
    tracked, _ = windows(sim, 0, 6.0)
    assert len(found) == len(tracked) and all(m.sum() > 50 for m in found)
    for result, mixed in zip(tracked, found, strict=True):
        assert result.info["mixed"] == mixed.sum()
        assert np.isnan(result.depth[mixed]).all() and np.isnan(result.phase[mixed]).all()
        assert (result.order[mixed] == -1).all() and not result.mask[mixed].any()


def test_the_depth_passes_equal_the_projection_and_the_reference(sim, monkeypatch):
    """The stream's depth through an undistorted projector: the projector columns from the
    row's coefficients (``projector_pixels(..., rows=False)``: one division a pixel) are
    the projected points' (``rows=True``, OpenCV's model) within 1e-4 px, undecided at the
    same pixels; ``plane_depth``'s pass without branches gives its NumPy reference's
    order exactly, depth and column to float32's rounding (1e-6 of the value: 6e-4 mm,
    6e-4 px at 600; the reference divides where the pass multiplies by reciprocals),
    every window, also with every 35th column a period off (its neighbours' corners spread
    too far: undecided)."""
    from support import reference

    from bistair.geometry import unwrap_stream

    calls: dict[str, list] = {"projector_pixels": [], "plane_depth": []}

    def recorder(name):
        real, found = getattr(unwrap_stream, name), calls[name]

        def recorded(*args, **kwargs):
            found.append(([np.copy(a) if isinstance(a, np.ndarray) else a for a in args],
                          kwargs))
            return real(*args, **kwargs)
        return recorded

    for name in calls:
        monkeypatch.setattr(unwrap_stream, name, recorder(name))
    windows(sim, 0, 6.0)
    monkeypatch.undo()
    assert len(calls["plane_depth"]) == 7
    for (cargs, kwargs), (dargs, _) in zip(*calls.values(), strict=True):
        assert kwargs == {"rows": False}
        fast, rows = unwrap_stream.projector_pixels(*cargs, rows=False)
        slow = unwrap_stream.projector_pixels(*cargs, rows=True)[0]
        assert rows is None and np.array_equal(np.isnan(fast), np.isnan(slow))
        assert np.isfinite(fast).sum() > 5000 and np.nanmax(np.abs(fast - slow)) < 1e-4
        cols, _, u, v, phase, ax, az, period, step, kp, dp, tp, zmin, zmax = dargs
        assert not np.any(dp) and kp[0, 1] == 0
        bumped = cols.copy()  # (and columns a period off: corners that spread too far)
        bumped[::7, ::5] += period
        decided = []
        for grid in (cols, bumped):
            got = unwrap_stream.plane_depth(grid, *dargs[1:])
            want = reference.plane_depth(grid, u, v, phase, ax, az, period, step, kp, tp,
                                         zmin, zmax)
            assert np.array_equal(got[1], want[1])
            for a, b in ((got[0], want[0]), (got[2], want[2])):
                assert np.array_equal(np.isnan(a), np.isnan(b))
                assert np.nanmax(np.abs(a - b) / np.maximum(np.abs(b), 1)) < 1e-6  # 2 ulps
            decided.append(int((got[1] >= 0).sum()))
        assert decided[0] > 5000 and 1000 < decided[1] < 0.95 * decided[0], decided
