"""``bistair scan --scans N`` (issue 32): the pattern set scanned again and again, each scan
written and decoded on worker threads while the next is grabbed; a scan the decode falls
behind on is counted and said, never dropped silently; Ctrl-C and SIGTERM keep the scans
grabbed, whole. The sim camera at a frame rate (``sim:...@FPS``) renders each pattern once.
Nothing here depends on how fast the machine is: counts, files and values only."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import cli_run

from bistair.acquire.cameras import SIM_IMAGING, SimCamera
from bistair.app import scan_series as series
from bistair.app.scan_series import BEHIND, scan_series, summary_lines
from bistair.codecs import decode, encode, make_spec
from bistair.errors import BistairError
from bistair.io.read import read_captures
from bistair.sim import Imaging, preset, render

SPEC = make_spec("graycode", width=1920, height=1080, period=120, complementary=1)  # 9 frames
SIZE = (128, 96)
CAMERA = f"sim:sphere-on-plane:{SIZE[0]}x{SIZE[1]}"
ARRAYS = ("coord.npy", "info.json", "mask.npy", "order.npy", "phase.npy")


def _spec_file(tmp_path: Path) -> Path:
    path = tmp_path / "pats" / "spec.json"
    path.parent.mkdir()
    path.write_text(SPEC.to_json())
    return path


def _check_scan_folder(folder: Path, decoded: bool) -> np.ndarray:
    """A scan folder whole: every frame, spec.json, scan.json; its decode whole or absent."""
    names = sorted(p.name for p in folder.iterdir())
    frames = [f"{i:02d}.png" for i in range(SPEC.frame_count)]
    assert names == sorted([*frames, "scan.json", "spec.json", *(["decode"] if decoded else [])])
    assert len(json.loads((folder / "scan.json").read_text())["frames"]) == SPEC.frame_count
    stack = read_captures(folder)
    assert stack.shape == (SPEC.frame_count, SIZE[1], SIZE[0])
    if decoded:
        assert set(ARRAYS) <= {p.name for p in (folder / "decode").iterdir()}
    return stack


def test_every_scan_is_written_and_decoded_against_the_truth(tmp_path, monkeypatch, capsys):
    out = tmp_path / "series"
    code, text, err = cli_run(monkeypatch, capsys, "scan", "--spec", _spec_file(tmp_path),
                              "--display", "none", "--camera", f"{CAMERA}@200", "--scans", 5,
                              "--decode", "--no-previews", "--backlog", 5, "--out", out)
    assert code == 0, err
    lines = text.strip().splitlines()
    assert lines[0].startswith(f"scanned 5 graycode pattern sets with none and {CAMERA}@200 "
                               "in ") and lines[0].endswith(f"wrote {out}")
    assert lines[1].startswith("decoded 5 of 5 while the next was grabbed (median ")
    data = json.loads((out / "series.json").read_text())
    assert (data["grabbed"], data["decoded"], data["behind"], data["failed"], data["stopped"]) \
        == (5, 5, 0, 0, None)
    assert sorted(p.name for p in out.iterdir()) == [
        *(f"scan-{i:04d}" for i in range(5)), "series.json"]
    # the truth: what the rig's camera sees (the images of bistair simulate: frame k with the
    # noise of frame k) and the projector columns it sees
    rig, scene = preset("sphere-on-plane", camera_size=SIZE)
    images, truth = render(encode(SPEC), rig, scene, Imaging(**SIM_IMAGING))
    want = truth.coord(SPEC)
    for i, record in enumerate(data["scans"]):
        assert record["decoded"] and record["folder"] == f"scan-{i:04d}"
        folder = out / record["folder"]
        stack = _check_scan_folder(folder, decoded=True)
        assert np.array_equal(stack, images)  # at a frame rate: the same images every scan
        coord = np.load(folder / "decode" / "coord.npy")
        assert np.array_equal(coord, decode(stack, SPEC).coord, equal_nan=True)
        good = np.isfinite(coord) & np.isfinite(want)
        assert record["valid"] == pytest.approx(np.isfinite(coord).mean(), abs=1e-6)
        error = np.abs(coord - want)[good]  # (a camera pixel spans 15 projector columns)
        assert good.mean() > 0.85 and np.median(error) < 1.0 and np.mean(error > 30) < 0.01


class _HeldCamera(SimCamera):
    """The sim camera, which waits before the second scan until the decoder has begun the
    first."""

    def __init__(self, begun: threading.Event) -> None:
        super().__init__("sphere-on-plane", SIZE)
        self.begun = begun

    def grab(self):
        if self.grabs == SPEC.frame_count:  # the second scan's first frame
            assert self.begun.wait(60)
        return super().grab()


@pytest.mark.parametrize("backlog", [1, 2])
def test_scans_the_decode_falls_behind_on_are_counted_and_said(tmp_path, monkeypatch, backlog):
    """The first decode is held until every scan is grabbed (the grab loop never waits for
    it): one decode under way, ``backlog`` scans waiting, the others not decoded, counted
    and said, whatever the machine's speed."""
    begun, release = threading.Event(), threading.Event()

    def slow(frames, spec):
        if frames.shape[1:] == (SIZE[1], SIZE[0]):  # a scan (not the decoder's warm-up)
            begun.set()
            assert release.wait(60)
        return decode(frames, spec)

    finish = series._Pipeline.finish

    def finished(pipe, stop):  # every scan is grabbed and handed on: let the decoder go
        release.set()
        finish(pipe, stop)

    monkeypatch.setattr(series, "decode_stack", slow)
    monkeypatch.setattr(series._Pipeline, "finish", finished)
    count = 5
    out = tmp_path / "series"
    report = scan_series(SPEC, "none", _HeldCamera(begun), out, count, decode=True,
                         backlog=backlog, previews=False)
    decoded = [r["decoded"] for r in report.records]
    assert decoded == [True] * (1 + backlog) + [False] * (count - 1 - backlog)
    assert [r["not_decoded"] for r in report.records[1 + backlog:]] == [BEHIND] * (
        count - 1 - backlog)
    assert report.count("behind") == count - 1 - backlog
    assert report.info["most_waiting"] == backlog
    for record in report.records:  # every scan's captures, decoded or not
        _check_scan_folder(out / record["folder"], decoded=record["decoded"])
    data = json.loads((out / "series.json").read_text())
    assert (data["decoded"], data["behind"]) == (1 + backlog, count - 1 - backlog)
    lines, warnings = summary_lines(report)
    assert lines[1].startswith(f"decoded {1 + backlog} of {count} while the next was grabbed")
    rate = report.info["scans_per_s"]  # how far behind: a decode's time against a scan's
    assert any(w.startswith(f"{count - 1 - backlog} of {count} scans not decoded: the decode ("
                            "median ") and f"bistair batch {out} --out RESULT" in w
               and f"scans/s, one every {1e3 / rate:.0f} ms)" in w for w in warnings), warnings


