"""Stereo calibrations: ``bistair import-calibration --stereo`` (OpenCV FileStorage YAML and
XML from a known calibration come back exactly; renamed keys, two files merged, sizes from
the files; wrong keys, missing sizes and other bad input are one line, exit code 2, nothing
written) and ``bistair calibrate-stereo`` on board pairs rendered by the two-camera virtual
rig, against the rig's truth (:func:`check_against_truth`: focal lengths, principal points,
rotation, T).
"""

from __future__ import annotations

import json
import shutil

import cv2
import numpy as np
import pytest
from conftest import cli_run

import bistair
from bistair.errors import BistairError
from bistair.geometry.board import Board, parse_board
from bistair.geometry.calibrate import calibrate_stereo_images
from bistair.geometry.calibration import (
    Calibration,
    StereoCalibration,
    load_calibration,
    load_stereo_calibration,
    save_calibration,
    save_stereo_calibration,
)
from bistair.geometry.opencv import _example_stereo
from bistair.io.read import read_image
from bistair.sim.stereo import StereoRig, write_board_pairs

KEYS = ("M1", "D1", "M2", "D2", "R", "T")


def write_fs(path, items: dict):
    """Write ``items`` with cv2.FileStorage (format from the suffix); a list is written as a
    sequence, a scalar as a scalar, the rest as a matrix."""
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    for key, value in items.items():
        if isinstance(value, list):
            fs.startWriteStruct(key, cv2.FileNode_SEQ | cv2.FileNode_FLOW)
            for v in value:
                fs.write("", v)
            fs.endWriteStruct()
        elif isinstance(value, int | str):
            fs.write(key, value)
        else:
            fs.write(key, np.asarray(value, float))
    fs.release()
    return path


def items(cal: StereoCalibration, names=KEYS) -> dict:
    values = (cal.left.K, cal.left.dist[None, :], cal.right.K, cal.right.dist[None, :], cal.R,
              cal.T[:, None])
    return dict(zip(names, values, strict=True))


def assert_same(got: StereoCalibration, want: StereoCalibration, tol: float = 1e-12) -> None:
    assert got.left.size == want.left.size and got.right.size == want.right.size
    for a, b in ((got.left.K, want.left.K), (got.left.dist, want.left.dist),
                 (got.right.K, want.right.K), (got.right.dist, want.right.dist),
                 (got.R, want.R), (got.T, want.T)):
        assert np.abs(a - b).max() <= tol


def run(monkeypatch, capfd, *args):
    return cli_run(monkeypatch, capfd, "import-calibration", "--stereo", *args)


@pytest.mark.parametrize("suffix", [".yml", ".xml"])
def test_import_round_trip(suffix, tmp_path, monkeypatch, capfd):
    cal = _example_stereo()
    src = write_fs(tmp_path / f"stereo{suffix}", {**items(cal), "imageSize": [1280, 1024]})
    out = tmp_path / "stereo.json"
    code, stdout, err = run(monkeypatch, capfd, src, "--out", out)
    assert code == 0, err
    assert err == "" and stdout == f"cameras 1280x1024, baseline 150.00 mm; wrote {out}\n"
    got = load_stereo_calibration(out)
    assert_same(got, cal)
    assert json.loads(out.read_text())["kind"] == "stereo"


def test_import_renamed_keys_in_two_files(tmp_path, monkeypatch, capfd):
    """Another tool's names: camera matrices and distortion in one file, the pose in
    another, the size given on the command line."""
    cal = _example_stereo()
    names = ("cameraMatrixL", "distCoeffsL", "cameraMatrixR", "distCoeffsR", "Rot", "Trns")
    both = items(cal, names)
    intr = write_fs(tmp_path / "intrinsics.yml", {k: both[k] for k in names[:4]})
    extr = write_fs(tmp_path / "extrinsics.xml", {k: both[k] for k in names[4:]})
    out = tmp_path / "s.json"
    keys = ("left=cameraMatrixL,left_dist=distCoeffsL,right=cameraMatrixR,"
            "right_dist=distCoeffsR,R=Rot,T=Trns")
    code, _, err = run(monkeypatch, capfd, intr, extr, "--out", out, "--keys", keys,
                       "--camera-size", "1280x1024")
    assert code == 0, err
    assert_same(load_stereo_calibration(out), cal)


