"""Every refusal of the command line in one table: (arguments, fragment of the message).

Each row runs ``bistair`` in-process and must exit with code 2, print exactly one non-empty
line on stderr, starting with ``Error:`` and holding the fragment, and leave its output path
uncreated. ``{out}`` stands for the output path, ``{pats}`` for a folder of small graycode
patterns with their spec (they decode), ``{zero}`` and ``{corrupt}`` for copies whose frame
03.png is empty or not an image, ``{nan}`` for an all-NaN ``.npy`` stack of as many
frames, ``{blank}`` for Gray code captures alone whose finest column bit shows no contrast
(every pixel modulated, none decoded: the library answers nothing, the command line
refuses), ``{nospec}`` for a copy of ``{pats}`` without its spec, ``{dataset}`` for a data
set laid out as ``simulate --count`` writes it (two scenes, each set a folder below, and
``index.csv``), ``{poses}`` for calibration captures of two poses that show no board,
``{set}`` for a stereo set (``left/`` and ``right/``: copies of ``{pats}``, a spec and a
calibration file), ``{link}`` for a symbolic link to ``{pats}`` and ``{ramp}`` for captures
of a gamma ramp (``ramp.json``, ``gamma.json``). Paths in a message are written the same way.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import cli_run

import bistair
from bistair.app.patterns import save_patterns, save_ramp
from bistair.io.atomic import write_image
from bistair.io.read import read_image

SIM = ["simulate", "--scene", "plane", "--method", "graycode", "--out", "{out}"]
BIDI = ["patterns", "bidirectional", "--out", "{out}"]
DECODE = ["decode", "{pats}", "--out", "{out}"]
CALIBRATE = ["calibrate", "{poses}", "--out", "{out}"]

ROWS = [
    # simulate: camera size, every imaging option, scene and method
    (SIM + ["--camera", "0x0"], "camera size 0x0 must be 8 to 8192 whole pixels per side"),
    (SIM + ["--camera", "-5x10"], "camera size -5x10 must be 8 to 8192 whole pixels per side"),
    (SIM + ["--camera", "100000x100000"], "camera size 100000x100000 must be 8 to 8192 whole"),
    (SIM + ["--camera", "640"], "expected WIDTHxHEIGHT, e.g. 1280x1024"),
    (SIM + ["--noise", "-1"], "read noise (read_noise) must be a finite number of at least 0, "
                              "got -1.0"),
    (SIM + ["--noise", "nan"], "read noise (read_noise) must be a finite number of at least 0, "
                               "got nan"),
    (SIM + ["--blur", "-1"], "camera blur (camera_blur) must be a finite number of at least 0"),
    (SIM + ["--blur", "inf"], "camera blur (camera_blur) must be a finite number of at least 0"),
    (SIM + ["--ambient", "nan"], "ambient light (ambient) must be a finite number of at least 0"),
    (SIM + ["--ambient", "-0.5"], "ambient light (ambient) must be a finite number of at least"),
    (SIM + ["--gamma", "0"], "projector gamma (gamma) must be a finite number above 0, got 0.0"),
    (SIM + ["--gamma", "-1", "--uncompensated"], "projector gamma (gamma) must be a finite "
                                                 "number above 0, got -1.0"),
    (SIM + ["--gamma", "9"], "patterns cannot pre-compensate a projector gamma of 9"),
    (SIM + ["--bits", "7"], "Invalid value for '--bits': '7' is not one of"),
    (SIM + ["--seed", "-1"], "seed must be a whole number of at least 0, got -1"),
    (["simulate", "--scene", "calibration", "--method", "multifreq", "--camera", "4x4",
      "--out", "{out}"], "camera size 4x4 must be 8 to 8192 whole pixels per side"),
    (["simulate", "--scene", "moon", "--method", "all", "--out", "{out}"],
     "unknown scene 'moon'"),
    (["simulate", "--scene", "plane", "--method", "fourier", "--out", "{out}"],
     "unknown method(s) fourier"),
    # demo
    (["demo", "--camera", "0x0", "--out", "{out}"], "camera size 0x0 must be 8 to 8192 whole"),
    (["demo", "--seed", "-1", "--out", "{out}"], "seed must be a whole number of at least 0"),
    # decode: output paths that would break the next run, unreadable frames named
    (["decode", "{pats}", "--out", "{pats}"], "pats is the input "),
    (["decode", "{pats}", "--out", "{pats}/00.png/result"], "00.png is a file, not a folder"),
    (["reconstruct", "{pats}", "--calibration", "{pats}/spec.json", "--out", "{out}.xyz"],
     "must name a .ply file: the point cloud is written as PLY"),
    (["patterns", "graycode", "--out", "{pats}/spec.json/new"],
     "spec.json is a file, not a folder"),
    (["decode", "{pats}", "--out", ""], "the output path is empty"),
    # outputs that are, hold or mix with an input: refused for every command (issue 31)
    (["stereo", "{set}/left", "{set}/right", "--calibration", "{pats}/spec.json", "--out",
      "{set}"], "set holds the input "),
    (["stereo", "{set}/left", "{set}/right", "--calibration", "{pats}/spec.json", "--out",
      "{set}/left/.."], "set/left/.. holds the input "),
    (["stereo", "{set}/left", "{set}/right", "--calibration", "{pats}/spec.json", "--out", ""],
     "the output path is empty"),
    (["stereo", "{set}/left", "{set}/right", "--calibration", "{set}/stereo.json", "--out",
      "{set}/right"], "right is the input "),
    (["decode", "{pats}/*.png", "--out", "{pats}/.."], "holds the input "),
    (["decode", "{link}", "--out", "{pats}"], "pats is the input "),  # a symbolic link to it
    (["decode", "{pats}", "--out", "{link}"], "link is the input "),
    (["decode", "{pats}", "--spec", "{set}/spec.json", "--out", "{set}"], "set holds the input "),
    (["batch", "{set}", "--out", "{set}"], "set is the input "),
    (["batch", "{set}", "--out", "{set}/.."], "holds the input "),
    (["batch", "{set}", "--out", ""], "the output path is empty"),
    (["import-calibration", "{pats}/spec.json", "--out", "{pats}/spec.json"],
     "spec.json is the input "),
    (["import-calibration", "{pats}/spec.json", "--stereo", "--out", "{link}/spec.json"],
     "spec.json is the input "),
    (["reconstruct", "{pats}", "--calibration", "{pats}/spec.json", "--out", "{out}.ply",
      "--depth", "{pats}"], "pats is the input "),
    (["reconstruct", "{pats}", "--calibration", "{set}/stereo.json", "--out", "{set}/c.ply",
      "--depth", "{set}"], "set holds the input "),
    (CALIBRATE[:-1] + ["{poses}"], "poses is the input "),
    (CALIBRATE[:-1] + ["{poses}/board.json", "--board", "{poses}/board.json"],
     "board.json is the input "),
    (["calibrate-stereo", "{poses}", "--board", "{poses}/board.json", "--out",
      "{poses}/board.json"], "board.json is the input "),
    (["gamma", "{ramp}", "--out", "{ramp}/gamma.png"], "gamma.png lies in the capture folder"),
    (["gamma", "{ramp}", "--out", "{ramp}/ramp.json"], "ramp.json is the input "),  # read
    (["height", "{pats}", "--reference", "{pats}", "--plane", "{zero}:5", "--plane",
      "{pats}:10", "--out", "{zero}"], "zero is the input "),
    (["patterns", "graycode", "--gamma-file", "{ramp}/gamma.json", "--out", "{ramp}"],
     "ramp holds the input "),
    (["scan", "--spec", "{pats}/spec.json", "--display", "none", "--camera",
      "sim:plane:64x48", "--out", "{pats}"], "pats holds the input "),
    (["simulate", "--scene", "plane", "--method", "graycode", "--out", ""],
     "the output path is empty"),
    (["demo", "--out", " "], "the output path is empty"),
    # a first hour's slips: no spec beside the captures, a misspelt method, a data set's
    # folder given to batch instead of its index.csv (issue 31)
    (["decode", "{nospec}", "--out", "{out}"], "nospec/spec.json not found: give the spec "
                                              "that made the patterns with --spec FILE"),
    (["reconstruct", "{nospec}", "--calibration", "{pats}/spec.json", "--out", "{out}.ply"],
     "nospec/spec.json not found: give the spec that made the patterns with --spec FILE"),
    (["patterns", "bidirectinal", "--out", "{out}"],
     "unknown method 'bidirectinal', did you mean 'bidirectional'? (methods: bidirectional, "
     "lv, phase-coding, graycode, multifreq; also: gamma)"),
    (["patterns", "fourier", "--out", "{out}"], "unknown method 'fourier' (methods: "),
    (["batch", "{dataset}", "--out", "{out}"], "no capture sets in {dataset}: none of its 2 "
     "sub-folders holds images (or L/ and R/); {dataset}/index.csv lists the sets of a data "
     "set: bistair batch {dataset}/index.csv"),
    (["batch", "{pats}", "--out", "{out}"], "it is one capture set itself: bistair decode"),
    (["decode", "{zero}", "--out", "{out}"], "03.png is empty (0 bytes)"),
    (["decode", "{nan}", "--spec", "{pats}/spec.json", "--out", "{out}"],
     "captures contain NaN or infinite values"),  # with no NumPy warning before it
    (["decode", "{corrupt}", "--out", "{out}"], "03.png: not a readable image (corrupt or of "
                                                 "another format)"),
    (DECODE + ["--threads", "0"], "Invalid value for '--threads': 0 is not in the range x>=1"),
    (DECODE + ["--threads", "many"], "Invalid value for '--threads': 'many' is not a valid"),
    # decode --min-modulation: a fraction of full scale, strictly between 0 and 1
    (DECODE + ["--min-modulation", "-1"], "the minimum modulation must lie between 0 and 1 "
                                          "(a fraction of full scale), got -1.0"),
    (DECODE + ["--min-modulation", "0"], "the minimum modulation must lie between 0 and 1"),
    (DECODE + ["--min-modulation", "1"], "the minimum modulation must lie between 0 and 1"),
    (DECODE + ["--min-modulation", "2"], "the minimum modulation must lie between 0 and 1 "
                                         "(a fraction of full scale), got 2.0"),
    (DECODE + ["--min-modulation", "nan"], "the minimum modulation must lie between 0 and 1 "
                                           "(a fraction of full scale), got nan"),
    (DECODE + ["--min-modulation", "0.9"], "no pixel has the minimum modulation 0.9 asked for "
                                           "(the most is 0.5"),
    # decode: an answer of nothing is refused (bistair.decode returns it, every pixel -1)
    (["decode", "{blank}/columns", "--out", "{out}"],
     "Error: no pixel decoded (3072 pixels have fringes): does the spec fit the captures "
     "(method, periods, frame order, phase_offset, shift_sign)?"),
    (["decode", "{blank}/both", "--out", "{out}"], "Error: x: no pixel decoded (3072 pixels "
                                                   "have fringes): does the spec fit"),
    # calibrate: at least 3 poses, asked for and usable
    (CALIBRATE + ["--min-poses", "1"], "--min-poses 1 is too few: a camera-projector "
                                       "calibration needs at least 3 board poses"),
    (CALIBRATE + ["--min-poses", "2"], "--min-poses 2 is too few"),
    (CALIBRATE + ["--min-poses", "-3"], "--min-poses -3 is too few"),
    (CALIBRATE, "board found in 0 of 2 poses, need at least 3"),
    # a board's square refused up front, not by OpenCV after decoding every pose (QA C08)
    (CALIBRATE + ["--board", "chessboard:9x7:inf"], "board spacing must be a positive number "
                                                    "of mm, got inf"),
    (CALIBRATE + ["--board", "chessboard:9x7:nan"], "board spacing must be a positive number"),
    (["batch", "{set}", "--out", "{out}", "--depth-range", "0:100"],
     "--depth-range applies to the reconstruction: give --calibration too"),
    # patterns: each field's own range before it enters another field's message
    (BIDI + ["--group-rows", "0"], "group rows must lie in 3..1080 (the projector's height), "
                                   "got 0"),
    (BIDI + ["--group-rows", "2"], "group rows must lie in 3..1080"),
    (BIDI + ["--group-rows", "5000"], "group rows must lie in 3..1080"),
    (BIDI + ["--orientation", "rows", "--width", "400", "--group-rows", "500"],
     "group rows must lie in 3..400 (the projector's width), got 500"),
    (BIDI + ["--local-rows", "0"], "local rows must lie in 1..29 (fewer than the 30 group "
                                   "rows), got 0"),
    (BIDI + ["--group-rows", "12", "--local-rows", "12"], "local rows must lie in 1..11"),
    (BIDI + ["--local-rows", "15"], "local rows (15) equal partition rows (15)"),
    (BIDI + ["--stairs", "1"], "stairs must be at least 2, got 1"),
    (BIDI + ["--stairs", "1", "--partitions", "40"], "stairs must be at least 2, got 1"),
    (BIDI + ["--partitions", "40"], "partitions must be at most 32"),
    (BIDI + ["--partitions", "0"], "partitions must be at least 2 (use phase-coding for one "
                                   "stair), got 0"),
    (BIDI + ["--period", "29"], "narrower than the 1080-px coded axis"),
    (BIDI + ["--period", "3"], "period must be at least 4 projector pixels, got 3.0"),
    (BIDI + ["--period", "nan"], "spec field 'period' must be a number, got 'nan'"),
    (BIDI + ["--width", "0"], "projector size 0x1080 is too small (at least 8x8)"),
    (BIDI + ["--height", "-5"], "projector size 1080x-5 is too small (at least 8x8)"),
    (BIDI + ["--steps", "2"], "steps must be at least 3, got 2"),
    (BIDI + ["--offset", "0.8"], "offset 0.8 and amplitude 0.5 must satisfy"),
    (BIDI + ["--gamma", "9"], "gamma must lie in [0.2, 5], got 9.0"),
    (BIDI + ["--bits", "12"], "Invalid value for '--bits': '12' is not one of '8', '16'"),
    (["patterns", "lv", "--levels", "1", "--out", "{out}"], "levels must lie in 2..32 (more "
                                                           "leave too little phase per level)"),
    (["patterns", "lv", "--levels", "40", "--out", "{out}"], "levels must lie in 2..32"),
    (["patterns", "lv", "--window", "1", "--out", "{out}"], "window must lie in 2..36 (the "
                                                           "fringes across the coded axis)"),
    (["patterns", "lv", "--window", "50", "--out", "{out}"], "window must lie in 2..36"),
    (["patterns", "lv", "--levels", "3", "--out", "{out}"], "36 fringes need more than 3 "
                                                           "levels for unique 4-code windows"),
    (["patterns", "lv", "--period", "1080", "--out", "{out}"], "a 1080-px period leaves fewer "
                                                              "than 2 fringes"),
    (["patterns", "phase-coding", "--period", "1080", "--out", "{out}"],
     "a 1080-px period leaves fewer than 2 fringes"),
    (["patterns", "phase-coding", "--form", "triple", "--out", "{out}"],
     "Invalid value for '--form'"),
    (["patterns", "graycode", "--complementary", "2", "--out", "{out}"],
     "Invalid value for '--complementary'"),
    (["patterns", "graycode", "--second-period", "3", "--out", "{out}"],
     "second_period must be 0 (none) or at least 4 projector pixels, got 3.0"),
    (["patterns", "graycode", "--second-period", "15", "--out", "{out}"],
     "period / second_period = 2.000 is too close to a whole number"),
    (["patterns", "multifreq", "--periods", "0", "--out", "{out}"],
     "periods must be finite and at least 4 projector pixels, got (0)"),
    (["patterns", "multifreq", "--periods", "1080,30,30", "--out", "{out}"],
     "periods must differ"),
    (["patterns", "multifreq", "--periods", "1080,inf", "--out", "{out}"],
     "spec field 'periods' must be a number, got 'inf'"),
    (["patterns", "multifreq", "--periods", "180,30", "--unwrap", "hierarchical", "--out",
      "{out}"], "hierarchical unwrapping needs a period covering the 1080-px axis"),
]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A decodable folder of graycode patterns, two calibration poses without a board, a
    stereo set (left/ and right/), a symbolic link to the patterns and a gamma ramp."""
    root = tmp_path_factory.mktemp("inputs")
    spec = bistair.make_spec("graycode", width=64, height=48, period=16)
    save_patterns(spec, root / "pats")
    np.save(root / "nan.npy", np.full((spec.frame_count, 48, 64), np.nan, np.float32))
    for name, content in (("zero", b""), ("corrupt", b"not a png at all")):
        shutil.copytree(root / "pats", root / name)
        (root / name / "03.png").write_bytes(content)
    for orientation in ("columns", "both"):  # the finest column bit and its inverse grey
        spec = bistair.make_spec("graycode", width=64, height=48, steps=0, inverse=1,
                                 orientation=orientation)
        images = np.round(bistair.encode(spec) * 200 + 20).astype(np.uint8)
        finest = [i for i, name in enumerate(spec.frames)
                  if name.removeprefix("x/") in ("gray-5", "gray-5-inv")]
        images[finest] = 120
        save_captures(images, spec, root / "blank" / orientation)
    for side in ("left", "right"):
        shutil.copytree(root / "pats", root / "set" / side)
    shutil.copy(root / "pats" / "spec.json", root / "set" / "spec.json")
    (root / "set" / "stereo.json").write_text("{}")
    (root / "link").symlink_to(root / "pats", target_is_directory=True)
    save_ramp(16, 16, 9, 8, root / "ramp")  # captured at 80% contrast: a gamma of 1
    for frame in sorted((root / "ramp").glob("*.png")):
        write_image(frame, (read_image(frame) * 0.8 + 20).astype(np.uint8))
    (root / "ramp" / "gamma.json").write_text('{"gamma": 1.0}')
    shutil.copytree(root / "pats", root / "nospec")
    (root / "nospec" / "spec.json").unlink()
    for scene in ("scene-0000", "scene-0001"):  # as simulate --count lays a data set out
        shutil.copytree(root / "pats", root / "dataset" / scene / "graycode")
    (root / "dataset" / "index.csv").write_text(
        "name,captures,calibration\n" + "".join(f"scene-000{i},scene-000{i}/graycode,\n"
                                                for i in range(2)))
    (root / "poses").mkdir()
    (root / "poses" / "board.json").write_text(json.dumps(
        {"type": "checkerboard", "columns": 9, "rows": 6, "spacing": 20.0}))
    for orientation in ("columns", "rows"):
        spec = bistair.make_spec("multifreq", width=96, height=64, periods=(96, 16),
                                 orientation=orientation, white=1)
        images = np.round(bistair.encode(spec) * 200 + 20).astype(np.uint8)
        for pose in ("pose-00", "pose-01"):
            folder = root / "poses" / pose / orientation
            folder.mkdir(parents=True)
            for i, image in enumerate(images):
                write_image(folder / f"{i:02d}.png", image)
            (folder / "spec.json").write_text(spec.to_json())
    return root


