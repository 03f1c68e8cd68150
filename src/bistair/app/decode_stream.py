"""``bistair decode FOLDER --window W``: a stream of frames decoded window by window.

A stream's frame ``i`` shows shift ``i mod N`` of one single-period N-step set (``patterns
multifreq --periods T``, ``simulate --frames F --continuous``); the spec's conventions
(``phase_offset``, ``shift_sign``) describe frame 0, the frames are taken in their order on
disk. ``--window N`` is plain N-step: window ``s`` is frames ``s .. s+N-1``; ``--window
N+K`` compensates motion of order ``K`` (binomial self-compensation,
:mod:`bistair.core.motion`): window ``s`` is frames ``s .. s+N+K-1`` and describes the time
``s + (N+K-1)/2``. The frames go through one :class:`~bistair.core.motion.PhaseStream`,
which reuses the sums of the frames already seen. For each window start asked for (all by
default) it writes::

    OUT/<start, 4 digits>/wrapped.npy     float32 wrapped phase in [0, 2*pi), NaN where the
                                          modulation is below the threshold (as decode)
    OUT/<start, 4 digits>/modulation.npy  float32, fractions of full scale (as decode)
    OUT/<start, 4 digits>/phase.npy       the absolute phase, only where the spec's code
                                          gives it (one period covering the coded axis)
    OUT/<start, 4 digits>/info.json       start, frames used, order K, lag, threshold, ...

all at once (nothing is written on an error). The modulation threshold is decode's (four
times the camera noise measured on the first window, at least 1% of full scale) or
``min_modulation``.

Examples
--------
>>> import json, tempfile, pathlib
>>> from bistair.codecs import make_spec
>>> from bistair.core.phase import wrap
>>> spec = make_spec("multifreq", width=64, height=24, periods=(16,), steps=4)
>>> x = np.arange(64.0)[None, :].repeat(24, 0)
>>> frames = np.stack([0.5 + 0.4 * np.cos(2 * np.pi * x / 16 + np.pi * i / 2)
...                    for i in range(7)])
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = decode_stream(frames, spec, pathlib.Path(tmp) / "s", "4+1", starts=[0, 2])
...     names = sorted(p.name for p in out.iterdir())
...     files = sorted(p.name for p in (out / "0002").iterdir())
...     phi = np.load(out / "0002" / "wrapped.npy")
...     info = json.loads((out / "0002" / "info.json").read_text())
>>> names, files
(['0000', '0002'], ['info.json', 'modulation.npy', 'wrapped.npy'])
>>> bool(np.abs(wrap(phi - 2 * np.pi * x / 16)).max() < 1e-4), info["frames"], info["lag"]
(True, [2, 6], 2.0)
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs.multifreq import MultiFreqSpec, single_period_refusal, top_phase
from ..core.captures import prepare
from ..core.measure import measure
from ..core.motion import PhaseStream
from ..errors import BistairError
from ..io.atomic import check_output, output_folder
from ..io.jsonfile import write_json
from ..io.read import Captures, capture_files, find_spec, read_captures
from ..spec import BaseSpec, format_period


@dataclass(frozen=True)
class Window:
    """``--window N`` or ``N+K``: ``steps`` frames a set, compensation ``order`` ``K``."""

    steps: int
    order: int

    @property
    def frames(self) -> int:
        """The frames one result uses, ``N + K``."""
        return self.steps + self.order

    @property
    def lag(self) -> float:
        """Frames between a result's newest frame and the time it describes."""
        return (self.frames - 1) / 2


def parse_window(text: str, steps: int) -> Window:
    """``"N"`` or ``"N+K"`` (``N`` the spec's steps, ``K`` 1 or more).

    Examples
    --------
    >>> parse_window("4+2", 4), parse_window(" 4 ", 4).order
    (Window(steps=4, order=2), 0)
    >>> parse_window("3+1", 4)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --window must be 4 (plain 4-step) or 4+K (order K ... got '3+1'
    """
    match = re.fullmatch(r"\s*(\d+)\s*(?:\+\s*(\d+))?\s*", str(text))
    if (match is None or int(match.group(1)) != steps
            or (match.group(2) is not None and int(match.group(2)) < 1)):
        raise BistairError(f"--window must be {steps} (plain {steps}-step) or {steps}+K (order "
                           f"K of motion compensation, K >= 1), got {text!r}")
    return Window(steps, int(match.group(2) or 0))


