"""The binocular jobs behind the command line: reconstruct from two cameras
(``bistair stereo``), calibrate two cameras from board pairs (``bistair calibrate-stereo``),
import an OpenCV stereo calibration (``bistair import-calibration --stereo``) and render a
two-camera scene (``bistair simulate --cameras 2``).

Each reads its inputs, works in memory and writes its outputs atomically, so a failed job
leaves nothing behind.

``bistair stereo`` writes into ``OUT``::

    left/, right/      each camera's decode, as ``bistair decode`` writes it
    disparity.npy      float32 on the rectified left grid, NaN where unmatched
    depth.npy          float32 z (mm) on the left camera's own image grid, NaN where unknown
    depth.png          its preview
    cloud.ply          x, y, z (mm) in the left camera's frame, grey from the white frame
                       (else the fringes' average)
    info.json          the matching's counts, the rectification, both decodes' warnings
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import encode
from ..errors import BistairError
from ..evaluation.benchmark import method_specs
from ..geometry.board import Board
from ..geometry.calibrate import calibrate_stereo_images
from ..geometry.calibration import (
    STEREO,
    Calibration,
    StereoCalibration,
    load_calibration,
    save_calibration,
)
from ..geometry.opencv import read_opencv_stereo
from ..geometry.projection_matrices import recorded_origin
from ..geometry.stereo import StereoResult, stereo
from ..geometry.unwrap import is_single_period, stereo_unwrap
from ..io.atomic import check_output, output_folder, write_image
from ..io.jsonfile import write_json
from ..io.read import (
    default_spec_path,
    find_spec,
    list_images,
    natural_key,
    read_image,
    read_with_spec,
)
from ..io.writers import write_depth, write_ply, write_result
from ..sim import preset, scene_names, trace
from ..sim.render import expose
from ..sim.stereo import StereoRig, write_board_pairs
from ..spec import BaseSpec
from .calibrate import board_option
from .jobs import parse_keys, parse_size
from .simulate import _imaging, write_truth

Say = Callable[[str], None]
SIDES = (("L", "R"), ("left", "right"))  # the folders of a stereo capture set


def _silent(stage: str) -> None:
    """The progress callback of a job nobody watches."""


# -- reconstruct -----------------------------------------------------------------------------
def stereo_folder(left: Any, right: Any, out: str | Path,
                  calibration: StereoCalibration | str | Path,
                  spec: BaseSpec | str | Path | None = None, min_depth: float = 0.0,
                  max_depth: float = np.inf, force: bool = False, smooth: float = 1.0,
                  previews: bool = True, progress: Say | None = None,
                  **options: Any) -> StereoResult:
    """Decode two cameras' captures (each a folder, image files, a glob pattern or a ``.npy``
    stack, as for ``bistair decode``) of one pattern set, match and triangulate, and write
    the files of the module docstring into ``out``.

    ``spec`` is used for both cameras; by default ``spec.json`` beside the left captures,
    which must equal the one beside the right captures if they have one (both cameras see
    one pattern set: two that differ are refused, naming the fields). LEFT and RIGHT must
    not be the same path. ``calibration`` must be a stereo calibration (``"kind":
    "stereo"``). ``force`` goes to
    the decoder when it takes it and keeps a reconstruction with few matches; ``smooth``:
    see :func:`~bistair.geometry.stereo.reconstruct_stereo`. ``options`` are decoder
    options. Nothing is written on error.
    """
    say = progress or _silent
    for side in (left, right):
        check_output(out, side)
    if _same_place(left, right):
        raise BistairError(f"LEFT and RIGHT are the same captures ({left}): give each camera's "
                           "own")
    if isinstance(calibration, Calibration):
        raise BistairError("a camera-projector calibration was given: stereo needs the two "
                           "cameras' calibration (bistair calibrate-stereo)")
    recorded = None
    if not isinstance(calibration, StereoCalibration):
        recorded = _recorded_origin(calibration)
        calibration = load_calibration(calibration, STEREO)
    spec = find_spec(left, spec) if spec is not None else _one_spec(left, right)
    stacks = []
    for name, captures in (("left", left), ("right", right)):
        say(f"reading the {name} captures")
        try:
            stacks.append(read_with_spec(captures, spec))
        except BistairError as exc:
            raise BistairError(f"{name}: {exc}") from None
    (lstack, used), (rstack, _) = stacks
    if is_single_period(used):
        say(f"unwrapping 2 x {len(lstack)} frames of {lstack.shape[2]}x{lstack.shape[1]} "
            f"by the projector at {min_depth:g}-{max_depth:g} mm")
        if recorded is not None:  # import-calibration --projection-matrices's: checked
            options = {"pixel_origin": recorded, **options}
        result = _unwrapped(lstack, rstack, used, calibration, min_depth, max_depth, force,
                            options)
    else:
        say(f"decoding 2 x {len(lstack)} frames of {lstack.shape[2]}x{lstack.shape[1]} "
            f"({used.method}) and matching")
        result = stereo(lstack, rstack, used, calibration, min_depth=min_depth,
                        max_depth=max_depth, force=force, smooth=smooth, **options)
    say(f"writing {int(result.mask.sum())} points")
    with output_folder(out) as tmp:
        write_stereo(result, tmp, previews)
    return result


def _unwrapped(lstack: np.ndarray, rstack: np.ndarray, spec: BaseSpec,
               calibration: StereoCalibration, min_depth: float, max_depth: float,
               force: bool, options: dict[str, Any]) -> StereoResult:
    """Stereo phase unwrapping of a single-period set (:func:`~bistair.geometry.unwrap.
    stereo_unwrap`): it needs the depth range and the projector in the calibration."""
    if not (min_depth > 0 and np.isfinite(max_depth)):
        raise BistairError(f"one period ({spec.periods[0]:g} px) gives no fringe order: "
                           "stereo phase unwrapping needs --depth-range ZMIN:ZMAX (mm, left "
                           "camera frame) holding the whole scene")
    if calibration.projector is None:
        raise BistairError("one period gives no fringe order: stereo phase unwrapping needs "
                           "the projector in the calibration (bistair simulate --cameras 2 "
                           "writes one; or import-calibration --projection-matrices)")
    unknown = sorted(set(options) - {"min_modulation", "pixel_origin"})
    if unknown:
        raise BistairError(f"stereo phase unwrapping takes no {', '.join(unknown)} option")
    if lstack.shape != rstack.shape:
        raise BistairError("left and right captures differ: " + " and ".join(
            f"{s[0]} frames of {s[2]}x{s[1]}" for s in (lstack.shape, rstack.shape)))
    return stereo_unwrap(lstack, rstack, spec, calibration, min_depth, max_depth, force,
                         options.get("min_modulation"),
                         pixel_origin=options.get("pixel_origin"))


def _recorded_origin(path: str | Path) -> int | None:
    """The cameras' pixel origin a calibration file records (``"pixel_origin"``, written by
    ``import-calibration --projection-matrices``), ``None`` when it records none."""
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None  # load_stereo_calibration says what is wrong with the file
    if not isinstance(data, dict) or "pixel_origin" not in data:
        return None
    return recorded_origin(data)


def _same_place(left: Any, right: Any) -> bool:
    """Whether LEFT and RIGHT name the same folder, file or pattern."""
    if not (isinstance(left, str | Path) and isinstance(right, str | Path)):
        return False
    return Path(left).expanduser().resolve() == Path(right).expanduser().resolve()


def _one_spec(left: Any, right: Any) -> BaseSpec:
    """The spec beside the left captures, refused if the right captures have their own and
    it differs (:func:`spec_differences`)."""
    spec = find_spec(left)
    try:
        other = default_spec_path(right)
    except BistairError:
        return spec  # unlistable right captures: their reading says why
    if not other.is_file():
        return spec
    try:
        differ = spec_differences(spec, find_spec(right))
    except BistairError as exc:
        raise BistairError(f"right: {exc}") from None
    if differ:
        raise BistairError(f"the spec.json beside RIGHT differs from the one beside LEFT in "
                           f"{'; '.join(differ)}: both cameras see one pattern set (give it "
                           "with --spec, or correct the wrong file)")
    return spec


def spec_differences(left: BaseSpec, right: BaseSpec) -> list[str]:
    """The fields in which two specs differ, each ``"name (left value and right value)"``
    (the method alone when the methods differ; a list by its first difference).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> a = make_spec("graycode", width=1920, height=1080, period=30)
    >>> spec_differences(a, a.replace(period=36.0))
    ['period (30 and 36)']
    >>> spec_differences(a, a.replace(frame_order=a.frames[::-1]))
    ['frames (shift-0 and gray-5 at 0)']
    >>> spec_differences(a, make_spec("bidirectional", width=1920, height=1080,
    ...                               partitions=8, stairs=8))
    ['method (graycode and bidirectional)']
    """
    a, b = left.to_dict(), right.to_dict()
    if a["method"] != b["method"]:
        return [f"method ({a['method']} and {b['method']})"]
    return [f"{key} ({_shown(a.get(key), b.get(key))})" for key in dict.fromkeys([*a, *b])
            if a.get(key) != b.get(key)]


def _shown(a: Any, b: Any) -> str:
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{len(a)} and {len(b)} items"
        i = next(i for i, (x, y) in enumerate(zip(a, b, strict=True)) if x != y)
        return f"{a[i]} and {b[i]} at {i}"
    return f"{'none' if a is None else a} and {'none' if b is None else b}"


def write_stereo(result: StereoResult, folder: Path, previews: bool = True) -> None:
    """Write a binocular reconstruction into the existing ``folder`` (module docstring)."""
    for name, res in (("left", result.left), ("right", result.right)):
        (folder / name).mkdir(exist_ok=True)
        write_result(res, folder / name, previews=previews)
    np.save(folder / "disparity.npy", result.disparity)
    write_depth(result.depth, folder)
    write_ply(folder / "cloud.ply", *result.cloud())
    write_json(folder / "info.json", {**result.info, "warnings": warnings(result)})


def warnings(result: StereoResult) -> list[str]:
    """The warnings of both decodes (``left: ...``, ``right: ...``) and of the matching."""
    out = []
    for name, res in (("left", result.left), ("right", result.right)):
        infos = [res.info] if not hasattr(res, "x") else [res.x.info, res.y.info]
        out += [f"{name}: {w}" for info in infos for w in info.get("warnings", [])]
    return out + list(result.info.get("warnings", []))


def stereo_pair(captures: str | Path) -> tuple[Path, Path] | None:
    """The left and right capture folders of a stereo set (``L/`` and ``R/``, or ``left/``
    and ``right/``), ``None`` if ``captures`` is not such a folder."""
    folder = Path(captures)
    for names in SIDES:
        if all((folder / n).is_dir() for n in names):
            return folder / names[0], folder / names[1]
    return None


# -- calibrate -------------------------------------------------------------------------------
def board_pairs(folder: str | Path) -> tuple[list[str], list[Path], list[Path]]:
    """The poses of a stereo calibration folder: ``(names, left images, right images)``.

    Either ``left/`` and ``right/`` folders whose images pair up in natural name order, or
    one sub-folder per pose holding two images: the one whose name says ``left`` (or ``l``)
    and the one that says ``right`` (or ``r``), else the first and second in name order.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise BistairError(f"calibration captures {folder} not found")
    if (folder / "left").is_dir() and (folder / "right").is_dir():
        left, right = (list_images(folder / side) for side in ("left", "right"))
        if len(left) != len(right) or not left:
            raise BistairError(f"{folder}/left has {len(left)} images and {folder}/right "
                               f"{len(right)}: they pair up one to one")
        return [p.stem for p in left], left, right
    names, lefts, rights = [], [], []
    for sub in sorted((p for p in folder.iterdir() if p.is_dir()),
                      key=lambda p: natural_key(p.name)):
        images = list_images(sub)
        if len(images) != 2:
            raise BistairError(f"pose {sub.name} holds {len(images)} images: one left and one "
                               "right image are needed")
        sides = [_side(p.stem) for p in images]
        if sides == ["right", "left"]:
            images = images[::-1]
        names.append(sub.name)
        lefts.append(images[0])
        rights.append(images[1])
    if not names:
        raise BistairError(f"no poses in {folder}: give one folder per pose holding a left and "
                           "a right image, or left/ and right/ folders of pairs")
    return names, lefts, rights


