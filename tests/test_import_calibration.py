"""``bistair import-calibration``: OpenCV FileStorage files (YAML and XML, written by
``cv2.FileStorage``) from a known calibration come back exactly; renamed keys, two files
merged, sizes from the files; every bad input is one line on stderr, exit code 2, and
nothing written.

The command runs in-process with ``capfd``, so anything OpenCV might print at the C level
would be caught too.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import cli_run

from bistair.errors import BistairError
from bistair.geometry.calibration import Calibration, load_calibration
from bistair.geometry.opencv import _example_calibration, read_opencv_calibration
from bistair.sim import preset


def write_fs(path: Path, items: dict) -> Path:
    """Write ``items`` with cv2.FileStorage (the format from the suffix); a list value is
    written as a FileStorage sequence, an int or str as a scalar, the rest as a matrix."""
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


def stereo_items(cal: Calibration, names: dict | None = None) -> dict:
    """The calibration under stereo_calib's key names (or renamed ones)."""
    names = {"camera": "M1", "camera_dist": "D1", "projector": "M2", "projector_dist": "D2",
             "R": "R", "T": "T", **(names or {})}
    return {names["camera"]: cal.camera.K, names["camera_dist"]: cal.camera.dist[None, :],
            names["projector"]: cal.projector.K,
            names["projector_dist"]: cal.projector.dist[None, :], names["R"]: cal.R,
            names["T"]: cal.T[:, None]}


def assert_same(got: Calibration, want: Calibration, tol: float = 1e-12) -> None:
    assert got.camera.size == want.camera.size and got.projector.size == want.projector.size
    for a, b in ((got.camera.K, want.camera.K), (got.camera.dist, want.camera.dist),
                 (got.projector.K, want.projector.K),
                 (got.projector.dist, want.projector.dist), (got.R, want.R), (got.T, want.T)):
        assert a.shape == b.shape and np.abs(a - b).max() <= tol


def run(monkeypatch, capfd, *args):
    return cli_run(monkeypatch, capfd, "import-calibration", *args)


# -- round trips ---------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".yml", ".yaml", ".xml"])
def test_round_trip_of_one_file(suffix, tmp_path, monkeypatch, capfd):
    cal = _example_calibration()
    src = write_fs(tmp_path / f"stereo{suffix}",
                   {**stereo_items(cal), "image_size": [640, 480]})
    out = tmp_path / "calib.json"
    code, stdout, err = run(monkeypatch, capfd, src, "--out", out, "--projector-size", "1280x800")
    assert code == 0, err
    assert err == "" and "baseline 150.00 mm" in stdout
    assert_same(load_calibration(out), cal)


def test_stereo_calib_layout_two_files_xml_and_yaml(tmp_path, monkeypatch, capfd):
    """stereo_calib writes intrinsics.yml and extrinsics.yml, without the image size."""
    cal = _example_calibration()
    items = stereo_items(cal)
    intr = write_fs(tmp_path / "intrinsics.yml", {k: items[k] for k in ("M1", "D1", "M2", "D2")})
    extr = write_fs(tmp_path / "extrinsics.xml", {"R": items["R"], "T": items["T"],
                                                  "R1": np.eye(3), "Q": np.eye(4)})
    out = tmp_path / "calib.json"
    code, _, err = run(monkeypatch, capfd, intr, extr, "--out", out, "--projector-size",
                       "1280x800", "--camera-size", "640x480")
    assert code == 0, err
    assert_same(load_calibration(out), cal)


def test_the_rigs_calibration_survives_the_trip(tmp_path, monkeypatch, capfd):
    rig = preset("sphere-on-plane", camera_size=(640, 512))[0]
    cal = Calibration.from_rig(rig)
    src = write_fs(tmp_path / "rig.xml", {**stereo_items(cal), "imageSize": [640, 512]})
    out = tmp_path / "calib.json"
    code, _, err = run(monkeypatch, capfd, src, "-o", out, "--projector-size", "1920x1080")
    assert code == 0, err
    assert_same(load_calibration(out), cal)


