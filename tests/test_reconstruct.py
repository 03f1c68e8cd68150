"""Reconstruction: exact triangulation, accuracy of every codec on the virtual rig (with the
rig's true calibration), the rows orientation, the reference-plane height mode, the output
files and every bad-input path.

Field of view: the 640 x 512 camera (f = 1200 px) sees 320 mm x 256 mm at 600 mm; errors
below are also given as fractions of the 320 mm width.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from conftest import cli_run
from plyfile import PlyData

import bistair
from bistair.app.decode import reconstruct_folder
from bistair.errors import BistairError
from bistair.evaluation.metrics import fit_plane, fit_sphere
from bistair.evaluation.views import render_cloud
from bistair.geometry.calibration import Calibration, Device, save_calibration
from bistair.geometry.height import HeightModel
from bistair.geometry.triangulate import reconstruct, triangulate
from bistair.io.writers import write_ply
from bistair.sim import Imaging, Plane, Rig, Scene, Sphere, expose, preset, trace

FOV = 320.0  # mm across the camera's view at the working distance
# the pattern set of each codec on the 1920 x 1080 projector
SPECS = {
    "bidirectional": dict(period=30, partitions=8, stairs=8),
    "multifreq": dict(periods=(1920, 240, 30)),
    "phase-coding": dict(period=30),
    "lv": dict(period=30),
    "graycode": dict(period=30, complementary=1),
}
# measured on sphere-on-plane (sphere r = 50 mm at 520 mm, plane at 700 mm), fits on the
# points within 2 mm of the truth: every codec gives radius within 0.007 mm, centre within
# 0.023 mm (7e-5 of the field of view), plane flatness RMS 0.21 mm (the noise), plane offset
# 0.009 mm, tilt 0.002 deg, median point error 0.12 mm. Share of points off by more than
# 2 mm (wrong fringe orders where the sphere's limb meets the plane):
# bidirectional 0.04%, lv 2.6% (its four-level codes cannot tell the sphere's last fringe
# from the plane's it joins), phase-coding, multifreq and graycode 0
GROSS = {"bidirectional": 0.001, "multifreq": 1e-4, "phase-coding": 1e-4, "lv": 0.04,
         "graycode": 1e-4}


def spec_for(method: str, orientation: str = "columns") -> bistair.spec.BaseSpec:
    return bistair.make_spec(method, width=1920, height=1080, orientation=orientation,
                             white=1, gamma=2.2, **SPECS[method])


def one_line(exc: pytest.ExceptionInfo) -> str:
    assert "\n" not in str(exc.value)
    return str(exc.value)


# -- exactness ------------------------------------------------------------------------------
@pytest.mark.parametrize("orientation", ["columns", "rows"])
def test_triangulation_is_exact_with_distortion(orientation):
    cam = Device(640, 480, [[800.0, 0, 322], [0, 805, 236], [0, 0, 1]],
                 [-0.2, 0.1, 0.001, -0.002, 0.02])
    proj = Device(1280, 800, [[1500.0, 0, 640], [0, 1500, 700], [0, 0, 1]],
                  [0.08, -0.05, 0.002, 0.001, 0])
    tilt = [0.0, 0.3, 0.0] if orientation == "columns" else [-0.3, 0.0, 0.0]
    rot = cv2.Rodrigues(np.array(tilt))[0]
    shift = [150.0, 0, 0] if orientation == "columns" else [0, 150.0, 0]
    cal = Calibration(cam, proj, rot, -rot @ np.array(shift))
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-250, 250, 800), rng.uniform(-250, 250, 800),
                           rng.uniform(450, 750, 800)])
    pix = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), cam.K, cam.dist)[0].reshape(-1, 2)
    ppix = cv2.projectPoints(pts, cv2.Rodrigues(cal.R)[0], cal.T, proj.K, proj.dist)[0]
    ppix = ppix.reshape(-1, 2)
    axis = 0 if orientation == "columns" else 1
    inside = ((ppix >= 0) & (ppix <= np.subtract(proj.size, 1))).all(axis=1)
    got = triangulate(pix, ppix[:, axis], cal, orientation)
    assert inside.sum() > 200
    assert np.abs(got[inside] - pts[inside]).max() < 1e-6
    beside = (ppix[:, 1 - axis] < -0.5) | (ppix[:, 1 - axis] > proj.size[1 - axis] - 0.5)
    assert beside.sum() > 20 and np.isnan(got[beside]).all()  # off the projector image


# -- accuracy of every codec on the virtual rig ------------------------------------------------
@pytest.fixture(scope="module")
def sphere_rig():
    rig, scene = preset("sphere-on-plane", camera_size=(640, 512))
    return rig, trace(rig, scene, Imaging(seed=3))


def test_every_codec_has_a_pattern_set():
    assert set(SPECS) == set(bistair.methods())


@pytest.mark.parametrize("method", sorted(SPECS))
def test_codec_accuracy_on_sphere_and_plane(method, sphere_rig):
    rig, traced = sphere_rig
    truth, spec = traced.truth, spec_for(method)
    result = bistair.decode(expose(traced, bistair.encode(spec)), spec)
    rec = reconstruct(result, Calibration.from_rig(rig), spec)
    ok = rec.mask & truth.mask
    assert ok.sum() > 0.95 * truth.mask.sum()
    err = np.linalg.norm(rec.points - truth.points, axis=2)
    assert np.mean(err[ok] > 2.0) <= GROSS[method]
    assert np.median(err[ok]) < 0.2  # measured 0.12 mm
    # the fits use the points within 2 mm of the truth (the gross errors are counted above)
    good = ok & (err < 2.0)
    centre, radius = fit_sphere(rec.points[good & (truth.object_id == 1)].astype(float))
    assert abs(radius - 50.0) < 0.05
    assert np.linalg.norm(centre - [0, 0, 520]) / FOV < 2e-4  # < 0.064 mm
    pcentre, normal, resid = fit_plane(rec.points[good & (truth.object_id == 2)].astype(float))
    assert np.sqrt(np.mean(resid**2)) < 0.3  # flatness RMS, mm
    assert abs(abs(normal[2]) - 1) < 1.5e-6  # tilt below 0.1 degree
    assert abs(pcentre[2] - 700) < 0.05


def test_rows_on_a_rig_with_a_vertical_baseline():
    rig, scene = preset("sphere-on-plane", camera_size=(320, 256), roll_deg=90)
    traced = trace(rig, Scene([scene.surfaces[0]]), Imaging(seed=4))
    spec = spec_for("graycode", "rows")
    result = bistair.decode(expose(traced, bistair.encode(spec)), spec)
    rec = reconstruct(result, Calibration.from_rig(rig), spec, orientation="rows")
    ok = rec.mask & traced.truth.mask
    err = np.linalg.norm(rec.points[ok] - traced.truth.points[ok], axis=1)
    centre, radius = fit_sphere(rec.points[ok].astype(float))
    # measured: radius +0.06 mm, centre 0.12 mm, point error median 0.07 mm and max 0.9 mm;
    # the same as columns on the unrolled rig at this 320 x 256 resolution
    assert abs(radius - 50) < 0.2 and np.linalg.norm(centre - [0, 0, 520]) < 0.3
    assert np.median(err) < 0.2 and err.max() < 2


def test_a_coded_axis_across_the_baseline_is_refused():
    rig, scene = preset("sphere-on-plane", camera_size=(320, 256))
    traced = trace(rig, Scene([scene.surfaces[0]]), Imaging(seed=4))
    spec = spec_for("graycode", "rows")
    result = bistair.decode(expose(traced, bistair.encode(spec)), spec)
    with pytest.raises(BistairError) as exc:
        reconstruct(result, Calibration.from_rig(rig), spec)
    assert one_line(exc).startswith("projector rows barely change with depth in this rig")


def test_reference_plane_height_mode():
    rig = Rig.default(camera_size=(320, 256), projector_size=(960, 540), projector_focal=1000)
    spec = bistair.make_spec("graycode", width=960, height=540, period=15, complementary=1,
                             gamma=2.2)
    patterns = bistair.encode(spec)

    def measure(*surfaces):
        traced = trace(rig, Scene(list(surfaces)), Imaging(seed=len(surfaces)))
        return bistair.decode(expose(traced, patterns), spec).coord, traced.truth

    def wall(z):
        return Plane(center=(0, 0, z), size=(500, 400), albedo=0.7)

    reference = measure(wall(600))[0]
    planes = [measure(wall(600 - h))[0] for h in (-20.0, 20.0, 40.0)]
    model = HeightModel.fit(reference, planes, [-20.0, 20.0, 40.0])
    coord, truth = measure(Sphere(center=(0, 0, 590), radius=40, albedo=0.8), wall(600))
    height = model.height(coord)
    sphere = truth.mask & (truth.object_id == 1) & np.isfinite(height)
    err = height[sphere] - (600 - truth.depth[sphere])
    # measured: median |error| 0.18 mm, 99th percentile 0.70 mm, mean -0.03 mm over heights
    # of 0-30 mm (triangulation with the true calibration: 0.12 mm and 0.64 mm; the model
    # adds the noise of the reference and plane phases)
    assert sphere.sum() > 3000
    assert np.median(np.abs(err)) < 0.3 and np.percentile(np.abs(err), 99) < 1.2
    assert abs(err.mean()) < 0.1


# -- files -----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def small_capture(tmp_path_factory):
    """A small sphere capture (.npy + spec.json) and its rig's calibration file."""
    rig, scene = preset("sphere-on-plane", camera_size=(160, 128))
    root = tmp_path_factory.mktemp("recon")
    traced = trace(rig, scene, Imaging(seed=5))
    spec = spec_for("multifreq")
    np.save(root / "caps.npy", expose(traced, bistair.encode(spec)))
    (root / "spec.json").write_text(spec.to_json())
    save_calibration(Calibration.from_rig(rig), root / "calib.json")
    return root, rig


