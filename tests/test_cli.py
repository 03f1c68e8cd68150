"""The command line: the documented workflow, and every bad-input path (one line, exit 2,
no traceback, nothing written)."""

import json
import shutil
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest
from conftest import cli_run, warped_scene

import bistair
from bistair.sim.warp import render_warp

run = cli_run


@pytest.fixture()
def pats(tmp_path, monkeypatch, capsys):
    out = tmp_path / "pats"
    code, _, err = run(monkeypatch, capsys, "patterns", "bidirectional", "--width", 480,
                       "--height", 240, "--period", 20, "--partitions", 4, "--stairs", 6,
                       "--out", out)
    assert code == 0, err
    return out


def test_patterns_writes_six_images_and_the_spec(pats):
    names = sorted(p.name for p in pats.iterdir())
    assert names == ["00.png", "01.png", "02.png", "03.png", "04.png", "05.png", "spec.json"]
    spec = json.loads((pats / "spec.json").read_text())
    assert spec["group_rows"] == 30 and spec["local_rows"] == 20 and spec["steps"] == 4
    img = iio.imread(pats / "04.png")
    assert img.shape == (240, 480) and img.dtype == np.uint8


def test_patterns_into_a_folder_of_a_longer_set_leave_only_the_new_frames(pats, monkeypatch,
                                                                          capsys):
    (pats / "notes.txt").write_text("mine")  # a file of the user's: kept
    code, _, err = run(monkeypatch, capsys, "patterns", "bidirectional", "--width", 480,
                       "--height", 240, "--period", 20, "--partitions", 4, "--stairs", 6,
                       "--white", 1, "--out", pats)
    assert code == 0, err
    assert (pats / "06.png").exists()  # the white frame of the set of 7
    code, _, err = run(monkeypatch, capsys, "patterns", "bidirectional", "--width", 480,
                       "--height", 240, "--period", 20, "--partitions", 4, "--stairs", 6,
                       "--out", pats)
    assert code == 0, err
    names = sorted(p.name for p in pats.iterdir())
    assert names == ["00.png", "01.png", "02.png", "03.png", "04.png", "05.png", "notes.txt",
                     "spec.json"]


def test_bare_command_shows_the_help(monkeypatch, capsys):
    code, out, err = run(monkeypatch, capsys)
    assert code == 0 and err == ""
    assert out.startswith("Usage: bistair") and "decode" in out


def test_a_bare_group_shows_its_help(monkeypatch, capsys):
    """``bistair patterns`` alone: its help on stdout, exit 0 (click 8.2 raises a usage
    error for it, which was printed as 'Error: Usage: ...', exit 2)."""
    code, out, err = run(monkeypatch, capsys, "patterns")
    assert (code, err) == (0, "")
    assert out.startswith("Usage: bistair patterns") and "bidirectional" in out


def test_swapped_stair_pair_is_named_in_the_refusal(pats, tmp_path, monkeypatch, capsys):
    spec = json.loads((pats / "spec.json").read_text())
    frames = spec["frames"]
    i, j = frames.index("stair-cos"), frames.index("stair-sin")
    frames[i], frames[j] = frames[j], frames[i]
    (tmp_path / "swapped.json").write_text(json.dumps(spec))
    code, _, err = run(monkeypatch, capsys, "decode", pats, "--spec", tmp_path / "swapped.json",
                       "--out", tmp_path / "o")
    assert code == 2 and not (tmp_path / "o").exists()
    assert "stair-cos and stair-sin" in err, err  # named, whichever check sees it


def test_sixteen_bit_patterns(tmp_path, monkeypatch, capsys):
    code, _, _ = run(monkeypatch, capsys, "patterns", "bidirectional", "--width", 360,
                     "--height", 120, "--period", 20, "--partitions", 3, "--bits", 16,
                     "--out", tmp_path / "p16")
    assert code == 0
    assert iio.imread(tmp_path / "p16" / "00.png").dtype == np.uint16