def test_import_refusals(tmp_path, monkeypatch, capfd):
    cal = _example_stereo()
    good = write_fs(tmp_path / "good.yml", items(cal))
    sized = write_fs(tmp_path / "sized.yml", {**items(cal), "image_size": [1280, 1024]})
    metres = write_fs(tmp_path / "metres.yml", {**items(cal), "image_size": [1280, 1024]})
    cases = {
        "missing size": ([good], "no camera size in"),
        "wrong key": ([sized, "--keys", "left=K1"],
                      "no key 'K1' (left camera matrix) in "),
        "unknown part": ([sized, "--keys", "camera=M1"], "unknown part 'camera' in the keys"),
        "bad keys": ([sized, "--keys", "left"], "--keys must be NAME=KEY items"),
        "bad size": ([good, "--camera-size", "1280"], "--camera-size must be WIDTHxHEIGHT"),
        "projector": ([sized, "--projector-size", "1920x1080"],
                      "--projector-size does not apply to a stereo calibration"),
        "no file": ([tmp_path / "none.yml"], "calibration file"),
    }
    for name, (args, message) in cases.items():
        out = tmp_path / f"{name}.json"
        code, stdout, err = run(monkeypatch, capfd, *args, "--out", out)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith("Error:"), (name, err)
        assert message in lines[0], (name, lines[0])
        assert stdout == "" and not out.exists(), name
    assert "rename it with --keys left=KEY" in run(monkeypatch, capfd, sized, "--keys",
                                                   "left=K1", "--out", tmp_path / "x")[2]
    # without --stereo it is a camera and a projector, whose size the files lack
    code, _, err = cli_run(monkeypatch, capfd, "import-calibration", sized, "--out",
                           tmp_path / "m.json")
    assert code == 2 and "no projector size in" in err and not (tmp_path / "m.json").exists()
    # a baseline of 5 mm (cameras can sit so close; or T in metres of a 5 m rig): imported,
    # with a warning naming the unit
    write_fs(metres, {**items(cal), "T": cal.T[:, None] / 30, "image_size": [1280, 1024]})
    code, stdout, err = run(monkeypatch, capfd, metres, "--out", tmp_path / "metres.json")
    assert code == 0 and "baseline 5.00 mm" in stdout and "T must be in millimetres" in err


@pytest.mark.parametrize("change, message", [
    (lambda c: {"T": np.zeros((3, 1))}, "T = [0, 0, 0]: the two cameras would be at one place"),
    (lambda c: {"T": c.T[:, None] / 1000}, "the cameras would be 0.15 mm apart (T = [-0.146, "
                                           "0.001, 0.036]): T must be in millimetres (in "
                                           "metres, this is a 150 mm baseline)"),
    (lambda c: {"R": c.R.T, "T": (-c.R.T @ c.T)[:, None]},
     "the right camera (M2) sits 145.7 mm to the left of the left one (M1; T's x is +150.0 mm, "
     "negative for a left camera first): is M1 the right camera, or are R, T inverted (right "
     "to left)?")])
def test_import_refuses_a_pair_no_reconstruction_should_use(change, message, tmp_path,
                                                            monkeypatch, capfd):
    """QA I07 (T = 0: imported, then a cv2 traceback in stereo), T in metres (depths of
    0.6 mm) and R, T of the right camera to the left one (a wrong cloud): refused at the
    import, nothing written."""
    cal = _example_stereo()
    path = write_fs(tmp_path / "c.yml", {**items(cal), **change(cal),
                                         "image_size": [1280, 1024]})
    out = tmp_path / "c.json"
    code, stdout, err = run(monkeypatch, capfd, path, "--out", out)
    assert code == 2 and stdout == "" and not out.exists()
    assert err.startswith(f"Error: {path}: {message}") and err.count("\n") == 1


# -- calibrate-stereo on rendered board pairs -----------------------------------------------
RIG = StereoRig.default(camera_size=(640, 512), baseline=200)


@pytest.fixture(scope="module")
def boards(tmp_path_factory):
    """Board pairs in eight poses (``pose-NN/left.png``, ``right.png``, ``board.json``)."""
    return write_board_pairs(RIG, Board("checkerboard", 9, 6, 20.0),
                             tmp_path_factory.mktemp("boards") / "poses")


