"""Two cameras and a projector: rectification, ``bistair.stereo`` against the virtual rig's
truth (a level pair; a rolled, offset pair with lens distortion and both projector axes),
the command line (``simulate --cameras 2``, ``stereo``, ``batch`` of stereo sets) and every
refusal: one line, exit code 2, nothing written.

Small cameras (320 x 256, f = 600 px) keep the renders fast; the 1280 x 1024 figures of the
issue come from ``benchmarks/stereo_accuracy.py``. Measured here (sphere-on-plane, Gray code
with the complementary pattern, default optics): the level pair matches 97.7% of the pixels
both cameras decode, depth RMS 0.034% of the distance, p99 0.096%, no point off by 1%; the
rolled, distorted pair with both axes 96.8%, 0.022%, 0.066% (the left camera's phases
resampled onto the rectified grid average some noise away).
"""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
from conftest import cli_run
from plyfile import PlyData

import bistair
from bistair.app.stereo import simulate_stereo
from bistair.core.jit import set_threads
from bistair.errors import BistairError
from bistair.evaluation.stereo import score_stereo
from bistair.geometry.calibration import Calibration
from bistair.geometry.stereo import rectify, stereo
from bistair.geometry.stereo_calibration import StereoCalibration, save_stereo_calibration
from bistair.io.atomic import write_image
from bistair.sim import Imaging, preset
from bistair.sim.stereo import StereoRig, render_stereo

SIZE = (320, 256)
DIST_L, DIST_R = (-0.08, 0.1, 0.001, -0.0005, 0.0), (-0.06, 0.05, -0.0008, 0.0007, 0.0)


def tilted_rig() -> StereoRig:
    """A pair that is not level: distortion on both cameras, the right one 6 mm higher and
    rolled by 1.5 degrees."""
    return StereoRig.default(camera_size=SIZE, baseline=180, camera_dist=DIST_L,
                             right_dist=DIST_R, right_height=6.0, right_roll_deg=1.5)


def graycode(orientation: str = "columns", **params) -> bistair.spec.BaseSpec:
    return bistair.make_spec("graycode", width=1920, height=1080, period=30, complementary=1,
                             gamma=2.2, orientation=orientation, **params)


def one_line(exc: pytest.ExceptionInfo) -> str:
    assert "\n" not in str(exc.value)
    return str(exc.value)


def test_rectified_rows_are_epipolar_lines():
    rig = tilted_rig()
    cal = StereoCalibration.from_rig(rig)
    rect = rectify(cal)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-120, 120, 200), rng.uniform(-90, 90, 200),
                           rng.uniform(450, 900, 200)])
    lpix, rpix = rig.left.project(pts), rig.right.project(pts)
    lk = np.array([[rect.f, 0, rect.cx_left], [0, rect.f, rect.cy], [0, 0, 1]])
    rk = np.array([[rect.f, 0, rect.cx_right], [0, rect.f, rect.cy], [0, 0, 1]])
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)
    lr = cv2.undistortPoints(lpix.reshape(-1, 1, 2), cal.left.K, cal.left.dist, R=rect.R1,
                             P=lk, criteria=crit).reshape(-1, 2)
    rr = cv2.undistortPoints(rpix.reshape(-1, 1, 2), cal.right.K, cal.right.dist, R=rect.R2,
                             P=rk, criteria=crit).reshape(-1, 2)
    np.testing.assert_allclose(lr[:, 1], rr[:, 1], atol=1e-6)  # same rows
    z_rect = (pts @ rect.R1.T)[:, 2]  # Z = -f tx / d in the rectified frame
    d = (lr[:, 0] - rect.cx_left) - (rr[:, 0] - rect.cx_right)
    np.testing.assert_allclose(-rect.f * rect.tx / d, z_rect, rtol=1e-9)
    low, high = rect.disparities(450.0, 900.0)
    assert (d >= low).all() and (d <= high).all()