def test_ply_depth_and_view_files(small_capture, tmp_path):
    root, _ = small_capture
    rec = reconstruct_folder(root / "caps.npy", None, root / "calib.json",
                             tmp_path / "cloud.ply", depth_dir=tmp_path / "depth")
    pts, cols = rec.cloud()
    ply = PlyData.read(str(tmp_path / "cloud.ply"))
    vertex = ply["vertex"]
    assert ply.text is False and ply.byte_order == "<"
    assert len(vertex) == rec.mask.sum() == len(pts) > 10000
    assert [p.name for p in vertex.properties] == ["x", "y", "z", "red", "green", "blue"]
    assert vertex["x"].dtype == np.float32 and vertex["red"].dtype == np.uint8
    assert np.array_equal(vertex["z"], pts[:, 2]) and np.array_equal(vertex["green"], cols[:, 1])
    assert cols.max() > 100  # colours from the white frame
    depth = np.load(tmp_path / "depth" / "depth.npy")
    assert depth.dtype == np.float32 and np.array_equal(np.isfinite(depth), rec.mask)
    assert (tmp_path / "depth" / "depth.png").stat().st_size > 1000
    view = render_cloud(pts, cols, tmp_path / "view.png", size=(320, 240), title="sphere")
    assert view.shape == (240, 320, 3) and view.any()
    assert (tmp_path / "view.png").stat().st_size > 1000
    write_ply(tmp_path / "empty.ply", np.zeros((0, 3)))
    assert len(PlyData.read(str(tmp_path / "empty.ply"))["vertex"]) == 0


