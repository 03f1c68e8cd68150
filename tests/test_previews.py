"""Views a user reads (issue 25): previews, depth.png and height.png carry a colour bar in
their unit beside the unchanged image; refused decodes show as refused in tables, reports
and the robustness plots; file names have no spaces or parentheses; the simulated
calibration renders every method named and says which pose it is rendering."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from conftest import cli_run

import bistair
from bistair.evaluation.benchmark import Comparison, Row, format_table, table
from bistair.evaluation.report import draw_method, write_report
from bistair.io.previews import PREVIEW_NAMES, SCALES, _lut, colorize, preview_images
from bistair.io.writers import write_depth
from bistair.sim.warp import WarpScene, render_warp

ROOT = Path(__file__).resolve().parents[1]


def _bar_column(image: np.ndarray, width: int) -> np.ndarray:
    """The colours down the middle of the colour bar: the strip's column with the most
    distinct colours."""
    strip = image[:, width:]
    counts = [len(np.unique(strip[:, x], axis=0)) for x in range(strip.shape[1])]
    return strip[:, int(np.argmax(counts))]


@pytest.fixture(scope="module")
def decoded(tmp_path_factory):
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30)
    images, _ = render_warp(spec, WarpScene(size=(240, 320), noise=0.01, blur=1.0))
    result = bistair.decode(images, spec)
    return result, result.save(tmp_path_factory.mktemp("res") / "res")


def test_previews_keep_their_names_and_pixels_and_add_a_colour_bar(decoded):
    result, folder = decoded
    plain = preview_images(result)
    for stem in PREVIEW_NAMES:
        png = iio.imread(folder / f"{stem}.png")
        h, w = result.mask.shape
        assert png.shape[0] == h and png.shape[1] > w + 40, stem
        assert np.array_equal(png[:, :w], plain[stem]), stem  # the camera's pixels, unchanged
        column = _bar_column(png, w)
        lut = _lut(SCALES[stem].cmap)
        inside = np.flatnonzero(~(column == 255).all(axis=1) & ~(column == 0).all(axis=1))
        top, bottom = column[inside[0]], column[inside[-1]]
        assert np.abs(top.astype(int) - lut[255]).max() <= 2, stem  # vmax at the top
        assert np.abs(bottom.astype(int) - lut[0]).max() <= 2, stem  # vmin at the bottom
        assert (png[:, w:] == 0).all(axis=2).sum() > 30, stem  # black labels on white


def test_each_preview_names_its_unit():
    units = {stem: SCALES[stem].unit for stem in PREVIEW_NAMES}
    assert units == {"wrapped": "rad", "ks": "code level", "order": "fringe order",
                     "phase": "rad", "modulation": "fraction of full scale"}
    values = np.linspace(0, 1, 200 * 100).reshape(200, 100)
    a, b = (colorize(values, "gray", 0, 1, unit=u) for u in ("rad", "mm"))
    assert a.shape[0] == b.shape[0] == 200 and not np.array_equal(a[:, 100:], b[:, 100:])


def test_depth_png_has_a_colour_bar_in_mm(tmp_path):
    depth = np.linspace(550, 650, 120 * 160, dtype=np.float32).reshape(120, 160)
    depth[:10] = np.nan
    write_depth(depth, tmp_path)
    png = iio.imread(tmp_path / "depth.png")
    lo, hi = np.nanpercentile(depth, [1, 99])
    assert png.shape[0] == 120 and png.shape[1] > 200
    assert np.array_equal(png[:, :160], colorize(depth, "turbo_r", float(lo), float(hi)))
    assert np.array_equal(png, colorize(depth, "turbo_r", float(lo), float(hi), unit="mm"))


def test_height_png_has_a_colour_bar_in_mm(tmp_path, monkeypatch, capsys):
    spec = bistair.make_spec("graycode", width=240, height=48, period=24)
    for name, shift in (("ref", 0.0), ("obj", 5.0)):
        images, _ = render_warp(spec, WarpScene(size=(48, 120), noise=0, blur=0,
                                                offset=shift))
        (tmp_path / name).mkdir()
        np.save(tmp_path / name / "stack.npy", images)
        (tmp_path / name / "spec.json").write_text(spec.to_json())
    monkeypatch.setenv("BISTAIR_PROGRESS_DELAY", "0")
    code, _, err = cli_run(monkeypatch, capsys, "height", tmp_path / "obj" / "stack.npy",
                           "--reference", tmp_path / "ref" / "stack.npy", "--spec",
                           tmp_path / "ref" / "spec.json", "--geometry", "600,200,0.1",
                           "--out", tmp_path / "h")
    assert code == 0, err
    # (a stage that runs long on a loaded machine repeats its line as "still ...": not counted)
    assert [line.split(" (")[0] for line in err.splitlines()
            if not line.startswith("bistair: still ")] == [
        "bistair: reading the captures", f"bistair: decoding {tmp_path / 'ref' / 'stack.npy'}",
        "bistair: decoding 8 frames of 120x48", "bistair: writing height.npy and height.png"]
    heights = np.load(tmp_path / "h" / "height.npy")
    png = iio.imread(tmp_path / "h" / "height.png")
    assert png.shape[0] == max(48, 60) and png.shape[1] > 120
    assert np.array_equal(png, colorize(heights, "viridis", unit="mm"))


def _refused_comparison() -> Comparison:
    spec = bistair.make_spec("graycode", width=240, height=60, period=20)
    images, truth = render_warp(spec, WarpScene(size=(60, 120), noise=0, blur=0))
    good = bistair.decode(images, spec)
    shape = images.shape[1:]
    bad = bistair.core.result.make_result("graycode", np.zeros(shape), np.full(shape, -1),
                                          20.0, np.zeros(shape),
                                          info={"refused": "the captures do not fit"})
    scores = {"coverage": 0.0, "order_error_rate": 0.0, "phase_rmse": float("nan"),
              "objects": {}}
    ok = {"coverage": 1.0, "order_error_rate": 0.0, "phase_rmse": 0.01, "objects": {}}
    return Comparison([Row("graycode", spec, good, ok), Row("graycode (x)", spec, bad, scores)],
                      truth, [1])


def test_a_refused_decode_reads_refused_in_the_table_and_report(tmp_path):
    comparison = _refused_comparison()
    rows = table(comparison)
    assert [r["refused"] for r in rows] == [None, "the captures do not fit"]
    text = format_table(rows, comparison.objects)
    frames = str(comparison.rows[1].frames)
    assert text.splitlines()[-1].split() == ["graycode", "(x)", frames, "refused:", "the",
                                             "captures", "do", "not", "fit"]
    html = write_report(tmp_path / "r.html", "t", "i", rows, comparison.objects, []).read_text()
    assert "refused: the captures do not fit" in html and html.count("0.000%") == 1
    fig = draw_method(comparison.rows[1], comparison.truth)
    assert fig._suptitle.get_text() == (f"graycode (x): {frames} frames, refused: the "
                                        "captures do not fit")


def _robustness(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))  # as `python benchmarks/...` runs
    spec = importlib.util.spec_from_file_location("robustness", ROOT / "benchmarks"
                                                  / "robustness.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_robustness_plots_draw_refused_decodes_as_refused_under_clean_names(tmp_path,
                                                                            monkeypatch):
    rob = _robustness(monkeypatch)
    rows = [{"factor": "gamma (uncompensated)", "value": v, "method": m,
             "refused": "refused" if (m, v) == ("lv", 2.2) else None,
             "order_error_rate": 0.0 if (m, v) == ("lv", 2.2) else 0.01 * v}
            for m in rob.METHODS for v in (1.0, 2.2)]
    path = rob.plot(rows, "gamma (uncompensated)", "order_error_rate", tmp_path, "errors (%)")
    assert path.name == "gamma-uncompensated-order_error_rate.png" and path.exists()
    assert not any(c in p.name for p in tmp_path.iterdir() for c in " ()")
    runs = [{"lv": {"order_error_rate": 0.0, "coverage": 0.0, "worst": 0.0, "refused": True}},
            {"lv": {"order_error_rate": 0.02, "coverage": 0.9, "worst": 0.5, "refused": False}}]
    assert rob.cells(rob.median_of(runs[:1], "lv")) == "refused | refused | refused"
    assert rob.cells(rob.median_of(runs, "lv")).startswith("2.000% (refused 1 of 2 seeds)")


def test_simulated_calibration_renders_every_method_and_shows_each_pose(tmp_path, monkeypatch,
                                                                         capsys):
    """Two methods in two poses (eight take minutes: every pattern is blurred at the
    projector's 1920 x 1080): each its own calibrate folder, a progress line per pose."""
    from bistair.app import simulate as job
    from bistair.sim.boards import POSES

    def two_poses(*args, **kwargs):
        return write_board_sets(*args, poses=POSES[:2], **kwargs)

    write_board_sets = job.write_board_sets
    monkeypatch.setattr(job, "write_board_sets", two_poses)
    monkeypatch.setenv("BISTAIR_PROGRESS_DELAY", "0")
    code, out, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "calibration",
                             "--method", "lv", "--method", "bidirectional", "--camera",
                             "32x24", "--out", tmp_path / "cal")
    assert code == 0, err
    lines = [line.split(" (")[0] for line in err.splitlines()]
    assert lines == ["bistair: rendering board pose 1 of 2", "bistair: rendering board pose 2 of 2"]
    assert sorted(p.name for p in (tmp_path / "cal").iterdir()) == ["bidirectional", "lv"]
    for method in ("lv", "bidirectional"):
        folder = tmp_path / "cal" / method
        assert (folder / "board.json").exists()
        assert sorted(p.name for p in folder.glob("pose-*")) == ["pose-00", "pose-01"]
        spec = bistair.load_spec(folder / "pose-01" / "rows" / "spec.json")
        assert spec.method == method and spec.orientation == "rows" and spec.white == 1
    assert out.strip().endswith(f"to {tmp_path / 'cal'}/<method>/")
