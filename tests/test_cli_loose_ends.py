"""Loose ends of the command line (issue 34 and earlier), as a new user meets them: ``stereo
--window`` honours ``--no-previews`` and refuses ``--smooth`` (one period is unwrapped by the
projector, with no smoothing; so is the one-set ``stereo`` of a single-period spec),
``simulate --motion`` refuses an empty motion, every command that writes files takes
``-q/--quiet``, and a stereo calibration carries the pixel origin its file records."""

from __future__ import annotations

import json

import click
import imageio.v3 as iio
import numpy as np
import pytest
from conftest import cli_run

from bistair.app.cli import cli
from bistair.app.simulate_motion import simulate_motion
from bistair.app.stereo import stereo_folder
from bistair.app.stereo_stream import stereo_stream
from bistair.geometry.calibration import StereoCalibration, load_calibration, save_calibration
from bistair.geometry.projection_matrices import save_matrix_calibration, with_pixel_origin
from bistair.io.read import read_captures

SIZE = (160, 120)
RANGE = "520:650"  # two-masks lies at 559-633 mm


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    """Six frames of two-masks (4 steps, period 48, the masks moving 2 mm nearer a frame),
    two cameras 200 mm apart, the projector halfway."""
    out = tmp_path_factory.mktemp("loose-ends") / "sim"
    return simulate_motion("two-masks", ["multifreq"], out, "0,0,-2mm", frames=6,
                           continuous=True, cameras=2, camera_size=SIZE, period=48)


def _stream_args(sim, out):
    return ["stereo", sim / "multifreq" / "L", sim / "multifreq" / "R", "--calibration",
            sim / "stereo.json", "--depth-range", RANGE, "--window", "4", "--out", out]


def test_a_stream_writes_each_windows_depth_preview_unless_no_previews(sim, tmp_path,
                                                                       monkeypatch, capsys):
    """As the one-set ``stereo`` writes ``depth.png`` beside ``depth.npy``, so does each
    window; ``--no-previews`` (ignored by ``--window`` before) leaves it out, and the depth
    is the same either way."""
    shown, bare = tmp_path / "shown", tmp_path / "bare"
    code, _, err = cli_run(monkeypatch, capsys, *_stream_args(sim, shown))
    assert code == 0, err
    code, _, err = cli_run(monkeypatch, capsys, *_stream_args(sim, bare), "--no-previews")
    assert code == 0, err
    assert sorted(p.name for p in shown.iterdir()) == ["0000", "0001", "0002"]
    for start in ("0000", "0001", "0002"):
        assert sorted(p.name for p in (shown / start).iterdir()) == [
            "cloud.ply", "depth.npy", "depth.png", "info.json"]
        assert sorted(p.name for p in (bare / start).iterdir()) == [
            "cloud.ply", "depth.npy", "info.json"]
        depth = np.load(shown / start / "depth.npy")
        assert depth.dtype == np.float32 and np.isfinite(depth).mean() > 0.3
        assert np.array_equal(depth, np.load(bare / start / "depth.npy"), equal_nan=True)
        png = iio.imread(shown / start / "depth.png")
        assert png.shape[0] == depth.shape[0] and png.shape[1] >= depth.shape[1]
        # undecided pixels are black, decided ones coloured
        image = png[:, :depth.shape[1], :3].astype(int).sum(-1)
        assert np.all(image[~np.isfinite(depth)] == 0) and np.all(image[np.isfinite(depth)] > 0)


def test_smooth_is_refused_where_nothing_is_smoothed(sim, tmp_path, monkeypatch, capsys):
    """``--smooth`` smooths the projector coordinates that matching compares; stereo phase
    unwrapping (a stream, or one set of one period) compares none: asked for, it is refused
    in one line (exit 2, nothing written) rather than ignored."""
    out = tmp_path / "out"
    code, _, err = cli_run(monkeypatch, capsys, *_stream_args(sim, out), "--smooth", "2")
    assert code == 2 and "--smooth does not apply to a stream" in err, err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
    one_set = tmp_path / "one"
    np.save(tmp_path / "L.npy", read_captures(sim / "multifreq" / "L")[:4])
    np.save(tmp_path / "R.npy", read_captures(sim / "multifreq" / "R")[:4])
    args = ["stereo", tmp_path / "L.npy", tmp_path / "R.npy", "--spec",
            sim / "multifreq" / "L" / "spec.json", "--calibration", sim / "stereo.json",
            "--depth-range", RANGE, "--out", one_set]
    code, _, err = cli_run(monkeypatch, capsys, *args, "--smooth", "0")
    assert code == 2 and "--smooth does not apply to a single-period spec" in err, err
    assert len(err.strip().splitlines()) == 1 and not one_set.exists()
    code, printed, err = cli_run(monkeypatch, capsys, *args)  # not asked for: runs
    assert code == 0 and "by the projector at 520-650 mm" in printed, err


@pytest.mark.parametrize("motion", ["", "1,2", "x", "1,2,3px", "0,0mm", "nanpx", "1e999px",
                                    "0,0,0mm,1deg", "1px,2deg"])