def _side(stem: str) -> str | None:
    words = stem.lower().replace("-", "_").replace(".", "_").split("_")
    if "left" in words or "l" in words or stem.lower().startswith("left"):
        return "left"
    if "right" in words or "r" in words or stem.lower().startswith("right"):
        return "right"
    return None


def calibrate_stereo_folder(folder: str | Path, out: str | Path | None = None,
                            board: Board | str | Path | None = None, min_poses: int = 3,
                            progress: Say | None = None
                            ) -> tuple[StereoCalibration, list[str]]:
    """Calibrate two cameras from board image pairs (:func:`board_pairs`) and write the
    stereo calibration to ``out`` (atomically) if given; returns it and the poses skipped
    (board not found in both images). ``board``: a Board, ``"chessboard:9x6:20"``, a
    ``board.json``, or by default ``FOLDER/board.json``."""
    say = progress or _silent
    names, lefts, rights = board_pairs(folder)
    board = board_option(board, Path(folder))
    say(f"reading {len(names)} image pairs")
    left = [read_image(p) for p in lefts]
    right = [read_image(p) for p in rights]
    say(f"finding the board and calibrating from {len(names)} poses")
    cal, skipped = calibrate_stereo_images(left, right, board, names, min_poses)
    if out is not None:
        save_calibration(cal, out)
    return cal, skipped


