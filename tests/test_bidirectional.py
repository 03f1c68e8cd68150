"""The bidirectional codec against ground truth: exact round trips, then warped captures.

Tolerances are measured: on 8 seeds x (0.5%, 0.5 px), (1%, 1 px) and (2%, 1.5 px) of noise
and blur, the default decoder made no order error, covered every truth pixel and decoded
every small object wholly; phase RMSE stayed under 0.022, 0.033 and 0.066 rad. The paper's
decoder made 20-50% order errors on the same scenes.
"""

import numpy as np
import pytest
from conftest import score, warped_scene
from scipy import ndimage

import bistair
from bistair.errors import BistairError
from bistair.evaluation import metrics
from bistair.sim.warp import Blob, WarpScene, render_warp

VARIANTS = [
    dict(width=1080, height=1080, period=30),
    dict(width=1920, height=1080, period=30, partitions=8, stairs=8),
    dict(width=1080, height=600, period=30, partitions=4, stairs=9),
    dict(width=1080, height=600, period=30, partitions=12, stairs=3),
    dict(width=800, height=600, period=16, partitions=5, stairs=10, group_rows=24, local_rows=16),
    dict(width=1080, height=600, period=30, local_rows=10),
    dict(width=1080, height=700, period=30, orientation="rows"),
    dict(width=1080, height=600, period=30, steps=3),
    dict(width=1080, height=600, period=30, steps=5, bits=16),
]


