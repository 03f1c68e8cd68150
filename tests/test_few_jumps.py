"""The wrap check on few phase jumps: fringes a few camera pixels wide leave few clean wraps.

The bidirectional paper decoder on sphere-on-plane at 320 x 256 (5-px fringes, default optics)
gave 58.8% of its pixels a wrong order and was accepted: only 89 clean wraps were judged, under
the 200 the share needs, and 22 of them (24.7%) stepped wrong. From 50 jumps a share that
exceeds the limit beyond doubt (99% Wilson lower bound) is refused.
"""

from __future__ import annotations

import pytest

import bistair
from bistair.core.checks import jump_problem
from bistair.evaluation.benchmark import method_specs
from bistair.sim import Imaging, preset, render

OPTICS = dict(gamma=2.2, read_noise=0.01, camera_blur=1.0, projector_blur=0.5, ambient=0.05)


def test_a_share_beyond_doubt_on_few_jumps_is_refused():
    assert "22 of the 89 phase jumps" in jump_problem(22, 89)
    assert jump_problem(5, 60) is None and jump_problem(10, 60) is None  # within doubt
    assert jump_problem(30, 49) is None  # too few to say anything
    assert jump_problem(150, 2000) is None  # many: the share against the limit, as before


def test_the_paper_decoder_on_narrow_fringes_is_refused():
    rig, scene = preset("sphere-on-plane", camera_size=(320, 256))
    spec, _ = method_specs(rig.projector.size, gamma=2.2)["bidirectional (paper decoder)"]
    images, _ = render(bistair.encode(spec), rig, scene, Imaging(**OPTICS, seed=0))
    with pytest.raises(bistair.BistairError, match="phase jumps judged"):
        bistair.decode(images, spec, strategy="paper")
