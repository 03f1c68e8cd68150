"""A Gray code alone (steps 0): OpenCV's GrayCodePattern bit for bit (its own images, kept in
tests/data), decodes them and rendered scenes against ground truth, and agrees with the real
rigs' own decoders."""

from __future__ import annotations

import json
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from click.testing import CliRunner
from conftest import SHARED, warped_scene
from support import opencv_graycode

import bistair
from bistair.app.cli import cli
from bistair.errors import BistairError
from bistair.io.read import read_with_spec
from bistair.sim.warp import render_warp

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PROCAM = SHARED / "data" / "procam-calibration"
KAMINO = SHARED / "data" / "kamino-object1"


def patterns_of(tmp_path: Path, width: int, height: int) -> np.ndarray:
    """``bistair patterns graycode --steps 0 --inverse 1 --white 1 --orientation both``."""
    result = CliRunner().invoke(cli, ["patterns", "graycode", "--steps", "0", "--inverse", "1",
                                      "--white", "1", "--orientation", "both", "--width",
                                      str(width), "--height", str(height), "--out",
                                      str(tmp_path)])
    assert result.exit_code == 0, result.output
    spec = json.loads((tmp_path / "spec.json").read_text())
    assert spec["period"] == 1 and spec["frames"][-2:] == ["white", "black"]
    return np.stack([iio.imread(p) for p in sorted(tmp_path.glob("*.png"))])


@pytest.mark.parametrize("size", opencv_graycode.SIZES)
def test_patterns_and_decode_are_opencvs_graycodepattern(tmp_path, size):
    """OpenCV's own GrayCodePattern images (tests/data/opencv_graycode.npz, made by
    OpenCV 5.0 with tests/support/opencv_graycode.py): the patterns bit for bit, and decoded
    (OpenCV's images as captures, one camera pixel a projector pixel) to each pixel's own
    column and row, with and without the white and black frames."""
    width, height = size
    theirs = opencv_graycode.load(width, height)
    assert np.array_equal(patterns_of(tmp_path, width, height), theirs)
    for white in (1, 0):
        spec = bistair.make_spec("graycode", steps=0, inverse=1, white=white,
                                 orientation="both", width=width, height=height)
        res = bistair.decode(theirs if white else theirs[:-2], spec)
        rows, columns = np.indices((height, width))
        assert res.x.mask.all() and res.y.mask.all()
        assert np.array_equal(res.x.order, columns) and np.array_equal(res.y.order, rows)
        # the coordinate goes through the float32 phase: 28.999998 for 29
        assert np.abs(res.x.coord - columns).max() < 1e-4
        assert np.abs(res.y.coord - rows).max() < 1e-4


@pytest.mark.skipif(not PROCAM.is_dir(), reason="../shared/data/procam-calibration not present")
def test_patterns_are_procams_own_1024x768(tmp_path):
    """procam-calibration's graycode_pattern/ (made by its gen_graycode_imgs.py with
    OpenCV's GrayCodePattern for its 1024 x 768 projector): the same 42 images."""
    theirs = np.stack([iio.imread(p) for p in sorted((PROCAM / "graycode_pattern")
                                                      .glob("pattern_*.png"))])
    assert np.array_equal(patterns_of(tmp_path, 1024, 768), theirs)


@pytest.mark.parametrize(("inverse", "period", "orientation"),
                         [(1, 1, "columns"), (0, 8, "rows"), (1, 12, "both")])
def test_decodes_rendered_scenes_within_the_cell(inverse, period, orientation):
    spec = bistair.make_spec("graycode", width=1080, height=1080, steps=0, period=period,
                             inverse=inverse, white=1, orientation=orientation)
    scene = warped_scene(0, noise=0.01, blur=0.8)
    for axis, sub in spec.axes():
        images, truth = render_warp(sub, scene)
        res = bistair.decode(images, sub)
        coord, known = truth.coord(sub), truth.mask
        got = res.mask & known
        assert got.sum() > 0.6 * known.sum()
        # the cell's centre: within half a cell of the truth (and a pixel of blur)
        err = np.abs(res.coord - coord)[got]
        assert np.mean(err <= period / 2 + 1.0) > 0.995, axis
        assert np.mean(err > period + 2) < 1e-3, axis
        assert res.method == "graycode" and np.isnan(res.coord[~res.mask]).all()


def test_bad_gray_alone_specs_are_refused_with_one_line():
    for name, value in (("second_period", 40), ("complementary", 1), ("gray_offset", 0.5)):
        with pytest.raises(BistairError, match=f"{name} needs phase shifts"):
            bistair.make_spec("graycode", steps=0, inverse=1, **{name: value})
    with pytest.raises(BistairError, match="needs inverse patterns"):
        bistair.make_spec("graycode", steps=0)
    with pytest.raises(BistairError, match="at least 3 .or 0 for a Gray code alone"):
        bistair.make_spec("graycode", steps=2)
    with pytest.raises(BistairError, match="at least 3, got 0"):
        bistair.make_spec("phase-coding", steps=0)
    spec = bistair.make_spec("graycode", width=64, height=16, steps=0, inverse=1)
    with pytest.raises(BistairError, match="strategy 'region' needs phase shifts"):
        bistair.decode(bistair.encode(spec), spec, strategy="region")


@pytest.mark.skipif(not KAMINO.is_dir(), reason="../shared/data/kamino-object1 not present")
def test_kamino_gray_frames_alone_agree_with_its_phase_decode():
    """kamino-object1's Gray frames alone (the phase shifts ignored) against its full decode:
    within one cell on >= 99% of the pixels whose bits are clear."""
    stack, spec = read_with_spec(KAMINO, EXAMPLES / "kamino-object1-graycode.json")
    full = bistair.decode(*read_with_spec(KAMINO, EXAMPLES / "kamino-object1.json"))
    gray = bistair.decode(stack, spec)
    for axis in "xy":
        g, p = getattr(gray, axis), getattr(full, axis)
        both = g.mask & p.mask
        assert both.sum() > 0.5 * p.mask.sum()
        cells = np.floor(p.coord[both] / 100).astype(int)
        assert np.mean(np.abs(cells - g.order[both]) <= 1) >= 0.99, axis


@pytest.mark.skipif(not PROCAM.is_dir(), reason="../shared/data/procam-calibration not present")
def test_procam_capture_matches_the_rigs_own_decode():
    """procam-calibration's pose 0 against the rig's own rule (calibrate.py: bit = pattern >
    inverse; pixels where |pattern - inverse| < 5 or white - black <= 40 left out)."""
    stack, spec = read_with_spec(PROCAM / "capture_0", EXAMPLES / "procam-graycode.json")
    res = bistair.decode(stack, spec)
    frames = stack.astype(np.int32)
    for axis, first in (("x", 0), ("y", 20)):
        pattern, inverse = frames[first:first + 20:2], frames[first + 1:first + 20:2]
        theirs_ok = (np.abs(pattern - inverse) >= 5).all(axis=0) & (frames[40] - frames[41] > 40)
        gray = np.zeros(pattern.shape[1:], np.int64)
        for p, q in zip(pattern, inverse, strict=True):
            gray = (gray << 1) | (p > q)
        cell, shift = gray.copy(), 1
        while shift < 32:
            cell ^= cell >> shift
            shift <<= 1
        ours = getattr(res, axis)
        both = theirs_ok & ours.mask
        assert both.sum() > 0.9 * ours.mask.sum() and both.sum() > 0.9 * theirs_ok.sum()
        assert np.array_equal(ours.order[both], cell[both])
        assert np.allclose(ours.coord[both], cell[both])  # one-pixel cells: the column itself