def parse_starts(text: str | Sequence[int] | None, count: int, window: Window) -> list[int]:
    """The window starts asked for (``"0,30,60"``), checked against a stream of ``count``
    frames; all of them (``0 .. count - N - K``) by default.

    Examples
    --------
    >>> parse_starts("0, 3", 8, Window(4, 1)), parse_starts(None, 6, Window(4, 0))
    ([0, 3], [0, 1, 2])
    >>> parse_starts("4", 8, Window(4, 1))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: --starts 4 is beyond the stream: 8 frames give ... 0 to 3 ...
    """
    last = count - window.frames
    if last < 0:
        raise BistairError(f"--window {shown_window(window)} needs {window.frames} frames, the "
                           f"stream has {count}")
    if text is None:
        return list(range(last + 1))
    if isinstance(text, str):
        items = [t.strip() for t in text.split(",")]
        if not all(re.fullmatch(r"\d+", t) for t in items):
            raise BistairError(f"--starts must be frame numbers joined by commas (0,30,60), "
                               f"got {text!r}")
        starts = [int(t) for t in items]
    else:
        starts = [int(s) for s in text]
    beyond = [s for s in starts if not 0 <= s <= last]
    if beyond:
        raise BistairError(f"--starts {','.join(map(str, beyond))} is beyond the stream: "
                           f"{count} frames give window starts 0 to {last} for --window "
                           f"{shown_window(window)}")
    return sorted(set(starts))


def check_stream_spec(spec: BaseSpec) -> MultiFreqSpec:
    """Refuse a spec a stream cannot use: it needs one N-step set of one period on one
    axis (``patterns multifreq --periods T``).

    Examples
    --------
    >>> from bistair.codecs import make_spec
    >>> check_stream_spec(make_spec("multifreq", width=300, height=32, periods=(42, 45, 48)))
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: a stream needs a single-period N-step spec ... (42, 45, 48)
    """
    need = ("a stream needs a single-period N-step spec of one axis (patterns multifreq "
            "--periods T), one frame a shift")
    if not isinstance(spec, MultiFreqSpec):
        raise BistairError(f"{need}; got the method {spec.method}")
    if spec.orientation == "both":
        raise BistairError(f"{need}; got a spec of both axes")
    if len(spec.periods) != 1:
        shown = ", ".join(format_period(t) for t in spec.periods)
        raise BistairError(f"{need}; got {len(spec.periods)} periods ({shown})")
    if list(spec.frames) != list(spec.method_frames()):
        raise BistairError(f"{need}; the spec's frame list differs from its shifts in order")
    return spec


def refuse_single_period(captures: Captures, spec: BaseSpec | str | Path | None) -> None:
    """``decode`` without ``--window``: refuse a single-period spec at once, before the
    frames are counted (a stream has more frames than its set), saying why and what to
    use instead (:func:`~bistair.codecs.multifreq.single_period_refusal`)."""
    found = find_spec(captures, spec)
    if isinstance(found, MultiFreqSpec) and found.single_period:
        raise BistairError(single_period_refusal(found))


def decode_stream(captures: Captures | np.ndarray, spec: BaseSpec | str | Path | None,
                  out: str | Path, window: str, starts: str | Sequence[int] | None = None,
                  min_modulation: float | None = None,
                  progress: Callable[[str], None] | None = None) -> Path:
    """Decode a stream window by window into ``OUT/<start>/`` (see the module docstring).

    Parameters
    ----------
    captures : folder, files, glob patterns, a ``.npy`` stack, or an array
        The stream's frames in order (:func:`~bistair.io.read.capture_files`).
    spec : BaseSpec, path or None
        The single-period spec (default: ``spec.json`` beside the captures).
    out : str or Path
        The output folder.
    window : str
        ``"N"`` or ``"N+K"``.
    starts : str or sequence of int, optional
        The window starts to write (default: every one).
    min_modulation : float, optional
        The modulation a valid pixel needs (fraction of full scale; default from noise).
    progress : callable, optional
        Called with each stage's name.

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    BistairError
        A spec that is not one period's N-step set, a window that is not N or N+K, too few
        frames, starts beyond the stream, unreadable captures; nothing is written then.
    """
    say = progress or (lambda stage: None)
    if isinstance(captures, np.ndarray):
        if not isinstance(spec, BaseSpec):
            raise BistairError("a stream given as an array needs its spec")
        stack, files = captures, None
    else:
        check_output(out, captures)
        files = capture_files(captures)
        spec = find_spec(captures, spec, files)
        stack = None
    spec = check_stream_spec(spec)
    win = parse_window(window, spec.steps)
    count = len(stack) if stack is not None else frame_count(files)
    chosen = parse_starts(starts, count, win)
    last = chosen[-1] + win.frames  # the frames read: up to the last window's end
    if stack is None:
        say(f"reading {last} of {count} frames")
        stack = read_captures(files[:last] if len(files) > 1 else files)[:last]
    first = prepare(stack[:spec.steps], spec.steps, spec.method)  # shape, dtype, scale
    if stack.dtype.kind == "f" and not np.isfinite(stack).all():
        raise BistairError("captures contain NaN or infinite values")
    scale = first.full_scale
    fs = measure(first, 0, spec.steps, min_modulation, check=False, shift_sign=spec.shift_sign,
                 phase_offset=spec.phase_offset)
    threshold = fs.threshold
    say(f"decoding {len(chosen)} windows of {shown_window(win)} frames "
        f"({stack.shape[2]}x{stack.shape[1]})")
    stream = PhaseStream(spec.steps, win.order, spec.shift_sign, spec.phase_offset)
    wanted = set(chosen)
    with output_folder(out) as tmp:
        for i in range(last):
            result = stream.push(stack[i].astype(np.float32) / np.float32(scale))
            start = i + 1 - win.frames
            if result is None or start not in wanted:
                continue
            _write_window(tmp / f"{start:04d}", result, spec, win, start, threshold, fs.noise)
    remove_other_windows(Path(out), {f"{s:04d}" for s in chosen})
    return Path(out)


