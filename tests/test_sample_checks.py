"""The thresholded checks of the whole capture judge pass 0's sample (issue 32): each keeps
its figure on the side of its limit where it was before (the rendered scene of
tests/test_spec_mismatch.py; the real captures: tests/test_no_false_refusals.py,
benchmarks/sample_checks.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import bistair
from bistair.codecs import REGISTRY
from bistair.codecs.base import shift_order_problem
from bistair.codecs.bidirectional.bands import union_levels
from bistair.core.checks import axis_problem, axis_rates, stair_misfit, stair_sample
from bistair.sim import Imaging, expose, preset, trace


@pytest.fixture(scope="module")
def scene() -> Any:
    rig, geometry = preset("objects-on-plane", camera_size=(480, 384))
    imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=1)
    return rig, imaging, trace(rig, geometry, imaging)


def _measured(scene: Any, method: str, swap: tuple[int, int] | None = None,
              **changes: Any) -> tuple[Any, Any]:
    rig, imaging, traced = scene
    width, height = rig.projector.size
    spec = bistair.make_spec(method, width=width, height=height, gamma=imaging.gamma,
                             **REGISTRY[method].comparable(width, height, 30, 4))
    images = expose(traced, bistair.encode(spec), imaging)
    if swap is not None:
        images[list(swap)] = images[list(swap[::-1])]
    spec = spec.replace(**changes)
    codec = REGISTRY[method]
    _, cols = codec._columns(images, spec)
    return codec.measure_columns(cols, spec, None), spec


def test_axis_figure_keeps_its_side_of_the_limit(scene):
    """Right: 0.047 (0.048 before); turned: 11 (42); two shift frames swapped, a garbled
    phase but no turned camera: 0.52 (0.75; on one-row steps down the columns 1.06, over
    the limit, which would name a turned camera beside the frame order)."""
    ratio = {}
    for case, changes, swap in (("right", {}, None), ("rows", {"orientation": "rows"}, None),
                                ("swapped", {}, (0, 1))):
        fs, spec = _measured(scene, "graycode", swap, **changes)
        along, down = axis_rates(fs.sample)
        ratio[case] = down / along
        turned = axis_problem(fs.sample, spec.orientation)
        assert (turned is not None) == (case == "rows"), (case, ratio[case])
    assert ratio["right"] < 0.1 and ratio["rows"] > 5 and ratio["swapped"] < 0.7, ratio
    assert turned is None


def test_shift_order_judged_on_the_sample(scene):
    fs, spec = _measured(scene, "graycode")
    assert shift_order_problem(fs.sample, spec) is None
    fs, spec = _measured(scene, "graycode", (1, 2))
    assert shift_order_problem(fs.sample, spec).startswith(
        "frames shift-1 and shift-2 look swapped")
    # too few strong pixels in the sample to judge: nothing said
    dim = type(fs.sample)(**{**fs.sample.__dict__, "strong": np.zeros_like(fs.sample.strong)})
    assert shift_order_problem(dim, spec) is None


def test_stair_misfit_judged_on_the_sample(scene):
    """The sample's stair phases are the full pass's at the grid (the same bits), and a
    graycode capture read as a bidirectional one sits between the stair levels (0.77)."""
    fs, spec = _measured(scene, "bidirectional")
    theta, ok = stair_sample(fs.sample, fs.stair[0], fs.valid)
    grid = np.ix_(fs.sample.rows, fs.sample.cols)
    assert np.array_equal(theta, fs.stair[0][grid]) and np.array_equal(ok, fs.sample.strong)
    levels = union_levels(spec.partitions, spec.stairs)
    assert stair_misfit(theta, ok, levels) < 0.25
    rig, imaging, traced = scene
    width, height = rig.projector.size
    gray = bistair.make_spec("graycode", width=width, height=height, gamma=imaging.gamma,
                             **REGISTRY["graycode"].comparable(width, height, 30, 4))
    images = expose(traced, bistair.encode(gray), imaging)
    other = bistair.make_spec("bidirectional", width=width, height=height,  # 11 frames too
                              **REGISTRY["bidirectional"].comparable(width, height, 30, 9))
    _, cols = REGISTRY["bidirectional"]._columns(images, other)
    fs = REGISTRY["bidirectional"].measure_columns(cols, other, None)
    assert stair_misfit(*stair_sample(fs.sample, fs.stair[0], fs.valid),
                        union_levels(other.partitions, other.stairs)) > 0.7


def test_refusals_of_the_sample_come_before_pass_1(scene, monkeypatch):
    """Swapped shift frames and a turned camera are refused from pass 0's sample alone: the
    pass over every pixel never runs."""
    from bistair.core import measure

    def no_full_pass(*args, **kwargs):
        raise AssertionError("pass 1 ran")

    rig, imaging, traced = scene
    width, height = rig.projector.size
    spec = bistair.make_spec("bidirectional", width=width, height=height, gamma=imaging.gamma,
                             **REGISTRY["bidirectional"].comparable(width, height, 30, 4))
    images = expose(traced, bistair.encode(spec), imaging)
    monkeypatch.setattr(measure, "front_end", no_full_pass)
    swapped = images.copy()
    swapped[[0, 1]] = swapped[[1, 0]]
    with pytest.raises(bistair.BistairError, match="shift-0 and shift-1 look swapped"):
        bistair.decode(swapped, spec)
    with pytest.raises(bistair.BistairError, match="is orientation columns"):
        bistair.decode(images, spec.replace(orientation="rows"))
    with pytest.raises(AssertionError, match="pass 1 ran"):  # a right capture goes on
        bistair.decode(images, spec)


def test_stair_fit_on_a_fixed_grid(scene):
    """The stair fit's pixels come from a fixed grid (every m-th pixel, m prime to the
    width), and it still accepts the right spec and refuses one more partition (the
    figures: 0.004 and 0.21, before on a scan of the decoded pixels 0.004 and 0.21)."""
    from bistair.codecs.bidirectional.stairs import grid_sample

    valid = np.random.default_rng(0).random((384, 480)) < 0.9
    order = np.where(np.random.default_rng(1).random((384, 480)) < 0.5, 3, -1)
    idx = grid_sample(valid, order, 1000)
    assert idx.size <= 1000 and np.all(valid.ravel()[idx] & (order.ravel()[idx] >= 0))
    assert np.unique(idx // 480).size > 300  # spread over the rows, no band left out
    # a fixed grid (every 61st pixel), not every j-th of the decoded pixels found by a scan
    assert np.gcd.reduce(np.diff(idx)) == 61
    rig, imaging, traced = scene
    width, height = rig.projector.size
    spec = bistair.make_spec("bidirectional", width=width, height=height, gamma=imaging.gamma,
                             **REGISTRY["bidirectional"].comparable(width, height, 30, 4))
    images = expose(traced, bistair.encode(spec), imaging)
    right = bistair.decode(images, spec)
    assert right.info["stair_misfit"] < 0.05
    wrong = bistair.decode(images, spec.replace(partitions=spec.partitions + 1), force=True)
    assert wrong.info["stair_misfit"] > 0.15
    assert any("stair phase is nearer a level" in f for f in wrong.info["forced"])