def test_renamed_keys_rotation_vector_and_other_size_keys(tmp_path, monkeypatch, capfd):
    cal = _example_calibration()
    names = {"camera": "camera_matrix", "camera_dist": "dist_cam", "projector": "K_proj",
             "projector_dist": "dist_proj", "R": "rvec", "T": "tvec"}
    items = stereo_items(cal, names)
    items["rvec"] = cv2.Rodrigues(cal.R)[0]  # 3x1 rotation vector
    items["dist_cam"] = np.append(cal.camera.dist[:4], np.zeros(4))[:, None]  # 8x1, k4-k6 = 0
    items["dist_proj"] = np.append(cal.projector.dist, np.zeros(9))  # 14 numbers
    keys = ",".join(f"{k}={v}" for k, v in names.items())
    for extra, more in (({"image_width": 640, "image_height": 480}, ()),
                        ({"sensor": [640, 480]}, (",camera_size=sensor",))):
        src = write_fs(tmp_path / "renamed.yml", {**items, **extra})
        out = tmp_path / "calib.json"
        code, _, err = run(monkeypatch, capfd, src, "--out", out, "--projector-size",
                           "1280x800", "--keys", keys + "".join(more))
        assert code == 0, err
        # R went through cv2.Rodrigues both ways, still within 1e-12
        assert_same(load_calibration(out), cal)


@pytest.mark.parametrize("suffix", [".xml", ".yml"])
def test_slstudio_names_and_sizes(suffix, tmp_path, monkeypatch, capfd):
    """SLStudio's calibration file: Kc, kc, Kp, kp, Rp, Tp (X_p = Rp X_c + Tp), its errors,
    the camera size as frameWidth + frameHeight and the projector's as screenResX +
    screenResY: no size option needed."""
    cal = _example_calibration()
    names = {"camera": "Kc", "camera_dist": "kc", "projector": "Kp", "projector_dist": "kp",
             "R": "Rp", "T": "Tp"}
    src = write_fs(tmp_path / f"calibration{suffix}",
                   {**stereo_items(cal, names), "cam_error": np.array(0.12),
                    "proj_error": np.array(0.2), "stereo_error": np.array(0.25),
                    "frameWidth": 640, "frameHeight": 480, "screenResX": 1280,
                    "screenResY": 800})
    out = tmp_path / "calib.json"
    code, stdout, err = run(monkeypatch, capfd, src, "--out", out, "--keys",
                            "camera=Kc,camera_dist=kc,projector=Kp,projector_dist=kp,R=Rp,T=Tp")
    assert code == 0, err
    assert stdout.startswith("camera 640x480, projector 1280x800, baseline 150.00 mm")
    assert_same(load_calibration(out), cal)
    # a size option still wins over the file's
    got = read_opencv_calibration([src], (1920, 1080), (1280, 960), keys=names)
    assert got.camera.size == (1280, 960) and got.projector.size == (1920, 1080)


def test_size_as_s_and_named_projector_size(tmp_path):
    """``S`` holds the camera size when it is two numbers (and is left alone otherwise);
    ``projector_size=KEY`` names the projector's."""
    cal = _example_calibration()
    src = write_fs(tmp_path / "s.yml", {**stereo_items(cal), "S": [640, 480],
                                        "display": [1280, 800]})
    got = read_opencv_calibration([src], keys={"projector_size": "display"})
    assert_same(got, cal)
    other = write_fs(tmp_path / "s3.yml", {**stereo_items(cal), "S": np.eye(3),
                                           "projector_size": [1280, 800]})
    with pytest.raises(BistairError, match="no camera size in .*give it with --camera-size"):
        read_opencv_calibration([other])
    assert read_opencv_calibration([other], camera_size=(640, 480)).projector.size == (1280,
                                                                                       800)


def test_hand_written_yaml_with_plain_sequences(tmp_path):
    """YAML a person or another tool wrote: sequences instead of !!opencv-matrix, a 1.0
    header, image_width + image_height."""
    cal = _example_calibration()

    def seq(a: np.ndarray) -> str:
        return repr(np.asarray(a).tolist())

    text = "\n".join([
        "%YAML:1.0", "image_width: 640", "image_height: 480",
        f"M1: {seq(cal.camera.K)}", f"D1: {seq(cal.camera.dist[:4])}",
        f"M2: {seq(cal.projector.K)}", f"D2: {seq(cal.projector.dist)}",
        f"R: {seq(cv2.Rodrigues(cal.R)[0].ravel())}", f"T: {seq(cal.T)}", "name: rig 1", ""])
    (tmp_path / "rig.yaml").write_text(text)
    got = read_opencv_calibration([tmp_path / "rig.yaml"], (1280, 800))
    assert_same(got, cal, tol=1e-12)