def check_against_truth(cal: StereoCalibration) -> None:
    """The calibration against the rig's truth. Measured at 640 x 512 (8 poses; 7 with
    pose-03 left out): focal lengths within 0.046% (0.084%), principal points within 1.8 px
    (1.0 px), |T| -0.078% (-0.014%), T within 0.32 mm (0.29 mm) of the truth's, rotation
    0.058 deg (0.032 deg), stereo RMS 0.08 px (0.07 px)."""
    truth = StereoCalibration.from_rig(RIG)
    for got, want in ((cal.left, truth.left), (cal.right, truth.right)):
        for i in (0, 1):
            assert abs(got.K[i, i] / want.K[i, i] - 1) < 0.0015
        assert np.abs(got.K[:2, 2] - want.K[:2, 2]).max() < 2.5
    assert abs(cal.baseline / truth.baseline - 1) < 0.0015
    assert np.linalg.norm(cal.T - truth.T) < 0.6
    assert np.rad2deg(np.linalg.norm(cv2.Rodrigues(cal.R @ truth.R.T)[0])) < 0.15
    assert cal.rms < 0.15


def test_calibrate_stereo_command(boards, tmp_path, monkeypatch, capfd):
    out = tmp_path / "stereo.json"
    code, stdout, err = cli_run(monkeypatch, capfd, "calibrate-stereo", boards, "--board",
                                "chessboard:9x6:20", "--out", out)
    assert code == 0, err
    cal = load_stereo_calibration(out)
    check_against_truth(cal)
    lines = stdout.splitlines()
    assert lines[0].startswith("stereo RMS ") and "8 of 8 poses; wrote" in lines[0]
    assert lines[1].startswith("  left:   fx ") and lines[2].startswith("  right:  fx ")
    assert len(lines) == 3 + 8 and lines[3].startswith("  pose-00: 54 corners, left ")
    assert cal.uncertainty is not None and cal.uncertainty.baseline > 0
    assert json.loads(out.read_text())["poses"][0]["left_rms"] < 0.3


def test_left_right_folders_and_skipped_poses(boards, tmp_path, monkeypatch, capfd):
    """The other layout (left/, right/ of pairs); a pose whose right image shows no board is
    skipped with a warning; board.json is the default board."""
    root = tmp_path / "pairs"
    for side in ("left", "right"):
        (root / side).mkdir(parents=True)
        for pose in sorted(p for p in boards.iterdir() if p.is_dir()):
            shutil.copy(pose / f"{side}.png", root / side / f"{pose.name}.png")
    shutil.copy(boards / "board.json", root / "board.json")
    blank = np.full((512, 640), 128, np.uint8)
    cv2.imwrite(str(root / "right" / "pose-03.png"), blank)
    out = tmp_path / "stereo.json"
    code, stdout, err = cli_run(monkeypatch, capfd, "calibrate-stereo", root, "--out", out)
    assert code == 0, err
    assert err.strip() == ("Warning: pose pose-03 skipped: the board is not found in both "
                           "images")
    assert "7 of 8 poses" in stdout
    check_against_truth(load_stereo_calibration(out))


def test_calibrate_stereo_refusals(boards, tmp_path, monkeypatch, capfd):
    few = tmp_path / "few"
    for pose in ("pose-00", "pose-01"):
        shutil.copytree(boards / pose, few / pose)
    odd = tmp_path / "odd"
    shutil.copytree(boards / "pose-00", odd / "pose-00")
    shutil.copy(boards / "pose-01" / "left.png", odd / "pose-00" / "extra.png")
    cases = [
        ([few, "--board", "chessboard:9x6:20"], "board found in both images of 2 of 2 poses, "
                                                "need at least 3"),
        ([boards, "--board", "chessboard:9x6"], "a board is TYPE:COLUMNSxROWS:SPACING (e.g. "
                                                "chessboard:9x7:25"),
        ([boards, "--board", "chessboard:9x6:inf"], "board spacing must be a positive number "
                                                    "of mm, got inf"),  # not OpenCV's error
        ([boards, "--board", "chessboard:9x6:20", "--min-poses", "2"],
         "min_poses 2 is too few: a stereo calibration needs at least 3 board poses"),
        ([odd, "--board", "chessboard:9x6:20"], "pose pose-00 holds 3 images: one left and one "
                                                "right image are needed"),
        ([tmp_path / "none", "--board", "chessboard:9x6:20"], "not found"),
    ]
    for args, message in cases:
        out = tmp_path / "out.json"
        code, stdout, err = cli_run(monkeypatch, capfd, "calibrate-stereo", *args, "--out", out)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and lines[0].startswith("Error:"), (args, err)
        assert message in lines[0], (message, lines[0])
        assert not out.exists()


