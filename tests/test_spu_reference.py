"""bistair's stereo phase unwrapping against the published pipeline's reference
(benchmarks/spu_reference.py) on a small render of a rectified virtual rig, through the
user's commands: BSC frames as %04d.bmp, MATLAB .mat matrices with 1-based camera pixels,
patterns multifreq --shift-sign -1, import-calibration --projection-matrices, stereo
--depth-range."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
spu_reference = pytest.importorskip("spu_reference")


def test_points_match_the_reference(tmp_path):
    """At least 90% as many points as the reference, a median nearest-point distance
    under 0.1 mm (both triangulate the left camera with the projector's column: the same
    points where both decide the same order), and the .mat files read 1-based."""
    out = spu_reference.run("two-masks", (160, 120), 0.5, tmp_path)
    assert out["ratio"] >= 0.9, out
    assert out["median_mm"] < 0.1, out
    assert out["ours_off_truth"] <= out["ref_off_truth"] + 0.01, out
    info = json.loads((tmp_path / "out" / "info.json").read_text())
    assert info["pixel_origin"] == 1 and not info["warnings"]
    assert json.loads((tmp_path / "rig.json").read_text())["pixel_origin"] == 1