def test_a_motion_that_is_no_motion_is_refused(tmp_path, monkeypatch, capsys, motion):
    """``--motion ""`` rendered a still scene as if no --motion had been given; it and
    every other malformed motion (wrong arity, no unit, not a number, NaN, infinite) exit
    2 with one line naming it, and write nothing."""
    out = tmp_path / "no"
    code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                           "multifreq", "--camera", "32x24", "--motion", motion, "--out", out)
    assert code == 2 and f"--motion {motion!r} is not a motion" in err, err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def _commands(group: click.Group, ctx: click.Context, path: str = "bistair"):
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        sub = click.Context(command, info_name=name, parent=ctx)
        if isinstance(command, click.Group):
            yield from _commands(command, sub, f"{path} {name}")
        else:
            yield f"{path} {name}", command


def test_every_command_that_writes_files_takes_quiet():
    """``-q/--quiet`` means one thing everywhere: no progress and no summary. ``demo``
    alone has none: its table is what it is for."""
    lacking = [name for name, command in _commands(cli, click.Context(cli, info_name="bistair"))
               if name != "bistair demo" and not any(
                   p.opts == ["--quiet", "-q"] and p.is_flag for p in command.params)]
    assert lacking == []


def test_quiet_patterns_print_nothing_and_write_the_set(tmp_path, monkeypatch, capsys):
    out = tmp_path / "pats"
    code, printed, err = cli_run(monkeypatch, capsys, "patterns", "multifreq", "--width", 64,
                                 "--height", 48, "--periods", "16,21", "--out", out, "-q")
    assert code == 0 and printed == "" and err == "", err
    spec = json.loads((out / "spec.json").read_text())
    assert len(list(out.glob("*.png"))) == spec["steps"] * 2
    code, printed, _ = cli_run(monkeypatch, capsys, "patterns", "multifreq", "--width", 64,
                               "--height", 48, "--periods", "16,21", "--out", out)
    assert code == 0 and printed.startswith("wrote 8 multifreq patterns")
    code, printed, err = cli_run(monkeypatch, capsys, "patterns", "gamma", "--width", 32,
                                 "--height", 24, "--levels", 5, "--out", tmp_path / "ramp",
                                 "--quiet")
    assert code == 0 and printed == "" and err == "" and (tmp_path / "ramp" / "ramp.json").is_file()


def test_the_calibration_carries_the_pixel_origin_its_file_records(sim, tmp_path, monkeypatch,
                                                                   capsys):
    """``pixel_origin`` is a field of :class:`StereoCalibration` that save and load keep;
    files written before (none recorded, or recorded by ``save_matrix_calibration``) load
    as they did. A loaded calibration given to ``stereo`` as an object is checked as its
    file is: before, only a path was (its JSON read a second time), and an object that
    recorded the wrong origin kept the camera model one pixel off."""
    right = load_calibration(sim / "stereo.json")
    assert right.pixel_origin is None and "pixel_origin" not in right.to_dict()
    # one pixel off, as a MATLAB matrix read 0-based, recorded as 1-based
    wrong = with_pixel_origin(right, 1)
    save_matrix_calibration(wrong, 1, tmp_path / "old.json")  # the importer's writer
    loaded = load_calibration(tmp_path / "old.json")
    assert loaded.pixel_origin == 1
    again = load_calibration(save_calibration(loaded, tmp_path / "again.json"))
    assert again.pixel_origin == 1 and json.loads((tmp_path / "again.json").read_text())[
        "pixel_origin"] == 1
    with pytest.raises(Exception, match="'pixel_origin' must be 0 or 1"):
        StereoCalibration.from_dict({**right.to_dict(), "pixel_origin": 2})
    left, rightc = (read_captures(sim / "multifreq" / s)[:4] for s in ("L", "R"))
    np.save(tmp_path / "L.npy", left)
    np.save(tmp_path / "R.npy", rightc)
    spec = sim / "multifreq" / "L" / "spec.json"
    for given in (tmp_path / "old.json", loaded):
        res = stereo_folder(tmp_path / "L.npy", tmp_path / "R.npy", tmp_path / "one", given,
                            spec, min_depth=520.0, max_depth=650.0)
        assert res.info.get("pixel_origin") == 0, type(given).__name__
        assert any("pixel-origin" in w for w in res.info["warnings"])
    for given in (tmp_path / "old.json", loaded):
        kept = stereo_stream(sim / "multifreq" / "L", sim / "multifreq" / "R",
                             tmp_path / "stream", given, None, "4", "0", 520.0, 650.0,
                             previews=False)
        info = json.loads((tmp_path / "stream" / "0000" / "info.json").read_text())
        assert info.get("pixel_origin") == 0 and len(kept) == 1, type(given).__name__
    # the command says so on stderr, as one set's does (quiet too); before, only info.json
    code, printed, err = cli_run(monkeypatch, capsys, *_stream_args(sim, tmp_path / "cli")[:4],
                                 tmp_path / "old.json", "--depth-range", RANGE, "--window",
                                 "4", "--starts", "0,2", "--out", tmp_path / "cli", "-q")
    assert code == 0 and printed == "", err
    assert err.count("Warning: ") == 1 and "pixel origin 0, " in err and "used 0" in err, err