def remove_other_windows(out: Path, written: set[str]) -> None:
    """Remove the window folders an earlier stream left in ``out`` and this one did not
    write (an earlier run's windows must not mix with this one's); other files stay.

    Parameters
    ----------
    out : Path
        The output folder (it exists).
    written : set of str
        The names of the window folders this run wrote (``"0000"`` ...).

    Returns
    -------
    None

    Examples
    --------
    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp())
    >>> for name in ("0000", "0003"):
    ...     (out / name).mkdir()
    ...     _ = (out / name / "info.json").write_text("{}")
    >>> remove_other_windows(out, {"0000"})
    >>> sorted(p.name for p in out.iterdir())
    ['0000']
    >>> shutil.rmtree(out)
    """
    for old in out.iterdir():
        if (old.is_dir() and re.fullmatch(r"\d{4,}", old.name) and old.name not in written
                and (old / "info.json").is_file()):
            shutil.rmtree(old, ignore_errors=True)


def _write_window(folder: Path, result: tuple[np.ndarray, np.ndarray], spec: MultiFreqSpec,
                  win: Window, start: int, threshold: float, noise: float) -> None:
    """One window's maps and ``info.json``."""
    phi, mod = result
    valid = mod >= threshold
    folder.mkdir()
    np.save(folder / "wrapped.npy", np.where(valid, phi, np.float32(np.nan)))
    np.save(folder / "modulation.npy", mod.astype(np.float32))
    period = float(spec.periods[0])
    absolute = not spec.single_period
    if absolute:  # one period covering the axis: the wrapped phase is the absolute one
        phase = top_phase(phi.astype(np.float64), period, spec.coded_length)
        np.save(folder / "phase.npy", np.where(valid, phase, np.nan))
    info: dict[str, Any] = {
        "method": spec.method, "start": start, "frames": [start, start + win.frames - 1],
        "window": shown_window(win), "steps": spec.steps, "order": win.order, "lag": win.lag,
        "time": start + win.lag, "period": period, "absolute_phase": absolute,
        "threshold": float(threshold), "noise": float(noise),
        "valid": int(valid.sum()), "pixels": int(valid.size)}
    write_json(folder / "info.json", info)


def frame_count(files: Sequence[Path]) -> int:
    """Frames in the captures: one a file, or the frames of one ``.npy`` stack.

    Parameters
    ----------
    files : sequence of Path
        The captures' files (:func:`~bistair.io.read.capture_files`).

    Returns
    -------
    int

    Examples
    --------
    >>> frame_count([Path("a.png"), Path("b.png")])
    2
    """
    if len(files) == 1 and files[0].suffix.lower() == ".npy":
        try:
            shape = np.load(files[0], mmap_mode="r").shape
        except (OSError, ValueError) as exc:
            raise BistairError(f"cannot read {files[0]}: {exc}") from None
        return int(shape[0]) if len(shape) == 3 else 1
    return len(files)


def shown_window(win: Window) -> str:
    """``--window`` as given: ``"N"`` or ``"N+K"``.

    Parameters
    ----------
    win : Window
        The window.

    Returns
    -------
    str

    Examples
    --------
    >>> shown_window(Window(4, 2)), shown_window(Window(4, 0))
    ('4+2', '4')
    """
    return f"{win.steps}+{win.order}" if win.order else str(win.steps)
