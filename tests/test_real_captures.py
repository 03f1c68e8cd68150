"""The multi-frequency reference on real captures (../shared/data/cfpe, MIT licence).

Three-frequency, twelve-step phase shifting (periods 42/45/48 px, heterodyne), projector
1920x1080, camera 640x480, 8 bit, uncompensated projector gamma, frame 36 fully lit.
Measured here: the three periods agree on 99.2% of well-modulated pixels on both scenes,
0.02% (plate) and 0.01% (david) of neighbouring valid pixel pairs jump by more than pi.
"""

import numpy as np
import pytest
from conftest import CFPE

import bistair
from bistair.io.files import read_captures

pytestmark = pytest.mark.skipif(not CFPE.is_dir(), reason="../shared/data/cfpe not present")


def cfpe_spec():
    return bistair.make_spec("multifreq", width=1920, height=1080, periods=(42, 45, 48),
                             steps=12, unwrap="heterodyne", white=1, offset=128 / 255,
                             amplitude=96 / 255)


def jump_share(phase: np.ndarray) -> float:
    dx = np.abs(np.diff(phase, axis=1))
    dy = np.abs(np.diff(phase, axis=0))
    pairs = np.isfinite(dx).sum() + np.isfinite(dy).sum()
    return float(((dx > np.pi).sum() + (dy > np.pi).sum()) / pairs)


@pytest.fixture(scope="module", params=["plate", "david"])
def decoded(request):
    stack = read_captures(CFPE / request.param)
    assert stack.shape == (37, 480, 640) and stack.dtype == np.uint8
    return request.param, bistair.decode(stack, cfpe_spec())


def test_periods_agree_and_phase_is_smooth(decoded):
    name, res = decoded
    assert res.info["period_agreement"] >= 0.97
    assert jump_share(res.phase) < 0.01
    lit = res.texture > 0.2  # the fully lit frame
    assert res.mask[lit].mean() > 0.85


def test_projector_columns_span_the_board_left_to_right(decoded):
    name, res = decoded
    lo, hi = np.nanpercentile(res.coord, [1, 99])
    assert 60 < lo < 100 and 1500 < hi < 1550  # "roughly 80..1520 px"
    rows = res.coord[100:380:40]
    slope = np.nanmedian(np.diff(rows, axis=1), axis=1)
    assert (slope > 1.5).all() and (slope < 3.5).all()  # increasing to the right


def test_dark_border_and_shadows_are_invalid(decoded):
    name, res = decoded
    dark = res.texture < 0.1  # the unlit border (and the bust's shadow)
    assert dark.sum() > 5000
    assert res.mask[dark].mean() < 0.01
