"""bistair scan without a window system: device strings, the opencv camera on an image
sequence the test writes, the sim camera against ``bistair simulate``, the settle time,
bad input (one line, exit 2, nothing written) and Ctrl-C / SIGTERM mid-scan. The window
display and the screen camera are tested on Xvfb in ``test_scan_window.py``."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import PATIENCE, cli_run
from support.scan_devices import Screen

from bistair.acquire import scan
from bistair.acquire.cameras import SIM_BOARD, OpenCVCamera
from bistair.acquire.devices import parse_camera, parse_display
from bistair.acquire.latency import Latency, save_latency
from bistair.acquire.loop import DEFAULT_SETTLE_MS, pattern_images, settle_time
from bistair.app.calibrate import calibrate_folder
from bistair.app.scan import scan_folder
from bistair.codecs import make_spec
from bistair.errors import BistairError
from bistair.evaluation.benchmark import method_specs
from bistair.io.atomic import write_image
from bistair.io.read import read_captures

run = cli_run


@pytest.fixture()
def spec():
    return make_spec("graycode", width=480, height=240, period=30, complementary=1)


def _write_spec(spec, folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "spec.json").write_text(spec.to_json())
    return folder / "spec.json"


@pytest.mark.parametrize(("text", "message"), [
    ("webcam:0", "unknown camera 'webcam:0' (known: opencv:INDEX|URL, "),
    ("opencv:", "camera opencv needs a device number or a URL"),
    ("screen:one", "the monitor of camera 'screen:one' must be a number from 0, got 'one'"),
    ("sim:moon", "unknown sim scene 'moon' (known: plane, "),
    ("sim:plane:64", "the camera size of 'sim:plane:64' must be WIDTHxHEIGHT"),
    ("genicam:", "camera 'genicam:' must be genicam:PRODUCER.cti"),
    ("genicam:/nowhere/p.cti:S1", "GenTL producer file /nowhere/p.cti not found"),
])
def test_camera_strings_refused_in_one_line(text, message):
    with pytest.raises(BistairError) as info:
        parse_camera(text)
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


@pytest.mark.parametrize(("text", "settings", "message"), [
    ("screen", {"gain": 2}, "the screen camera has no gain setting (it takes none)"),
    ("opencv:0", {"pixel_format": "Mono8"}, "the opencv camera has no pixel format setting"),
    ("sim", {"gain": 1}, "the sim camera has no gain setting"),
])
def test_settings_a_camera_does_not_take(text, settings, message):
    with pytest.raises(BistairError, match=re.escape(message)):
        parse_camera(text, **settings)


def test_the_package_names_scan():
    import bistair

    assert bistair.scan is scan and "scan" in dir(bistair)


def test_display_strings():
    assert parse_display("window").name == "window:0"
    assert parse_display("window:2").screen == 2
    assert parse_display(" none ").drives is False
    for bad in ("projector", "window:-1", "none:1"):
        with pytest.raises(BistairError, match="display"):
            parse_display(bad)


def _sequence(folder: Path, images: np.ndarray, stale: int, average: int) -> str:
    """An image sequence a camera would deliver: per pattern ``stale`` frames of the
    pattern before, then ``average`` frames of the pattern, with +-2 codes of noise when
    more than one (away from the ends, so two frames average to the pattern)."""
    folder.mkdir()
    frames, before = [], np.zeros_like(images[0])
    for image in images:
        frames += [before] * stale
        inside = (image >= 2) & (image <= 253)
        for k in range(average):
            sign = 0 if average == 1 else 2 if k % 2 == 0 else -2
            frames.append((image.astype(np.int16) + np.where(inside, sign, 0)).astype(np.uint8))
        before = image
    for i, frame in enumerate(frames):
        write_image(folder / f"f{i:03d}.png", frame)
    return str(folder / "f%03d.png")


def test_opencv_camera_on_an_image_sequence(spec, tmp_path, monkeypatch, capsys):
    """--display none: the frames come in the projector's order, averaged in pairs; the
    scan folder is a normal capture folder for bistair decode."""
    images = pattern_images(spec)
    source = _sequence(tmp_path / "seq", images, stale=0, average=2)
    spec_path = _write_spec(spec, tmp_path / "pats")
    out = tmp_path / "scan"
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display", "none",
                          "--camera", f"opencv:{source}", "--average", 2, "--out", out)
    assert code == 0, err
    assert f"scanned 9 graycode patterns with none and opencv:{source}" in text
    assert np.array_equal(read_captures(out), images)
    info = json.loads((out / "scan.json").read_text())
    assert info["settle_source"] == "none" and info["average"] == 2
    assert [f["file"] for f in info["frames"]] == [f"{i:02d}.png" for i in range(9)]
    assert [f["name"] for f in info["frames"]] == list(spec.frames)
    code, _, err = run(monkeypatch, capsys, "decode", out, "--out", tmp_path / "result")
    assert code == 0, err
    coord = np.load(tmp_path / "result" / "coord.npy")
    assert np.abs(coord - np.arange(480)[None, :]).max() < 0.05


def test_opencv_camera_drops_the_buffered_frames(spec, tmp_path):
    """A display bistair drives: after each pattern the stale frames are dropped."""
    images = pattern_images(spec)
    source = _sequence(tmp_path / "seq", images, stale=3, average=1)
    result = scan(spec, Screen((480, 240)), f"opencv:{source}", settle_ms=0, drop=3)
    assert np.array_equal(result.frames, images)
    assert [r["dropped"] for r in result.records] == [3] * len(images)
    camera = OpenCVCamera(0)
    assert camera.drop == 0  # a device's own drop count is known once it is open


@pytest.mark.parametrize(("camera", "extra", "message"), [
    ("opencv:{seq}", ["--exposure", 5], "camera opencv:.* does not take the exposure 5"),
    ("opencv:{seq}", [], "delivered no frame after 3 "),
    ("opencv:{tmp}/nothing.mp4", [], "cannot open camera opencv:.*nothing.mp4: no such file"),
    ("sim:plane:64x48", ["--average", 0], "--average must be a whole number from 1"),
    ("sim:paper-sim:64x48", [], "the spec's 1920x1080 patterns do not fit the 1080x1080 "
                                "projector of sim:paper-sim:64x48"),
    # options accepted and ignored or out of range until issue 31 (QA N27, N28)
    ("sim:plane:64x48", ["--exposure", 100], "the sim camera's exposure is its response to "
                                             "white, above 0 and at most 1, got 100"),
    ("sim:plane:64x48", ["--exposure", 0], "above 0 and at most 1, got 0"),
    ("sim:plane:64x48", ["--depth-range", "0:100"], "--depth-range applies to the "
                                                    "reconstruction: give --calibration too"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, monkeypatch, capsys, camera,
                                                   extra, message):
    spec = make_spec("graycode", width=1920, height=1080, period=30)
    images = pattern_images(spec)[:3, :48, :64]
    seq = _sequence(tmp_path / "seq", images, stale=0, average=1)
    spec_path = _write_spec(spec, tmp_path / "pats")
    out = tmp_path / "runs" / "scan"
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display", "none",
                          "--camera", camera.format(seq=seq, tmp=tmp_path), "--out", out,
                          *extra)
    assert code == 2 and text == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("Error: ")
    assert re.search(message, err), err
    assert not (tmp_path / "runs").exists() or not list((tmp_path / "runs").iterdir())


def test_scan_needs_spec_and_out_and_a_folder_of_its_own(spec, tmp_path, monkeypatch, capsys):
    spec_path = _write_spec(spec, tmp_path / "pats")
    code, _, err = run(monkeypatch, capsys, "scan", "--display", "none", "--camera", "sim",
                       "--out", tmp_path / "x")
    assert code == 2 and "Error: --spec is needed for a scan" in err
    code, _, err = run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display", "none",
                       "--camera", "sim")
    assert code == 2 and "Error: --out is needed for a scan" in err
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "a.txt").write_text("mine")
    code, _, err = run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display", "none",
                       "--camera", "sim:plane:48x32", "--out", tmp_path / "notes")
    assert code == 2 and "holds files and is not an earlier scan" in err
    assert sorted(p.name for p in (tmp_path / "notes").iterdir()) == ["a.txt"]
    code, _, err = run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display", "none",
                       "--camera", "sim:plane:48x32", "--out", tmp_path / "pats")
    assert code == 2 and "pats holds the input " in err  # its own spec (issue 31)
    assert sorted(p.name for p in (tmp_path / "pats").iterdir()) == ["spec.json"]
    code, _, err = run(monkeypatch, capsys, "scan", "--measure-latency", "--display", "none",
                       "--camera", "sim")
    assert code == 2 and "display none is not driven by bistair" in err


def test_a_new_scan_replaces_an_earlier_one_whole(tmp_path, monkeypatch, capsys):
    out = tmp_path / "scan"
    for method, frames in (("graycode", 8), ("lv", 6)):
        spec = make_spec(method, width=480, height=240, period=30)
        path = _write_spec(spec, tmp_path / method)
        code, _, err = run(monkeypatch, capsys, "scan", "--spec", path, "--display", "none",
                           "--camera", "sim:plane:48x32", "--out", out, "-q")
        assert code == 0, err
        assert len(list(out.glob("*.png"))) == frames  # none left of the earlier scan
    assert json.loads((out / "spec.json").read_text())["method"] == "lv"


def test_settle_time_sources(tmp_path, monkeypatch):
    latency_file = tmp_path / "latency.json"
    screen, camera = Screen((64, 48)), parse_camera("opencv:3")
    assert settle_time(screen, camera, 40, latency_file) == (40.0, "option")
    assert settle_time(parse_display("none"), camera, None, latency_file) == (0.0, "none")
    assert settle_time(screen, parse_camera("sim"), None, latency_file) == (0.0, "camera")
    assert settle_time(screen, camera, None, latency_file) == (DEFAULT_SETTLE_MS, "default")
    save_latency(latency_file, Latency(screen.name, "opencv:3", [31.0, 39.6], 0.1, 0.8))
    assert settle_time(screen, camera, None, latency_file) == (50.0, "measured")
    monkeypatch.setenv("BISTAIR_LATENCY_FILE", str(latency_file))
    assert settle_time(screen, camera) == (50.0, "measured")
    with pytest.raises(BistairError, match="--settle-ms must be from 0 to 60000 ms"):
        settle_time(screen, camera, -1.0)


def test_sim_scan_decodes_like_simulate(tmp_path, monkeypatch, capsys):
    """The sim camera renders the paper scene as bistair simulate does: the same images,
    so the same decode; with the rig's calibration also the cloud and depth."""
    sim = tmp_path / "sim"
    code, _, err = run(monkeypatch, capsys, "simulate", "--scene", "paper-sim", "--method",
                       "bidirectional", "--camera", "640x512", "--out", sim)
    assert code == 0, err
    out = tmp_path / "scan"
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", sim / "bidirectional" /
                          "spec.json", "--display", "none", "--camera", "sim:paper-sim:640x512",
                          "--out", out, "--calibration", sim / "calibration.json",
                          "--depth-range", "400:800")
    assert code == 0, err
    assert np.array_equal(read_captures(out), read_captures(sim / "bidirectional"))
    code, _, err = run(monkeypatch, capsys, "decode", sim / "bidirectional", "--out",
                       tmp_path / "simulated")
    assert code == 0, err
    for name in ("coord", "order", "mask", "phase"):
        assert np.array_equal(np.load(out / "decode" / f"{name}.npy"),
                              np.load(tmp_path / "simulated" / f"{name}.npy"), equal_nan=True)
    truth = np.load(sim / "truth" / "coord.npy")
    coord = np.load(out / "decode" / "coord.npy")
    good = np.isfinite(truth) & np.isfinite(coord)
    assert good.mean() > 0.3 and np.median(np.abs(coord - truth)[good]) < 0.3
    depth = np.load(out / "decode" / "depth.npy")
    assert (out / "decode" / "cloud.ply").stat().st_size > 1000
    assert np.nanmin(depth) >= 400 and np.nanmax(depth) <= 800
    assert "points; wrote" in text


