"""Stair levels that cannot be read where the patterns put them (issue 31, item 2). A
projector gamma the patterns do not compensate moves each stair level's reading by its own
amount; with 11 x 11 levels some read nearer a neighbour than themselves, and whole
partitions of the paper scene took their neighbour's order with exit 0 (12-24% of its decoded
pixels under the hard optics at 640 x 512). The default decoder now fits the response to
the capture's own stair phases and reads the levels where it puts them; a region that reads
a level whose band rows still read far from it (where the response squeezes levels together
its noise counts for more) decides nothing alone. The rendered scenes: 640 x 512, the hard
optics of the robustness issue (3% noise, 1.2 px camera and 1 px projector blur, 15%
ambient, gamma 2.2).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import bistair
from bistair.app.cli import cli
from bistair.sim import Imaging, expose, preset, trace

HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)
DEFAULT = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, ambient=0.05)


@pytest.fixture(scope="module")
def paper_hard():
    rig, geometry = preset("paper-sim", camera_size=(640, 512))
    return rig, trace(rig, geometry, Imaging(**HARD))


@pytest.fixture(scope="module")
def sculptures_hard():
    rig, geometry = preset("two-sculptures", camera_size=(640, 512))
    return rig, trace(rig, geometry, Imaging(**HARD))


@pytest.fixture(scope="module")
def plane_default():
    rig, geometry = preset("plane", camera_size=(640, 512))
    return rig, trace(rig, geometry, Imaging(**DEFAULT))


def _decode(scene, optics: dict, seed: int, levels: int, period: int, compensated: bool):
    """(result, share of the decoded truth pixels more than half a period off, share of the
    truth pixels decoded) of one rendered capture, or the BistairError's text."""
    rig, traced = scene
    imaging = Imaging(**optics, seed=seed)
    spec = bistair.make_spec("bidirectional", width=rig.projector.size[0],
                             height=rig.projector.size[1], period=period, partitions=levels,
                             stairs=levels, gamma=imaging.gamma if compensated else 1.0)
    try:
        result = bistair.decode(expose(traced, bistair.encode(spec), imaging), spec)
    except bistair.BistairError as error:
        return str(error), 1.0, 0.0
    both = result.mask & traced.truth.mask
    wrong = float(np.mean(np.abs(result.coord - traced.truth.coord_x)[both] > period / 2))
    return result, wrong, float(both.sum() / traced.truth.mask.sum())


def test_levels_are_read_where_an_uncompensated_response_puts_them(paper_hard):
    """The issue's case: 11 x 11 at T = 16, gamma not compensated (13.9% of the decoded
    pixels a partition off before, exit 0; now none, 89.9% of the truth decoded)."""
    result, wrong, coverage = _decode(paper_hard, HARD, 1, 11, 16, compensated=False)
    assert not isinstance(result, str), result
    assert abs(result.info["stair_response"] - 2.2) < 0.15
    assert wrong <= 0.005 and coverage >= 0.8, (wrong, coverage)


def test_a_region_reading_a_doubtful_level_decides_nothing_alone(sculptures_hard):
    """Two sculptures at 8 x 8, the same optics, seed 1: the response squeezes levels 0 and 1
    together and their rows read up to 0.32 of the way to halfway; a fringe of the bust
    read its local level 0 and partition level 3 the other way round (order 3 for 24) and its
    neighbours followed: 5.15% of the pixels 21 orders off with the regions' readings taken
    at face value, none now (97.5% of the truth decoded)."""
    result, wrong, coverage = _decode(sculptures_hard, HARD, 1, 8, 30, compensated=False)
    assert not isinstance(result, str), result
    assert result.info["doubtful_levels"] >= 1
    assert wrong <= 0.005 and coverage >= 0.9, (wrong, coverage)


def test_the_same_optics_at_8x8_are_accepted_and_right(paper_hard):
    result, wrong, coverage = _decode(paper_hard, HARD, 2, 8, 30, compensated=False)
    assert not isinstance(result, str), result
    assert "forced" not in result.info
    assert wrong <= 0.005 and coverage >= 0.95, (wrong, coverage)  # measured 0, 97.1%


def test_a_compensated_capture_is_read_as_it_is(paper_hard):
    result, wrong, coverage = _decode(paper_hard, HARD, 1, 11, 16, compensated=True)
    assert not isinstance(result, str), result
    assert "stair_response" not in result.info and "doubtful_levels" not in result.info
    assert wrong <= 0.005 and coverage >= 0.9, (wrong, coverage)