def test_the_camera_keeps_its_frame_rate(tmp_path, monkeypatch):
    """At 50 frames a second frame k comes no sooner than k / 50 s after the first (a lower
    bound: the camera sleeps until a frame is due, and delivers one asked for late at once,
    as from its buffer), and it renders each pattern once."""
    rendered = []
    render_one = SimCamera._render
    monkeypatch.setattr(SimCamera, "_render", lambda self, shown, frame: (
        rendered.append(frame), render_one(self, shown, frame))[1])
    camera = SimCamera("plane", (48, 32), fps=50)
    report = scan_series(SPEC, "none", camera, tmp_path / "s", 2)
    assert rendered == list(range(SPEC.frame_count))  # pattern k with the noise of frame k
    grabbed = [t for r in range(2) for t in json.loads(
        (tmp_path / "s" / f"scan-000{r}" / "scan.json").read_text())["frames"]]
    assert len(grabbed) == 2 * SPEC.frame_count
    assert (report.count("decoded"), report.count("failed")) == (0, 0)  # none asked for
    times = np.array([f["grabbed"][0] for f in grabbed[:SPEC.frame_count]])
    assert np.all(times - times[0] >= np.arange(SPEC.frame_count) / 50 - 1e-3)
    assert camera.grabs == 2 * SPEC.frame_count


@pytest.mark.parametrize(("args", "message"), [
    (["--scans", "0"], "--scans must be a whole number from 1 to 1000000, got 0"),
    (["--scans", "3", "--decode", "--backlog", "0"],
     "--backlog must be a whole number from 1 to 100, got 0"),
    (["--backlog", "3"], "--backlog applies to --scans N with --decode"),
    (["--scans", "3", "--backlog", "3"], "--backlog applies to --scans N with --decode"),
    (["--compress-captures"], "--compress-captures applies to --scans N (one scan's captures "
                              "are always compressed)"),
    (["--scans", "3", "--calibration", "c.json"], "--calibration applies to one scan"),
    (["--camera", "sim:plane:64x48@0"], "the frame rate of camera 'sim:plane:64x48@0' must be"),
    (["--camera", "sim@fast"], "the frame rate of camera 'sim@fast' must be a number"),
    (["--camera", "sim:plane@5000"], "the frame rate of the sim camera must be above 0 and at "
                                     "most 1000"),
])
def test_bad_series_options_one_line_nothing_written(tmp_path, monkeypatch, capsys, args,
                                                     message):
    base = ["scan", "--spec", _spec_file(tmp_path), "--display", "none", "--out",
            tmp_path / "out"]
    if "--camera" not in args:
        base += ["--camera", "sim:plane:64x48@100"]
    code, out, err = cli_run(monkeypatch, capsys, *base, *args)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and message in err, err
    assert not (tmp_path / "out").exists()


