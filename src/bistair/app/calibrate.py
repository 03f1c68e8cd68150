"""``bistair calibrate``: a camera and a projector calibrated from folders of board captures.

Every sub-folder of the captures' folder (natural name order, hidden ones left out) is a
pose, in one of two layouts::

    calib/pose-00/columns/   images + spec.json (orientation columns)
    calib/pose-00/rows/      images + spec.json (orientation rows)

    calib/capture_0/         images of both axes, decoded by one spec of orientation both:
                             --spec, else its own spec.json, else calib/spec.json

The board is the ``--board`` description (a ``board.json`` file or
``chessboard:COLUMNSxROWS:SQUARE``), by default ``calib/board.json``. It is found in the
pose's white frame, or for a spec without one (or when it is not found there) in the mean
image of the captures (the decode's average: the mean of the phase shifts, or of each Gray
code bit and its inverse),
and each feature is mapped to the projector by a local homography of the decoded
coordinates around it (:func:`~bistair.geometry.calibrate.board_view`). A pose whose
captures do not decode, or whose board is not found or not mapped, is skipped (the
``skipped`` callback names it and says why); a spec that cannot be read or does not fit its
folder, projector sizes or camera images that differ, stop the job.

The other calibrations of a rig live here too: two cameras from board image pairs
(:func:`calibrate_stereo_folder`, ``bistair calibrate-stereo``), and calibrations made
elsewhere, imported (``bistair import-calibration``: :func:`import_calibration`,
:func:`import_stereo_calibration` with ``--stereo``, :func:`import_projection_matrices`
with ``--projection-matrices``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import decode
from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..geometry.board import Board, is_board_text, parse_board
from ..geometry.calibrate import (
    MIN_POSES,
    BoardView,
    PoseCapture,
    board_view,
    calibrate_stereo_images,
    calibrate_views,
    check_min_poses,
)
from ..geometry.calibration import Calibration, StereoCalibration, save_calibration
from ..geometry.opencv import read_opencv_calibration, read_opencv_stereo
from ..geometry.projection_matrices import (
    default_origin,
    import_matrices,
    save_matrix_calibration,
)
from ..io.read import list_images, load_spec, natural_key, read_image, read_with_spec
from ..spec import BaseSpec
from .progress import Say, silent

Skipped = Callable[[str, str], None]
AXES = ("columns", "rows")


def pose_folders(folder: Path) -> list[Path]:
    """The pose sub-folders of a calibration capture folder (natural name order, hidden ones
    left out); a folder with ``columns/`` but no ``rows/`` (or the other way) is refused."""
    subs = sorted((p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")),
                  key=lambda p: natural_key(p.name))
    for sub in subs:
        have = [(sub / o).is_dir() for o in AXES]
        if any(have) and not all(have):
            missing = "rows" if have[0] else "columns"
            raise BistairError(f"pose {sub.name} has no {missing}/ folder")
    return subs


def pose_specs(folder: Path, root: Path, spec: BaseSpec | None) -> dict[str, BaseSpec] | None:
    """The specs that decode a pose: ``{"columns": ..., "rows": ...}`` for the two-folder
    layout, ``{"both": ...}`` for captures of both axes; ``None`` when a folder of captures
    has no spec (neither ``spec`` given, nor its own, nor ``root``'s ``spec.json``).

    Refuses a spec that cannot be read, codes another axis than its folder, or codes one
    axis for a folder of captures."""
    if all((folder / o).is_dir() for o in AXES):
        if spec is not None:
            raise BistairError(f"--spec is for pose folders of captures of both axes; "
                               f"{folder.name} has columns/ and rows/ with their own specs")
        specs = {o: load_spec(folder / o / "spec.json") for o in AXES}
        for o, s in specs.items():
            if s.orientation != o:
                raise BistairError(f"{folder.name}/{o}/spec.json codes {s.orientation}, the "
                                   f"folder is for {o}")
        return specs
    where = "--spec"
    if spec is None:
        for path in (folder / "spec.json", root / "spec.json"):
            if path.is_file():
                spec, where = load_spec(path), path.relative_to(root).as_posix()
                break
        else:
            return None
    if spec.orientation != "both":
        raise BistairError(f"{where} codes the {spec.orientation} alone: a pose folder of "
                           "captures needs a spec of both axes (orientation both), or "
                           "columns/ and rows/ folders")
    return {"both": spec}


def read_pose(folder: Path, specs: dict[str, BaseSpec]
              ) -> tuple[PoseCapture, np.ndarray | None]:
    """Decode one pose: its :class:`~bistair.geometry.calibrate.PoseCapture` (the board
    image: the white frame, else the mean image; the projector column and row per camera
    pixel) and, when the board image is the white frame, the mean image (a second place to
    look for the board)."""
    if "both" in specs:
        stack, spec = read_with_spec(folder, specs["both"])
        result = decode(stack, spec)
        assert isinstance(result, AxesResult)
        del stack
        x, y = result.x, result.y
    else:
        x, y = (_decode_axis(folder, o, specs[o]) for o in AXES)
        if x.phase.shape != y.phase.shape:
            raise _SizeError(f"{folder.name}/rows images are {y.phase.shape[1]}x"
                             f"{y.phase.shape[0]}, earlier ones {x.phase.shape[1]}x"
                             f"{x.phase.shape[0]}")
    white = x.texture if x.texture is not None else y.texture
    mean = (x.average + y.average) / 2
    if white is None:
        return PoseCapture(folder.name, mean, x.coord, y.coord), None
    return PoseCapture(folder.name, white, x.coord, y.coord), mean


class _SizeError(BistairError):
    """Images of one pose that differ in size: an error, not a pose to skip."""


def _decode_axis(folder: Path, orientation: str, spec: BaseSpec) -> DecodeResult:
    try:
        stack, spec = read_with_spec(folder / orientation, spec)
        result = decode(stack, spec)
    except BistairError as exc:
        raise BistairError(f"{orientation}: {exc}") from None
    assert isinstance(result, DecodeResult)
    return result


def board_option(board: Board | str | Path | None, root: Path) -> Board:
    """The board of ``--board``: a :class:`~bistair.geometry.board.Board`, a short
    description (``chessboard:9x7:25``), a ``board.json`` file, or by default
    ``root/board.json``."""
    if isinstance(board, Board):
        return board
    if board is not None and is_board_text(str(board)):
        return parse_board(str(board))
    path = root / "board.json" if board is None else Path(board)
    if not path.exists():
        raise BistairError(f"board description {path} not found (give --board FILE or "
                           "--board TYPE:COLUMNSxROWS:SPACING, e.g. chessboard:9x7:25)")
    return Board.load(path)


def calibrate_folder(folder: str | Path, out: str | Path | None = None,
                     board: Board | str | Path | None = None,
                     spec: BaseSpec | str | Path | None = None, min_poses: int = MIN_POSES,
                     corner_fit: str = "homography", progress: Say | None = None,
                     skipped: Skipped | None = None, **options: Any) -> Calibration:
    """Calibrate from board captures; write the calibration file to ``out`` (atomically) if
    given.

    ``spec`` decodes every pose folder of captures (by default each one's ``spec.json``, else
    ``folder/spec.json``); ``corner_fit`` maps the features to the projector
    (``"homography"`` or ``"quadratic"``, see
    :func:`~bistair.geometry.calibrate.board_view`); ``options`` go to
    :func:`~bistair.geometry.calibrate.calibrate_points` (``fix_k3``, ``refine``).
    ``min_poses`` (at least :data:`~bistair.geometry.calibrate.MIN_POSES`, 3) poses must show
    the board with its features mapped to the projector; the calibration carries the
    standard deviations of its parameters (``uncertainty``). ``progress`` is called with each
    stage's name as it starts, ``skipped`` with the name of each pose left out and why.
    Layouts and rules: see the module's notes.
    """
    say = progress or silent
    check_min_poses(min_poses)
    folder = Path(folder)
    if not folder.is_dir():
        raise BistairError(f"calibration captures {folder} not found")
    board = board_option(board, folder)
    if spec is not None and not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    folders = pose_folders(folder)
    if not folders:
        raise BistairError(f"no pose folders in {folder} (sub-folders with columns/ and rows/, "
                           "or with captures of both axes)")
    views: list[BoardView] = []
    failed: list[str] = []
    proj_size = cam_size = None

    def skip(name: str, why: str) -> None:
        if skipped is not None:
            skipped(name, why)

    for number, sub in enumerate(folders, 1):
        specs = pose_specs(sub, folder, spec)
        if specs is None:
            failed.append(f"{sub.name}: no spec.json (give --spec)")
            skip(sub.name, "no spec.json beside its captures (give --spec)")
            continue
        for where, s in specs.items():
            if proj_size is None:
                proj_size = (s.width, s.height)
            elif (s.width, s.height) != proj_size:
                name = f"{sub.name}/{where}/spec.json" if where != "both" else sub.name
                raise BistairError(f"{name} is for a {s.width}x{s.height} projector, earlier "
                                   f"specs for {proj_size[0]}x{proj_size[1]}")
        say(f"decoding pose {number} of {len(folders)} ({sub.name})")
        try:
            pose, mean = read_pose(sub, specs)
        except _SizeError:
            raise
        except BistairError as exc:
            failed.append(f"{sub.name}: {exc}")
            skip(sub.name, str(exc))
            continue
        say(f"finding the board in pose {number} of {len(folders)} ({sub.name})")
        view = board_view(pose, board, corner_fit)
        if not view.found and mean is not None:  # e.g. a white frame with clipped squares
            view = board_view(replace(pose, white=mean), board, corner_fit)
        if not view.usable:
            where = "mean image" if mean is None else "white frame nor in its mean image"
            skip(sub.name, f"{view.why} in its {where}" if not view.found else view.why)
        elif cam_size is None:
            cam_size = pose.white.shape
        elif pose.white.shape != cam_size:
            raise BistairError(f"{sub.name} images are {pose.white.shape[1]}x"
                               f"{pose.white.shape[0]}, earlier poses' {cam_size[1]}x"
                               f"{cam_size[0]}")
        views.append(view)
    say(f"calibrating from {sum(v.usable for v in views)} poses")
    camera = (cam_size[1], cam_size[0]) if cam_size else (0, 0)  # (0, 0): no pose to use
    try:
        cal = calibrate_views(views, board, camera, proj_size or (0, 0), min_poses,
                              len(folders), **options)
    except BistairError as exc:
        if not failed:
            raise
        raise BistairError(f"{exc}; {len(failed)} not decoded ({failed[0]})") from None
    if out is not None:
        save_calibration(cal, out)
    return cal


def summary_lines(cal: Calibration, out: str | Path) -> list[str]:
    """What ``bistair calibrate`` prints: the RMS errors, baseline and poses, every intrinsic
    with one standard deviation, the pose's uncertainty and each pose's errors."""
    sigma = cal.uncertainty
    assert sigma is not None
    lines = [f"camera RMS {cal.camera.rms:.3f} px, projector RMS {cal.projector.rms:.3f} px, "
             f"stereo RMS {cal.rms:.3f} px, baseline {cal.baseline:.2f} +/- "
             f"{sigma.baseline:.2f} mm, {len(cal.poses)} of {cal.poses_total} poses; "
             f"wrote {out}"]
    for name in ("camera", "projector"):
        dev, sd = getattr(cal, name), getattr(sigma, name)
        values = (dev.K[0, 0], dev.K[1, 1], dev.K[0, 2], dev.K[1, 2])
        lines.append(f"  {name + ':':10s} " + ", ".join(
            f"{key} {v:.2f} +/- {s:.2f}"
            for key, v, s in zip(("fx", "fy", "cx", "cy"), values, sd[:4], strict=True)) + " px")
    lines.append(f"  rotation +/- {sigma.angle:.3f} deg, T +/- "
                 f"({', '.join(f'{v:.2f}' for v in sigma.T)}) mm (one standard deviation, "
                 f"from correspondence noise of {sigma.noise[0]:.3f} px in the camera and "
                 f"{sigma.noise[1]:.3f} px in the projector per coordinate)")
    lines += [f"  {pose['name']}: {pose['features']} features, camera "
              f"{pose['camera_rms']:.3f} px, projector {pose['projector_rms']:.3f} px"
              for pose in cal.poses]
    return lines


# -- two cameras ------------------------------------------------------------------------------
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
    say = progress or silent
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


# -- imported calibrations -------------------------------------------------------------------
def import_calibration(files: Sequence[str | Path], out: str | Path,
                       projector_size: tuple[int, int] | str | None,
                       camera_size: tuple[int, int] | str | None = None,
                       keys: Mapping[str, str] | str | None = None) -> Calibration:
    """Read an OpenCV FileStorage calibration (YAML or XML, keys of several files merged)
    and write it as a bistair calibration file ``out`` (atomically).

    Sizes are ``(width, height)`` or ``"WxH"``, or ``None`` to read them from the files;
    ``keys`` renames parts (a mapping or ``"camera=M1,T=T"``), see
    :func:`~bistair.geometry.opencv.read_opencv_calibration`.
    Nothing is written on error.
    """
    if isinstance(projector_size, str):
        projector_size = parse_size(projector_size, "--projector-size")
    if isinstance(camera_size, str):
        camera_size = parse_size(camera_size, "--camera-size")
    if isinstance(keys, str):
        keys = parse_keys(keys)
    cal = read_opencv_calibration(list(files), projector_size, camera_size, keys)
    save_calibration(cal, out)
    return cal

def import_projection_matrices(files: Sequence[str | Path] | str, out: str | Path,
                               camera_size: tuple[int, int] | str | None,
                               projector_size: tuple[int, int] | str | None,
                               pixel_origin: int | None = None
                               ) -> tuple[StereoCalibration, int]:
    """Read three 3x4 projection matrices (left camera, right camera, projector: ``.npy``,
    ``.txt`` or ``.mat``, one world frame) and write the two-camera-and-projector
    calibration ``out`` in the left camera's frame
    (:mod:`~bistair.geometry.projection_matrices`), recording the cameras' pixel origin
    (``pixel_origin``: 0 or 1, by default 1 for ``.mat`` files, 0 otherwise). ``files``
    may be ``"L,R,P"``. Returns the calibration and the origin used. Nothing is written on
    error."""
    if isinstance(files, str):
        files = [f.strip() for f in files.split(",")]
    sizes = []
    for size, name in ((camera_size, "--camera-size"), (projector_size, "--projector-size")):
        if size is None:
            raise BistairError(f"--projection-matrices needs {name} WxH (a matrix does not "
                               "hold the image size)")
        sizes.append(parse_size(size, name) if isinstance(size, str) else size)
    cal = import_matrices(tuple(files), *sizes, pixel_origin=pixel_origin)
    origin = default_origin(files) if pixel_origin is None else int(pixel_origin)
    save_matrix_calibration(cal, origin, out)
    return cal, origin


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


# -- option strings --------------------------------------------------------------------------
def parse_size(text: str, name: str = "size") -> tuple[int, int]:
    """``"WxH"`` as ``(width, height)``, positive integers.

    Raises
    ------
    BistairError
        If ``text`` is not two positive whole numbers joined by ``x``.

    Examples
    --------
    >>> parse_size("1920x1080")
    (1920, 1080)
    >>> parse_size("1920")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: size must be WIDTHxHEIGHT in pixels, e.g. 1920x1080, got '1920'
    """
    parts = text.strip().lower().split("x")
    if len(parts) != 2 or not all(p.strip().isdigit() and int(p) > 0 for p in parts):
        raise BistairError(f"{name} must be WIDTHxHEIGHT in pixels, e.g. 1920x1080, got "
                           f"{text!r}")
    return int(parts[0]), int(parts[1])

def parse_keys(text: str) -> dict[str, str]:
    """``"NAME=KEY,NAME=KEY"`` as a dictionary (names checked by the reader).

    Raises
    ------
    BistairError
        If an item is not ``NAME=KEY`` or a name repeats.

    Examples
    --------
    >>> parse_keys("camera=K_cam, T=translation")
    {'camera': 'K_cam', 'T': 'translation'}
    """
    out: dict[str, str] = {}
    for item in text.split(","):
        name, sep, key = (part.strip() for part in item.partition("="))
        if not sep or not name or not key:
            raise BistairError(f"--keys must be NAME=KEY items joined by commas, e.g. "
                               f"camera=M1,T=T; got {item.strip()!r}")
        if name in out:
            raise BistairError(f"--keys names {name} twice")
        out[name] = key
    return out
