"""genicam: GenICam cameras through harvesters. No GenTL producer is installed here, so the
grab loop runs against a stand-in with the harvesters API's shape
(``support/scan_devices.py``): the settings reach their nodes, buffered frames are dropped,
frames are averaged, every refusal is one line with exit 2 and nothing written, and the
camera is released on every way out (Ctrl-C included)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from conftest import cli_run
from support import scan_devices

from bistair.acquire import genicam, scan
from bistair.acquire.loop import pattern_images
from bistair.app import scan as scan_job
from bistair.codecs import decode, make_spec
from bistair.errors import BistairError

SIZE = (480, 240)


@pytest.fixture()
def spec():
    return make_spec("phase-coding", width=SIZE[0], height=SIZE[1], period=30)


@pytest.fixture()
def producer(tmp_path):
    path = tmp_path / "vendor" / "producer.cti"
    path.parent.mkdir()
    path.write_bytes(b"a stand-in for a vendor's GenTL producer")
    return path


@pytest.fixture()
def harvester(monkeypatch):
    """The stand-in Harvester class, watching a screen the loop drives."""
    stand_in = type("StandIn", (scan_devices.Harvester,),
                    {"screen": scan_devices.Screen(SIZE), "made": []})
    monkeypatch.setattr(genicam, "Harvester", stand_in)
    monkeypatch.setattr(scan_job, "parse_display", lambda text: stand_in.screen)
    return stand_in


def _released(harvester) -> bool:
    made = harvester.made[-1]
    return made.was_reset and all(a.stopped and a.destroyed for a in made.acquirers)


def test_grab_loop_drops_buffered_frames_and_averages(spec, producer, harvester):
    result = scan(spec, harvester.screen, f"genicam:{producer}", settle_ms=0, average=2,
                  pixel_format="Mono16")
    expected = pattern_images(spec).astype(np.uint16) * 257  # 8-bit codes seen in 16 bits
    assert result.frames.dtype == np.uint16
    assert np.array_equal(result.frames, expected)  # +-2 codes of noise averaged away
    assert [r["dropped"] for r in result.records] == [0] + [3] * (len(expected) - 1)
    assert all(len(r["grabbed"]) == 2 and len(r["stamps"]) == 2 for r in result.records)
    acquirer = harvester.made[-1].acquirers[0]
    assert acquirer.nodes["PixelFormat"].value == "Mono16"
    assert acquirer.queued_back == acquirer.delivered  # every buffer handed back
    assert _released(harvester)
    assert result.info["camera"]["serial"] == "S1"
    coord = decode(result.frames, spec).coord
    assert np.abs(coord - np.arange(SIZE[0])[None, :]).max() < 0.05


def test_without_dropping_the_frames_show_the_pattern_before(spec, producer, harvester):
    harvester.noise = 0
    result = scan(spec, harvester.screen, f"genicam:{producer}", settle_ms=0, drop=0)
    images = pattern_images(spec)
    assert np.array_equal(result.frames[0], images[0])
    assert np.array_equal(result.frames[1], images[0])  # a stale frame, not pattern 1


def test_settings_reach_their_nodes(spec, producer, harvester):
    scan(spec, harvester.screen, f"genicam:{producer}:S1", settle_ms=0, exposure=5000,
         gain=6, pixel_format="Mono12")
    nodes = harvester.made[-1].acquirers[0].nodes
    assert (nodes["ExposureTime"].value, nodes["Gain"].value,
            nodes["PixelFormat"].value) == (5000, 6, "Mono12")


def test_a_refused_setting_is_one_line_and_releases_the_camera(spec, producer, harvester):
    with pytest.raises(BistairError, match=r"refused ExposureTime = 1: OutOfRange"):
        scan(spec, harvester.screen, f"genicam:{producer}", settle_ms=0, exposure=1)
    assert _released(harvester)
    harvester.missing_nodes = ("Gain",)
    with pytest.raises(BistairError, match="has no Gain or GainRaw node"):
        scan(spec, harvester.screen, f"genicam:{producer}", settle_ms=0, gain=3)
    assert _released(harvester)


def _scan(monkeypatch, capsys, spec, tmp_path, camera, *extra, display="test"):
    """``bistair scan`` in this process; the display ``test`` is the stand-in's screen."""
    (tmp_path / "spec.json").write_text(spec.to_json())
    return cli_run(monkeypatch, capsys, "scan", "--spec", tmp_path / "spec.json", "--display",
                   display, "--camera", camera, "--out", tmp_path / "out", "--settle-ms", 0,
                   *extra)


def _nothing_written(tmp_path) -> bool:
    return sorted(p.name for p in tmp_path.iterdir()) == ["spec.json", "vendor"]


@pytest.mark.parametrize(("camera", "setup", "message"), [
    ("genicam:{dir}/missing.cti", {}, "GenTL producer file .*missing.cti not found"),
    ("genicam:{dir}/producer.cti", {"devices": ()}, "no GenICam camera found through"),
    ("genicam:{dir}/producer.cti:S9", {"devices": ("S1", "S2")},
     r"no GenICam camera with serial S9 .*\(found: S1, S2\)"),
    ("genicam:{dir}/producer.txt", {}, "must be genicam:PRODUCER.cti"),
    ("genicam:{dir}/producer.cti", {"grow_after": 4},
     "delivered a 480x242 frame after 480x240 ones: frames of changing size"),
])
def test_bad_cameras_one_line_exit_2_nothing_written(monkeypatch, capsys, spec, tmp_path,
                                                     producer, harvester, camera, setup,
                                                     message):
    for key, value in setup.items():
        setattr(harvester, key, value)
    code, out, err = _scan(monkeypatch, capsys, spec, tmp_path,
                           camera.format(dir=producer.parent))
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("Error: ")
    assert re.search(message, err), err
    assert _nothing_written(tmp_path)
    if harvester.made and harvester.made[-1].acquirers:
        assert _released(harvester)


def test_without_harvesters_the_error_names_the_extra(monkeypatch, capsys, spec, tmp_path,
                                                      producer):
    monkeypatch.setattr(genicam, "Harvester", None)
    code, _, err = _scan(monkeypatch, capsys, spec, tmp_path, f"genicam:{producer}",
                         display="none")
    assert code == 2
    assert err.strip() == ("Error: genicam cameras need harvesters: pip install "
                           "'bistair[genicam]'")
    assert _nothing_written(tmp_path)


def test_ctrl_c_releases_the_camera_and_writes_nothing(monkeypatch, capsys, spec, tmp_path,
                                                       producer, harvester):
    harvester.interrupt_after = 7
    code, out, err = _scan(monkeypatch, capsys, spec, tmp_path, f"genicam:{producer}")
    assert code == 1 and "Aborted" in err and "Traceback" not in err
    assert _released(harvester) and harvester.screen.closed == 1
    assert _nothing_written(tmp_path)


def test_a_scan_writes_a_capture_folder(monkeypatch, capsys, spec, tmp_path, producer,
                                        harvester):
    code, out, err = _scan(monkeypatch, capsys, spec, tmp_path, f"genicam:{producer}",
                           "--pixel-format", "Mono16", "--exposure", 2000, "--decode")
    assert code == 0, err
    folder = tmp_path / "out"
    assert "scanned 6 phase-coding patterns" in out and "16-bit frames" in out
    scan_json = json.loads((folder / "scan.json").read_text())
    assert scan_json["camera"]["exposure"] == 2000
    assert scan_json["camera"]["pixel_format"] == "Mono16"
    coord = np.load(folder / "decode" / "coord.npy")
    assert np.abs(coord - np.arange(SIZE[0])[None, :]).max() < 0.05