def import_stereo_calibration(files: Sequence[str | Path], out: str | Path,
                              camera_size: tuple[int, int] | str | None = None,
                              keys: Mapping[str, str] | str | None = None
                              ) -> StereoCalibration:
    """Read an OpenCV FileStorage stereo calibration (left camera first) and write it as a
    bistair stereo calibration ``out`` (atomically); ``keys`` renames parts (a mapping or
    ``"left=K1,T=T"``). Nothing is written on error."""
    if isinstance(camera_size, str):
        camera_size = parse_size(camera_size, "--camera-size")
    if isinstance(keys, str):
        keys = parse_keys(keys)
    cal = read_opencv_stereo(list(files), camera_size, keys)
    save_calibration(cal, out)
    return cal


# -- simulate --------------------------------------------------------------------------------
def simulate_stereo(scene: str, methods: Sequence[str], out: str | Path,
                    camera_size: tuple[int, int] | None = None, baseline: float = 200.0,
                    compensated: bool = True, progress: Say | None = None,
                    **imaging: Any) -> Path:
    """Render ``scene`` on the two-camera rig (:class:`~bistair.sim.stereo.StereoRig`:
    cameras ``baseline`` mm apart, the projector between them) for each method and write::

        OUT/<method>/L/, OUT/<method>/R/   each camera's captures and spec.json
        OUT/truth/L/, OUT/truth/R/         each camera's truth (as bistair simulate)
        OUT/stereo.json                    the cameras' exact calibration, the projector's
                                           included
        OUT/calibration.json               the left camera and the projector's
        OUT/scene.json                     the scene, rig and imaging

    The scene ``calibration`` writes a 9 x 6 chessboard (20 mm) in eight poses instead,
    ``OUT/pose-NN/left.png`` and ``right.png`` with ``board.json`` (what ``bistair
    calibrate-stereo`` reads). ``imaging`` goes to :class:`~bistair.sim.Imaging`.
    """
    say = progress or _silent
    if not 10 <= baseline <= 2000:
        raise BistairError(f"--baseline must be 10 to 2000 mm, got {baseline:g}")
    if scene not in (*scene_names(), "calibration"):
        raise BistairError(f"unknown scene {scene!r} (known: {', '.join(scene_names())}, "
                           "calibration)")
    im = _imaging(compensated, imaging)
    size = {} if camera_size is None else {"camera_size": camera_size}
    if scene == "calibration":
        srig = StereoRig.default(baseline=baseline, **size)
        return write_board_pairs(srig, Board("checkerboard", 9, 6, 20.0), out, imaging=im)
    rig, geometry = preset(scene, **size)
    srig = StereoRig.default(camera_size=rig.camera.size, projector_size=rig.projector.size,
                             baseline=baseline)
    specs = method_specs(rig.projector.size, gamma=im.gamma if compensated else 1.0,
                         methods=methods)
    patterns = {method: encode(spec) for method, (spec, _) in specs.items()}
    with output_folder(out) as tmp:
        truths = {}
        for i, (side, folder) in enumerate((("left", "L"), ("right", "R"))):
            say(f"tracing the scene from the {side} camera")
            cam = dataclasses.replace(im, seed=im.seed + i)
            traced = trace(srig.rig(side), geometry, cam)
            truths[folder] = traced.truth
            for method, (spec, _) in specs.items():
                say(f"rendering {method} ({side})")
                sub = tmp / method / folder
                sub.mkdir(parents=True)
                for k, img in enumerate(expose(traced, patterns[method], cam)):
                    write_image(sub / f"{k:02d}.png", img)
                (sub / "spec.json").write_text(spec.to_json())
        (tmp / "truth").mkdir()
        first = next(iter(specs.values()))[0]
        for folder, truth in truths.items():
            write_truth(tmp / "truth" / folder, truth, first)
        save_calibration(StereoCalibration.from_rig(srig), tmp / "stereo.json")
        save_calibration(Calibration.from_rig(srig.rig("left")), tmp / "calibration.json")
        write_json(tmp / "scene.json", {
            "scene": scene, "methods": list(methods), "compensated": compensated,
            "cameras": 2, "baseline": baseline, "imaging": dataclasses.asdict(im),
            "rig": {name: _device(getattr(srig, name))
                    for name in ("left", "right", "projector")}})
    return Path(out)


def _device(dev: Any) -> dict[str, Any]:
    return {"width": dev.width, "height": dev.height, "K": dev.K.tolist(),
            "dist": list(dev.dist), "R": dev.R.tolist(), "t": dev.t.tolist()}

