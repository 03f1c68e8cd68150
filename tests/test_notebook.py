"""A user's first hour in a notebook (issue 25): the package's public names, captures read
with their spec, one-line reprs, ``result.save`` (what ``bistair decode`` writes),
``result.plot`` and ``bistair.reconstruct`` with the spec the result carries."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import cli_run

import bistair
from bistair.app.patterns import save_patterns
from bistair.app.simulate import simulate
from bistair.geometry.calibration import Calibration
from bistair.sim import Imaging, preset, render

PUBLIC = {"AxesResult", "BistairError", "DecodeResult", "Reconstruction", "decode", "encode",
          "get_codec", "load_calibration", "load_spec", "make_spec", "methods", "plot_result",
          "read_captures", "reconstruct", "save_result", "scan", "spec_from_dict", "stereo"}
SUBPACKAGES = {"acquire", "app", "codecs", "core", "evaluation", "geometry", "io", "sim"}


def _python(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True, timeout=300).stdout


def test_import_bistair_stays_light():
    """``import bistair`` imports neither NumPy nor the codecs, matplotlib or click."""
    loaded = json.loads(_python("import sys, json, bistair\n"
                                "print(json.dumps(sorted(sys.modules)))"))
    heavy = [m for m in loaded if m.split(".")[0] in ("numpy", "scipy", "numba", "matplotlib",
                                                     "cv2", "click", "dask")]
    ours = [m for m in loaded if m.startswith("bistair")]
    assert not heavy and ours == ["bistair", "bistair.errors", "bistair.hooks"]


def test_dir_lists_the_public_names_only():
    names = set(dir(bistair))
    assert names == PUBLIC | SUBPACKAGES | {"__version__"}
    assert set(bistair.__all__) == PUBLIC
    assert not names & {"Any", "TYPE_CHECKING", "importlib", "annotations", "typing"}
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        bistair.nothing  # noqa: B018


def test_every_public_name_and_subpackage_is_an_attribute():
    """In a fresh interpreter: ``bistair.sim`` without ``import bistair.sim`` first."""
    code = ("import bistair\n"
            f"for name in {sorted(PUBLIC | SUBPACKAGES)!r}: getattr(bistair, name)\n"
            "print(bistair.sim.preset.__module__, bistair.read_captures.__module__)")
    assert _python(code).split() == ["bistair.sim.presets", "bistair.io.read"]


@pytest.fixture(scope="module")
def pats(tmp_path_factory):
    spec = bistair.make_spec("graycode", width=240, height=48, period=24)
    return save_patterns(spec, tmp_path_factory.mktemp("caps") / "pats"), spec


def test_read_captures_takes_what_decode_takes(pats, tmp_path):
    folder, spec = pats
    truth = bistair.encode(spec)
    stack, found = bistair.read_captures(folder)  # spec.json beside them
    assert found == spec and stack.shape == truth.shape and stack.dtype == np.uint8
    files = sorted(folder.glob("*.png"))
    np.save(tmp_path / "stack.npy", stack)
    for captures, given in ((str(folder / "*.png"), None), (files, folder / "spec.json"),
                            (tmp_path / "stack.npy", spec)):
        again, used = bistair.read_captures(captures, given)
        assert used == spec and np.array_equal(again, stack)
    result = bistair.decode(stack, found)
    assert np.array_equal(result.order[0, ::24], np.arange(10))
    with pytest.raises(bistair.BistairError, match="frames"):
        bistair.read_captures(files[:3], spec)


def test_reprs_are_one_line():
    spec = bistair.make_spec("graycode", width=240, height=48, period=24)
    result = bistair.decode(bistair.encode(spec), spec)
    text = repr(result)
    assert text == ("DecodeResult('graycode', shape (48, 240), 100.00% valid, noise 0.00% of "
                    "full scale)")
    both = bistair.make_spec("graycode", width=240, height=48, period=24, orientation="both")
    axes = bistair.decode(bistair.encode(both), both)
    assert repr(axes).startswith("AxesResult('graycode', shape (48, 240), 100.00% valid on "
                                 "both axes (x 100.00%, y 100.00%)")
    assert "\n" not in repr(axes) and axes.spec == both and axes.x.spec.orientation == "columns"
    result.info["warnings"] = ["one", "two"]
    assert repr(result).endswith(", 2 warnings)")


def test_save_writes_what_decode_writes(pats, tmp_path, monkeypatch, capsys):
    folder, _ = pats
    code, _, err = cli_run(monkeypatch, capsys, "decode", folder, "--out", tmp_path / "cli")
    assert code == 0, err
    stack, spec = bistair.read_captures(folder)
    result = bistair.decode(stack, spec)
    assert result.save(tmp_path / "nb") == tmp_path / "nb"
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "nb").iterdir())
    for name in names:
        a, b = (tmp_path / "cli" / name).read_bytes(), (tmp_path / "nb" / name).read_bytes()
        assert a == b, name
    # an earlier decode's previews do not stay beside a save without them
    bistair.save_result(result, tmp_path / "nb", previews=False)
    assert not list((tmp_path / "nb").glob("*.png"))


def test_plot_draws_six_panels_with_units():
    spec = bistair.make_spec("graycode", width=240, height=48, period=24)
    fig = bistair.decode(bistair.encode(spec), spec).plot()
    titles = [ax.get_title() for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert titles == ["wrapped phase", "absolute phase", "projector coordinate",
                      "fringe order", "modulation", "mask (100.0% valid)"]
    units = [ax.get_ylabel() for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert units == ["rad", "rad", "projector px", "fringe order", "fraction of full scale"]
    both = spec.replace(orientation="both")
    fig = bistair.decode(bistair.encode(both), both).plot()
    titles = [ax.get_title() for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(titles) == 12 and titles[0] == "x: wrapped phase" and titles[6].startswith("y:")


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim") / "sim"
    return simulate("plane", ["graycode"], out, camera_size=(160, 128), read_noise=0.0)


def test_reconstruct_takes_the_spec_from_the_result(rig):
    stack, spec = bistair.read_captures(rig / "graycode")
    result = bistair.decode(stack, spec)
    rec = bistair.reconstruct(result, rig / "calibration.json")  # a file, no spec
    truth = np.load(rig / "truth" / "depth.npy")
    both = rec.mask & np.isfinite(truth)
    assert both.mean() > 0.9
    assert np.median(np.abs(rec.depth[both] - truth[both])) < 0.5  # mm, at 600 mm
    assert repr(rec).startswith(f"Reconstruction({int(rec.mask.sum())} points of shape "
                                "(128, 160), depth ")
    cal = bistair.load_calibration(rig / "calibration.json")
    assert np.array_equal(bistair.reconstruct(result, cal, spec).depth, rec.depth,
                          equal_nan=True)
    result.spec = None
    with pytest.raises(bistair.BistairError, match="give the captures' spec"):
        bistair.reconstruct(result, cal)


def test_reconstruct_of_the_rows_knows_its_axis():
    """The result's spec decides the coded axis, not a default: rows, across which this
    rig's baseline carries no depth, are refused as with the spec given."""
    rig, scene = preset("plane", camera_size=(160, 128))
    spec = bistair.make_spec("graycode", width=1920, height=1080, period=24,
                             orientation="rows")
    images, _ = render(bistair.encode(spec), rig, scene, Imaging(read_noise=0.0))
    result = bistair.decode(images, spec)
    assert result.spec == spec
    for given in (None, spec):
        with pytest.raises(bistair.BistairError, match="projector rows barely change"):
            bistair.reconstruct(result, Calibration.from_rig(rig), given)


def test_hooks_refuse_an_unknown_action():
    with pytest.raises(bistair.BistairError, match="nothing provides 'print'"):
        bistair.hooks.call("print")