@pytest.fixture(scope="module")
def scenes():
    """(rig, spec, left, right, left truth, right truth) of the level and the tilted pair."""
    out = {}
    scene = preset("sphere-on-plane")[1]
    for name, rig, spec in (("level", StereoRig.default(camera_size=SIZE), graycode()),
                            ("tilted", tilted_rig(), graycode("both"))):
        out[name] = (rig, spec, *render_stereo(bistair.encode(spec), rig, scene,
                                               Imaging(seed=4)))
    return out


@pytest.mark.parametrize("name, matched, rms", [("level", 0.97, 0.0006),
                                                ("tilted", 0.96, 0.0005)])
def test_stereo_against_the_truth(scenes, name, matched, rms):
    rig, spec, left, right, lt, rt = scenes[name]
    res = stereo(left, right, spec, StereoCalibration.from_rig(rig))
    s = score_stereo(res, rig, lt, rt)
    assert s["both"] > 40000
    assert s["matched"] >= matched
    assert s["rms"] <= rms and s["p99"] <= 3 * rms
    assert s["wrong"] == 0
    assert res.info["matched_axis"] == "columns"
    assert res.depth.shape == res.mask.shape == SIZE[::-1]
    assert res.points.shape == (*SIZE[::-1], 3) and res.colors.shape == (*SIZE[::-1], 3)
    assert np.isnan(res.depth[~res.mask]).all() and np.isfinite(res.points[res.mask]).all()
    assert res.disparity.shape == tuple(res.rectification.size_left[::-1])
    # points in the left camera's frame, not the rectified one
    err = np.linalg.norm(res.points[res.mask & lt.mask] - lt.points[res.mask & lt.mask], axis=1)
    assert np.median(err) < 0.3


def test_both_cameras_at_once_give_what_one_after_the_other_gives(scenes):
    """The decodes run side by side on two threads (half the kernel threads each) where
    numba allows it; on one thread they run one after the other: the same numbers."""
    rig, spec, left, right, *_ = scenes["tilted"]
    cal = StereoCalibration.from_rig(rig)
    together = stereo(left, right, spec, cal)
    set_threads(1)
    try:
        apart = stereo(left, right, spec, cal)
    finally:
        set_threads(None)
    for a, b in ((together.left, apart.left), (together.right, apart.right)):
        np.testing.assert_array_equal(a.coord_x, b.coord_x)
        np.testing.assert_array_equal(a.coord_y, b.coord_y)
    np.testing.assert_array_equal(together.depth, apart.depth)


def test_depth_range(scenes):
    rig, spec, left, right, lt, _ = scenes["level"]
    cal = StereoCalibration.from_rig(rig)
    whole = stereo(left, right, spec, cal)
    near = stereo(left, right, spec, cal, max_depth=650.0)  # the sphere, not the plane
    assert (near.depth[near.mask] <= 650).all()
    keep = whole.mask & (whole.depth <= 650)
    assert abs(int(near.mask.sum()) - int(keep.sum())) < 0.01 * keep.sum()
    # the search window shrank with the range: the plane's pixels found no match
    assert near.info["unmatched"] > whole.info["unmatched"] + 0.5 * whole.info["matched"]


def test_refusals_of_the_function(scenes):
    rig, spec, left, right, *_ = scenes["level"]
    cal = StereoCalibration.from_rig(rig)
    with pytest.raises(BistairError) as exc:
        stereo(left, right[:-1], spec, cal)
    assert "left and right captures differ: 11 frames of 320x256 and 10 frames" in one_line(exc)
    with pytest.raises(BistairError) as exc:
        stereo(left, right[:, :, :200], spec, cal)
    assert "and 11 frames of 200x256" in one_line(exc)
    small = StereoRig.default(camera_size=(160, 128))
    with pytest.raises(BistairError) as exc:
        stereo(left, right, spec, StereoCalibration.from_rig(small))
    assert "calibration is for 160x128 left images, the left captures are 320x256" in \
        one_line(exc)
    mono = Calibration.from_rig(rig.rig("left"))
    with pytest.raises(BistairError) as exc:
        stereo(left, right, spec, mono)
    assert "a camera-projector calibration was given" in one_line(exc)