def test_bad_inputs_leave_nothing_behind(small_capture, tmp_path):
    root, rig = small_capture
    out, depth = tmp_path / "cloud.ply", tmp_path / "depth"
    big = Calibration.from_rig(preset("sphere-on-plane", camera_size=(1280, 1024))[0])
    save_calibration(big, tmp_path / "big.json")
    (tmp_path / "broken.json").write_text('{"format": "bistair-calibration", "version": 1,')
    cases = {
        "big.json": "calibration is for 1280x1024 camera images, captures are 160x128",
        "broken.json": "is not valid JSON",
        "missing.json": "not found",
    }
    for name, message in cases.items():
        with pytest.raises(BistairError) as exc:
            reconstruct_folder(root / "caps.npy", None, tmp_path / name, out, depth)
        assert message in one_line(exc)
    with pytest.raises(BistairError) as exc:
        reconstruct_folder(root / "caps.npy", None, root / "calib.json", out, depth,
                           orientation="rows")
    assert one_line(exc) == "the spec codes columns, but rows were asked for"
    other = spec_for("multifreq").replace(width=1280, height=800, periods=(1280, 160, 20))
    with pytest.raises(BistairError) as exc:
        reconstruct_folder(root / "caps.npy", other, root / "calib.json", out, depth)
    assert one_line(exc) == ("calibration is for a 1920x1080 projector, the spec for "
                             "1280x800")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.json", "broken.json"]


