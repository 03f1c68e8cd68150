"""bistair scan on a real window system: an X server of the test's own (Xvfb, 1920x1080,
24-bit), the window display (SDL2 through pygame) and the screen camera (mss).

- A screenshot of the window showing a pattern equals the pattern image bit for bit.
- ``bistair scan --display window --camera screen --decode`` of every method, both axes,
  gives projector coordinates equal to the screen's pixel columns and rows within 0.05 px
  on at least 99.9% of the pixels.
- ``--measure-latency`` times the camera and the next scan settles that long.

The tests skip only where no X server can be started (no Xvfb, or it fails), and say so;
``.ci/run`` installs Xvfb with apt where it is missing.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from conftest import PATIENCE, cli_run
from support.xserver import own_xvfb

from bistair.acquire import displays
from bistair.acquire.cameras import ScreenCamera
from bistair.acquire.displays import WindowDisplay
from bistair.app.patterns import save_patterns
from bistair.codecs import make_spec, methods
from bistair.errors import BistairError
from bistair.evaluation.benchmark import method_specs
from bistair.io.read import read_captures

SCREEN = (1920, 1080)
run = cli_run


@pytest.fixture(scope="module")
def xvfb():
    """The display (``:N``) of an Xvfb of this module's own, 1920x1080, on a free number."""
    with own_xvfb(SCREEN) as display:
        yield display


@pytest.fixture()
def x11(xvfb, monkeypatch):
    """The tests' X server as the window system (whatever DISPLAY the user has)."""
    monkeypatch.setenv("DISPLAY", xvfb)
    monkeypatch.setenv("SDL_VIDEODRIVER", "x11")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    return xvfb


def test_a_screenshot_of_the_window_equals_the_pattern(x11, tmp_path):
    spec = method_specs(SCREEN, methods=["bidirectional"])["bidirectional"][0]
    pats = save_patterns(spec, tmp_path / "pats")
    images = read_captures(pats)
    grey = np.random.default_rng(7).integers(0, 256, SCREEN[::-1], dtype=np.uint8)
    small = images[4, :700, :1300]  # a pattern smaller than the screen: top-left, black around
    with WindowDisplay() as window, ScreenCamera() as camera:
        assert window.size == SCREEN
        for image in (images[0], images[4], grey):
            window.show(image)
            assert np.array_equal(camera.grab().image, image)
        window.show(small)
        shot = camera.grab().image
        assert np.array_equal(shot[:700, :1300], small) and not shot[700:].any()
        assert not shot[:, 1300:].any()


def test_sixteen_bit_patterns_show_their_nearest_8_bit_codes(x11):
    codes = (np.arange(SCREEN[0], dtype=np.uint32) * 65535 // (SCREEN[0] - 1)).astype(np.uint16)
    image = np.repeat(codes[None], SCREEN[1], axis=0)
    with WindowDisplay() as window, ScreenCamera() as camera:
        window.show(image)
        assert np.array_equal(camera.grab().image, np.round(image / 257).astype(np.uint8))


def _specs() -> dict:
    """Every method at the screen's size, both axes (multifreq with 4 steps a period, to
    keep the scan short)."""
    out = {}
    for method in methods():
        spec = method_specs(SCREEN, methods=[method])[method][0]
        if method == "multifreq":
            spec = spec.replace(steps=4)
        out[method] = spec.replace(orientation="both")
    return out


@pytest.mark.parametrize("method", methods())
def test_every_method_decodes_to_the_screen_pixels(x11, tmp_path, monkeypatch, capsys,
                                                   method):
    spec = _specs()[method]
    path = tmp_path / "spec.json"
    path.write_text(spec.to_json())
    out = tmp_path / "scan"
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", path, "--display", "window",
                          "--camera", "screen", "--settle-ms", 20, "--out", out, "--decode")
    assert code == 0, err
    assert f"scanned {spec.frame_count} {method} patterns with window:0 and screen:0" in text
    columns = np.load(out / "decode" / "coord_x.npy")
    rows = np.load(out / "decode" / "coord_y.npy")
    assert columns.shape == rows.shape == SCREEN[::-1]
    near_x = np.abs(columns - np.arange(SCREEN[0])[None, :]) < 0.05  # NaN: not near
    near_y = np.abs(rows - np.arange(SCREEN[1])[:, None]) < 0.05
    assert near_x.mean() >= 0.999 and near_y.mean() >= 0.999, (near_x.mean(), near_y.mean())
    info = json.loads((out / "scan.json").read_text())
    assert info["display"]["size"] == list(SCREEN) and info["settle_ms"] == 20
    shown = [f["shown"] for f in info["frames"]]
    assert all(f["settled"] - f["shown"] >= 0.0199 for f in info["frames"])  # 0.1-ms steps
    assert all(f["grabbed"][0] >= f["settled"] for f in info["frames"])
    assert shown == sorted(shown)