@pytest.mark.parametrize("strategy", ["region", "paper"])
@pytest.mark.parametrize("params", VARIANTS, ids=lambda p: "-".join(f"{v}" for v in p.values()))
def test_patterns_decode_exactly(params, strategy):
    spec = bistair.make_spec("bidirectional", **params)
    pats = bistair.encode(spec)
    assert pats.shape == (spec.frame_count, spec.height, spec.width)
    res = bistair.decode(pats, spec, strategy=strategy)
    x = np.arange(spec.coded_length, dtype=float)
    x = x[None, :] if spec.orientation == "columns" else x[:, None]
    assert res.mask.all()
    assert np.abs(res.coord - x).max() < 1e-3
    assert np.array_equal(res.order, np.broadcast_to(x // spec.period, res.order.shape))
    assert np.abs(res.phase - 2 * np.pi * x / spec.period).max() < 1e-4


def test_gamma_precompensated_patterns_decode_exactly_through_that_gamma():
    spec = bistair.make_spec("bidirectional", width=1080, height=300, period=30, gamma=2.2,
                             bits=16)
    projected = bistair.encode(spec) ** 2.2  # what a gamma-2.2 projector emits
    res = bistair.decode(projected, spec)
    assert np.abs(res.coord - np.arange(1080)[None, :]).max() < 1e-3


def test_encoded_frames_follow_the_equations(spec36):
    pats = bistair.encode(spec36)
    x = np.arange(1080)
    assert np.allclose(pats[1, 0], 0.5 + 0.5 * np.cos(2 * np.pi * x / 30 + np.pi / 2), atol=1e-6)
    k = x // 30
    local = -np.pi + np.pi / 6 + 2 * np.pi / 6 * (k % 6)  # Eq. 13
    part = -np.pi + np.pi / 6 + 2 * np.pi / 6 * (k // 6)  # Eq. 14
    assert np.allclose(pats[4, 0], 0.5 + 0.5 * np.cos(local), atol=1e-6)  # rows 0-19: local
    assert np.allclose(pats[5, 19], 0.5 + 0.5 * np.sin(local), atol=1e-6)
    assert np.allclose(pats[4, 20], 0.5 + 0.5 * np.cos(part), atol=1e-6)  # rows 20-29
    assert np.allclose(pats[5, 59], 0.5 + 0.5 * np.sin(part), atol=1e-6)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(("noise", "blur"), [(0.005, 0.5), (0.01, 1.0)])
def test_moderate_warped_captures(spec36, seed, noise, blur):
    res, truth, m = score(spec36, warped_scene(seed, noise, blur))
    assert m["order_error_rate"] < 0.001
    assert m["coverage"] > 0.995
    assert m["phase_rmse"] < 0.05
    assert min(m["objects"].values()) > 0.99  # every small object, 1-2 fringes wide too
    # Background far from every object is invalid: NaN phase, order -1.
    far = ~ndimage.binary_dilation(truth.object_id > 0, iterations=6)
    assert not res.mask[far].any() and np.isnan(res.phase[far]).all()
    assert (res.order[far] == -1).all()


@pytest.mark.parametrize("seed", [3, 4])
def test_hard_warped_captures(spec36, seed):
    res, truth, m = score(spec36, warped_scene(seed, noise=0.02, blur=1.5))
    assert m["order_error_rate"] < 0.001
    assert m["coverage"] > 0.99
    assert m["phase_rmse"] < 0.09


@pytest.mark.parametrize("seed", [0, 5])
def test_default_beats_the_paper_decoder(spec36, seed):
    scene = warped_scene(seed, noise=0.01, blur=1.0)
    _, _, ours = score(spec36, scene)
    _, _, paper = score(spec36, scene, strategy="paper")
    assert ours["order_error_rate"] < paper["order_error_rate"]
    assert ours["order_errors"] * ours["decoded"] <= paper["order_errors"] * paper["decoded"]
    assert ours["coverage"] >= paper["coverage"] - 0.001
    assert min(ours["objects"].values()) >= min(paper["objects"].values())


def _wrong(res, truth, period=30.0):
    ok = res.mask & truth.mask
    err = np.abs(res.phase - 2 * np.pi * truth.coord("columns") / period)
    return ok & (err > np.pi)


def test_stair_edges_are_not_misordered(spec36):
    """Pixels within 2 camera pixels of a fringe edge, where code and phase change together."""
    scene = warped_scene(1, noise=0.02, blur=1.5)
    res, truth, _ = score(spec36, scene)
    frac = (truth.coord(spec36) / 30) % 1.0
    near_edge = truth.mask & (np.minimum(frac, 1 - frac) * 30 / scene.stretch < 2.0)
    assert near_edge.sum() > 2000
    assert _wrong(res, truth)[near_edge].sum() == 0
    paper, _, _ = score(spec36, scene, strategy="paper")
    assert _wrong(paper, truth)[near_edge].sum() > 0


def test_top_and_bottom_borders_of_objects(spec36):
    """The first and last 4 rows of every object, where groups are cut by the border."""
    scene = warped_scene(2, noise=0.01, blur=1.0)
    res, truth, _ = score(spec36, scene)
    inner = ndimage.binary_erosion(truth.mask, structure=np.ones((9, 1)))
    border = truth.mask & ~inner
    assert border.sum() > 1000
    assert _wrong(res, truth)[border].sum() == 0
    assert res.mask[border].mean() > 0.99


def test_64_fringes_on_a_wide_projector():
    spec = bistair.make_spec("bidirectional", width=1920, height=1080, period=30,
                             partitions=8, stairs=8)
    scene = warped_scene(6, noise=0.01, blur=1.0, stretch=2.2, offset=200.0,
                         size=(480, 720))
    _, _, m = score(spec, scene)
    assert m["order_error_rate"] < 0.001 and m["coverage"] > 0.99


def test_unequal_partitions_and_stairs():
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30,
                             partitions=4, stairs=9)
    _, _, m = score(spec, warped_scene(7, noise=0.01, blur=1.0))
    assert m["order_error_rate"] < 0.001 and m["coverage"] > 0.99


def test_rows_orientation_round_trip():
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30,
                             orientation="rows")
    res, truth, m = score(spec, warped_scene(8, noise=0.01, blur=1.0))
    assert res.phase.shape == (640, 480)  # the camera image, transposed by the scene
    assert m["order_error_rate"] < 0.001 and m["coverage"] > 0.99


def test_an_object_smaller_than_a_band_is_not_guessed(spec36):
    """Less than a fringe wide and a third of a group tall: may stay invalid, never wrong."""
    blobs = (Blob(160, 200, 14, 5, shift=0.0), Blob(420, 260, 100, 120, dome=10.0))
    for row_offset in np.linspace(0, 30, 7):
        scene = WarpScene(size=(400, 560), blobs=blobs, stretch=1.2, row_offset=row_offset,
                          noise=0.01, blur=1.0, seed=3)
        res, truth, m = score(spec36, scene)
        assert m["order_errors"] == 0


def test_dark_and_saturated_captures_are_refused(spec36):
    dark = np.full((6, 100, 120), 3, np.uint8)
    with pytest.raises(BistairError, match="dark"):
        bistair.decode(dark, spec36)
    blown = np.full((6, 100, 120), 255, np.uint8)
    with pytest.raises(BistairError, match="saturated"):
        bistair.decode(blown, spec36)


def test_wrong_frame_count_and_unknown_option(spec36):
    with pytest.raises(BistairError, match="needs 6 frames, the captures have 4"):
        bistair.decode(np.zeros((4, 50, 50)), spec36)
    with pytest.raises(BistairError, match="no option"):
        bistair.decode(bistair.encode(spec36), spec36, speed="fast")
    with pytest.raises(BistairError, match="unknown strategy"):
        bistair.decode(bistair.encode(spec36), spec36, strategy="magic")


def test_saturated_pixels_are_invalid(spec36):
    images, truth = render_warp(spec36, warped_scene(0, noise=0.005, blur=0.5))
    exposed = images * 2.2  # over-exposed: the brightest objects clip
    res = bistair.decode(np.clip(exposed, 0, 1), spec36)
    heavily = (exposed[:4] > 1.05).sum(axis=0) >= 2  # two phase samples cut well short
    assert heavily.sum() > 1000
    assert not res.mask[heavily].any()
    m = metrics.score(res, truth.coord(spec36), truth.mask)
    assert m["order_errors"] == 0 and m["phase_rmse"] < 0.05


@pytest.mark.parametrize("bits", [10, 12, 14])
def test_saturation_of_msb_aligned_16_bit_containers(spec36, bits):
    """A 10-14-bit camera's images stored MSB-aligned in 16-bit PNGs saturate at
    ``65536 - 2**(16 - bits)``: those pixels are flagged as in the 8-bit capture."""
    images, _ = render_warp(spec36, warped_scene(0, noise=0.005, blur=0.5))
    exposed = np.clip(images * 2.2, 0, 1)
    codes = np.round(exposed * ((1 << bits) - 1)).astype(np.uint16) << (16 - bits)
    res = bistair.decode(codes, spec36)
    heavily = (images[:4] * 2.2 > 1.05).sum(axis=0) >= 2
    assert heavily.sum() > 1000
    assert not res.mask[heavily].any()
    lsb = bistair.decode(codes >> (16 - bits), spec36)  # the same data LSB-aligned
    np.testing.assert_array_equal(res.mask, lsb.mask)
