"""``bistair stereo LEFT RIGHT --window W``: a depth map for every window of a two-camera
stream.

Each camera's frame ``i`` shows shift ``i mod N`` of one single-period N-step set (``patterns
multifreq --periods T``, ``simulate --cameras 2 --frames F --continuous``), the frames taken
in their order on disk; the spec's conventions describe frame 0. ``--window N`` is plain
N-step, ``--window N+K`` compensates motion of order ``K`` (:mod:`bistair.core.motion`).
Both streams go through one :class:`~bistair.geometry.unwrap_stream.StereoStream`: the
first window is unwrapped as the one-set ``stereo`` command does (its depth range checked),
each later one near the previous window's disparity. For each window start asked for (all
by default) it writes::

    OUT/<start, 4 digits>/depth.npy   float32 z (mm) on the left camera's own grid, NaN
                                      where unknown
    OUT/<start, 4 digits>/depth.png   its preview, as the one-set ``stereo`` writes it
                                      (not with ``--no-previews``)
    OUT/<start, 4 digits>/cloud.ply   x, y, z (mm, left camera frame), grey from the
                                      left camera's modulation
    OUT/<start, 4 digits>/info.json   start, frames used, window, order, lag, time, the
                                      decided pixels, the depth range, the first window's
                                      range check, the pixel counts

all at once: nothing is written on an error, and window folders of an earlier run that this
one did not write are removed.

Examples
--------
>>> parse_window("4+2", 4).lag  # frames between the newest frame and the time described
2.5
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import BistairError
from ..geometry.calibration import STEREO, Calibration, StereoCalibration, load_calibration
from ..geometry.stereo import cloud_points
from ..geometry.unwrap_stream import StereoStream, StreamDepth
from ..io.atomic import check_output, output_folder
from ..io.jsonfile import write_json
from ..io.read import capture_files, find_spec, read_captures
from ..io.writers import write_depth, write_ply
from ..spec import BaseSpec
from .decode_stream import (
    Window,
    check_stream_spec,
    frame_count,
    parse_starts,
    parse_window,
    remove_other_windows,
    shown_window,
)
from .stereo import one_spec, same_place


def stereo_stream(left: str | Path, right: str | Path, out: str | Path,
                  calibration: StereoCalibration | str | Path, spec: BaseSpec | str | Path | None,
                  window: str, starts: str | None = None, min_depth: float = 0.0,
                  max_depth: float = math.inf, force: bool = False,
                  min_modulation: float | None = None, previews: bool = True,
                  progress: Callable[[str], None] | None = None) -> list[StreamDepth]:
    """Depth maps of a two-camera stream, window by window, into ``OUT/<start>/`` (module
    docstring).

    Parameters
    ----------
    left, right : str or Path
        Each camera's frames in order: a folder, a quoted glob pattern or a ``.npy`` stack.
    out : str or Path
        The output folder.
    calibration : StereoCalibration, str or Path
        The two cameras and the projector.
    spec : BaseSpec, str, Path or None
        The single-period spec (default: ``spec.json`` beside LEFT, equal to RIGHT's).
    window : str
        ``"N"`` or ``"N+K"``.
    starts : str, optional
        The window starts to write (``"0,30,60"``; default: every one).
    min_depth, max_depth : float
        The depth range (left camera frame, mm); needed.
    force : bool, optional
        Keep the first window when its depth range check would refuse it (a warning).
    min_modulation : float, optional
        The modulation a valid pixel needs (fraction of full scale; default from noise).
    previews : bool, optional
        Write each window's ``depth.png`` (default ``True``).
    progress : callable, optional
        Called with each stage's name.

    Returns
    -------
    list of StreamDepth
        The windows written, in order.

    Raises
    ------
    BistairError
        A window that is not N or N+K, starts beyond the stream, streams whose frame counts
        or sizes differ, a spec that is not single-period, no depth range, what stereo
        phase unwrapping refuses; nothing is written then.

    Examples
    --------
    >>> stereo_stream("L", "R", "out", "stereo.json", None, "4")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: a stream of two cameras needs --depth-range ZMIN:ZMAX ...
    """
    say = progress or (lambda stage: None)
    if not (min_depth > 0 and math.isfinite(max_depth)):
        raise BistairError("a stream of two cameras needs --depth-range ZMIN:ZMAX (mm, left "
                           "camera frame, holding the whole scene): one period gives no "
                           "fringe order")
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
    spec = check_stream_spec(find_spec(left, spec) if spec is not None
                             else one_spec(left, right))
    win = parse_window(window, spec.steps)
    files = [capture_files(side) for side in (left, right)]
    counts = [frame_count(f) for f in files]
    if counts[0] != counts[1]:
        raise BistairError(f"LEFT has {counts[0]} frames and RIGHT {counts[1]}: the two "
                           "cameras' streams pair up frame by frame")
    chosen = parse_starts(starts, counts[0], win)
    last = chosen[-1] + win.frames
    say(f"reading 2 x {last} of {counts[0]} frames")
    stacks = []
    for name, f in zip(("left", "right"), files, strict=True):
        try:
            stacks.append(read_captures(f[:last] if len(f) > 1 else f)[:last])
        except BistairError as exc:
            raise BistairError(f"{name}: {exc}") from None
    if stacks[0].shape != stacks[1].shape:
        raise BistairError("left and right frames differ: " + " and ".join(
            f"{s[0]} frames of {s[2]}x{s[1]}" for s in (stacks[0].shape, stacks[1].shape)))
    for name, stack in zip(("left", "right"), stacks, strict=True):
        if stack.dtype.kind == "f" and not np.isfinite(stack).all():
            raise BistairError(f"{name}: captures contain NaN or infinite values")
    stream = StereoStream(calibration, spec, min_depth, max_depth, win.order, min_modulation,
                          force=force, pixel_origin=calibration.pixel_origin)  # checked
    say(f"unwrapping {last - win.frames + 1} windows of {shown_window(win)} frames "
        f"({stacks[0].shape[2]}x{stacks[0].shape[1]}, both cameras) at "
        f"{min_depth:g}-{max_depth:g} mm")
    wanted, kept = set(chosen), []
    with output_folder(out) as tmp:
        for i in range(last):
            result = stream.push(stacks[0][i], stacks[1][i])
            if result is None or result.start not in wanted:
                continue
            write_window(tmp / f"{result.start:04d}", result, stream, win, previews)
            kept.append(result)
    remove_other_windows(Path(out), {f"{s:04d}" for s in chosen})
    return kept


def write_window(folder: Path, result: StreamDepth, stream: StereoStream, win: Window,
                 previews: bool = True) -> None:
    """Write one window's ``depth.npy``, ``depth.png`` (with ``previews``), ``cloud.ply``
    and ``info.json`` into ``folder`` (made here).

    Parameters
    ----------
    folder : Path
        The window's folder (not there yet).
    result : StreamDepth
        The window.
    stream : StereoStream
        The stream it came from (the depth range, the first window's check).
    win : Window
        ``--window``.
    previews : bool, optional
        Also write ``depth.png`` (:func:`~bistair.io.writers.write_depth`).

    Returns
    -------
    None

    Examples
    --------
    >>> import json, tempfile
    >>> from types import SimpleNamespace
    >>> from bistair.geometry.stereo import _toy_stereo, rectify
    >>> depth = np.full((480, 640), np.nan, np.float32)
    >>> depth[10, 20] = 500.0
    >>> info = {"decided": 1, "decided_fraction": 0.5, "left_decoded": 2, "warnings": []}
    >>> res = StreamDepth(3, depth, np.zeros(depth.shape, np.int32), depth, np.isfinite(depth),
    ...                   depth, np.zeros(depth.shape, np.uint8), info)
    >>> fake = SimpleNamespace(range=(400.0, 600.0), check=None, rect=rectify(_toy_stereo()),
    ...                        pixel_origin=None)
    >>> folder = Path(tempfile.mkdtemp()) / "0003"
    >>> write_window(folder, res, fake, Window(4, 1))
    >>> sorted(p.name for p in folder.iterdir())
    ['cloud.ply', 'depth.npy', 'depth.png', 'info.json']
    >>> json.loads((folder / "info.json").read_text())["frames"]
    [3, 7]
    """
    folder.mkdir()
    if previews:
        write_depth(result.depth, folder)  # depth.npy (float32) and depth.png
    else:
        np.save(folder / "depth.npy", result.depth.astype(np.float32))
    write_ply(folder / "cloud.ply", *cloud_points(result.depth, *stream.rect.rays,
                                                  result.grey, result.mask))
    info = result.info
    info_out: dict[str, Any] = {
        "unwrapping": "stereo stream", "start": result.start,
        "frames": [result.start, result.start + win.frames - 1],
        "window": shown_window(win), "steps": win.steps, "order": win.order, "lag": win.lag,
        "time": result.start + win.lag, "depth_range": list(stream.range),
        "decided": info["decided"], "decided_fraction": info["decided_fraction"],
        "left_decoded": info.get("left_decoded", 0), "pixels": int(result.depth.size),
        "range_check": stream.check,
        **({} if stream.pixel_origin is None else {"pixel_origin": stream.pixel_origin}),
        **{k: v for k, v in info.items() if k not in ("decided", "decided_fraction",
                                                         "left_decoded", "start")}}
    write_json(folder / "info.json", info_out)