def test_board_images_named_the_wrong_way_round_are_refused(boards, tmp_path, monkeypatch,
                                                            capfd):
    """QA C30: the board images named the wrong way round give R, T of the right camera to
    the left one (T = (+199.9, 0.08, 0.03)), which put every point 98% wrong: refused with
    the hint, nothing written."""
    swapped = tmp_path / "swapped"
    for pose in sorted(p for p in boards.iterdir() if p.is_dir()):
        (swapped / pose.name).mkdir(parents=True)
        shutil.copy(pose / "left.png", swapped / pose.name / "right.png")
        shutil.copy(pose / "right.png", swapped / pose.name / "left.png")
    out = tmp_path / "sw.json"
    code, stdout, err = cli_run(monkeypatch, capfd, "calibrate-stereo", swapped, "--board",
                                "chessboard:9x6:20", "--out", out)
    assert code == 2 and stdout == "" and not out.exists()
    assert err.startswith("Error: the camera of the right images sits 189.") and \
        err.endswith(" mm to the left of the other (the right camera is the one at +x of the "
                     "left, to the right in its image): are the board images named the wrong "
                     "way round? Exchange left and right\n")


def test_calibration_from_images_in_memory(boards):
    poses = sorted(p for p in boards.iterdir() if p.is_dir())
    left = [read_image(p / "left.png") for p in poses]
    right = [read_image(p / "right.png") for p in poses]
    cal, skipped = calibrate_stereo_images(left, right, parse_board("checkerboard:9x6:20"))
    assert skipped == [] and cal.poses_total == 8 and cal.board["columns"] == 9
    check_against_truth(cal)
    with pytest.raises(BistairError, match="3 left and 2 right images"):
        calibrate_stereo_images(left[:3], right[:2], Board())
    with pytest.raises(BistairError, match="the right image is 320x256, the right image of"):
        calibrate_stereo_images(left[:3], [*right[:2], right[2][::2, ::2]], Board())


def test_the_two_kinds_of_calibration_file(tmp_path):
    """A camera-projector file reads as before (no kind, or "kind": "camera-projector");
    each reader refuses the other kind with one line."""
    pair = _example_stereo()
    mono = save_calibration(Calibration(pair.left, pair.right, pair.R, pair.T),
                            tmp_path / "mono.json")
    data = json.loads(mono.read_text())
    assert "kind" not in data and load_calibration(mono).baseline == pytest.approx(150)
    (tmp_path / "kind.json").write_text(json.dumps({**data, "kind": "camera-projector"}))
    assert load_calibration(tmp_path / "kind.json").baseline == pytest.approx(150)
    stereo = save_stereo_calibration(pair, tmp_path / "stereo.json")
    assert_same(load_stereo_calibration(stereo), pair)
    # one loader, either kind as the file says (issue 35); a kind asked for refuses the other
    assert isinstance(load_calibration(mono), Calibration)
    assert isinstance(load_calibration(stereo), StereoCalibration)
    assert_same(load_calibration(stereo), pair)
    assert bistair.load_calibration is load_calibration
    with pytest.raises(BistairError, match="a stereo calibration .two cameras: for bistair "
                                           "stereo., not a camera-projector one"):
        load_calibration(stereo, "camera-projector")
    with pytest.raises(BistairError, match="a camera-projector calibration, not a stereo one"):
        load_stereo_calibration(mono)
    with pytest.raises(BistairError, match="a camera-projector calibration, not a stereo one"):
        load_calibration(mono, "stereo")
    (tmp_path / "odd.json").write_text(json.dumps({**data, "kind": "three-cameras"}))
    with pytest.raises(BistairError, match=r"odd.json: calibration kind 'three-cameras' is "
                                           "neither 'camera-projector' .a camera and a "
                                           "projector. nor 'stereo' .two cameras.$"):
        load_calibration(tmp_path / "odd.json")
    # negative focal lengths, refused by name (QA of issue 31, S19)
    data = json.loads(stereo.read_text())
    data["right"]["K"][0][0] = data["right"]["K"][1][1] = -1200.0
    (tmp_path / "focal.json").write_text(json.dumps(data))
    with pytest.raises(BistairError, match="calibration field 'right.K' has the focal lengths "
                                           "fx -1200 and fy -1200 px: both must be positive"):
        load_stereo_calibration(tmp_path / "focal.json")


