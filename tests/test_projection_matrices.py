"""import-calibration --projection-matrices: three 3x4 matrices of one world frame to a
calibration of two cameras and the projector in the left camera's frame."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.io
from click.testing import CliRunner

from bistair.app.cli import cli
from bistair.errors import BistairError
from bistair.geometry.projection_matrices import decompose, read_matrix, rig_from_matrices
from bistair.geometry.stereo_calibration import StereoCalibration, load_stereo_calibration
from bistair.sim.stereo import StereoRig

# a world frame that is not the left camera's: turned 20 degrees about z, then moved
_TURN = np.array([[np.cos(0.35), -np.sin(0.35), 0], [np.sin(0.35), np.cos(0.35), 0], [0, 0, 1]])
_SHIFT = np.array([30.0, -40.0, 250.0])


def _matrices(srig: StereoRig, scale: tuple[float, float, float] = (1.0, -2.5, 0.01)
              ) -> list[np.ndarray]:
    """The rig's projection matrices in the world frame ``X_left = _TURN @ X_w + _SHIFT``,
    each multiplied by a scale (a negative one too: a matrix is known up to scale)."""
    out = []
    for dev, s in zip((srig.left, srig.right, srig.projector), scale, strict=True):
        R, t = dev.R @ _TURN, dev.R @ _SHIFT + dev.t
        out.append(s * dev.K @ np.hstack([R, t[:, None]]))
    return out


#: 0-based camera pixels to MATLAB's 1-based ones: (u + 1, v + 1)
_ONE_BASED = np.array([[1.0, 0, 1], [0, 1, 1], [0, 0, 1]])


def _write(folder, matrices, kind):
    paths = []
    if kind == "mat":  # MATLAB's cameras number pixels from 1; the projector's column is kept
        matrices = [_ONE_BASED @ P for P in matrices[:2]] + [matrices[2]]
    for name, P in zip(("left", "right", "projector"), matrices, strict=True):
        path = folder / f"{name}.{kind}"
        if kind == "npy":
            np.save(path, P)
        elif kind == "txt":
            sep = ", " if name == "right" else " "
            path.write_text("# P = K [R | t]\n" + "\n".join(sep.join(f"{v:.17g}" for v in row)
                                                         for row in P) + "\n")
        else:
            scipy.io.savemat(path, {"P": P, "note": np.zeros((1, 3))})
        paths.append(path)
    return paths


def _same(cal: StereoCalibration, truth: StereoCalibration) -> None:
    for got, want in ((cal.left, truth.left), (cal.right, truth.right),
                      (cal.projector.device, truth.projector.device)):
        assert got.size == want.size
        np.testing.assert_allclose(got.K, want.K, atol=1e-6)
        assert not got.dist.any()
    np.testing.assert_allclose(cal.R, truth.R, atol=1e-9)
    np.testing.assert_allclose(cal.T, truth.T, atol=1e-6)
    np.testing.assert_allclose(cal.projector.R, truth.projector.R, atol=1e-9)
    np.testing.assert_allclose(cal.projector.T, truth.projector.T, atol=1e-6)


@pytest.mark.parametrize("kind", ["npy", "txt", "mat"])
def test_matrices_round_trip_to_the_rig(tmp_path, kind):
    """The virtual rig's matrices (another world frame, scaled, one negated; 1-based camera
    pixels in the .mat files, as MATLAB's) come back as its exact calibration, through each
    file format and the command, which says and records the pixel origin."""
    srig = StereoRig.default(camera_size=(640, 480), projector_size=(1280, 800),
                             projector_at=0.3, right_height=5.0, right_roll_deg=1.0)
    truth = StereoCalibration.from_rig(srig)
    paths = _write(tmp_path, _matrices(srig), kind)
    out = tmp_path / "rig.json"
    res = CliRunner().invoke(cli, ["import-calibration", "--projection-matrices",
                                   ",".join(map(str, paths)), "--camera-size", "640x480",
                                   "--projector-size", "1280x800", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "baseline 200.06 mm" in res.output
    origin = int(kind == "mat")
    assert f"(pixel origin {origin})" in res.output
    _same(load_stereo_calibration(out), truth)
    data = json.loads(out.read_text())
    assert data["projector"]["width"] == 1280 and data["pixel_origin"] == origin


def test_pixel_origin_moves_the_cameras_principal_points(tmp_path):
    """--pixel-origin overrides the default: MATLAB's 1-based matrices read 0-based keep
    their principal points one pixel off (the projector's never moves); 0-based .npy
    matrices read 1-based lose one."""
    srig = StereoRig.default(camera_size=(640, 480), projector_size=(1280, 800))
    truth = StereoCalibration.from_rig(srig)
    mats = _write(tmp_path, _matrices(srig), "mat")
    npys = _write(tmp_path, _matrices(srig), "npy")
    for paths, origin, offset in ((mats, 0, 1.0), (npys, 1, -1.0), (npys, 0, 0.0)):
        out = tmp_path / "rig.json"
        res = CliRunner().invoke(cli, ["import-calibration", "--projection-matrices",
                                       ",".join(map(str, paths)), "--camera-size", "640x480",
                                       "--projector-size", "1280x800", "--pixel-origin",
                                       str(origin), "--out", str(out)])
        assert res.exit_code == 0 and f"(pixel origin {origin})" in res.output, res.output
        cal = load_stereo_calibration(out)
        for got, want in ((cal.left, truth.left), (cal.right, truth.right)):
            np.testing.assert_allclose(got.K[:2, 2], want.K[:2, 2] + offset, atol=1e-6)
        np.testing.assert_allclose(cal.projector.device.K, truth.projector.device.K,
                                   atol=1e-6)
        assert json.loads(out.read_text())["pixel_origin"] == origin
    mixed = [mats[0], npys[1], npys[2]]
    res = CliRunner().invoke(cli, ["import-calibration", "--projection-matrices",
                                   ",".join(map(str, mixed)), "--camera-size", "640x480",
                                   "--projector-size", "1280x800", "--out",
                                   str(tmp_path / "mixed.json")])
    assert res.exit_code == 2 and "give --pixel-origin" in res.output


def test_decompose_gives_a_proper_rotation_and_positive_focals():
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        q *= np.sign(np.linalg.det(q))
        K = np.array([[rng.uniform(500, 3000), rng.uniform(-2, 2), rng.uniform(0, 1000)],
                      [0, rng.uniform(500, 3000), rng.uniform(0, 1000)], [0, 0, 1]])
        t = rng.normal(size=3) * 100
        s = rng.choice([-1.0, 1.0]) * rng.uniform(0.01, 100)
        k, r, tt = decompose(s * K @ np.hstack([q, t[:, None]]))
        np.testing.assert_allclose(k, K, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(r, q, atol=1e-9)
        np.testing.assert_allclose(tt, t, atol=1e-7)
        assert np.linalg.det(r) == pytest.approx(1.0)


def test_bad_matrices_are_refused_in_one_line(tmp_path):
    srig = StereoRig.default(camera_size=(64, 48), projector_size=(128, 80))
    good = _write(tmp_path, _matrices(srig), "npy")
    bad = tmp_path / "bad.npy"
    np.save(bad, np.ones((3, 3)))
    low = tmp_path / "low.npy"
    np.save(low, np.hstack([np.ones((3, 3)), np.zeros((3, 1))]))
    junk = tmp_path / "junk.txt"
    junk.write_text("1 2 x\n")
    two = tmp_path / "two.mat"
    scipy.io.savemat(two, {"A": np.eye(3, 4), "B": np.eye(3, 4)})
    none = tmp_path / "none.mat"
    scipy.io.savemat(none, {"A": np.eye(3)})
    cases = [([bad, good[1], good[2]], "a 3x4 matrix is needed, got 3x3"),
             ([good[0], low, good[2]], "has rank 1"),
             ([good[0], good[1], junk], "cannot be read"),
             ([two, good[1], good[2]], "exactly one 3x4 array, it holds 2 (A, B)"),
             ([none, good[1], good[2]], "it holds 0 (none)"),
             ([good[0], good[1]], "three files, got 2"),
             ([good[1], good[0], good[2]], "to the left of the left one")]
    for files, want in cases:
        out = tmp_path / "rig.json"
        res = CliRunner().invoke(cli, ["import-calibration", "--projection-matrices",
                                       ",".join(map(str, files)), "--camera-size", "64x48",
                                       "--projector-size", "128x80", "--out", str(out)])
        assert res.exit_code == 2 and want in res.output, (want, res.output)
        assert len(res.output.strip().splitlines()) == 1 and not out.exists()
    res = CliRunner().invoke(cli, ["import-calibration", "--projection-matrices",
                                   ",".join(map(str, good)), "--camera-size", "64x48",
                                   "--out", str(tmp_path / "rig.json")])
    assert res.exit_code == 2 and "needs --projector-size" in res.output
    with pytest.raises(BistairError, match="no such file"):
        read_matrix(tmp_path / "missing.npy")


def test_rig_frame_is_the_left_camera():
    K = np.array([[1000.0, 0, 319.5], [0, 1000, 239.5], [0, 0, 1]])
    P = [K @ np.hstack([np.eye(3), [[x], [0], [0]]]) for x in (50.0, -150.0, -50.0)]
    cal = rig_from_matrices(P, (640, 480), (640, 480))
    assert np.allclose(cal.R, np.eye(3)) and cal.baseline == pytest.approx(200.0)
    # the point (0, 0, 500) of the left camera's frame lies at the projector's column
    u = cal.projector.project(np.array([[0.0, 0.0, 500.0]]))[0, 0]
    assert u == pytest.approx(319.5 - 1000 * 100 / 500)