def test_decode_a_folder_with_the_spec_beside_it(pats, tmp_path, monkeypatch, capsys):
    code, out, err = run(monkeypatch, capsys, "decode", pats, "--out", tmp_path / "res")
    assert code == 0, err
    res = tmp_path / "res"
    for name in ("phase", "coord", "order", "wrapped", "modulation"):
        assert (res / f"{name}.npy").exists()
    for name in ("wrapped", "ks", "order", "phase"):
        assert (res / f"{name}.png").exists()
    coord = np.load(res / "coord.npy")
    phase = np.load(res / "phase.npy")
    order = np.load(res / "order.npy")
    assert coord.dtype == np.float32 and order.dtype == np.int32
    assert np.abs(coord - np.arange(480)[None, :]).max() < 0.05  # 8-bit levels: 0.015 px
    assert np.allclose(phase, 2 * np.pi * coord / 20, atol=1e-4)
    assert np.array_equal(np.isnan(phase), order < 0)
    assert np.array_equal(order, np.broadcast_to(np.arange(480) // 20, order.shape))
    assert "pixels valid" in out


def test_decode_a_synthetic_npy_stack_with_explicit_spec(tmp_path, monkeypatch, capsys):
    import bistair

    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    images, truth = render_warp(spec, warped_scene(0, noise=0.01, blur=1.0))
    stack = (images * 65535).round().astype(np.uint16)  # a 16-bit camera
    np.save(tmp_path / "caps.npy", stack)
    (tmp_path / "my-spec.json").write_text(spec.to_json())
    code, _, err = run(monkeypatch, capsys, "decode", tmp_path / "caps.npy", "--spec",
                       tmp_path / "my-spec.json", "--out", tmp_path / "res", "--no-previews")
    assert code == 0, err
    phase = np.load(tmp_path / "res" / "phase.npy")
    ok = truth.mask & np.isfinite(phase)
    assert ok.sum() > 0.99 * truth.mask.sum()
    assert np.abs(phase[ok] - 2 * np.pi * truth.coord(spec)[ok] / 30).max() < np.pi
    assert not (tmp_path / "res" / "phase.png").exists()


def test_colour_captures_in_natural_name_order(pats, tmp_path, monkeypatch, capsys):
    caps = tmp_path / "caps"
    caps.mkdir()
    for i, src in enumerate(sorted(pats.glob("*.png"))):
        grey = iio.imread(src)
        iio.imwrite(caps / f"frame{i}.bmp", np.stack([grey] * 3, axis=-1))  # 0..5
    shutil.copy(pats / "spec.json", caps / "spec.json")
    code, _, err = run(monkeypatch, capsys, "decode", caps, "--out", tmp_path / "res")
    assert code == 0, err
    assert np.abs(np.load(tmp_path / "res" / "coord.npy") - np.arange(480)).max() < 0.05


def _expect_refusal(monkeypatch, capsys, out, *args, message):
    code, stdout, err = run(monkeypatch, capsys, *args)
    assert code == 2
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and message in lines[0], err
    assert "Traceback" not in err
    if out is not None:
        assert not out.exists() or not any(p for p in out.iterdir() if p.suffix == ".npy")


def _copy(pats, dst):
    shutil.copytree(pats, dst)
    return dst


def test_wrong_frame_count(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    (caps / "05.png").unlink()
    out = tmp_path / "res"
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out,
                    message="needs 6 frames, the captures have 5")


def test_frames_of_different_sizes(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    iio.imwrite(caps / "03.png", np.zeros((100, 100), np.uint8))
    out = tmp_path / "res"
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out,
                    message="frame 03.png is 100x100 but 00.png is 480x240")


def test_frames_of_different_bit_depths(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    iio.imwrite(caps / "02.png", iio.imread(caps / "02.png").astype(np.uint16) * 257)
    _expect_refusal(monkeypatch, capsys, None, "decode", caps, "--out", tmp_path / "r",
                    message="frame 02.png is uint16 but 00.png is uint8")


def test_unreadable_image(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    (caps / "01.png").write_bytes(b"not a png at all")
    out = tmp_path / "res"
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out,
                    message="cannot read image")


def test_missing_captures_and_empty_folder(tmp_path, monkeypatch, capsys):
    _expect_refusal(monkeypatch, capsys, None, "decode", tmp_path / "nope", "--out",
                    tmp_path / "r", message="captures")
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "spec.json").write_text(
        bistair.make_spec("bidirectional", width=1080, height=1080, period=30).to_json())
    _expect_refusal(monkeypatch, capsys, None, "decode", tmp_path / "empty", "--out",
                    tmp_path / "r", message="no PNG, TIFF or BMP images")


def test_spec_not_json_or_missing_fields(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    (caps / "spec.json").write_text("{'method': bidirectional")
    out = tmp_path / "res"
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out,
                    message="is not valid JSON")
    (caps / "spec.json").write_text(json.dumps({"method": "bidirectional", "width": 480}))
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out,
                    message="spec misses field(s): height, steps")
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--spec", tmp_path / "x.json",
                    "--out", out, message="not found")