def test_uncertainty_names_the_devices_after_the_kind(boards, tmp_path):
    """A pair's uncertainty has a left and a right camera (issue 35), in memory as in the
    file (which keeps its layout: the cameras last); camera and projector still read them;
    a camera-projector calibration's has no left."""
    names = sorted(p.name for p in boards.iterdir() if p.is_dir())
    left, right = ([read_image(boards / n / f"{side}.png") for n in names]
                   for side in ("left", "right"))
    cal, _ = calibrate_stereo_images(left, right, Board("checkerboard", 9, 6, 20.0), names)
    sd = cal.uncertainty
    assert sd.kind == "stereo" and sd.devices == ("left", "right")
    assert sd.left is sd.camera and sd.right is sd.projector and sd.left[0] > 0
    data = json.loads(save_calibration(cal, tmp_path / "s.json").read_text())
    assert list(data["uncertainty"]) == ["rotation_deg", "T", "baseline", "noise", "left",
                                         "right"]
    assert list(data["uncertainty"]["noise"]) == ["left", "right"]
    assert data["uncertainty"]["right"]["fx"] == float(sd.right[0])
    back = load_calibration(tmp_path / "s.json").uncertainty
    assert back.kind == "stereo"
    np.testing.assert_array_equal(back.right, sd.right)
    assert back.noise == sd.noise
    mono = Calibration(cal.left, cal.right, cal.R, cal.T, uncertainty=sd)
    assert mono.uncertainty.devices == ("camera", "projector")
    assert list(mono.to_dict()["uncertainty"])[:2] == ["camera", "projector"]
    with pytest.raises(AttributeError, match="names its devices camera and projector"):
        _ = mono.uncertainty.left


def test_the_old_module_names_read_on():
    """The two-camera modules merged into their concepts (issue 35) stay importable for a
    release, naming the same objects."""
    from bistair.geometry import (
        calibrate,
        calibration,
        corners,
        opencv,
        stereo_calibrate,
        stereo_opencv,
    )
    from bistair.geometry import stereo_calibration as old

    assert old.StereoCalibration is calibration.StereoCalibration
    assert old.load_stereo_calibration is calibration.load_stereo_calibration
    assert old.save_stereo_calibration is calibration.save_calibration
    assert old.ProjectorPose is calibration.ProjectorPose
    assert stereo_calibrate.calibrate_stereo_images is calibrate.calibrate_stereo_images
    assert stereo_opencv.read_opencv_stereo is opencv.read_opencv_stereo
    assert calibrate.sample_local is corners.sample_local
    assert calibrate.board_view is corners.board_view


def test_one_board_parser_for_both_calibrations(boards, tmp_path, monkeypatch, capfd):
    """calibrate and calibrate-stereo read --board alike (one parser, issue 35): the same
    option and the same refusal of a description without its spacing."""
    from bistair.app.cli.calibrate import calibrate, calibrate_stereo

    options = [next(p for p in cmd.params if p.name == "board")
               for cmd in (calibrate, calibrate_stereo)]
    assert options[0].metavar == options[1].metavar == "FILE|TYPE:COLSxROWS:SPACING"
    errors = []
    for command, folder in (("calibrate", tmp_path), ("calibrate-stereo", boards)):
        code, stdout, err = cli_run(monkeypatch, capfd, command, folder, "--board",
                                    "chessboard:9x6", "--out", tmp_path / "out.json")
        assert code == 2 and stdout == "", err
        errors.append(err.strip())
    assert errors[0] == errors[1] == (
        "Error: a board is TYPE:COLUMNSxROWS:SPACING (e.g. chessboard:9x7:25 for 9 x 7 inner "
        "corners of 25 mm squares), got 'chessboard:9x6'")
