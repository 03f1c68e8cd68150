"""Calibration from a real rig's board captures through the command line:
kamino410/procam-calibration (../shared/data/procam-calibration, MIT), five poses of a
9 x 7-corner chessboard under OpenCV's Gray code alone (no phase shifts), with the spec and
board description in examples/.

Reference values: ``tests/data/procam_reference.json``, what the rig's own ``calibrate.py``
gives on these captures (run with its README's command; the file says with which OpenCV and
the one change OpenCV 5 needs). Its camera block is the published ``calibration_result.xml``'s;
the file's projector block and translation are from another run, so the projector's come
from running the script.
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import SHARED, cli_run

from bistair.geometry.calibration import load_calibration

PROCAM = SHARED / "data" / "procam-calibration"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REFERENCE = Path(__file__).resolve().parent / "data" / "procam_reference.json"


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
    reference = json.loads(REFERENCE.read_text())
    fs = cv2.FileStorage(str(PROCAM / "calibration_result.xml"), cv2.FILE_STORAGE_READ)
    published = fs.getNode("cam_int").mat()
    fs.release()
    camera = reference["camera"]  # the published camera block, reproduced by the script
    assert np.allclose([published[0, 0], published[1, 1], published[0, 2], published[1, 2]],
                       [camera[k] for k in ("fx", "fy", "cx", "cy")], atol=1e-4)
    # measured against the reference: camera fx, fy -0.27%, -0.22%, cx, cy +5.4, +7.8 px
    # (bistair's standard deviations 11.5, 10.8 px); projector fx, fy -0.30%, -0.14%, cx, cy
    # +18.0, +5.3 px (4.8, 6.7 px); |T| 675.33 mm, -0.15%; rotation 0.46 deg; stereo RMS
    # 0.25 px. The reference's own spread is wider (OpenCV 4.14's run of the same script:
    # projector fx +4.5%, cx -60 px, cy -200 px, |T| -3.5%), so these bounds catch gross
    # errors (axes exchanged or flipped, a wrong size or unit), not half a pixel
    for name, focal, centre in (("camera", 0.01, 20.0), ("projector", 0.01, 30.0)):
        got, want = getattr(cal, name).K, reference[name]
        assert abs(got[0, 0] / want["fx"] - 1) < focal and abs(got[1, 1] / want["fy"] - 1) < focal
        assert abs(got[0, 2] - want["cx"]) < centre and abs(got[1, 2] - want["cy"]) < centre
    assert abs(cal.baseline / reference["baseline"] - 1) < 0.01
    turn = cv2.Rodrigues(cal.R @ np.asarray(reference["R"]).T)[0]
    assert np.rad2deg(np.linalg.norm(turn)) < 1.5
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