def save_captures(images: np.ndarray, spec: bistair.spec.BaseSpec, folder: Path) -> None:
    """``images`` as ``NN.png`` and ``spec.json`` in ``folder``."""
    folder.mkdir(parents=True)
    for i, image in enumerate(images):
        write_image(folder / f"{i:02d}.png", image)
    (folder / "spec.json").write_text(spec.to_json())


def row_id(args: list[str]) -> str:
    """The command and the options that make the row (not the common ones)."""
    for common in (SIM, BIDI, DECODE, CALIBRATE):
        if args[:len(common)] == common:
            args = [*common[:2 if common is BIDI else 1], *args[len(common):]]
            break
    return " ".join(a for a in args if "{" not in a and a != "--out")


@pytest.mark.filterwarnings("error::RuntimeWarning")  # printed before the error otherwise
@pytest.mark.parametrize(("args", "message"), ROWS, ids=[row_id(args) for args, _ in ROWS])
def test_refused_with_one_line(args, message, inputs, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    paths = {"out": out, "nan": inputs / "nan.npy",
             **{name: inputs / name for name in ("pats", "poses", "zero", "corrupt", "blank",
                                                 "set", "link", "ramp", "nospec", "dataset")}}
    cwd = tmp_path / "cwd"  # where a relative (or empty) output path would land
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    before = _tree(inputs)
    code, _, err = cli_run(monkeypatch, capsys, *(a.format(**paths) for a in args))
    # a calibration names each pose it leaves out (a warning) before it refuses
    lines = [line for line in err.splitlines()
             if line.strip() and not line.startswith("Warning: skipped pose-0")]
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("Error: "), err
    assert message.format(**paths) in lines[0], lines[0]
    # nothing written: not the output, not beside the inputs (an output path that is an
    # input folder), not in the working directory (an empty or relative output path)
    assert not out.exists()
    assert _tree(inputs) == before, "files written or changed among the inputs"
    assert list(cwd.iterdir()) == [], "files written in the working directory"


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file and folder under ``root``: (size, mtime in ns), hidden ones included."""
    return {str(p.relative_to(root)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(root.rglob("*"))}
