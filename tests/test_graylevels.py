"""The multi-level Gray code (``code_levels``, issue 33 item 3): SLMaster's quaternary
patterns bit for bit through the command line, the base-L reflected Gray code for other L,
the decode of rendered scenes against the renderer's truth, and the refusals."""

from __future__ import annotations

import json
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from click.testing import CliRunner

import bistair
from bistair.app.cli import cli
from bistair.codecs import graylevels
from bistair.codecs.base import measure_shifts
from bistair.core.captures import prepare
from bistair.errors import BistairError
from bistair.sim import Imaging, preset
from bistair.sim.render import render

DEFAULT = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, projector_blur=0.5, ambient=0.05)


def written(tmp_path: Path, *args: str) -> tuple[np.ndarray, dict]:
    """``bistair patterns graycode ARGS``: the images it wrote and its spec.json."""
    result = CliRunner().invoke(cli, ["patterns", "graycode", *args, "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    images = np.stack([iio.imread(p) for p in sorted(tmp_path.glob("*.png"))])
    return images, json.loads((tmp_path / "spec.json").read_text())


def slmaster_interzone(width: int, height: int, periods: int = 16, shifts: int = 3
                       ) -> np.ndarray:
    """SLMaster's ``InterzoneSinusFourGrayscalePattern::generate`` (vertical fringes) as its
    formulas read, written out independently: ``P = width // periods`` px fringes,
    ``uint8(127.5 + 127.5 cos(2 pi (x mod P) / P - pi + 2 pi n / N))`` (truncated), then
    ``log4(periods)`` frames of grey levels (0, 85, 170, 255) whose level sequence over
    ``width // len(seq)`` px blocks starts 0, 1, 2, 3 and becomes ``[s, reversed(s), s,
    reversed(s)]`` after each frame; columns past the last whole block stay 0."""
    grey = (0, 85, 170, 255)
    pitch = width // periods
    x = np.arange(width, dtype=np.float32)
    rows = []
    for n in range(shifts):
        angle = (np.float32(2 * np.pi) * (x % pitch) / np.float32(pitch) - np.float32(np.pi)
                 + np.float32(2 * np.pi * n / shifts))
        rows.append((np.float32(127.5) + np.float32(127.5) * np.cos(angle)).astype(np.uint8))
    seq = [0, 1, 2, 3]
    for _ in range(round(np.log(periods) / np.log(4))):
        block = width // len(seq)
        row = np.zeros(width, np.uint8)
        for b, digit in enumerate(seq):
            row[b * block:(b + 1) * block] = grey[digit]
        rows.append(row)
        seq = seq + seq[::-1] + seq + seq[::-1]
    return np.repeat(np.stack(rows)[:, None, :], height, axis=1)


def reflected_code(levels: int, digits: int) -> np.ndarray:
    """The base-L reflected Gray code by its recursive definition: the codes of ``n``
    digits are, for each leading digit d, d followed by the codes of ``n - 1`` digits,
    reversed where d is odd."""
    codes = [[d] for d in range(levels)]
    for _ in range(digits - 1):
        codes = [[d, *c] for d in range(levels) for c in (codes if d % 2 == 0 else codes[::-1])]
    return np.array(codes)


@pytest.mark.parametrize("orientation", ["columns", "rows"])
def test_patterns_are_slmasters_interzone_four_grayscale(tmp_path, orientation):
    """`patterns graycode --steps 3 --period 120 --code-levels 4 --phase-offset -pi` on a
    1920 x 1080 projector: SLMaster's code frames bit for bit, its fringes within one grey
    level (it truncates, bistair rounds); rows are the same patterns turned (a 1080 x 1920
    projector coded along its 1920 rows)."""
    width, height = (1920, 1080) if orientation == "columns" else (1080, 1920)
    images, spec = written(tmp_path, "--width", str(width), "--height", str(height),
                           "--steps", "3", "--period", "120", "--code-levels", "4",
                           "--phase-offset", "-pi", "--orientation", orientation)
    theirs = slmaster_interzone(1920, 1080)
    if orientation == "rows":
        theirs = theirs.transpose(0, 2, 1)
    assert spec["code_levels"] == 4 and spec["frames"][3:] == ["gray-0", "gray-1"]
    assert images.shape == theirs.shape and images.dtype == np.uint8
    assert np.array_equal(images[3:], theirs[3:])
    assert np.abs(images[:3].astype(int) - theirs[:3]).max() <= 1


@pytest.mark.parametrize(("levels", "period", "digits"), [(3, 30, 3), (8, 20, 2)])
def test_patterns_are_the_reflected_gray_code_of_base_l(tmp_path, levels, period, digits):
    """L = 3 (24 fringes, 3 digits) and L = 8 (48 fringes, 2 digits): fringe k's digits are
    the k-th code of the recursively defined base-L reflected Gray code, drawn at
    ``round(255 d / (L - 1))``; neighbouring fringes differ in one digit by one level."""
    images, spec = written(tmp_path, "--width", "720", "--height", "40", "--period",
                           str(period), "--code-levels", str(levels))
    fringes = 720 // period
    assert spec["frames"][4:] == [f"gray-{i}" for i in range(digits)]
    codes = reflected_code(levels, digits)[:fringes]
    grey = np.round(255 * codes / (levels - 1)).astype(np.uint8)
    expect = np.repeat(grey.T, period, axis=1)
    assert np.array_equal(images[4:], np.repeat(expect[:, None, :], 40, axis=1))
    steps = np.abs(np.diff(codes, axis=0))
    assert (steps.sum(axis=1) == 1).all()


def score(result, truth, period: float) -> tuple[float, float]:
    """Orders wrong among the decoded truth pixels (coordinate off by over half a period)
    and the share of the truth pixels decoded."""
    mask = truth.mask
    decoded = mask & result.mask
    wrong = decoded & (np.abs(result.coord - truth.coord_x) > period / 2)
    return np.count_nonzero(wrong) / max(np.count_nonzero(decoded), 1), \
        np.count_nonzero(decoded) / np.count_nonzero(mask)


@pytest.mark.parametrize(("scene", "seed"), [("paper-sim", 0), ("mugs-on-wall", 1)])
def test_decodes_renders_as_well_as_the_complementary_code(scene, seed):
    """Default optics, 640 x 512: the quaternary code (4 steps, T = 30, three code frames
    for 36 fringes) leaves at most 0.1% of its decoded pixels an order off and covers within
    2% of what the complementary Gray code covers on the same render."""
    rig, shapes = preset(scene, camera_size=(640, 512))
    imaging = Imaging(**DEFAULT, seed=seed)
    width, height = rig.projector.size
    quat = bistair.make_spec("graycode", width=width, height=height, period=30,
                             code_levels=4, gamma=2.2)
    comp = bistair.make_spec("graycode", width=width, height=height, period=30,
                             complementary=1, gamma=2.2)
    captures, truth = render(bistair.encode(quat), rig, shapes, imaging)
    wrong, covered = score(bistair.decode(captures, quat), truth, 30)
    captures, _ = render(bistair.encode(comp), rig, shapes, imaging)
    _, covered_comp = score(bistair.decode(captures, comp), truth, 30)
    assert wrong <= 0.001, wrong
    assert covered >= covered_comp - 0.02, (covered, covered_comp)


HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)


@pytest.mark.parametrize(("scene", "seed"), [("paper-sim", 1), ("objects-on-plane", 0)])
def test_decodes_hard_optics_read_a_cell_at_a_time(scene, seed):
    """Hard optics (the robustness table's: gamma 2.2 not compensated, so digits 0 and 1
    reach the camera at 0 and 9% of the light; 3% noise, 15% ambient, blur), 640 x 512,
    T = 30: the quaternary code is decoded, not refused, with at most 0.5% of its decoded
    pixels an order off and within 2% of the complementary code's coverage; the fringes'
    blur it fits is about the renderer's (its Gaussian blur plus the pixel's box)."""
    rig, shapes = preset(scene, camera_size=(640, 512))
    imaging = Imaging(**HARD, seed=seed)
    width, height = rig.projector.size
    quat = bistair.make_spec("graycode", width=width, height=height, period=30,
                             code_levels=4)
    comp = bistair.make_spec("graycode", width=width, height=height, period=30,
                             complementary=1)
    captures, truth = render(bistair.encode(quat), rig, shapes, imaging)
    wrong, covered = score(bistair.decode(captures, quat), truth, 30)
    cols = prepare(captures, quat.frame_count, quat.method)
    blur = graylevels.code_cells(cols, quat, measure_shifts(cols, quat)).blur
    shown, _ = render(bistair.encode(comp), rig, shapes, imaging)
    _, covered_comp = score(bistair.decode(shown, comp), truth, 30)
    assert wrong <= 0.005, wrong
    assert covered >= covered_comp - 0.02, (covered, covered_comp)
    assert 15 < blur < 60, blur


def test_pixels_read_alone_carry_no_order_where_the_levels_crowd_pixel_by_pixel():
    """Hard optics with 3 steps (paper-sim, seed 0): the cells read, but a pixel read one
    by one, its levels crowded, carries no order of its own (read alone, 1.5% of the
    decoded pixels are an order off): at most 0.5% off, over 80% of the truth covered."""
    rig, shapes = preset("paper-sim", camera_size=(640, 512))
    width, height = rig.projector.size
    quat = bistair.make_spec("graycode", width=width, height=height, period=30, steps=3,
                             code_levels=4)
    captures, truth = render(bistair.encode(quat), rig, shapes, Imaging(**HARD, seed=0))
    wrong, covered = score(bistair.decode(captures, quat), truth, 30)
    assert wrong <= 0.005 and covered >= 0.8, (wrong, covered)


def test_levels_are_estimated_through_an_uncompensated_gamma_and_heavy_blur():
    """Projector gamma 2.2 not compensated and heavy defocus (camera 3 px, projector 1.5
    px), 16 fringes as SLMaster projects them: the middle levels move far from -1/3 and 1/3,
    the decode follows them (at most 0.1% of its pixels an order off, 95% of the truth
    covered); read at the nominal positions instead, a third of the pixels fail."""
    rig, shapes = preset("paper-sim", camera_size=(640, 512))
    imaging = Imaging(gamma=2.2, read_noise=0.01, camera_blur=3.0, projector_blur=1.5,
                      ambient=0.05, seed=0)
    width, height = rig.projector.size
    spec = bistair.make_spec("graycode", width=width, height=height, period=width / 16,
                             code_levels=4)
    captures, truth = render(bistair.encode(spec), rig, shapes, imaging)
    result = bistair.decode(captures, spec)
    wrong, covered = score(result, truth, spec.period)
    assert wrong <= 0.001 and covered >= 0.95, (wrong, covered)
    cols = prepare(captures, spec.frame_count, spec.method)
    fs = measure_shifts(cols, spec)
    centres = graylevels.code_cells(cols, spec, fs).centres
    assert (np.abs(centres[:, 1:3] - np.float32([-1 / 3, 1 / 3])) > 0.1).all(), centres
    nominal = np.float32([[-1, -1 / 3, 1 / 3, 1]] * spec.code_bits)
    read = graylevels.read_levels(
        cols.raw, spec.steps, spec.code_bits, cols.scale, fs.avg, fs.mod, fs.valid, fs.phi,
        nominal, np.int32([[0, 1, 2, 3]] * 2), np.int32([4, 4]), 4, 16,
        fs.noise * np.sqrt(1 + 1 / spec.steps), 3.0, 0.5, np.pi / 3, graylevels.REACH,
        graylevels.SAME_FRINGE)[0]
    at_nominal = np.count_nonzero(truth.mask & (read >= 0)) / np.count_nonzero(truth.mask)
    assert at_nominal < 0.7, at_nominal


@pytest.fixture(scope="module")
def sixteen():
    """paper-sim at 640 x 512, default optics, 16 fringes (T = 67.5): a quaternary set
    (two code frames), the same fringes with a binary Gray code (four), and its traced
    rig."""
    rig, shapes = preset("paper-sim", camera_size=(640, 512))
    width, height = rig.projector.size
    quat = bistair.make_spec("graycode", width=width, height=height, period=width / 16,
                             code_levels=4, gamma=2.2)
    binary = bistair.make_spec("graycode", width=width, height=height, period=width / 16,
                               gamma=2.2)
    return rig, shapes, quat, binary


def refusal(captures: np.ndarray, spec) -> str:
    with pytest.raises(BistairError) as err:
        bistair.decode(captures, spec)
    message = str(err.value)
    assert "\n" not in message
    return message


def test_refuses_captures_whose_levels_do_not_separate(sixteen):
    """A binary code read as L = 4 (its first two bits, then its last two), the quaternary
    captures read as L = 8 (the same two frames) and a quaternary code washed out to 5% and
    10% of its contrast are refused in one line naming the frame and the levels; the
    quaternary captures themselves decode."""
    rig, shapes, quat, binary = sixteen
    imaging = Imaging(**DEFAULT, seed=0)
    patterns = bistair.encode(quat)
    captures, _ = render(patterns, rig, shapes, imaging)
    assert bistair.decode(captures, quat).mask.mean() > 0.4  # the scene: half the image
    eight = refusal(captures, quat.replace(code_levels=8))
    assert "not show 8 separate grey levels" in eight and "code_levels 8" in eight
    bits = bistair.encode(binary)
    for frames in ((4, 5), (6, 7)):
        shown, _ = render(bits[[0, 1, 2, 3, *frames]], rig, shapes, imaging)
        assert "not show 4 separate grey levels" in refusal(shown, quat)
    for contrast in (0.05, 0.10):  # (at 10% the cells separate the levels: too close)
        washed = patterns.copy()
        washed[4:] = 0.5 + contrast * (washed[4:] - 0.5)
        shown, _ = render(washed, rig, shapes, imaging)
        assert "washed out" in refusal(shown, quat)


@pytest.mark.parametrize(("change", "words"), [
    (dict(complementary=1), "complementary pattern is a binary code's"),
    (dict(gray_offset=0.5), "shifted Gray code (gray_offset 0.5) is binary"),
    (dict(inverse=1), "inverse patterns are a binary code's"),
    (dict(second_period=37), "second period checks a binary code"),
    (dict(steps=0, inverse=1), "needs phase shifts"),
    (dict(code_levels=1), "code_levels must be a whole number from 2 to 16"),
    (dict(code_levels=17), "code_levels must be a whole number from 2 to 16"),
])
def test_combinations_that_are_not_defined_are_refused_in_one_line(tmp_path, change, words):
    """Each combination with a binary code's parts is refused in one line, by the library
    and by ``bistair patterns`` (exit 2, nothing written); a white frame is the texture
    frame as always."""
    params = {**dict(width=480, height=32, period=30, code_levels=4), **change}
    with pytest.raises(BistairError, match=words.replace("(", r"\(").replace(")", r"\)")):
        bistair.make_spec("graycode", **params)
    args = [f"--{k.replace('_', '-')}={v}" for k, v in params.items()]
    result = CliRunner().invoke(cli, ["patterns", "graycode", *args, "--out",
                                      str(tmp_path / "out")])
    assert result.exit_code == 2 and words in result.output, result.output
    assert not (tmp_path / "out").exists()
    spec = bistair.make_spec("graycode", width=480, height=32, period=30, code_levels=4,
                             white=1)
    assert spec.frames[-1] == "white" and spec.frame_count == 7


def test_binary_specs_are_unchanged():
    """``code_levels`` 2 (the default) is today's binary code: its spec.json is written
    as before (without the field), a spec file that does not name it reads as binary, and
    one of L = 4 names it."""
    spec = bistair.make_spec("graycode", width=480, height=32, period=30, complementary=1)
    assert spec.code_levels == 2 and spec.code_bits == 4
    data = spec.to_dict()
    assert "code_levels" not in data
    assert bistair.spec_from_dict(data) == spec
    quat = bistair.make_spec("graycode", width=480, height=32, period=30, code_levels=4)
    assert quat.to_dict()["code_levels"] == 4
    assert bistair.spec_from_dict(quat.to_dict()) == quat
