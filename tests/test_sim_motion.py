"""The virtual rig moves things: sim/motion.py, simulate --motion / --continuous, and the
headline of issue 34 (binomial self-compensation against the renderer's truth)."""

import json

import imageio.v3 as iio
import numpy as np
import pytest
from conftest import cli_run

from bistair.core.motion import window_phases
from bistair.core.phase import TWO_PI, wrap
from bistair.errors import BistairError
from bistair.evaluation.motion import stream_errors
from bistair.sim import Box, Imaging, Plane, Rig, Scene, Sphere, euler, preset, render, trace
from bistair.sim.motion import Motion, moving, parse_motion, render_moving, scene_at

RIG = Rig.default(camera_size=(64, 52))
CLEAN = Imaging(read_noise=0, full_well=0)


def truth_of(scene):
    return trace(RIG, scene, CLEAN, workers=1).truth


def test_a_moved_object_is_the_object_built_at_its_new_pose():
    """Moved wraps a surface: translated and rotated about its centre, it traces as the
    same surface made at that pose (depth, projector coordinate, normals, object id)."""
    box = Box(center=(10, -5, 560), size=(60, 50, 40), rotation=euler(y=25), albedo=0.5)
    wall = Plane(center=(0, 0, 650), size=(900, 800))
    m = parse_motion("2,1,-3mm,0,4,1deg")
    got = truth_of(scene_at(Scene([box, wall]), m, 3))
    rot, shift = m.pose(3, box.center)
    built = Box(center=rot @ box.center + shift, size=(60, 50, 40),
                rotation=rot @ euler(y=25), albedo=0.5)
    want = truth_of(Scene([built, wall]))
    assert np.array_equal(got.object_id, want.object_id) and got.mask.sum() > 500
    for a, b in ((got.depth, want.depth), (got.coord_x, want.coord_x),
                 (got.normals, want.normals)):
        assert np.allclose(a, b, atol=1e-6, equal_nan=True)
    assert not np.allclose(got.depth, truth_of(Scene([box, wall])).depth, equal_nan=True)


def test_the_whole_scene_moves_in_depth_frame_by_frame():
    scene = Scene([Plane(center=(0, 0, 600), size=(700, 600))])
    m = parse_motion("0,0,10mm", whole=True)
    pats = np.full((3, 1080, 1920), 0.5)
    _, truths = render_moving(pats, RIG, scene, m, CLEAN)
    centre = [float(t.depth[26, 32]) for t in truths]
    assert centre == pytest.approx([600.0, 610.0, 620.0], abs=1e-9)
    assert moving(Scene([Sphere(), Plane()])) == [0] and moving(scene) == [0]


def test_a_still_motion_renders_what_a_still_render_gives():
    rig, scene = preset("sphere-on-plane", camera_size=(40, 32))
    pats = np.random.default_rng(1).uniform(0, 1, (4, 1080, 1920))
    still, truth = render(pats, rig, scene, Imaging(seed=3))
    frames, truths = render_moving(pats, rig, scene, Motion(), Imaging(seed=3))
    assert np.array_equal(frames, still)
    assert np.array_equal(truths[2].coord_x, truth.coord_x, equal_nan=True)


def test_a_moving_render_is_deterministic_for_a_seed():
    rig, scene = preset("sphere-on-plane", camera_size=(40, 32))
    pats = np.random.default_rng(1).uniform(0, 1, (3, 1080, 1920))
    m = parse_motion("0.5,0,1mm,0,2,0deg")
    a, _ = render_moving(pats, rig, scene, m, Imaging(seed=3))
    b, _ = render_moving(pats, rig, scene, m, Imaging(seed=3))
    c, _ = render_moving(pats, rig, scene, m, Imaging(seed=4))
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_a_velocity_in_pixels_moves_the_object_that_many_pixels():
    """1 px/frame along the coded axis: a point of the sphere at the median depth of its
    pixels moves 1 camera px per frame (its silhouette, farther, a little less)."""
    rig, scene = preset("sphere-on-plane", camera_size=(128, 104))
    m = parse_motion("1px").at_depth(rig, scene)
    assert m.pixels is None and m.translation[1:] == (0.0, 0.0)
    cols = []
    for t in (0, 4):
        tr = trace(rig, scene_at(scene, m, t), CLEAN).truth
        sphere = tr.object_id == scene.ids[0]
        cols.append(np.nonzero(sphere)[1].mean())
        if t == 0:
            start = tr
    sphere = start.object_id == scene.ids[0]
    median = float(np.median(start.depth[sphere]))
    assert m.translation[0] == pytest.approx(median / rig.camera.fx, rel=1e-9)
    rim = 520.0 - 50.0**2 / 520.0  # the depth of the sphere's silhouette
    assert (cols[1] - cols[0]) / 4 == pytest.approx(median / rim, abs=0.02)
    pixel = np.unravel_index(np.argmin(np.where(sphere, abs(start.depth - median), np.inf)),
                             sphere.shape)
    point = start.points[pixel]
    rot, shift = m.pose(4, scene.surfaces[0].center)
    uv = rig.camera.project(np.array([point, rot @ point + shift]))
    assert (uv[1] - uv[0]) / 4 == pytest.approx([1.0, 0.0], abs=0.01)
    assert parse_motion("1px", "rows").pixels == (0.0, 1.0)


@pytest.mark.parametrize("text", ["", "1", "px", "1 px", "1,2,3px", "1mm", "1,2mm",
                                  "1,2,3mm,1deg", "1,2,3px,0,0,1deg", "nan,0,0mm", "1deg,2mm",
                                  "1,,2,3mm", "inf px", "1e999,0,0mm", "1e-3e2px"])