def test_a_wrong_calibration_is_refused_with_both_axes(scenes):
    """The projector rows must agree where both axes are decoded: with the right camera
    placed 15 mm too high in the calibration, the rows are not the same epipolar lines and
    almost nothing matches. (With one axis, matching cannot tell: the projector columns
    change little down the image.)"""
    rig, spec, left, right, *_ = scenes["tilted"]
    cal = StereoCalibration.from_rig(rig)
    wrong = cal.replace(T=cal.T + cal.R @ np.array([0.0, -15.0, 0.0]))
    with pytest.raises(BistairError) as exc:
        stereo(left, right, spec, wrong)
    assert "found their match in the right camera: is the calibration for these" in \
        one_line(exc)
    forced = stereo(left, right, spec, wrong, force=True)
    assert forced.info["warnings"] and forced.info["other_axis"] > forced.info["matched"]


def test_the_axis_across_the_baseline_is_refused():
    rig = StereoRig.default(camera_size=(160, 128))
    spec = graycode("rows")
    left, right, _, _ = render_stereo(bistair.encode(spec), rig, preset("plane")[1])
    with pytest.raises(BistairError) as exc:
        stereo(left, right, spec, StereoCalibration.from_rig(rig))
    assert "the projector rows barely change along the cameras' baseline" in one_line(exc)


# -- the command line ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """What ``bistair simulate --cameras 2`` writes for sphere-on-plane at 320 x 256."""
    out = tmp_path_factory.mktemp("stereo") / "sim"
    return simulate_stereo("sphere-on-plane", ["graycode"], out, camera_size=SIZE)


def test_simulate_command(tmp_path, monkeypatch, capfd):
    out = tmp_path / "sim"
    code, stdout, err = cli_run(monkeypatch, capfd, "simulate", "--scene", "plane", "--method",
                                "graycode", "--cameras", "2", "--baseline", "150", "--camera",
                                "64x48", "--out", out)
    assert code == 0, err
    assert stdout == (f"wrote graycode captures of plane from two cameras 150 mm apart (L/, R/), "
                      f"stereo.json and the truth to {out}\n")
    assert json.loads((out / "stereo.json").read_text())["baseline"] == pytest.approx(150)
    code, _, err = cli_run(monkeypatch, capfd, "simulate", "--scene", "plane", "--method",
                           "graycode", "--cameras", "2", "--count", "2", "--out", out / "x")
    assert code == 2 and "--cameras 2 renders one scene: leave out --count" in err


def test_simulate_two_cameras_writes_both_and_the_truth(simulated):
    for side in ("L", "R"):
        assert len(list((simulated / "graycode" / side).glob("*.png"))) == 11
        assert (simulated / "graycode" / side / "spec.json").is_file()
        depth = np.load(simulated / "truth" / side / "depth.npy")
        assert depth.shape == (256, 320) and np.nanmin(depth) > 400
    cal = json.loads((simulated / "stereo.json").read_text())
    assert cal["kind"] == "stereo" and abs(cal["baseline"] - 200) < 1e-9
    assert json.loads((simulated / "scene.json").read_text())["cameras"] == 2


def test_stereo_command(simulated, tmp_path, monkeypatch, capfd):
    out = tmp_path / "res"
    code, stdout, err = cli_run(monkeypatch, capfd, "stereo", simulated / "graycode" / "L",
                                simulated / "graycode" / "R", "--calibration",
                                simulated / "stereo.json", "--out", out)
    assert code == 0, err
    assert err == "" and stdout.startswith("") and f"wrote {out}" in stdout
    assert sorted(p.name for p in out.iterdir()) == [
        "cloud.ply", "depth.npy", "depth.png", "disparity.npy", "info.json", "left", "right"]
    for side in ("left", "right"):
        assert (out / side / "coord.npy").is_file() and (out / side / "phase.png").is_file()
    info = json.loads((out / "info.json").read_text())
    assert info["matched"] > 0.8 * info["left_decoded"] and info["rectified"]["tx"] < 0
    assert f"{info['matched']} points from {info['left_decoded']} decoded left pixels" in stdout
    depth = np.load(out / "depth.npy")
    truth = np.load(simulated / "truth" / "L" / "depth.npy")
    mask = np.load(simulated / "truth" / "L" / "mask.npy")
    ok = np.isfinite(depth) & mask
    assert depth.dtype == np.float32 and ok.sum() > 40000
    assert np.median(np.abs(depth[ok] - truth[ok])) < 0.5
    assert np.load(out / "disparity.npy").dtype == np.float32
    vertex = PlyData.read(str(out / "cloud.ply"))["vertex"]
    assert len(vertex) == int(np.isfinite(depth).sum())
    np.testing.assert_allclose(np.sort(vertex["z"]), np.sort(depth[np.isfinite(depth)]))


