"""The binocular job behind the command line: reconstruct from two cameras and a projector
(``bistair stereo``). Two cameras are calibrated by :mod:`bistair.app.calibrate`
(``calibrate-stereo``, ``import-calibration --stereo``) and rendered by
:mod:`bistair.app.simulate` (``simulate --cameras 2``); ``stereo --window`` is
:mod:`bistair.app.stereo_stream`.

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

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..geometry.calibration import (
    STEREO,
    Calibration,
    StereoCalibration,
    load_calibration,
)
from ..geometry.stereo import StereoResult, stereo
from ..geometry.unwrap import is_single_period, stereo_unwrap
from ..io.atomic import check_output, output_folder
from ..io.jsonfile import write_json
from ..io.read import (
    default_spec_path,
    find_spec,
    read_with_spec,
)
from ..io.writers import write_depth, write_ply, write_result
from ..spec import BaseSpec
from .progress import Say, silent

SIDES = (("L", "R"), ("left", "right"))  # the folders of a stereo capture set


# -- reconstruct -----------------------------------------------------------------------------
def stereo_folder(left: Any, right: Any, out: str | Path,
                  calibration: StereoCalibration | str | Path,
                  spec: BaseSpec | str | Path | None = None, min_depth: float = 0.0,
                  max_depth: float = np.inf, force: bool = False,
                  smooth: float | None = None,
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
    see :func:`~bistair.geometry.stereo.reconstruct_stereo` (``None``: its default, 1 px;
    a single-period spec, unwrapped by the projector, matches no projector coordinates and
    refuses one). ``options`` are decoder options (and ``continue_unseen`` for a
    single-period spec: :func:`~bistair.geometry.unwrap.unwrap_stereo`). Nothing is written
    on error.
    """
    say = progress or silent
    for side in (left, right):
        check_output(out, side)
    if same_place(left, right):
        raise BistairError(f"LEFT and RIGHT are the same captures ({left}): give each camera's "
                           "own")
    if isinstance(calibration, Calibration):
        raise BistairError("a camera-projector calibration was given: stereo needs the two "
                           "cameras' calibration (bistair calibrate-stereo)")
    if not isinstance(calibration, StereoCalibration):
        calibration = load_calibration(calibration, STEREO)
    recorded = calibration.pixel_origin  # import-calibration --projection-matrices's
    spec = find_spec(left, spec) if spec is not None else one_spec(left, right)
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
        if smooth is not None:
            raise BistairError("--smooth does not apply to a single-period spec: stereo "
                               "phase unwrapping takes each pixel's depth from the projector "
                               "column of its phase, with no smoothing")
        if recorded is not None:  # checked against the data
            options = {"pixel_origin": recorded, **options}
        result = _unwrapped(lstack, rstack, used, calibration, min_depth, max_depth, force,
                            options)
    else:
        if options.pop("continue_unseen", False):
            raise BistairError("--continue-unseen applies to a single-period spec (stereo "
                               "phase unwrapping); a coded spec's pixels are matched by "
                               "their absolute phase")
        say(f"decoding 2 x {len(lstack)} frames of {lstack.shape[2]}x{lstack.shape[1]} "
            f"({used.method}) and matching")
        result = stereo(lstack, rstack, used, calibration, min_depth=min_depth,
                        max_depth=max_depth, force=force,
                        **({} if smooth is None else {"smooth": smooth}), **options)
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
    unknown = sorted(set(options) - {"min_modulation", "pixel_origin", "continue_unseen"})
    if unknown:
        raise BistairError(f"stereo phase unwrapping takes no {', '.join(unknown)} option")
    if lstack.shape != rstack.shape:
        raise BistairError("left and right captures differ: " + " and ".join(
            f"{s[0]} frames of {s[2]}x{s[1]}" for s in (lstack.shape, rstack.shape)))
    return stereo_unwrap(lstack, rstack, spec, calibration, min_depth, max_depth, force,
                         options.get("min_modulation"),
                         pixel_origin=options.get("pixel_origin"),
                         continue_unseen=bool(options.get("continue_unseen", False)))


def same_place(left: Any, right: Any) -> bool:
    """Whether LEFT and RIGHT name the same folder, file or pattern."""
    if not (isinstance(left, str | Path) and isinstance(right, str | Path)):
        return False
    return Path(left).expanduser().resolve() == Path(right).expanduser().resolve()


def one_spec(left: Any, right: Any) -> BaseSpec:
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
