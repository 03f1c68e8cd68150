"""The projector's gamma measured from a grey ramp on the virtual rig, and patterns that
pre-compensate it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import cli_run

import bistair
from bistair.core.phase import TWO_PI
from bistair.io.atomic import write_image
from bistair.io.read import read_captures
from bistair.sim import Imaging, expose, preset, trace


@pytest.fixture(scope="module")
def traced():
    rig, scene = preset("plane", camera_size=(320, 256), projector_size=(1080, 1080))
    return trace(rig, scene, Imaging(seed=5))


@pytest.mark.parametrize("gamma", [1.8, 2.2, 2.6])
def test_gamma_is_measured_from_a_ramp(traced, tmp_path, monkeypatch, capsys, gamma):
    code, _, err = cli_run(monkeypatch, capsys, "patterns", "gamma", "--levels", 17,
                           "--out", tmp_path / "ramp")
    assert code == 0, err
    ramp = read_captures(tmp_path / "ramp")
    caps = tmp_path / "caps"
    caps.mkdir()
    imaging = Imaging(gamma=gamma, read_noise=0.01, seed=6)
    for i, img in enumerate(expose(traced, ramp.astype(np.float32) / 255, imaging)):
        write_image(caps / f"{i:02d}.png", img)
    code, out, err = cli_run(monkeypatch, capsys, "gamma", caps, "--ramp",
                             tmp_path / "ramp" / "ramp.json", "--out", tmp_path / "g.json")
    assert code == 0, err
    fit = json.loads((tmp_path / "g.json").read_text())
    # measured: within 0.03 of the rig's gamma (8-bit patterns, 8-bit camera, 1% noise)
    assert abs(fit["gamma"] - gamma) < 0.05 and fit["rms"] < 0.01


def test_gamma_file_precompensates_the_patterns(traced, tmp_path, monkeypatch, capsys):
    (tmp_path / "g.json").write_text(json.dumps({"gamma": 2.2}))
    code, _, err = cli_run(monkeypatch, capsys, "patterns", "graycode", "--width", 1080,
                           "--height", 1080, "--period", 30, "--gamma-file",
                           tmp_path / "g.json", "--out", tmp_path / "pats")
    assert code == 0, err
    spec = bistair.load_spec(tmp_path / "pats" / "spec.json")
    assert spec.gamma == 2.2
    imaging = Imaging(gamma=2.2, read_noise=0.0, full_well=0, seed=7)
    truth = traced.truth
    ripple, covered = {}, {}
    for name, s in (("compensated", spec), ("plain", spec.replace(gamma=1.0))):
        res = bistair.decode(expose(traced, bistair.encode(s), imaging), s)
        ok = res.mask & truth.mask
        want = TWO_PI * truth.coord_x[ok] / 30
        err = res.phase[ok] - want
        assert np.abs(err).max() < 1.0  # no pixel an order off
        # the uncompensated gamma's harmonics ripple the 4-step phase four times a fringe
        # (its RMS alone was once this test's figure: it measured the orders read wrong
        # beside the code's edges, 720 and 3840 pixels, which are now left out)
        ripple[name] = 2 * np.hypot(np.mean(err * np.cos(4 * want)),
                                    np.mean(err * np.sin(4 * want)))
        covered[name] = ok.sum() / truth.mask.sum()
    # measured: 0.0023 against 0.0044 rad; 99.1% and 95.3% of the plane decoded
    assert ripple["compensated"] < 0.65 * ripple["plain"]
    assert covered["compensated"] > 0.98


def test_gamma_errors(tmp_path, monkeypatch, capsys):
    (tmp_path / "bad.json").write_text(json.dumps({"gamma": 9}))
    code, _, err = cli_run(monkeypatch, capsys, "patterns", "graycode", "--gamma-file",
                           tmp_path / "bad.json", "--out", tmp_path / "p")
    assert code == 2 and "no gamma in [0.2, 5]" in err and not (tmp_path / "p").exists()
    code, _, err = cli_run(monkeypatch, capsys, "patterns", "gamma", "--levels", 3,
                           "--out", tmp_path / "r")
    assert code == 2 and "at least 5 levels" in err
