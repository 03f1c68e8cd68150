"""``bistair simulate``: capture folders from the virtual rig, decodable like real ones.

For a preset scene and one method (or all) it writes::

    OUT/<method>/00.png ...   the captures (8 bit; 16-bit PNG for deeper cameras)
    OUT/<method>/spec.json    the pattern set, so ``bistair decode OUT/<method>`` works
    OUT/truth/                coord_x.npy, coord_y.npy, depth.npy, object_id.npy, mask.npy
    OUT/scene.json            the scene, rig (intrinsics, distortion, pose) and imaging

The scene ``calibration`` writes a checkerboard in eight poses instead, in the layout
``bistair calibrate`` reads (``board.json``, ``pose-NN/columns``, ``pose-NN/rows``).

Examples
--------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = simulate("plane", ["graycode"], pathlib.Path(tmp) / "sim",
...                    camera_size=(64, 48))
...     sorted(p.name for p in out.iterdir()), len(list((out / "graycode").glob("*.png")))
(['graycode', 'scene.json', 'truth'], 11)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

from ..codecs import encode
from ..codecs import methods as known_methods
from ..core.captures import to_bit_depth
from ..errors import BistairError
from ..evaluation.benchmark import method_specs
from ..geometry.board import Board
from ..io.files import output_folder, write_image
from ..io.jsonfile import write_json
from ..sim import Imaging, Rig, expose, preset, scene_names, trace
from ..sim.boards import write_board_captures


def simulate(scene: str, methods: Iterable[str], out: str | Path,
             camera_size: tuple[int, int] | None = None, compensated: bool = True,
             progress: Callable[[str], None] | None = None, **imaging: Any) -> Path:
    """Render ``scene`` for each of ``methods`` and write the capture folders into ``out``.

    ``imaging`` goes to :class:`bistair.sim.Imaging` (``gamma``, ``read_noise``,
    ``camera_blur``, ``bits``, ``seed``, ...); with ``compensated`` the patterns pre-compensate
    the projector's gamma. ``progress`` is called with each stage's name as it starts.

    Raises
    ------
    BistairError
        An unknown scene or method, imaging parameters :class:`~bistair.sim.Imaging` refuses,
        a camera size outside 8 to 8192 pixels per side
        (:func:`~bistair.sim.rig.check_size`) or a gamma the patterns cannot pre-compensate;
        nothing is written then.
    """
    if scene not in (*scene_names(), "calibration"):
        raise BistairError(f"unknown scene {scene!r} (known: {', '.join(scene_names())}, "
                           "calibration)")
    methods = list(methods)
    unknown = set(methods) - set(known_methods())
    if unknown:
        raise BistairError(f"unknown method(s) {', '.join(sorted(unknown))} "
                           f"(known: {', '.join(known_methods())}, all)")
    try:
        im = Imaging(**imaging)
    except TypeError as exc:  # a parameter Imaging does not have
        raise BistairError(f"bad imaging parameters: {exc}") from None
    if compensated and not 0.2 <= im.gamma <= 5.0:
        raise BistairError(f"patterns cannot pre-compensate a projector gamma of {im.gamma:g} "
                           "(a spec's gamma lies in [0.2, 5]); simulate it uncompensated")
    if scene == "calibration":
        return _calibration(methods, out, camera_size, compensated, im)
    rig, geometry = preset(scene, **({} if camera_size is None else {"camera_size": camera_size}))
    specs = method_specs(rig.projector.size, gamma=im.gamma if compensated else 1.0,
                         methods=methods)
    say = progress or (lambda stage: None)
    say(f"tracing {scene} ({rig.camera.size[0]}x{rig.camera.size[1]})")
    traced = trace(rig, geometry, im)
    with output_folder(out) as tmp:
        for method, (spec, _) in specs.items():
            say(f"rendering and writing {method}")
            folder = tmp / method
            folder.mkdir()
            images = expose(traced, encode(spec), im)
            if images.dtype.kind == "f":
                images = to_bit_depth(images, 16)
            for i, img in enumerate(images):
                write_image(folder / f"{i:02d}.png", img)
            (folder / "spec.json").write_text(spec.to_json())
        truth_dir = tmp / "truth"
        truth_dir.mkdir()
        t = traced.truth
        for name in ("coord_x", "coord_y", "depth", "object_id", "mask"):
            np.save(truth_dir / f"{name}.npy", getattr(t, name))
        write_json(tmp / "scene.json",
                   {"scene": scene, "methods": methods, "compensated": compensated,
                    "imaging": dataclasses.asdict(im), "rig": _rig_dict(rig)})
    return Path(out)


def _rig_dict(rig: Any) -> dict[str, Any]:
    def device(d: Any) -> dict[str, Any]:
        return {"width": d.width, "height": d.height, "K": np.asarray(d.K).tolist(),
                "dist": np.asarray(d.dist_coeffs).ravel().tolist(),
                "R": np.asarray(d.R).tolist(), "t": np.asarray(d.t).ravel().tolist()}

    return {"camera": device(rig.camera), "projector": device(rig.projector)}


def _calibration(methods: list[str], out: str | Path, camera_size: tuple[int, int] | None,
                 compensated: bool, imaging: Any) -> Path:
    """A 9 x 6 checkerboard (20 mm) in eight poses, both orientations with a white frame, in
    the layout ``bistair calibrate`` reads (one method: the first named)."""
    rig = Rig.default(**({} if camera_size is None else {"camera_size": camera_size}))
    base = method_specs(rig.projector.size, gamma=imaging.gamma if compensated else 1.0,
                        methods=methods[:1])[methods[0]][0]
    specs = {o: base.replace(orientation=o, white=1) for o in ("columns", "rows")}
    return write_board_captures(rig, Board("checkerboard", 9, 6, 20.0), specs, out,
                                imaging=imaging)