def test_batch_of_stereo_sets(simulated, tmp_path, monkeypatch, capfd):
    root = tmp_path / "scans"
    (root / "a").mkdir(parents=True)
    for side in ("L", "R"):
        (root / "a" / side).symlink_to(simulated / "graycode" / side)
    out = tmp_path / "out"
    args = ("batch", root, "--out", out, "--calibration", simulated / "stereo.json",
            "--workers", "1", "-q")
    code, _, err = cli_run(monkeypatch, capfd, *args)
    assert code == 0, err
    rows = (out / "batch.csv").read_text().splitlines()
    assert rows[1].startswith("a,ok,,")
    assert (out / "a" / "cloud.ply").is_file() and (out / "a" / "left" / "coord.npy").is_file()
    code, _, err = cli_run(monkeypatch, capfd, *args, "--resume")
    assert code == 0 and (out / "batch.csv").read_text().splitlines()[1].endswith(",yes")


def test_refusals_of_the_command_line(simulated, tmp_path, monkeypatch, capfd):
    """Each: one line on stderr, exit code 2, its output not created."""
    gray = simulated / "graycode"
    short = tmp_path / "short"  # the right captures, one frame short
    short.mkdir()
    for png in sorted((gray / "R").glob("*.png"))[:-1]:
        (short / png.name).symlink_to(png)
    small = tmp_path / "small"  # the right captures at another size
    small.mkdir()
    for png in sorted((gray / "R").glob("*.png")):
        write_image(small / png.name, cv2.resize(cv2.imread(str(png), 0), (160, 128)))
    mono = simulated / "calibration.json"
    stereo_cal = simulated / "stereo.json"
    spec = gray / "L" / "spec.json"
    cases = [
        (["stereo", gray / "L", short, "--calibration", stereo_cal, "--spec", spec],
         "right: the graycode spec needs 11 frames, the captures have 10"),
        (["stereo", gray / "L", small, "--calibration", stereo_cal, "--spec", spec],
         "left and right captures differ: 11 frames of 320x256 and 11 frames of 160x128"),
        (["stereo", gray / "L", gray / "R", "--calibration", mono],
         "a camera-projector calibration, not a stereo one"),
        (["stereo", gray / "L", gray / "R", "--calibration", stereo_cal, "--depth-range",
          "9:1"], "--depth-range MIN:MAX needs MIN < MAX"),
        (["reconstruct", gray / "L", "--calibration", stereo_cal],
         "a stereo calibration (two cameras: for bistair stereo), not a camera-projector one"),
    ]
    for args, message in cases:
        out = tmp_path / "out"
        ply = ["--out", out.with_suffix(".ply")] if args[0] == "reconstruct" else ["--out", out]
        code, stdout, err = cli_run(monkeypatch, capfd, *args, *ply)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith("Error:"), (args, err)
        assert message in lines[0], (message, lines[0])
        assert stdout == "" and not out.exists() and not out.with_suffix(".ply").exists()
        assert not (tmp_path / "out-depth").exists()


def test_simulate_writes_the_rigs_exact_calibration(simulated, tmp_path):
    rig = StereoRig.default(camera_size=SIZE)
    path = save_stereo_calibration(StereoCalibration.from_rig(rig), tmp_path / "s.json")
    assert json.loads(path.read_text()) == json.loads((simulated / "stereo.json").read_text())
