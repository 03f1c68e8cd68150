"""Specs: validation with one-line reasons, JSON round trips, frame order."""

import json

import numpy as np
import pytest

import bistair
from bistair import load_spec, spec_from_dict
from bistair.errors import BistairError


def test_round_trip_through_json(tmp_path):
    spec = bistair.make_spec("bidirectional", width=1920, height=1080, period=30,
                             partitions=8, stairs=8, group_rows=24, local_rows=16, bits=16)
    path = tmp_path / "spec.json"
    path.write_text(spec.to_json())
    again = load_spec(path)
    assert again == spec
    data = json.loads(path.read_text())
    assert data["method"] == "bidirectional"
    assert data["frames"] == ["shift-0", "shift-1", "shift-2", "shift-3", "stair-cos", "stair-sin"]


def test_frames_may_be_reordered():
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    data = spec.to_dict()
    data["frames"] = list(reversed(data["frames"]))
    again = spec_from_dict(data)
    assert again.frames == tuple(reversed(spec.frames))
    assert again.frame_index("stair-sin") == 0


@pytest.mark.parametrize(
    ("params", "reason"),
    [
        (dict(period=29), "narrower than the 1080-px coded axis"),
        (dict(period=30, local_rows=15), "equal partition rows"),
        (dict(period=30, stairs=1, partitions=36), "stairs must be at least 2"),
        (dict(period=3, partitions=60, stairs=6), "period must be at least 4"),
        (dict(period=30, local_rows=30), "local rows must lie in 1..29"),
        (dict(period=30, steps=2), "steps must be at least 3"),
        (dict(period=30, bits=12), "bits must be 8 or 16"),
        (dict(period=30, offset=0.8, amplitude=0.5), r"offset \+ amplitude <= 1"),
        (dict(period=30, partitions=1, stairs=36), "partitions must be at least 2"),
        (dict(period=30, orientation="diagonal"), "orientation must be"),
    ],
)
def test_parameters_that_cannot_work_are_refused(params, reason):
    with pytest.raises(BistairError, match=reason) as info:
        bistair.make_spec("bidirectional", width=1080, height=1080, **params)
    assert "\n" not in str(info.value)


FULL = bistair.make_spec("bidirectional", width=1080, height=1080, period=30).to_dict()


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        ({"width": 10, "height": 10, "period": 30}, "misses the field 'method'"),
        ({"method": "bidirectional", "width": 1080, "height": 1080}, "misses field"),
        ({"method": "nope", "width": 1080, "height": 1080}, "unknown method"),
        ({**FULL, "x": 1}, "unknown field"),
        ({**FULL, "width": "wide"}, "must be an integer"),
        ({**FULL, "frames": ["a"]}, "spec field 'frames' misses"),
        ([1, 2], "JSON object"),
    ],
)
def test_bad_spec_dicts(data, reason):
    with pytest.raises(BistairError, match=reason):
        spec_from_dict(data)


def test_spec_file_errors(tmp_path):
    with pytest.raises(BistairError, match="not found"):
        load_spec(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(BistairError, match="not valid JSON"):
        load_spec(bad)


@pytest.mark.parametrize("method, params", [
    ("graycode", dict(period=8)), ("multifreq", dict(periods=(64, 16, 8))),
    ("bidirectional", dict(period=8, partitions=2)), ("phase-coding", dict(period=8)),
    ("lv", dict(period=8))])
def test_both_axes_decode_in_the_default_frame_order(method, params):
    """Without a frame_order, each axis spec still sees the other axis's frames (ignored)."""
    spec = bistair.make_spec(method, width=64, height=32, orientation="both", white=1, **params)
    assert spec.frame_order == () and spec.frames[-1] == "white"
    for _, sub in spec.axes():
        assert len(sub.frames) == spec.frame_count
        assert sum(name != "ignore" for name in sub.frames) == len(sub.method_frames()) + 1
    result = bistair.decode(bistair.encode(spec), spec)
    assert result.mask.all()
    assert np.abs(result.coord_x - np.arange(64)[None, :]).max() < 1e-4
    assert np.abs(result.coord_y - np.arange(32)[:, None]).max() < 1e-4
