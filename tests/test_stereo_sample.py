"""A binocular sample of another tool, reconstructed through the command line without hand
work (issue 22): 12-step sinusoid + complementary Gray code with inverses in the tool's frame
order, BMP files, a hand-written spec, an OpenCV stereo YAML with the tool's key names
(``--keys``), rendered here at 640 x 512 (``tests/support/stereo_sample.py``;
``benchmarks/stereo_sample.py`` does the same at 1280 x 1024).

The reconstruction must lie within 0.2 mm (median) of the truth and of an independent
reconstruction: ``bistair reconstruct`` of the left camera with the projector's calibration
(camera-projector triangulation, which the stereo path never uses). Measured: 0.037 mm from
the truth, 0.097 mm from the camera-projector reconstruction (whose own noise is most of
it).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import cli_run
from support.stereo_sample import KEYS, write_sample


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    return write_sample(tmp_path_factory.mktemp("sample") / "sample", (640, 512))


def test_the_sample_reconstructs_through_the_command_line(sample, tmp_path, monkeypatch,
                                                          capfd):
    cal = tmp_path / "stereo.json"
    code, stdout, err = cli_run(monkeypatch, capfd, "import-calibration", sample["yml"],
                                "--stereo", "--keys", KEYS, "--out", cal)
    assert code == 0 and err == "", err
    assert stdout.startswith("cameras 640x512, baseline 160.03 mm")  # 3 mm high too
    out = tmp_path / "res"
    code, stdout, err = cli_run(monkeypatch, capfd, "stereo", sample["L"], sample["R"],
                                "--spec", sample["spec"], "--calibration", cal, "--out", out)
    assert code == 0 and err == "", err
    depth = np.load(out / "depth.npy")
    truth = np.load(sample["truth"] / "depth.npy")
    mask = np.load(sample["truth"] / "mask.npy")
    ok = np.isfinite(depth) & mask
    assert ok.sum() > 0.6 * mask.sum()
    assert np.median(np.abs(depth[ok] - truth[ok])) < 0.2
    code, _, err = cli_run(monkeypatch, capfd, "reconstruct", sample["L"], "--spec",
                           sample["spec"], "--calibration", sample["mono"], "--out",
                           tmp_path / "mono.ply")
    assert code == 0, err
    mono = np.load(tmp_path / "mono-depth" / "depth.npy")
    both = np.isfinite(depth) & np.isfinite(mono)
    assert both.sum() > 0.6 * mask.sum()
    assert np.median(np.abs(depth[both] - mono[both])) < 0.2
    info = json.loads((out / "info.json").read_text())
    assert info["matched_axis"] == "columns" and info["warnings"] == []