def test_camera_size_option_wins_and_rounded_rotation_is_made_exact(tmp_path):
    cal = _example_calibration()
    items = {**stereo_items(cal), "image_size": [320, 240]}
    items["R"] = np.round(cal.R, 4)  # a tool that writes four digits
    src = write_fs(tmp_path / "rounded.yml", items)
    got = read_opencv_calibration([src], (1280, 800), camera_size=(640, 480))
    assert got.camera.size == (640, 480)
    assert np.abs(got.R @ got.R.T - np.eye(3)).max() < 1e-14
    assert np.abs(got.R - cal.R).max() < 1e-4
    with pytest.raises(BistairError):  # 1e-2 off is not rounding
        read_opencv_calibration([write_fs(tmp_path / "bad.yml", {**items, "R": cal.R * 1.01})],
                                (1280, 800))


# -- every bad input through the command line -------------------------------------------------
def _bad_files(tmp: Path) -> dict[str, tuple[list[str], str]]:
    """name -> (arguments before --out, expected part of the message)."""
    cal = _example_calibration()
    good = {**stereo_items(cal), "image_size": [640, 480]}

    def fs(name: str, **changes) -> str:
        items = {k: v for k, v in {**good, **changes}.items() if v is not None}
        return str(write_fs(tmp / name, items))

    (tmp / "junk.yml").write_text("this is not {{ a FileStorage file ::\n")
    (tmp / "binary.xml").write_bytes(b"\x00\x01\x02\xff")
    (tmp / "plain.xml").write_text('<?xml version="1.0"?>\n<root><M1>1</M1></root>\n')
    (tmp / "list.yml").write_text("%YAML:1.0\n- 1\n- 2\n")
    proj = ["--projector-size", "1280x800"]
    k_cam = cal.camera.K
    return {
        "missing file": ([str(tmp / "none.yml"), *proj], "none.yml not found"),
        "a folder": ([str(tmp), *proj], "is a folder, not an OpenCV FileStorage file"),
        "not FileStorage": ([str(tmp / "junk.yml"), *proj],
                            "junk.yml is not an OpenCV FileStorage file"),
        "binary": ([str(tmp / "binary.xml"), *proj], "is not an OpenCV FileStorage file"),
        "XML without opencv_storage": ([str(tmp / "plain.xml"), *proj],
                                       "is not an OpenCV FileStorage file"),
        "no named keys": ([str(tmp / "list.yml"), *proj], "with named keys"),
        "missing key": ([fs("nokey.yml", M2=None), *proj],
                        "no key 'M2' (projector matrix) in "),  # + "(it has M1, D1, ...)"
        "missing key, two files": (
            [fs("a.yml", T=None), fs("b.xml", M1=None, T=None, R=None), *proj],
            "no key 'T' (translation) in "),
        "renamed key absent": ([fs("ok1.yml"), *proj, "--keys", "camera=K1"],
                               "no key 'K1' (camera matrix)"),
        "not numbers": ([fs("text.yml", M1="left camera"), *proj],
                        "camera matrix 'M1' in"),
        "two files disagree": ([fs("c.yml"), fs("d.yml", T=cal.T * 2), *proj],
                               "translation 'T' differs between"),
        "K shape": ([fs("k23.yml", M1=k_cam[:2]), *proj], "must be 3x3, got 2x3"),
        "K flat": ([fs("k9.yml", M1=k_cam.reshape(1, 9)), *proj], "must be 3x3, got 1x9"),
        "K not intrinsic": ([fs("kbad.yml", M1=np.vstack([k_cam[:2], [0, 0, 2]])), *proj],
                            "is not an intrinsic matrix"),
        "dist count": ([fs("d6.yml", D1=np.zeros((1, 6))), *proj],
                       "must hold 4, 5, 8, 12 or 14 numbers, got 1x6"),
        "dist matrix": ([fs("d22.yml", D2=np.zeros((2, 2))), *proj],
                        "projector distortion 'D2' in"),
        "dist rational": ([fs("d8.yml", D2=np.array([[0.1, 0, 0, 0, 0, 0.02, 0, 0.003]])), *proj],
                          "has non-zero k4, k6; bistair's model keeps only k1, k2, p1, p2, k3"),
        "dist tilted": ([fs("d14.yml", D1=np.r_[np.zeros(12), 0.01, 0]), *proj],
                        "has non-zero tauX"),
        "R shape": ([fs("r22.yml", R=np.eye(2)), *proj],
                    "must be a 3x3 rotation matrix or a rotation vector of 3 numbers, got 2x2"),
        "R scaled": ([fs("r2.yml", R=2 * cal.R), *proj], "is not a rotation matrix"),
        "R reflection": ([fs("rm.yml", R=-cal.R), *proj], "is not a rotation matrix"),
        "T count": ([fs("t2.yml", T=np.array([[1.0], [2.0]])), *proj],
                    "must hold 3 numbers, got 2x1"),
        "NaN in K": ([fs("nan.yml", M2=np.where(np.eye(3) > 0, np.nan, 0)), *proj],
                     "projector matrix 'M2' in"),
        "inf in T": ([fs("inf.xml", T=np.array([1.0, np.inf, 0.0])), *proj],
                     "translation 'T' in"),
        "projector size": ([fs("ok2.yml"), "--projector-size", "1280"],
                           "--projector-size must be WIDTHxHEIGHT"),
        "projector zero": ([fs("ok3.yml"), "--projector-size", "0x800"],
                           "--projector-size must be WIDTHxHEIGHT"),
        "projector words": ([fs("ok4.yml"), "--projector-size", "wide"],
                            "--projector-size must be WIDTHxHEIGHT"),
        "camera size": ([fs("ok5.yml"), *proj, "--camera-size", "640x480x3"],
                        "--camera-size must be WIDTHxHEIGHT"),
        "no camera size": ([fs("nosize.yml", image_size=None), *proj],
                           "give it with --camera-size WxH"),
        "no projector size": ([fs("noproj.yml")], "no projector size in "),
        "projector size key bad": ([fs("proj3.yml", screenResX=1280)],
                                   "no projector size in "),
        "projector size fractional": ([fs("projf.yml", screenResX=np.array(1280.5),
                                          screenResY=800)],
                                      "must be two positive whole numbers of pixels, got "
                                      "1280.5x800"),
        "size key bad": ([fs("size3.yml", image_size=[640, 480, 3]), *proj],
                         "must be [width, height], got 3 numbers"),
        "size key fractional": ([fs("sizef.yml", image_size=np.array([640.5, 480])), *proj],
                                "must be two positive whole numbers of pixels, got 640.5x480"),
        "keys format": ([fs("ok6.yml"), *proj, "--keys", "camera:M1"],
                        "--keys must be NAME=KEY items"),
        "keys unknown part": ([fs("ok7.yml"), *proj, "--keys", "cam=M1"],
                              "unknown part 'cam' in the keys"),
    }