def test_a_malformed_motion_is_refused_in_one_line(text):
    with pytest.raises(BistairError) as err:
        parse_motion(text)
    assert "\n" not in str(err.value) and "--motion" in str(err.value)


def test_headline_order_four_leaves_under_a_tenth_of_the_ripple_at_one_pixel_per_frame():
    """Issue 34's done-when on a small render: sphere-on-plane at 128x104, period 60 (8 camera
    px), the sphere moving 1 camera px per frame; noise-free so that the ripple is measured
    alone. Plain four-step shows a clear 2x ripple; order 4 at most a tenth of it."""
    rig, scene = preset("sphere-on-plane", camera_size=(128, 104))
    moved = stream_errors(rig, scene, parse_motion("1px"), 60, imaging=CLEAN)
    still = stream_errors(rig, scene, parse_motion("0px"), 60, orders=(0,), imaging=CLEAN)
    assert moved.pixels[4] > 800
    assert moved.ripple[0] > 0.03 and moved.ripple[0] > 4 * still.ripple[0]
    assert moved.ripple[4] <= moved.ripple[0] / 10
    assert moved.ripple[1] < moved.ripple[0] / 2
    assert moved.rms[4] < moved.rms[0]


def test_simulate_motion_writes_every_frame_and_its_truth(tmp_path, monkeypatch, capsys):
    out = tmp_path / "sim"
    code, stdout, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "sphere-on-plane",
                                "--method", "graycode", "--camera", "48x40", "--motion",
                                "2px", "--out", out)
    assert code == 0, err
    assert "objects moving 2px per frame" in stdout
    frames = sorted(p.name for p in (out / "graycode").glob("*.png"))
    truths = sorted(p.name for p in (out / "truth").glob("frame-*"))
    assert len(frames) == len(truths) == 11
    about = json.loads((out / "scene.json").read_text())
    assert about["reference_frame"] == 0 and about["frames"] == 11
    assert about["motion"]["pixels"] == [2.0, 0.0] and about["motion"]["translation_mm"][0] > 0
    first, last = (np.load(out / "truth" / f / "coord.npy") for f in ("frame-0000",
                                                                       "frame-0010"))
    assert np.array_equal(np.load(out / "truth" / "coord.npy"), first, equal_nan=True)
    assert not np.array_equal(first, last, equal_nan=True)


def test_a_continuous_stream_shows_shift_i_mod_4_from_both_cameras(tmp_path, monkeypatch,
                                                                   capsys):
    out = tmp_path / "stream"
    code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                           "multifreq", "--camera", "320x256", "--frames", 6, "--continuous",
                           "--cameras", 2, "--noise", 0, "--out", out)
    assert code == 0, err
    spec = json.loads((out / "multifreq" / "L" / "spec.json").read_text())
    assert spec["periods"] == [30] and spec["steps"] == 4 and spec["method"] == "multifreq"
    for side in ("L", "R"):
        frames = np.stack([iio.imread(out / "multifreq" / side / f"{i:04d}.png")
                           for i in range(6)]).astype(np.float32)
        phi, mod = window_phases(frames, 4)
        truth = np.load(out / "truth" / side / "frame-0003" / "coord.npy")
        mask = np.load(out / "truth" / side / "mask.npy") & (mod[0] > 20)
        assert mask.sum() > 30000
        for s in range(3):  # every window, its shift offset removed, gives the still phase
            assert np.median(np.abs(wrap(phi[s] - TWO_PI * truth / 30))[mask]) < 0.05


@pytest.mark.parametrize("args,message", [
    (["--motion", "3 px"], "is not a motion"),
    (["--frames", "8"], "both --frames N and --continuous"),
    (["--continuous", "--frames", "8"], "--method multifreq alone"),
    (["--motion", "1px", "--count", "2"], "leave out --count"),
])
def test_bad_motion_options_exit_2_in_one_line_and_write_nothing(tmp_path, monkeypatch, capsys,
                                                                 args, message):
    out = tmp_path / "no"
    code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                           "graycode", "--camera", "32x24", *args, "--out", out)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_both_cameras_see_the_same_motion(tmp_path):
    """--cameras 2: at every frame the right camera's truth lies on the sphere where the
    left camera's motion put it (the velocity in pixels converted once, at the left
    camera's depth)."""
    from bistair.app.simulate_motion import simulate_motion

    out = simulate_motion("sphere-on-plane", ["graycode"], tmp_path / "pair", "3px",
                          cameras=2, camera_size=(96, 80))
    about = json.loads((out / "scene.json").read_text())
    step = np.array(about["motion"]["translation_mm"])
    assert step[0] > 0 and about["motion"]["pixels"] == [3.0, 0.0]
    for side, cam in (("L", about["rig"]["left"]), ("R", about["rig"]["right"])):
        k_inv = np.linalg.inv(np.array(cam["K"]))
        rot, t = np.array(cam["R"]), np.array(cam["t"])
        for frame in (0, 5, 10):
            folder = out / "truth" / side / f"frame-{frame:04d}"
            depth = np.load(folder / "depth.npy")
            v, u = np.nonzero(np.load(folder / "object_id.npy") == 1)
            rays = np.stack([u, v, np.ones_like(u)], axis=1) @ k_inv.T
            world = (rays * depth[v, u, None] - t) @ rot  # X = R^T (X_cam - t)
            centre = np.array([0.0, 0.0, 520.0]) + frame * step
            assert len(u) > 200
            assert np.abs(np.linalg.norm(world - centre, axis=1) - 50.0).max() < 1e-6