def test_a_calibration_for_another_camera_is_refused_before_writing(tmp_path, monkeypatch,
                                                                    capsys):
    sim = tmp_path / "sim"
    code, _, err = run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                       "graycode", "--camera", "64x48", "--out", sim)
    assert code == 0, err
    code, _, err = run(monkeypatch, capsys, "scan", "--spec", sim / "graycode" / "spec.json",
                       "--display", "none", "--camera", "sim:plane:80x60", "--out",
                       tmp_path / "scan", "--calibration", sim / "calibration.json")
    assert code == 2
    assert err.strip() == ("Error: calibration is for 64x48 camera images, "
                           "sim:plane:80x60 delivered 80x60")
    assert not (tmp_path / "scan").exists()


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_mid_scan_leaves_nothing(tmp_path, sig):
    spec = method_specs((1920, 1080), methods=["multifreq"])["multifreq"][0]
    spec_path = _write_spec(spec, tmp_path / "pats")
    runs = tmp_path / "runs"
    runs.mkdir()
    cmd = [sys.executable, "-c", "from bistair.app.cli import main; main()", "scan", "--spec",
           str(spec_path), "--display", "none", "--camera", "sim:plane:320x256", "--out",
           str(runs / "scan")]
    env = {**os.environ, "BISTAIR_PROGRESS_DELAY": "0"}
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            env=env)
    for line in proc.stderr:
        if "pattern 3 of 36" in line:
            break
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=PATIENCE)
    assert proc.returncode != 0 and "Traceback" not in err
    assert list(runs.iterdir()) == []


def test_calibration_workflow_one_scan_per_board_pose(tmp_path):
    """Scan each board pose in both orientations (the virtual rig's board), then calibrate:
    the scan folders are the pose folders 'bistair calibrate' reads."""
    calib = tmp_path / "calib"
    calib.mkdir()
    (calib / "board.json").write_text(json.dumps(SIM_BOARD.to_dict()))
    for pose in range(3):
        for orientation in ("columns", "rows"):
            spec = make_spec("graycode", width=1920, height=1080, period=30, white=1,
                             orientation=orientation)
            scan_folder(spec, "none", f"sim:board-{pose}:640x512",
                        calib / f"pose-{pose:02d}" / orientation)
    cal = calibrate_folder(calib)
    assert len(cal.poses) == 3 and cal.rms < 0.5
    assert abs(cal.baseline - 200.0) < 2.0  # the rig's: 200 mm (201.3 +- 0.5 from 3 poses)
    assert abs(cal.camera.K[0, 0] / 1200.0 - 1) < 0.03  # the rig's: 1.875 * 640 px
