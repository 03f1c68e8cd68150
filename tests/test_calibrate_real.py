"""Calibration from a real rig's board captures through the command line:
kamino410/procam-calibration (../shared/data/procam-calibration, MIT), five poses of a
9 x 7-corner chessboard under OpenCV's Gray code alone (no phase shifts), with the spec and
board description in examples/.

Reference values: the camera block of the rig's own ``calibration_result.xml`` (what its
``calibrate.py`` gives on these captures) and, for the projector, what that script gives on
them (projector f about 1896 px, |T| about 676 mm; the file's projector block is from
another run).
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import SHARED, cli_run

from bistair.geometry.calibration import load_calibration

PROCAM = SHARED / "data" / "procam-calibration"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.skipif(not PROCAM.is_dir(),
                    reason="../shared/data/procam-calibration not present")
def test_procam_calibration_from_gray_code_alone(tmp_path, monkeypatch, capsys):
    out = tmp_path / "calib.json"
    code, text, err = cli_run(monkeypatch, capsys, "calibrate", PROCAM, "--spec",
                              EXAMPLES / "procam-graycode.json", "--board",
                              EXAMPLES / "procam-board.json", "--out", out)
    assert code == 0, err
    # the projected patterns (projector size, no board) are skipped with one line
    assert ("Warning: skipped graycode_pattern: board not found in its white frame nor in its "
            "mean image") in err.splitlines()
    cal = load_calibration(out)
    assert [pose["name"] for pose in cal.poses] == [f"capture_{i}" for i in range(5)]
    assert cal.poses_total == 6 and all(pose["features"] == 63 for pose in cal.poses)
    assert text.splitlines()[0].startswith(f"camera RMS {cal.camera.rms:.3f} px")
    fs = cv2.FileStorage(str(PROCAM / "calibration_result.xml"), cv2.FILE_STORAGE_READ)
    reference = fs.getNode("cam_int").mat()
    fs.release()
    # measured: camera fx 3442.9, fy 3442.5 px (-0.27%, -0.22% of 3452.4, 3449.9),
    # projector fx 1890.0, fy 1893.2 px, |T| 675.3 mm, stereo RMS 0.25 px
    for k in (0, 1):
        assert abs(cal.camera.K[k, k] / reference[k, k] - 1) < 0.01
        assert abs(cal.projector.K[k, k] / 1896 - 1) < 0.02
    assert abs(np.linalg.norm(cal.T) / 676 - 1) < 0.02
    assert cal.rms <= 1.0 and cal.camera.rms <= 1.0 and cal.projector.rms <= 1.0
    assert cal.camera.size == (1280, 1024) and cal.projector.size == (1024, 768)


@pytest.mark.skipif(not PROCAM.is_dir(),
                    reason="../shared/data/procam-calibration not present")
def test_the_rigs_own_calibration_file_imports(tmp_path, monkeypatch, capsys):
    """calibration_result.xml with the --keys of the README's table (its img_shape is
    (height, width), so both sizes are given)."""
    keys = ("camera=cam_int,camera_dist=cam_dist,projector=proj_int,projector_dist=proj_dist,"
            "R=roration,T=translation")
    code, text, err = cli_run(monkeypatch, capsys, "import-calibration",
                              PROCAM / "calibration_result.xml", "--keys", keys,
                              "--camera-size", "1280x1024", "--projector-size", "1024x768",
                              "--out", tmp_path / "calib.json")
    assert code == 0, err
    cal = load_calibration(tmp_path / "calib.json")
    fs = cv2.FileStorage(str(PROCAM / "calibration_result.xml"), cv2.FILE_STORAGE_READ)
    for got, key in ((cal.camera.K, "cam_int"), (cal.projector.K, "proj_int"),
                     (cal.T, "translation")):
        assert np.array_equal(got, fs.getNode(key).mat().reshape(got.shape)), key
    fs.release()
    # the file's translation (another run than its camera block) is 644.20 mm long
    assert text.startswith("camera 1280x1024, projector 1024x768, baseline 644.20 mm")