# -- depth range ------------------------------------------------------------------------------
def test_depth_range_keeps_the_sphere_and_drops_the_plane(small_capture, tmp_path, monkeypatch,
                                                          capsys):
    root, rig = small_capture
    truth = trace(rig, preset("sphere-on-plane", camera_size=(160, 128))[1],
                  Imaging(seed=5)).truth  # the scene of small_capture
    full = reconstruct_folder(root / "caps.npy", None, root / "calib.json",
                              tmp_path / "full.ply")
    out, depth = tmp_path / "near.ply", tmp_path / "near-depth"
    code, stdout, err = cli_run(monkeypatch, capsys, "reconstruct", root / "caps.npy",
                                "--calibration", root / "calib.json", "--out", out,
                                "--depth", depth, "--depth-range", "400:650")
    assert code == 0, err
    near = np.load(depth / "depth.npy")
    sphere, plane = truth.mask & (truth.object_id == 1), truth.mask & (truth.object_id == 2)
    # the sphere spans z 470-570 mm, the plane sits at 700 mm
    assert np.isfinite(near).sum() > 0.95 * sphere.sum()
    assert not np.isfinite(near[plane]).any()
    with np.errstate(invalid="ignore"):
        inside = (full.depth >= 400) & (full.depth <= 650)
    assert np.array_equal(np.isfinite(near), inside)
    assert np.array_equal(near[inside], full.depth[inside])
    assert len(PlyData.read(str(out))["vertex"]) == inside.sum()
    dropped = int(full.mask.sum() - inside.sum())
    assert f"{inside.sum()} points ({dropped} outside the depth range)" in stdout
    code, stdout, err = cli_run(monkeypatch, capsys, "reconstruct", root / "caps.npy",
                                "--calibration", root / "calib.json", "--out", out,
                                "--depth", depth, "--depth-range", "680:inf")
    assert code == 0, err
    far = np.load(depth / "depth.npy")
    assert np.isfinite(far[plane]).mean() > 0.95 and not np.isfinite(far[sphere]).any()


@pytest.mark.parametrize("value, message", [
    ("650:400", "--depth-range MIN:MAX needs MIN < MAX, got 650:400"),
    ("500:500", "--depth-range MIN:MAX needs MIN < MAX, got 500:500"),
    ("-5:800", "--depth-range MIN must be a depth of 0 mm or more, got -5:800"),
    ("near:far", "--depth-range must be MIN:MAX in mm, e.g. 400:800, got 'near:far'"),
    ("400", "--depth-range must be MIN:MAX in mm, e.g. 400:800, got '400'"),
    ("400:800:900", "--depth-range must be MIN:MAX in mm"),
    ("nan:800", "--depth-range MIN:MAX needs MIN < MAX, got nan:800"),
])
def test_bad_depth_range_is_one_line(small_capture, tmp_path, monkeypatch, capsys, value,
                                     message):
    root, _ = small_capture
    code, stdout, err = cli_run(monkeypatch, capsys, "reconstruct", root / "caps.npy",
                                "--calibration", root / "calib.json",
                                "--out", tmp_path / "c.ply", f"--depth-range={value}")
    assert code == 2 and stdout == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"Error: {message}")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(BistairError) as exc:
        reconstruct_folder(root / "caps.npy", None, root / "calib.json", tmp_path / "c.ply",
                           min_depth=700.0, max_depth=600.0)
    assert one_line(exc) == "the depth range needs 0 <= min_depth < max_depth, got 700.0:600.0"
