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


def test_mixed_pixels_at_the_objects_edges_are_left_undecided(tmp_path):
    """objects-on-plane, projector halfway, 320 x 240, through the commands: the cameras'
    blur across the boxes' edges makes ramps of mixed pixels that both cameras and the
    projector confirm; left undecided (165), the decided pixels over 5 mm off the truth's
    depth at the same pixel fall from 1.09% (434) to 0.72%, those within 2 mm rise from
    96.8% to 97.2%; still at least 90% as many points as the reference."""
    out = spu_reference.run("objects-on-plane", (320, 240), 0.5, tmp_path)
    assert out["ours_same_pixel_over_5mm"] <= 0.009, out
    assert out["ours_same_pixel_truth"] >= 0.97 and out["mixed"] > 100, out
    assert out["ratio"] >= 0.9 and out["ours_off_truth"] <= out["ref_off_truth"], out


def test_continue_unseen_is_asked_for(tmp_path):
    """``stereo --continue-unseen`` decides the left pixels the right camera cannot see
    (two-masks, 160 x 120: a band whose matches fall off the right image), none an order
    off (the share over 5 mm from the truth's depth at the same pixel moves by under a
    point); without it none are continued,
    as the published pipeline; with a stream (``--window``) it is refused, exit 2."""
    plain = spu_reference.run("two-masks", (160, 120), 0.5, tmp_path / "plain")
    more = spu_reference.run("two-masks", (160, 120), 0.5, tmp_path / "more",
                             continue_unseen=True)
    assert plain["continued"] == 0 and more["continued"] > 100, (plain, more)
    assert more["bistair"] == plain["bistair"] + more["continued"], (plain, more)
    assert more["ours_same_pixel_over_5mm"] <= plain["ours_same_pixel_over_5mm"] + 0.01, (
        plain["ours_same_pixel_over_5mm"], more["ours_same_pixel_over_5mm"])
    from click.testing import CliRunner

    from bistair.app.cli import cli

    folder = tmp_path / "more"
    res = CliRunner().invoke(cli, [
        "stereo", str(folder / "1_Rectified"), str(folder / "2_Rectified"), "--spec",
        str(folder / "patterns" / "spec.json"), "--calibration", str(folder / "rig.json"),
        "--depth-range", "500:700", "--window", "4", "--continue-unseen", "--out",
        str(tmp_path / "stream")])
    assert res.exit_code == 2 and "--continue-unseen" in res.output, res.output
    assert not (tmp_path / "stream").exists()
