"""Calibration from pose folders of captures of both axes decoded by one spec: a Gray code
alone without white frames on the virtual rig (the board found in the mean image), one
``--spec`` for every pose, folders that are not poses skipped with a line, the simulator's
board captures without white frames, and the refusals."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from conftest import cli_run
from test_calib import BOARD, assert_close, check_board_view, one_line, sim_rig

import bistair
from bistair.app.calibrate import calibrate_folder, read_pose
from bistair.errors import BistairError
from bistair.geometry.calibration import Calibration, load_calibration
from bistair.geometry.corners import CORNER_FITS, board_view
from bistair.io.atomic import write_image
from bistair.sim import Imaging
from bistair.sim.boards import POSES, write_board_captures


def alone_spec() -> bistair.spec.BaseSpec:
    """OpenCV's Gray code alone for the 960 x 540 projector: each bit and its inverse, both
    axes, no white frame."""
    return bistair.make_spec("graycode", steps=0, inverse=1, orientation="both", width=960,
                             height=540)


@pytest.fixture(scope="module")
def gray_poses(tmp_path_factory):
    """Eight board poses of the Gray code alone, pose-NN/ with the captures and spec.json."""
    rig, root = sim_rig(), tmp_path_factory.mktemp("gray") / "captures"
    write_board_captures(rig, BOARD, {"both": alone_spec()}, root, imaging=Imaging(seed=0),
                         suffix=".tif")
    return root, rig


def test_gray_code_alone_without_white_frames(gray_poses, tmp_path, monkeypatch, capsys):
    root, rig = gray_poses
    code, text, err = cli_run(monkeypatch, capsys, "calibrate", root, "--board",
                              "chessboard:9x6:20", "--out", tmp_path / "calib.json")
    assert code == 0, err
    cal = load_calibration(tmp_path / "calib.json")
    # measured: focal lengths +0.18-0.20% (camera) and +0.11-0.14% (projector), principal
    # points within 0.5 px, baseline +0.014 mm, rotation 0.06 deg, stereo RMS 0.08 px: the
    # tolerances of the multi-frequency captures with white frames (test_calib.py); the
    # quadratic fit: principal points within 0.7 px, focal lengths 0.01-0.02% longer
    assert_close(cal, Calibration.from_rig(rig), focal=0.005, centre=2.0, baseline=1.0,
                 angle_deg=0.2)
    assert cal.rms < 0.2 and len(cal.poses) == len(POSES) == cal.poses_total
    assert cal.board == BOARD.to_dict() and "8 of 8 poses" in text.splitlines()[0]


@pytest.mark.parametrize("corner_fit", CORNER_FITS)
def test_gray_cells_land_where_the_rig_projects_them(gray_poses, corner_fit):
    """Features mapped from one-pixel Gray code cells (each pixel decodes to its cell's
    centre) against the rig's exact projection (test_calib.check_board_view).

    measured (8 poses): within 0.059 px (homography) and 0.112 px (quadratic) per
    coordinate, 0.023 and 0.036 px RMS, mean offsets under 0.002 px; half a pixel added to
    every projector point: 0.5 px."""
    root, rig = gray_poses
    for i in (0, 1, 6):
        pose, _ = read_pose(root / f"pose-{i:02d}", {"both": alone_spec()})
        check_board_view(board_view(pose, BOARD, corner_fit), rig, POSES[i], seen_max=0.15,
                         seen_bias=0.02)


def test_one_spec_for_every_pose_and_folders_that_are_not_poses(gray_poses, tmp_path,
                                                                 monkeypatch, capsys):
    """procam-calibration's layout: capture folders of PNGs alone, ``--spec`` given once,
    beside them a folder of the projected patterns (the projector's size, no board) and one
    without images: both are skipped with a line naming them."""
    root, _ = gray_poses
    spec = alone_spec()
    for i in range(4):
        shutil.copytree(root / f"pose-{i:02d}", tmp_path / "caps" / f"capture_{i}")
        (tmp_path / "caps" / f"capture_{i}" / "spec.json").unlink()
    (tmp_path / "spec.json").write_text(spec.to_json())
    patterns = np.round(bistair.encode(spec) * 255).astype(np.uint8)
    (tmp_path / "caps" / "graycode_pattern").mkdir()
    for i, image in enumerate(patterns):
        write_image(tmp_path / "caps" / "graycode_pattern" / f"pattern_{i:02d}.png", image)
    (tmp_path / "caps" / "notes").mkdir()
    (tmp_path / "caps" / "notes" / "readme.txt").write_text("not a pose")
    code, text, err = cli_run(monkeypatch, capsys, "calibrate", tmp_path / "caps", "--spec",
                              tmp_path / "spec.json", "--board", root / "board.json", "--out",
                              tmp_path / "calib.json", "--quiet")
    assert code == 0, err
    assert text == ""  # --quiet: the warnings alone
    assert err.splitlines() == [
        "Warning: skipped graycode_pattern: board not found in its mean image",
        f"Warning: skipped notes: no PNG, TIFF or BMP images in {tmp_path / 'caps' / 'notes'}"]
    cal = load_calibration(tmp_path / "calib.json")
    assert [pose["name"] for pose in cal.poses] == [f"capture_{i}" for i in range(4)]
    assert cal.poses_total == 6 and cal.camera.size == (640, 512)


def test_pose_folders_of_captures_refused(gray_poses, tmp_path):
    root, _ = gray_poses
    for i in range(3):
        shutil.copytree(root / f"pose-{i:02d}", tmp_path / f"pose-{i:02d}")
        (tmp_path / f"pose-{i:02d}" / "spec.json").unlink()
    shutil.copy(root / "board.json", tmp_path)
    named: list[str] = []
    with pytest.raises(BistairError) as exc:  # no spec anywhere: every pose is named
        calibrate_folder(tmp_path, skipped=lambda name, why: named.append(f"{name}: {why}"))
    assert one_line(exc) == ("board found in 0 of 3 poses, need at least 3; 3 not decoded "
                             "(pose-00: no spec.json (give --spec))")
    assert named == [f"pose-0{i}: no spec.json beside its captures (give --spec)"
                     for i in range(3)]
    columns = alone_spec().replace(orientation="columns", frame_order=())
    (tmp_path / "spec.json").write_text(columns.to_json())  # the folder's spec: one axis
    with pytest.raises(BistairError) as exc:
        calibrate_folder(tmp_path)
    assert one_line(exc) == ("spec.json codes the columns alone: a pose folder of captures "
                             "needs a spec of both axes (orientation both), or columns/ and "
                             "rows/ folders")
    with pytest.raises(BistairError) as exc:
        calibrate_folder(tmp_path, spec=columns)
    assert one_line(exc).startswith("--spec codes the columns alone")
    (tmp_path / "pose-01" / "columns").mkdir()
    (tmp_path / "pose-01" / "rows").mkdir()
    with pytest.raises(BistairError) as exc:
        calibrate_folder(tmp_path, spec=alone_spec())
    assert one_line(exc) == ("--spec is for pose folders of captures of both axes; pose-01 "
                             "has columns/ and rows/ with their own specs")
    with pytest.raises(BistairError) as exc:
        calibrate_folder(tmp_path, board="chessboard:9x6")
    assert one_line(exc).startswith("a board is TYPE:COLUMNSxROWS:SPACING")
    with pytest.raises(BistairError) as exc:
        calibrate_folder(tmp_path, board=tmp_path / "nowhere.json")
    assert one_line(exc) == (f"board description {tmp_path / 'nowhere.json'} not found (give "
                             "--board FILE or --board TYPE:COLUMNSxROWS:SPACING, e.g. "
                             "chessboard:9x7:25)")
    with pytest.raises(BistairError, match="corner fit must be one of homography, quadratic"):
        calibrate_folder(tmp_path, spec=alone_spec(), corner_fit="cubic")


def test_simulated_board_captures_without_white_frames(tmp_path, monkeypatch, capsys):
    code, text, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "calibration",
                              "--method", "graycode", "--no-white", "--both-axes", "--camera",
                              "96x80", "--out", tmp_path / "calib")
    assert code == 0, err
    poses = sorted(p.name for p in (tmp_path / "calib").iterdir() if p.is_dir())
    assert poses == [f"pose-{i:02d}" for i in range(len(POSES))]
    spec = json.loads((tmp_path / "calib" / "pose-00" / "spec.json").read_text())
    assert spec["orientation"] == "both" and spec["white"] == 0
    assert "white" not in spec["frames"]
    assert len(list((tmp_path / "calib" / "pose-00").glob("*.png"))) == len(spec["frames"])
    code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                           "graycode", "--no-white", "--out", tmp_path / "plane")
    assert code == 2 and err.strip() == ("Error: board captures without a white frame or of "
                                         "both axes at once are for --scene calibration")
    assert not (tmp_path / "plane").exists()