def test_the_stair_check_judges_the_levels_where_they_read(plane_default):
    """A plane at 11 x 11 with gamma 2.2 not compensated, default optics: right, and was
    refused ('at 12% of the decoded pixels the stair phase is nearer a level other than...'):
    the check judged each pixel against levels where the patterns put them."""
    result, wrong, coverage = _decode(plane_default, DEFAULT, 0, 11, 16, compensated=False)
    assert not isinstance(result, str), result
    assert result.info["stair_misfit"] < 0.09  # measured 0.071 (0.045 compensated: blur)
    assert wrong == 0.0 and coverage >= 0.99, (wrong, coverage)


@pytest.mark.parametrize(("spec_gamma", "projector_gamma", "levels", "period"),
                         [(1.0, 2.8, 12, 12), (2.2, 2.8, 12, 12), (1.0, 2.2, 11, 16)])
def test_the_response_left_in_the_captures_is_fitted(spec_gamma, projector_gamma, levels,
                                                     period):
    """The exponent the patterns' compensation leaves (none, too little), fitted from the
    stair levels of captures without noise or blur: every order right (before: 65% wrong
    and refused, right, and 18% wrong with exit 0)."""
    width = levels * levels * period
    spec = bistair.make_spec("bidirectional", width=width, height=120, period=period,
                             partitions=levels, stairs=levels, group_rows=24, local_rows=16,
                             gamma=spec_gamma)
    result = bistair.decode(bistair.encode(spec) ** projector_gamma, spec)
    assert abs(result.info["stair_response"] - projector_gamma / spec_gamma) < 0.03
    assert (result.order == np.arange(width) // period).all()


def test_a_linear_response_is_not_fitted():
    spec = bistair.make_spec("bidirectional", width=1728, height=120, period=12,
                             partitions=12, stairs=12, group_rows=24, local_rows=16)
    result = bistair.decode(bistair.encode(spec), spec)
    assert "stair_response" not in result.info
    assert (result.order == np.arange(1728) // 12).all()


def test_band_rows_that_read_at_random_are_refused_and_force_decodes(tmp_path):
    """A linear projector whose sine frame came out 30% brighter than the cosine frame (the
    lamp or the exposure changed between them), the hard optics: no response read off the
    levels undoes it, the band rows read 59% of the way to halfway between two levels (50%
    at random), and under 3% noise the stair check sees too few sharp pixels to judge. The
    decode is refused; forced, 45% of its pixels are wrong (with exit 0 before)."""
    rig, geometry = preset("plane", camera_size=(640, 512))
    imaging = Imaging(**{**HARD, "gamma": 1.0}, seed=0)
    traced = trace(rig, geometry, imaging)
    spec = bistair.make_spec("bidirectional", width=1920, height=1080, period=16,
                             partitions=11, stairs=11)
    stack = expose(traced, bistair.encode(spec), imaging).astype(np.float32)
    stack[-1] *= 1.3  # stair-sin
    np.save(tmp_path / "caps.npy", np.clip(stack, 0, 255).astype(np.uint8))
    (tmp_path / "spec.json").write_text(spec.to_json())
    args = ["decode", str(tmp_path / "caps.npy"), "--spec", str(tmp_path / "spec.json")]
    refused = CliRunner().invoke(cli, [*args, "--out", str(tmp_path / "a")])
    assert refused.exit_code == 2 and not (tmp_path / "a").exists(), refused.output
    assert "the band rows read 59% of the way to halfway between two stair levels" in \
        refused.output, refused.output
    forced = CliRunner().invoke(cli, [*args, "--out", str(tmp_path / "b"), "--force"])
    assert forced.exit_code == 0, forced.output
    assert "forced past a check: the band rows read 59%" in forced.output
    info = json.loads((tmp_path / "b" / "info.json").read_text())
    assert [f[:25] for f in info["forced"]] == ["the band rows read 59% of"]  # nothing else
    order, known = np.load(tmp_path / "b" / "order.npy"), traced.truth.mask
    both = (order >= 0) & known
    truth = np.floor(traced.truth.coord_x / 16)
    assert np.mean(order[both] != truth[both]) > 0.3  # the refusal is right


@pytest.mark.parametrize(("levels", "gamma"), [(12, 2.2), (8, 2.8)])
def test_the_misfit_check_reads_levels_a_gamma_moved(levels, gamma):
    """An uncompensated gamma moves the stair phases 0.70 (12 x 12 at 2.2) and 0.79 (8 x 8
    at 2.8) of the way to halfway between the code's levels, past the misfit check's 0.7:
    the check judges them against where the levels read through the fitted response (0.01)
    and the decode reads every order right, where it refused the captures."""
    spec = bistair.make_spec("bidirectional", width=levels * levels * 4, height=96, period=4,
                             partitions=levels, stairs=levels, group_rows=16, local_rows=10)
    res = bistair.decode(bistair.encode(spec) ** gamma, spec)
    want = np.arange(spec.width // 4).repeat(4)[None, :].repeat(96, axis=0)
    assert res.mask.mean() > 0.9 and np.array_equal(res.order[res.mask], want[res.mask])