def test_measured_latency_is_the_next_scans_settle_time(x11, tmp_path, monkeypatch, capsys):
    latency = tmp_path / "latency.json"
    code, text, err = run(monkeypatch, capsys, "scan", "--measure-latency", "--display",
                          "window", "--camera", "screen", "--latency-file", latency)
    assert code == 0, err
    assert text.startswith("latency window:0 -> screen:0: ") and "over 6 changes" in text
    saved = json.loads(latency.read_text())["pairs"]["window:0 screen:0"]
    assert saved["white"] > 0.99 and saved["black"] < 0.01 and len(saved["latencies_ms"]) == 6
    spec = make_spec("phase-coding", width=960, height=540, period=30)
    (tmp_path / "spec.json").write_text(spec.to_json())
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", tmp_path / "spec.json",
                          "--display", "window", "--camera", "screen", "--out",
                          tmp_path / "scan", "--latency-file", latency)
    assert code == 0 and "Warning" not in err, err
    info = json.loads((tmp_path / "scan" / "scan.json").read_text())
    assert (info["settle_ms"], info["settle_source"]) == (saved["settle_ms"], "measured")


def test_patterns_larger_than_the_screen_are_refused(x11, tmp_path, monkeypatch, capsys):
    spec = make_spec("graycode", width=2560, height=1440, period=40)
    (tmp_path / "spec.json").write_text(spec.to_json())
    code, text, err = run(monkeypatch, capsys, "scan", "--spec", tmp_path / "spec.json",
                          "--display", "window", "--camera", "screen", "--out",
                          tmp_path / "scan")
    assert code == 2 and text == ""
    assert err.strip() == ("Error: the spec's 2560x1440 patterns do not fit window:0 "
                           "(1920x1080): the patterns are shown pixel for pixel, never scaled")
    assert not (tmp_path / "scan").exists()


def test_screens_and_monitors_that_are_not_there(x11):
    with pytest.raises(BistairError, match=r"window:1: the window system has 1 screen \("):
        with WindowDisplay(1):
            pass
    with pytest.raises(BistairError, match="screen:1: there is 1 monitor"):
        with ScreenCamera(1):
            pass


def test_the_x_server_outlives_its_clients(x11):
    """Screenshot connections and windows opened and closed one after the other, each the
    server's only client: an X server that resets when its last client leaves refuses about
    one connection in three meanwhile ('Cannot connect to display', issue 31)."""
    for _ in range(100):
        with ScreenCamera() as camera:
            assert camera.describe()["area"]["width"] == SCREEN[0]
    for _ in range(5):
        with WindowDisplay() as window:
            assert window.size == SCREEN


def test_each_x_server_takes_a_display_of_its_own(x11, monkeypatch):
    """A second server started beside the module's takes another free number, and each
    answers for itself (another X server on the machine is never in the way)."""
    with own_xvfb((640, 480)) as other:
        assert other != x11
        for display, size in ((x11, SCREEN), (other, (640, 480))):
            monkeypatch.setenv("DISPLAY", display)
            with ScreenCamera() as camera:
                assert camera.grab().image.shape == size[::-1]


def test_no_window_system_is_one_line(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    with pytest.raises(BistairError, match="no window system"):
        with WindowDisplay():
            pass
    with pytest.raises(BistairError, match="cannot open camera screen:0"):
        with ScreenCamera():
            pass


def test_escape_in_the_window_stops_like_ctrl_c(x11):
    pygame = displays.pygame  # imported there, after its greeting is turned off
    with pytest.raises(KeyboardInterrupt), WindowDisplay() as window:
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE))
        window.wait(time.monotonic() + 5)
    assert not pygame.display.get_init()  # the window is closed


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_closes_the_window_and_writes_nothing(x11, tmp_path):
    spec = make_spec("graycode", width=1920, height=1080, period=30, complementary=1)
    (tmp_path / "spec.json").write_text(spec.to_json())
    runs = tmp_path / "runs"
    runs.mkdir()
    cmd = [sys.executable, "-c", "from bistair.app.cli import main; main()", "scan", "--spec",
           str(tmp_path / "spec.json"), "--display", "window", "--camera", "screen",
           "--settle-ms", 400, "--out", str(runs / "scan")]
    env = {**os.environ, "BISTAIR_PROGRESS_DELAY": "0"}
    proc = subprocess.Popen(list(map(str, cmd)), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, env=env)
    for line in proc.stderr:
        if "pattern 3 of 11" in line:
            break
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=PATIENCE)
    assert proc.returncode == 1 and "Aborted" in err and "Traceback" not in err
    assert list(runs.iterdir()) == []