def test_every_bad_input_is_one_line_and_writes_nothing(tmp_path, monkeypatch, capfd):
    inputs = tmp_path / "in"
    inputs.mkdir()
    cases = _bad_files(inputs)
    before = sorted(p.name for p in inputs.iterdir())
    out = tmp_path / "out" / "calib.json"
    for name, (args, message) in cases.items():
        code, stdout, err = run(monkeypatch, capfd, *args, "--out", out)
        lines = [line for line in err.splitlines() if line.strip()]
        assert code == 2, (name, err)
        assert len(lines) == 1 and lines[0].startswith("Error: "), (name, err)
        assert message in lines[0], (name, lines[0])
        assert stdout == "" and "Traceback" not in err
        assert not out.parent.exists(), name
    assert sorted(p.name for p in inputs.iterdir()) == before


def test_messages_name_the_key_files_and_what_they_have(tmp_path, monkeypatch, capfd):
    cal = _example_calibration()
    items = stereo_items(cal)
    a = write_fs(tmp_path / "intrinsics.yml", {k: items[k] for k in ("M1", "D1", "M2", "D2")})
    b = write_fs(tmp_path / "extrinsics.yml", {"R": items["R"], "Rvec": np.zeros(3)})
    code, _, err = run(monkeypatch, capfd, a, b, "--out", tmp_path / "c.json",
                       "--projector-size", "1280x800", "--camera-size", "640x480")
    assert code == 2
    assert err.strip() == (f"Error: no key 'T' (translation) in {a}, {b} ({a} has M1, D1, M2, "
                           f"D2; {b} has R, Rvec); rename it with --keys T=KEY")
    assert not (tmp_path / "c.json").exists()