def test_spec_that_does_not_fit_the_captures(pats, tmp_path, monkeypatch, capsys):
    caps = _copy(pats, tmp_path / "caps")
    spec = json.loads((caps / "spec.json").read_text())
    spec["steps"] = 8
    del spec["frames"]
    (caps / "spec.json").write_text(json.dumps(spec))
    _expect_refusal(monkeypatch, capsys, None, "decode", caps, "--out", tmp_path / "r",
                    message="needs 10 frames")


@pytest.mark.parametrize(("value", "message"), [(2, "captures are dark"),
                                                (255, "captures are saturated")])
def test_dark_or_saturated_captures(pats, tmp_path, monkeypatch, capsys, value, message):
    caps = tmp_path / "caps"
    caps.mkdir()
    shutil.copy(pats / "spec.json", caps)
    for i in range(6):
        iio.imwrite(caps / f"{i:02d}.png", np.full((240, 480), value, np.uint8))
    out = tmp_path / "res"
    _expect_refusal(monkeypatch, capsys, out, "decode", caps, "--out", out, message=message)


def test_output_folder_that_cannot_be_written(pats, tmp_path, monkeypatch, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("in the way")
    _expect_refusal(monkeypatch, capsys, None, "decode", pats, "--out", blocker,
                    message="exists and is not a folder")
    _expect_refusal(monkeypatch, capsys, None, "decode", pats, "--out", blocker / "sub",
                    message="cannot write output folder")
    _expect_refusal(monkeypatch, capsys, None, "patterns", "bidirectional", "--out",
                    blocker / "sub", message="cannot write output folder")


def test_existing_output_folder_keeps_other_files(pats, tmp_path, monkeypatch, capsys):
    out = tmp_path / "res"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    code, _, _ = run(monkeypatch, capsys, "decode", pats, "--out", out)
    assert code == 0
    assert (out / "notes.txt").read_text() == "mine" and (out / "phase.npy").exists()
    assert not [p for p in out.iterdir() if p.name.startswith(".bistair")]


@pytest.mark.parametrize(("args", "message"), [
    (["--period", 29], "narrower than the 1080-px coded axis"),
    (["--local-rows", 15], "equal partition rows"),
    (["--stairs", 1, "--partitions", 40], "stairs must be at least 2"),
    (["--period", 3], "period must be at least 4"),
])
def test_patterns_refuse_parameters_that_cannot_work(tmp_path, monkeypatch, capsys, args,
                                                     message):
    out = tmp_path / "p"
    _expect_refusal(monkeypatch, capsys, out, "patterns", "bidirectional", *args, "--out", out,
                    message=message)
    assert not out.exists()


def test_switches_work_alone_or_with_a_value(tmp_path, monkeypatch, capsys):
    for args, expect in ((["--complementary", "--white"], (1, 1)),
                         (["--complementary", "0", "--white", "1"], (0, 1))):
        out = tmp_path / "-".join(args)
        code, _, err = run(monkeypatch, capsys, "patterns", "graycode", "--period", 30, *args,
                           "--out", out)
        assert code == 0, err
        spec = json.loads((out / "spec.json").read_text())
        assert (spec["complementary"], spec["white"]) == expect


def test_bad_option_value_exits_2(tmp_path, monkeypatch, capsys):
    code, _, err = run(monkeypatch, capsys, "patterns", "bidirectional", "--bits", 12,
                       "--out", tmp_path / "p")
    assert code == 2 and "Traceback" not in err


def test_installed_console_script(tmp_path):
    exe = shutil.which("bistair") or str(__import__("pathlib").Path(sys.executable).parent
                                         / "bistair")
    done = subprocess.run([exe, "decode", str(tmp_path / "none"), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip() == f"Error: captures {tmp_path / 'none'} not found"


def test_a_decode_into_a_folder_of_an_earlier_one_leaves_none_of_its_files(pats, tmp_path,
                                                                           monkeypatch, capsys):
    out = tmp_path / "res"
    out.mkdir()
    (out / "notes.txt").write_text("mine")  # not a decode's file: kept
    assert run(monkeypatch, capsys, "decode", pats, "--out", out)[0] == 0
    assert (out / "ks.png").exists()
    assert run(monkeypatch, capsys, "decode", pats, "--out", out, "--no-previews")[0] == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "coord.npy", "info.json", "mask.npy", "modulation.npy", "notes.txt", "order.npy",
        "phase.npy", "wrapped.npy"]
