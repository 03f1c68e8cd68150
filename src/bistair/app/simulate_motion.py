"""``bistair simulate --motion`` and ``--frames N --continuous``: the virtual rig moves things.

Every frame is rendered with the scene at its own pose (:mod:`bistair.sim.motion`: frame
``k`` at time ``k``, a constant rigid velocity per frame), once per camera. It writes::

    OUT/<method>/00.png ...       each method's set, frame k at pose k (with --cameras 2:
                                  OUT/<method>/L/ and R/)
    OUT/truth/                    the truth at the reference pose, frame 0's (as bistair
                                  simulate writes it), and OUT/truth/frame-NNNN/ the truth
                                  of every frame (with --cameras 2: truth/L/, truth/R/)
    OUT/calibration.json          (and stereo.json with --cameras 2)
    OUT/scene.json                the scene, rig, imaging and the motion: "motion" (as
                                  given, in mm and degrees per frame, what moves),
                                  "reference_frame" (0) and "frames"

``--frames N --continuous`` renders a stream instead: frame ``i`` shows shift ``i mod N``
of one N-step set of one period (``--steps``, ``--period``; 4 and 30 by default;
``OUT/multifreq/0000.png`` ...) and ``spec.json`` is that single-period spec (``patterns
multifreq --periods 30 --steps 4``: ``decode`` alone refuses it, ``decode --window``
decodes it; its conventions describe the stream's first frame).

Examples
--------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = simulate_motion("sphere-on-plane", ["multifreq"], pathlib.Path(tmp) / "s",
...                           "1px", frames=6, continuous=True, camera_size=(48, 40))
...     names = sorted(p.name for p in (out / "multifreq").iterdir())
...     frames = sorted(p.name for p in (out / "truth").glob("frame-*"))
>>> names[:2], names[-1], len(frames)
(['0000.png', '0001.png'], 'spec.json', 6)
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import encode, make_spec
from ..core.captures import to_bit_depth
from ..errors import BistairError
from ..evaluation.benchmark import method_specs
from ..geometry.calibration import (
    Calibration,
    StereoCalibration,
    save_calibration,
    save_stereo_calibration,
)
from ..io.atomic import output_folder, write_image
from ..io.jsonfile import write_json
from ..sim import Imaging, Trace, expose, preset, scene_names
from ..sim.motion import parse_motion, trace_frames
from ..sim.stereo import StereoRig
from ..spec import BaseSpec
from .simulate import check_methods, make_imaging, rig_dict, write_truth

STREAM_STEPS = 4
STREAM_PERIOD = 30


def simulate_motion(scene: str, methods: Sequence[str], out: str | Path,
                    motion: str | None, moves: str = "objects", frames: int | None = None,
                    continuous: bool = False, cameras: int = 1, baseline: float = 200.0,
                    camera_size: tuple[int, int] | None = None, compensated: bool = True,
                    progress: Callable[[str], None] | None = None, steps: int = STREAM_STEPS,
                    period: float = STREAM_PERIOD, **imaging: Any) -> Path:
    """Render ``scene`` with its objects (``moves="objects"``) or the whole scene
    (``"scene"``) moving by ``motion`` (:func:`~bistair.sim.motion.parse_motion`) every
    frame, each method's set or (``continuous``) a stream of ``frames`` frames of one
    ``steps``-step set of ``period`` (projector pixels); see the module docstring for the
    layout.

    Raises
    ------
    BistairError
        A malformed motion, a stream without ``frames`` (or ``frames`` without
        ``continuous``), a stream of a method other than multifreq or of fewer frames than
        one set, steps or a period a stream's spec refuses, an unknown scene or method;
        nothing is written then.
    """
    say = progress or (lambda stage: None)
    if moves not in ("objects", "scene"):
        raise BistairError(f"--motion-of must be objects or scene, got {moves!r}")
    if scene not in scene_names():
        raise BistairError(f"unknown scene {scene!r} for a moving render (known: "
                           f"{', '.join(scene_names())})")
    methods = check_methods(methods)
    if continuous != (frames is not None):
        raise BistairError("a stream needs both --frames N and --continuous")
    if continuous and methods != ["multifreq"]:
        raise BistairError("--continuous renders a single-period N-step stream: give "
                           "--method multifreq alone")
    if (steps, period) != (STREAM_STEPS, STREAM_PERIOD) and not continuous:
        raise BistairError("--steps and --period apply to a stream: give --frames N "
                           "--continuous too")
    if continuous and (isinstance(frames, bool) or not isinstance(frames, int)
                       or frames < steps):
        raise BistairError(f"--frames must be at least {steps} (one set), got {frames!r}")
    if motion is None and not continuous:
        raise BistairError("give --motion (or --frames N --continuous for a stream)")
    if cameras not in (1, 2):
        raise BistairError(f"--cameras must be 1 or 2, got {cameras!r}")
    if cameras == 2 and not 10 <= baseline <= 2000:
        raise BistairError(f"--baseline must be 10 to 2000 mm, got {baseline:g}")
    im = make_imaging(compensated, imaging)
    gamma = im.gamma if compensated else 1.0
    rig, geometry = preset(scene, **({} if camera_size is None else
                                     {"camera_size": camera_size}))
    if continuous:
        spec, patterns = stream_patterns(rig.projector.size, gamma, steps, period)
        specs = {"multifreq": spec}
        sets = {"multifreq": patterns[np.arange(frames) % steps]}
    else:
        chosen = method_specs(rig.projector.size, gamma=gamma, methods=methods)
        specs = {m: s for m, (s, _) in chosen.items()}
        sets = {m: encode(s) for m, s in specs.items()}
    first = next(iter(specs.values()))
    moving = parse_motion("0,0,0mm" if motion is None else motion, _coded(first).orientation,
                          whole=moves == "scene")
    if cameras == 2:
        srig = StereoRig.default(camera_size=rig.camera.size, projector_size=rig.projector.size,
                                 baseline=baseline)
        sides = {"L": srig.rig("left"), "R": srig.rig("right")}
    else:
        sides = {"": rig}
    mm = moving.at_depth(sides["L" if cameras == 2 else ""], geometry)
    count = max(len(p) for p in sets.values())
    with output_folder(out) as tmp:
        for i, (side, side_rig) in enumerate(sides.items()):
            cam = dataclasses.replace(im, seed=im.seed + i)
            say(f"tracing {count} poses{f' ({side})' if side else ''}")
            traces = trace_frames(side_rig, geometry, mm, range(count), cam)
            for method, patterns in sets.items():
                say(f"rendering and writing {method}{f' ({side})' if side else ''}")
                folder = tmp / method / side
                folder.mkdir(parents=True)
                digits = 4 if continuous else 2
                for k, img in enumerate(_expose_each(traces, patterns, cam)):
                    write_image(folder / f"{k:0{digits}d}.png", img)
                _write_spec(folder / "spec.json", specs[method], continuous)
            _write_truths(tmp / "truth" / side, traces, first)
        if cameras == 2:
            save_stereo_calibration(StereoCalibration.from_rig(srig), tmp / "stereo.json")
        save_calibration(Calibration.from_rig(sides["L" if cameras == 2 else ""]),
                         tmp / "calibration.json")
        write_json(tmp / "scene.json", {
            "scene": scene, "methods": list(specs), "compensated": compensated,
            "cameras": cameras, **({"baseline": baseline} if cameras == 2 else {}),
            "imaging": dataclasses.asdict(im),
            "motion": {**mm.to_dict(), **({"pixels": list(moving.pixels)}
                                          if moving.pixels is not None else {})},
            "reference_frame": 0, "frames": count, "continuous": continuous,
            "rig": ({"left": rig_dict(sides["L"])["camera"],
                     "right": rig_dict(sides["R"])["camera"],
                     "projector": rig_dict(sides["L"])["projector"]}
                    if cameras == 2 else rig_dict(rig))})
    return Path(out)


def stream_patterns(projector: tuple[int, int], gamma: float = 1.0, steps: int = STREAM_STEPS,
                    period: float = STREAM_PERIOD) -> tuple[dict[str, Any], np.ndarray]:
    """The stream's single-period spec (as a ``spec.json`` dictionary: ``multifreq``,
    ``periods`` [period], ``steps``) and its patterns (pre-compensating ``gamma``).

    Examples
    --------
    >>> spec, patterns = stream_patterns((64, 48))
    >>> spec["periods"], spec["steps"], patterns.shape
    ([30], 4, (4, 48, 64))
    >>> stream_patterns((64, 48), steps=3, period=12.5)[1].shape
    (3, 48, 64)
    """
    width, height = projector
    try:
        spec = make_spec("multifreq", width=width, height=height, gamma=gamma, steps=steps,
                         periods=(period,))
    except (TypeError, ValueError) as exc:
        raise BistairError(f"a stream of --steps {steps!r} and --period {period!r}: "
                           f"{exc}") from None
    if not spec.single_period:
        raise BistairError(f"--period {period:g} covers the {spec.coded_length}-px projector: "
                           "a stream's period is narrower (its fringe order comes from "
                           "elsewhere)")
    data = spec.to_dict()
    data.pop("frames", None)
    return data, encode(spec)


def _expose_each(traces: list[Trace], patterns: np.ndarray, imaging: Imaging) -> list:
    """Frame ``k`` of ``patterns`` exposed on trace ``k`` (with frame ``k``'s noise)."""
    out = []
    for k, pattern in enumerate(patterns):
        img = expose(traces[k], pattern[None], imaging, first_frame=k)[0]
        out.append(to_bit_depth(img, 16) if img.dtype.kind == "f" else img)
    return out


def _write_spec(path: Path, spec: BaseSpec | dict[str, Any], continuous: bool) -> None:
    if continuous:
        path.write_text(json.dumps(spec, indent=2) + "\n")
    else:
        path.write_text(spec.to_json())


def _write_truths(folder: Path, traces: list[Trace], spec: BaseSpec | dict[str, Any]) -> None:
    """``folder`` (frame 0's truth, the reference pose) and ``folder/frame-NNNN/``."""
    coded = _coded(spec)
    folder.parent.mkdir(exist_ok=True)
    write_truth(folder, traces[0].truth, coded)
    for k, tr in enumerate(traces):
        write_truth(folder / f"frame-{k:04d}", tr.truth, coded)


@dataclasses.dataclass(frozen=True)
class _Coded:
    """What :func:`~bistair.app.simulate.write_truth` reads of a spec."""

    orientation: str
    period: float


def _coded(spec: BaseSpec | dict[str, Any]) -> _Coded:
    """The coded axis and period of a spec or of the stream's spec dictionary."""
    if isinstance(spec, dict):
        return _Coded(spec["orientation"], float(min(spec["periods"])))
    return _Coded(spec.orientation, float(spec.period))
