"""``bistair simulate --count``: data sets of varied scenes on Dask, the same files for a
seed whatever the number of workers, a manifest for ``bistair batch``."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from conftest import cli_run

from bistair.app.simulate import scene_parameters
from bistair.sim.variation import build, check_vary


def _files(root):
    return sorted(p.relative_to(root) for p in root.rglob("*") if p.is_file())


def test_a_data_set_is_the_same_for_any_number_of_workers(tmp_path, monkeypatch, capsys):
    args = ["simulate", "--count", 2, "--seed", 13, "--vary", "optics,objects,pose",
            "--method", "graycode", "--camera", "160x128"]
    code, text, err = cli_run(monkeypatch, capsys, *args, "--out", tmp_path / "one",
                              "--workers", 1)
    assert code == 0, err
    assert "wrote 2 of 2 scenes (2 capture sets)" in text and "on 1 worker" in text
    code, _, err = cli_run(monkeypatch, capsys, *args, "--out", tmp_path / "two",
                           "--workers", 2)
    assert code == 0, err
    one, two = tmp_path / "one", tmp_path / "two"
    files = _files(one)
    assert files == _files(two)
    for rel in files:
        assert (one / rel).read_bytes() == (two / rel).read_bytes(), rel
    names = {str(f) for f in files}
    for scene in ("scene-0000", "scene-0001"):
        for name in ("scene.json", "calibration.json", "graycode/spec.json", "graycode/10.png",
                     *(f"truth/{t}.npy" for t in ("coord", "coord_x", "coord_y", "order",
                                                  "mask", "depth", "object_id"))):
            assert f"{scene}/{name}" in names
    truth = one / "scene-0001" / "truth"
    coord, order, mask = (np.load(truth / f"{n}.npy") for n in ("coord", "order", "mask"))
    assert np.array_equal(coord, np.load(truth / "coord_x.npy"))  # the columns are coded
    assert np.array_equal(order[mask], np.floor(coord[mask] / 30).astype(np.int32))
    assert (order[~mask] == -1).all() and order.dtype == np.int32
    # the parameters in scene.json rebuild the scene, and they are those of the seed
    about = json.loads((one / "scene-0001" / "scene.json").read_text())
    params = about["parameters"]
    assert params == scene_parameters(5, 13, ["optics", "objects", "pose"],
                                      camera_size=(160, 128),
                                      imaging=dict(read_noise=0.01, camera_blur=1.0,
                                                   gamma=2.2, ambient=0.05, bits=8))[1]
    rig, _, imaging = build(params)
    assert imaging.read_noise == params["imaging"]["read_noise"] != 0.01
    assert rig.projector.center[0] == pytest.approx(params["rig"]["baseline"])
    # index.csv is a batch manifest: decode and reconstruct with each scene's calibration
    with (one / "index.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["captures"] for r in rows] == ["scene-0000/graycode", "scene-0001/graycode"]
    code, text, err = cli_run(monkeypatch, capsys, "batch", one / "index.csv", "--out",
                              tmp_path / "decoded", "--workers", 1, "--no-previews")
    assert code == 0, err
    for row in rows:
        depth = np.load(tmp_path / "decoded" / row["out"] / "depth.npy")
        truth = one / row["scene"] / "truth"
        ok = np.load(truth / "mask.npy") & np.isfinite(depth)
        assert ok.sum() > 1000
        # within a few mm at 2 mm per camera pixel (a baseline 10% off: some 60 mm)
        assert np.median(np.abs(depth - np.load(truth / "depth.npy"))[ok]) < 5.0


def test_data_set_options_are_checked(tmp_path, monkeypatch, capsys):
    def refused(*args) -> str:
        code, out, err = cli_run(monkeypatch, capsys, "simulate", "--method", "graycode",
                                 "--out", tmp_path / "data", *args)
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        return err

    assert "give --count too" in refused("--scene", "plane", "--vary", "optics")
    assert "give --count too" in refused("--scene", "plane", "--workers", 2)
    assert "--count must be 1 or more" in refused("--scene", "plane", "--count", 0)
    assert "--vary takes optics, objects, pose" in refused("--scene", "plane", "--count", 2,
                                                            "--vary", "light")
    assert "leave out --scene" in refused("--scene", "plane", "--count", 2, "--vary", "objects")
    assert "name a --scene" in refused("--count", 2)
    assert "name a --scene" in refused()
    assert "board captures" in refused("--scene", "calibration", "--count", 2)
    assert "camera size" in refused("--scene", "plane", "--count", 2, "--camera", "4x4")
    assert not (tmp_path / "data").exists()


def test_each_aspect_draws_from_its_own_stream():
    base = scene_parameters(4, 3, ["objects"])
    more = scene_parameters(4, 3, ["objects", "pose", "optics"])
    assert [p["objects"] for p in base] == [p["objects"] for p in more]
    assert [p["preset"] for p in base] == [p["preset"] for p in more]
    assert [p["imaging"]["seed"] for p in base] == [p["imaging"]["seed"] for p in more]
    assert len({p["imaging"]["seed"] for p in base}) == 4
    assert check_vary("") == ()