def test_a_series_replaces_an_earlier_one_whole(tmp_path):
    out = tmp_path / "series"
    scan_series(SPEC, "none", "sim:plane:48x32@500", out, 3)
    scan_series(SPEC, "none", "sim:plane:48x32@500", out, 2)
    assert sorted(p.name for p in out.iterdir()) == ["scan-0000", "scan-0001", "series.json"]
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(BistairError, match="holds files and is not an earlier scan"):
        scan_series(SPEC, "none", "sim:plane:48x32@500", other, 2)


class _StopAt:
    """A queue's put that raises KeyboardInterrupt (a Ctrl-C) at its ``at``-th call, before
    or after the item is queued."""

    def __init__(self, put, at: int, after: bool) -> None:
        self.put, self.at, self.after, self.calls = put, at, after, 0

    def __call__(self, queue, item, *args, **kwargs):
        if item is None or item[0] is None:  # the end of the series, the decoder's warm-up
            return self.put(queue, item, *args, **kwargs)
        self.calls += 1
        if self.calls == self.at and not self.after:
            raise KeyboardInterrupt
        self.put(queue, item, *args, **kwargs)
        if self.calls == self.at:
            raise KeyboardInterrupt


@pytest.mark.parametrize(("where", "after", "listed"), [
    ("writes", False, 2),  # scan 3 never reached the writer: left out
    ("writes", True, 3),  # written, never handed to the decoder: stopped before its decode
    ("decodes", False, 3),
])
def test_a_stop_between_handing_a_scan_on_leaves_the_records_whole(tmp_path, monkeypatch,
                                                                    where, after, listed):
    """Ctrl-C may come between any two steps of handing a scan on (to the writer, then the
    decoder): series.json lists exactly the scan folders written, each decoded or stopped
    before its decode (the decodes still waiting when it came are not begun)."""
    import queue

    pipeline = series._Pipeline.__init__

    def init(pipe, *args, **kwargs):
        pipeline(pipe, *args, **kwargs)
        target = getattr(pipe, where)
        stop = _StopAt(queue.Queue.put, 3, after)
        target.put = lambda item, *a, **k: stop(target, item, *a, **k)

    monkeypatch.setattr(series._Pipeline, "__init__", init)
    out = tmp_path / "series"
    with pytest.raises(KeyboardInterrupt):
        scan_series(SPEC, "none", "sim:sphere-on-plane:128x96@500", out, 5, decode=True,
                    backlog=5, previews=False)
    data = json.loads((out / "series.json").read_text())
    assert data["stopped"] == "KeyboardInterrupt" and data["grabbed"] == listed
    assert all(r["decoded"] or r["not_decoded"] == "stopped before its decode"
               for r in data["scans"])
    if listed == 3:  # the scan the stop came at was written, not decoded
        assert not data["scans"][2]["decoded"]
    assert data["decoded"] + data["stopped_before_decode"] == listed
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == [
        r["folder"] for r in data["scans"]]
    for record in data["scans"]:
        _check_scan_folder(out / record["folder"], decoded=record["decoded"])


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_mid_series_keeps_the_scans_grabbed_whole(tmp_path, sig):
    """Stopped while scans are grabbed, written and decoded: the command stops (not exit 0,
    no traceback), no temporary is left, every scan folder is whole with its decode whole or
    absent, and series.json lists exactly those scans and says it was stopped."""
    spec_path = _spec_file(tmp_path)
    runs = tmp_path / "runs"
    runs.mkdir()
    cmd = [sys.executable, "-c", "from bistair.app.cli import main; main()", "scan", "--spec",
           str(spec_path), "--display", "none", "--camera", f"{CAMERA}@100", "--scans",
           "100000", "--decode", "--no-previews", "--out", str(runs / "series")]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if len(list(runs.glob(f".bistair-{proc.pid}-*/scan-*/scan.json"))) >= 3:
            break
        time.sleep(0.05)
    else:
        pytest.fail("the series never wrote its third scan")
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode != 0 and "Traceback" not in err, err
    assert [p.name for p in runs.iterdir()] == ["series"]  # no temporary left
    out = runs / "series"
    data = json.loads((out / "series.json").read_text())
    assert data["stopped"] in ("KeyboardInterrupt", "SystemExit")
    folders = sorted(p.name for p in out.iterdir() if p.is_dir())
    assert folders == [r["folder"] for r in data["scans"]] and len(folders) >= 3
    for record in data["scans"]:
        _check_scan_folder(out / record["folder"], decoded=record["decoded"])
    assert data["decoded"] >= 1
    assert os.path.getsize(out / "series.json") > 0


