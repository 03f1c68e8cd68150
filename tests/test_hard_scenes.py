"""The bidirectional decoder at its limits is never silently wrong (issue 21, items 7 and 8).

121 codewords (11 x 11 partitions x stairs at T = 16) under the hard optics (3% noise,
camera blur 1.2 px, projector blur 1.0 px, 15% ambient, gamma 2.2) and low-resolution
cameras (320 x 256: about 5 camera pixels per fringe, partition bands 3 px tall): every
decode is right (at most 0.5% of its valid pixels more than half a period off the truth),
or says why it may not be (a warning in ``info``). With the projector's gamma compensated,
the 121-codeword decodes are right. Each case must decode (a refusal of every decode would
pass "right or refused" and is as bad as a wrong one): at least 60% of the truth's pixels
(measured 68.9-99.7% at 320 x 256, 77.8% for the uncompensated gamma).
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

import bistair
from bistair.app.cli import cli
from bistair.errors import BistairError
from bistair.io.read import read_with_spec
from bistair.sim import Imaging, expose, preset, trace

HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)
CODE_121 = dict(period=16, partitions=11, stairs=11)


def _decode(scene: str, camera: tuple[int, int], seed: int, optics: dict, code: dict,
            compensated: bool) -> tuple[str, float, list[str]]:
    """(outcome, wrong share, warnings) of one rendered decode; a decode must answer for
    at least 60% of the pixels the truth knows."""
    rig, geometry = preset(scene, camera_size=camera)
    imaging = Imaging(**optics, seed=seed)
    traced = trace(rig, geometry, imaging)
    width, height = rig.projector.size
    spec = bistair.make_spec("bidirectional", width=width, height=height,
                             gamma=imaging.gamma if compensated else 1.0, **code)
    try:
        result = bistair.decode(expose(traced, bistair.encode(spec), imaging), spec)
    except BistairError:
        return "refused", 0.0, []
    both = result.mask & traced.truth.mask
    assert both.sum() >= 0.6 * traced.truth.mask.sum(), f"{both.sum()} pixels decoded"
    wrong = float(np.mean(np.abs(result.coord - traced.truth.coord_x)[both] > spec.period / 2))
    return "decoded", wrong, result.info.get("warnings", [])


@pytest.mark.parametrize(("scene", "seed"), [("mask-prism", 4), ("mask-prism", 1), ("plane", 4)])
def test_121_codewords_under_hard_optics_are_right(scene, seed):
    """The scenes the issue found 4.6-13.8% wrong: right now (measured 0.49%, 0.35%, 0%)."""
    outcome, wrong, _ = _decode(scene, (1280, 1024), seed, HARD, CODE_121, compensated=False)
    assert outcome == "decoded" and wrong <= 0.005, f"{outcome}, {100 * wrong:.2f}% wrong"


def test_121_codewords_misread_by_an_uncompensated_gamma_warn():
    """paper-sim: the uncompensated gamma moves a partition level nearer its neighbour, and
    a whole partition of the bust reads one partition off (measured 19.9% of the valid
    pixels, each region's own code consistent with it): not refused, but the decode says
    why."""
    outcome, wrong, warnings = _decode("paper-sim", (1280, 1024), 0, HARD, CODE_121,
                                       compensated=False)
    assert outcome == "decoded"
    assert wrong <= 0.005 or any("gamma" in w for w in warnings), \
        f"{100 * wrong:.2f}% wrong, no warning"


@pytest.mark.parametrize("scene", ["paper-sim"])
def test_121_codewords_with_the_gamma_compensated_are_right(scene):
    outcome, wrong, _ = _decode(scene, (1280, 1024), 4, HARD, CODE_121, compensated=True)
    assert outcome == "decoded" and wrong <= 0.005, f"{outcome}, {100 * wrong:.2f}% wrong"


LOW = dict(read_noise=0.01, camera_blur=1.0)


@pytest.mark.parametrize("scene", ["sphere-on-plane", "objects-on-plane", "two-sculptures",
                                   "mugs-on-wall"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_low_resolution_decodes_are_never_silently_wrong(scene, seed):
    outcome, wrong, warnings = _decode(scene, (320, 256), seed, LOW,
                                       dict(period=30, partitions=8, stairs=8),
                                       compensated=True)
    # measured: all 12 decode, 68.9-99.7% of the truth's pixels, 0-1.3% wrong
    assert outcome == "decoded"
    assert wrong <= 0.005 or any("partition bands" in w for w in warnings), \
        f"{100 * wrong:.2f}% wrong, no warning"
    assert wrong <= 0.02  # and never a whole object off


def test_the_stripe_above_the_sphere_is_not_given_the_spheres_orders(tmp_path):
    """The README's depth-range scene, as `bistair simulate` renders it at 320 x 256 (issue
    21, item 8): a stripe of the background above the sphere, whose phase runs on into the
    sphere's top, was decoded with the sphere's orders (682 px, 0.95% of the valid pixels)
    and became a rod at the sphere's depth in the point cloud."""
    result = CliRunner().invoke(cli, ["simulate", "--scene", "sphere-on-plane", "--method",
                                      "bidirectional", "--camera", "320x256", "--out",
                                      str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    res = bistair.decode(*read_with_spec(tmp_path / "bidirectional", None))
    truth, known = np.load(tmp_path / "truth" / "coord_x.npy"), np.load(tmp_path / "truth"
                                                                         / "mask.npy")
    both = res.mask & known
    assert both.sum() > 60000
    assert np.count_nonzero(np.abs(res.coord - truth)[both] > res.period / 2) == 0