def test_captures_stored_or_compressed_read_the_same(tmp_path, monkeypatch, capsys):
    """A series stores its captures' PNG (a tenth of the CPU time of deflating them) unless
    --compress-captures: either way 'bistair decode' reads the same pixel values and
    decodes them to the same numbers; the stored files hold every byte of the frame."""
    spec_path = _spec_file(tmp_path)
    outs = {}
    for name, extra in (("stored", []), ("deflated", ["--compress-captures"])):
        outs[name] = tmp_path / name
        code, _, err = cli_run(monkeypatch, capsys, "scan", "--spec", spec_path, "--display",
                               "none", "--camera", f"{CAMERA}@500", "--scans", 2, *extra,
                               "--out", outs[name])
        assert code == 0, err
        data = json.loads((outs[name] / "series.json").read_text())
        assert data["compress_captures"] is bool(extra)
        assert set(data["cpu_s"]) == {"grab", "write", "decode", "outputs", "process"}
        assert data["cpu_s"]["write"] > 0 and data["cpu_s"]["decode"] == 0  # none asked for
    rig, scene = preset("sphere-on-plane", camera_size=SIZE)
    images, _ = render(encode(SPEC), rig, scene, Imaging(**SIM_IMAGING))
    decoded = {}
    for name, out in outs.items():
        folder = out / "scan-0001"
        assert np.array_equal(_check_scan_folder(folder, decoded=False), images)
        code, _, err = cli_run(monkeypatch, capsys, "decode", folder, "--no-previews",
                               "--out", tmp_path / f"{name}-decode")
        assert code == 0, err
        decoded[name] = [np.load(tmp_path / f"{name}-decode" / f) for f in ARRAYS
                         if f.endswith(".npy")]
    for stored, deflated in zip(decoded["stored"], decoded["deflated"], strict=True):
        assert np.array_equal(stored, deflated, equal_nan=True)
    sizes = {name: sum(p.stat().st_size for p in (out / "scan-0000").glob("*.png"))
             for name, out in outs.items()}
    assert sizes["stored"] >= images.size > sizes["deflated"]  # 8-bit frames: a byte a pixel


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_a_stored_png_reads_back_bit_for_bit(tmp_path, dtype):
    """Stored PNG of 8- and 16-bit grey frames (a 12-bit camera's too: the byte order of
    PNG) reads back to the same values as deflated PNG, and is no smaller than the frame."""
    from bistair.io.atomic import write_image
    from bistair.io.read import read_image

    top = np.iinfo(dtype).max
    image = (np.add.outer(np.arange(64), np.arange(80)) * (top // 160)).astype(dtype)  # a ramp
    image[0, :4] = (0, 1, top - 1, top)
    image[5, 7:9] = np.random.default_rng(5).integers(0, top, 2, endpoint=True)
    for compress in (True, False):
        path = tmp_path / f"{compress}.png"
        write_image(path, image, compress=compress)
        back = read_image(path)
        assert back.dtype == image.dtype and np.array_equal(back, image)
    assert (tmp_path / "False.png").stat().st_size >= image.nbytes > \
        (tmp_path / "True.png").stat().st_size


def test_the_decoder_goes_on_while_a_decode_is_written(tmp_path, monkeypatch):
    """A decode's files and previews are written on their own thread: the decoder decodes
    the next scan while the first scan's outputs are still being written (held here until
    it has), and every scan ends decoded with its previews."""
    decoded_two = threading.Event()
    decodes = []

    def counted(frames, spec):
        result = decode(frames, spec)
        if frames.shape[1:] == (SIZE[1], SIZE[0]):  # a scan (not the decoder's warm-up)
            decodes.append(1)
            if len(decodes) == 2:
                decoded_two.set()
        return result

    save = series.save_result
    held = []

    def held_save(result, folder, previews):
        if not held:
            held.append(decoded_two.wait(60))  # False if the decoder waits for this write
        return save(result, folder, previews=previews)

    monkeypatch.setattr(series, "decode_stack", counted)
    monkeypatch.setattr(series, "save_result", held_save)
    out = tmp_path / "series"
    report = scan_series(SPEC, "none", f"{CAMERA}@500", out, 3, decode=True, backlog=3)
    assert held == [True]
    assert report.count("decoded") == 3
    for record in report.records:
        _check_scan_folder(out / record["folder"], decoded=True)
        assert (out / record["folder"] / "decode" / "phase.png").is_file()
