"""``bistair simulate``: capture folders from the virtual rig, decodable like real ones.

For a preset scene and one method (or all) it writes::

    OUT/<method>/00.png ...   the captures (8 bit; 16-bit PNG for deeper cameras)
    OUT/<method>/spec.json    the pattern set, so ``bistair decode OUT/<method>`` works
    OUT/truth/                coord.npy (projector coordinate along the specs' coded axis),
                              order.npy (its fringe order, -1 outside the mask), coord_x.npy,
                              coord_y.npy, depth.npy, object_id.npy, mask.npy
    OUT/calibration.json      the rig's exact calibration (for ``bistair reconstruct``)
    OUT/scene.json            the scene, rig (intrinsics, distortion, pose) and imaging

The scene ``calibration`` writes a checkerboard in eight poses instead, in the layout
``bistair calibrate`` reads (``board.json``, ``pose-NN/columns``, ``pose-NN/rows``): into
OUT for one method, into ``OUT/<method>/`` for each of several.

:func:`simulate_many` (``bistair simulate --count N``) writes a data set of N scenes in
that layout, ``DATA/scene-0000/`` ..., in parallel on Dask (see
:mod:`~bistair.app.engine`), each scene's parameters drawn from its own seed
(:mod:`bistair.sim.variation`), and ``DATA/index.csv``, which is also a manifest for
``bistair batch``.

:func:`simulate_stereo` (``bistair simulate --cameras 2``) renders a scene on the
two-camera rig instead; moving scenes (``--motion``) are :mod:`bistair.app.simulate_motion`.

Examples
--------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = simulate("plane", ["graycode"], pathlib.Path(tmp) / "sim",
...                    camera_size=(64, 48))
...     sorted(p.name for p in out.iterdir()), len(list((out / "graycode").glob("*.png")))
(['calibration.json', 'graycode', 'scene.json', 'truth'], 11)
"""

from __future__ import annotations

import csv
import dataclasses
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from ..codecs import encode
from ..codecs import methods as known_methods
from ..core.captures import to_bit_depth
from ..errors import BistairError
from ..evaluation.benchmark import method_specs
from ..geometry.board import Board
from ..geometry.calibration import Calibration, StereoCalibration, save_calibration
from ..io.atomic import output_file, output_folder, replace_folder, write_image
from ..io.jsonfile import write_json
from ..sim import Imaging, Rig, Scene, Truth, expose, preset, scene_names, trace
from ..sim.boards import write_board_sets
from ..sim.rig import check_size
from ..sim.stereo import StereoRig, write_board_pairs
from ..sim.variation import build, check_vary, draw, streams
from ..spec import BaseSpec
from .engine import (
    BATCH_PREFIX,
    check_workers,
    dask_client,
    remove_run_temporaries,
    run_prefix,
    run_tasks,
)
from .progress import Say, silent


def simulate(scene: str, methods: Iterable[str], out: str | Path,
             camera_size: tuple[int, int] | None = None, compensated: bool = True,
             progress: Callable[[str], None] | None = None, white: bool = True,
             both_axes: bool = False, spec: BaseSpec | None = None, **imaging: Any) -> Path:
    """Render ``scene`` for each of ``methods`` and write the capture folders into ``out``.

    With ``spec`` the set that spec describes is rendered (``methods`` empty or its method
    alone; the projector takes the spec's size, its patterns the spec's own gamma, whatever
    ``compensated`` says) instead of each method's comparable set.

    ``imaging`` goes to :class:`bistair.sim.Imaging` (``gamma``, ``read_noise``,
    ``camera_blur``, ``bits``, ``seed``, ...); with ``compensated`` the patterns pre-compensate
    the projector's gamma. ``progress`` is called with each stage's name as it starts.
    For the scene ``calibration``, ``white`` false leaves the white frame out (the board is
    then found in the mean image) and ``both_axes`` writes one capture set of both axes per
    pose instead of ``columns/`` and ``rows/``; several methods write ``out/<method>/`` each,
    and ``progress`` is called as each pose starts.

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
    if spec is not None:
        methods = _spec_methods(methods, spec)
    methods = check_methods(methods)
    im = make_imaging(compensated, imaging)
    if spec is not None and scene == "calibration":
        raise BistairError("--spec renders a preset scene; board captures (scene "
                           "calibration) take each method's comparable set")
    if scene == "calibration":
        return _calibration(methods, out, camera_size, compensated, im, white, both_axes,
                            progress)
    if not white or both_axes:
        raise BistairError("board captures without a white frame or of both axes at once "
                           "are for --scene calibration")
    sizes = {} if camera_size is None else {"camera_size": camera_size}
    if spec is not None:
        sizes["projector_size"] = (spec.width, spec.height)
    rig, geometry = preset(scene, **sizes)
    say = progress or (lambda stage: None)
    with output_folder(out) as tmp:
        write_scene(tmp, rig, geometry, im, methods, compensated,
                    {"scene": scene, "methods": methods, "compensated": compensated},
                    progress=say, spec=spec)
    return Path(out)


def _spec_methods(methods: Iterable[str], spec: BaseSpec) -> list[str]:
    """The methods to render with ``spec``: none named, or the spec's alone."""
    other = sorted(set(methods) - {spec.method})
    if other:
        raise BistairError(f"--spec describes a {spec.method} set: --method "
                           f"{', '.join(other)} does not match it (leave --method out, or "
                           f"name {spec.method})")
    return [spec.method]


def write_scene(folder: Path, rig: Rig, geometry: Scene, imaging: Imaging,
                methods: Sequence[str], compensated: bool, about: dict[str, Any],
                threads: int | None = None,
                progress: Callable[[str], None] | None = None,
                spec: BaseSpec | None = None) -> None:
    """Render ``geometry`` for each method into the existing ``folder``: the capture
    folders, ``truth/``, ``calibration.json`` and ``scene.json`` (``about``, the imaging and
    the rig). ``threads`` for ray casting and exposure (default: the cores; the images do
    not depend on it). ``progress`` is called with each stage's name as it starts. With
    ``spec``, its set is rendered (into ``folder/<its method>``) instead of the methods'
    comparable sets."""
    say = progress or (lambda stage: None)
    if spec is not None:
        specs = {spec.method: (spec, {})}
    else:
        specs = method_specs(rig.projector.size, gamma=imaging.gamma if compensated else 1.0,
                             methods=methods)
    say(f"tracing the scene ({rig.camera.size[0]}x{rig.camera.size[1]})")
    traced = trace(rig, geometry, imaging, workers=threads)
    for method, (spec, _) in specs.items():
        say(f"rendering and writing {method}")
        sub = folder / method
        sub.mkdir()
        images = expose(traced, encode(spec), imaging, workers=threads)
        if images.dtype.kind == "f":
            images = to_bit_depth(images, 16)
        for i, img in enumerate(images):
            write_image(sub / f"{i:02d}.png", img)
        (sub / "spec.json").write_text(spec.to_json())
    codes = {(spec.orientation, spec.period) for spec, _ in specs.values()}
    if len(codes) != 1:  # every comparable set codes the columns with one period
        raise BistairError(f"the methods code {len(codes)} different axes or periods")
    write_truth(folder / "truth", traced.truth, next(iter(specs.values()))[0])
    save_calibration(Calibration.from_rig(rig), folder / "calibration.json")
    write_json(folder / "scene.json", {**about, "imaging": dataclasses.asdict(imaging),
                                       "rig": rig_dict(rig)})


def write_truth(folder: Path, truth: Truth, spec: BaseSpec) -> None:
    """Write the ground truth into the new folder ``folder``: ``coord.npy`` (the projector
    coordinate along the spec's coded axis), ``order.npy`` (int32 ``floor(coord/period)``,
    -1 outside the mask), ``coord_x.npy``, ``coord_y.npy``, ``depth.npy`` (mm, camera
    frame), ``object_id.npy`` and ``mask.npy``; a spec of both axes writes the columns'
    ``coord`` and ``order``."""
    folder.mkdir()
    if spec.orientation == "both":
        spec = spec.replace(orientation="columns", frame_order=())
    coord = truth.coord(spec)
    order = np.full(coord.shape, -1, np.int32)
    ok = truth.mask & np.isfinite(coord)
    order[ok] = np.floor(coord[ok] / spec.period).astype(np.int32)
    arrays = {"coord": coord, "order": order, "coord_x": truth.coord_x,
              "coord_y": truth.coord_y, "depth": truth.depth, "object_id": truth.object_id,
              "mask": truth.mask}
    for name, arr in arrays.items():
        np.save(folder / f"{name}.npy", arr)


def rig_dict(rig: Any) -> dict[str, Any]:
    """A camera-projector rig as ``scene.json`` records it: each device's size,
    intrinsics, distortion and pose.

    Parameters
    ----------
    rig : Rig
        The rig (:class:`~bistair.sim.Rig`).

    Returns
    -------
    dict
        ``{"camera": {...}, "projector": {...}}``.

    Examples
    --------
    >>> from bistair.sim import preset
    >>> sorted(rig_dict(preset("plane", camera_size=(64, 48))[0])["camera"])
    ['K', 'R', 'dist', 'height', 't', 'width']
    """
    def device(d: Any) -> dict[str, Any]:
        return {"width": d.width, "height": d.height, "K": np.asarray(d.K).tolist(),
                "dist": np.asarray(d.dist_coeffs).ravel().tolist(),
                "R": np.asarray(d.R).tolist(), "t": np.asarray(d.t).ravel().tolist()}

    return {"camera": device(rig.camera), "projector": device(rig.projector)}


def _calibration(methods: list[str], out: str | Path, camera_size: tuple[int, int] | None,
                 compensated: bool, imaging: Any, white: bool = True,
                 both_axes: bool = False,
                 progress: Callable[[str], None] | None = None) -> Path:
    """A 9 x 6 checkerboard (20 mm) in eight poses, both orientations (``columns/`` and
    ``rows/``, or with ``both_axes`` one capture set of both axes per pose), with a white
    frame unless ``white`` is false, in the layout ``bistair calibrate`` reads: in ``out``
    for one method, in ``out/<method>/`` for each of several (each pose cast once)."""
    rig = Rig.default(**({} if camera_size is None else {"camera_size": camera_size}))
    bases = method_specs(rig.projector.size, gamma=imaging.gamma if compensated else 1.0,
                         methods=methods)
    axes = ("both",) if both_axes else ("columns", "rows")
    sets = {"" if len(methods) == 1 else method: {
        o: bases[method][0].replace(orientation=o, white=int(white)) for o in axes}
        for method in methods}
    return write_board_sets(rig, Board("checkerboard", 9, 6, 20.0), sets, out,
                            imaging=imaging, progress=progress)


def check_methods(methods: Iterable[str]) -> list[str]:
    """The methods to render, refused if none or one the registry does not know.

    Parameters
    ----------
    methods : iterable of str
        Method names (``all`` already expanded).

    Returns
    -------
    list of str
        The methods, in the order given.

    Raises
    ------
    BistairError
        If there is none, or an unknown one.

    Examples
    --------
    >>> check_methods(["graycode"])
    ['graycode']
    """
    methods = list(methods)
    if not methods:
        raise BistairError("name a method to render (or all)")
    unknown = set(methods) - set(known_methods())
    if unknown:
        raise BistairError(f"unknown method(s) {', '.join(sorted(unknown))} "
                           f"(known: {', '.join(known_methods())}, all)")
    return methods


def make_imaging(compensated: bool, imaging: dict[str, Any]) -> Imaging:
    """The camera's imaging (:class:`~bistair.sim.Imaging`) from its keyword parameters,
    refused with a one-line error for a parameter it does not have or, with patterns that
    pre-compensate it (``compensated``), a gamma outside [0.2, 5].

    Parameters
    ----------
    compensated : bool
        The patterns pre-compensate the projector's gamma.
    imaging : dict
        Keyword parameters of :class:`~bistair.sim.Imaging`.

    Returns
    -------
    Imaging
        The imaging.

    Raises
    ------
    BistairError
        On a parameter Imaging does not have, or a gamma that cannot be compensated.

    Examples
    --------
    >>> make_imaging(True, {"gamma": 2.2}).gamma
    2.2
    """
    try:
        im = Imaging(**imaging)
    except TypeError as exc:  # a parameter Imaging does not have
        raise BistairError(f"bad imaging parameters: {exc}") from None
    if compensated and not 0.2 <= im.gamma <= 5.0:
        raise BistairError(f"patterns cannot pre-compensate a projector gamma of {im.gamma:g} "
                           "(a spec's gamma lies in [0.2, 5]); simulate it uncompensated")
    return im


# -- two cameras ------------------------------------------------------------------------------
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
    say = progress or silent
    if not 10 <= baseline <= 2000:
        raise BistairError(f"--baseline must be 10 to 2000 mm, got {baseline:g}")
    if scene not in (*scene_names(), "calibration"):
        raise BistairError(f"unknown scene {scene!r} (known: {', '.join(scene_names())}, "
                           "calibration)")
    im = make_imaging(compensated, imaging)
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


# -- data sets: many scenes on Dask -----------------------------------------------------------
INDEX_COLUMNS = ("captures", "spec", "calibration", "out", "scene", "method", "content",
                 "read_noise", "camera_blur", "gamma", "ambient", "noise_seed")


@dataclass
class DataSetReport:
    """What :func:`simulate_many` wrote: one index row per capture set, the failed scenes
    (``(name, message)``), the time and the workers."""

    rows: list[dict[str, Any]]
    failed: list[tuple[str, str]]
    seconds: float
    workers: int
    out: Path


def scene_parameters(count: int, seed: int, vary: Iterable[str] = (), scene: str | None = None,
                     camera_size: tuple[int, int] | None = None,
                     imaging: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """The parameters of the scenes ``0 .. count-1`` of a data set: scene ``i`` draws from
    the ``i``-th child of ``numpy.random.SeedSequence(seed)`` (``spawn``), so it is the same
    whatever the count and the number of workers (see :mod:`bistair.sim.variation`).

    Examples
    --------
    >>> a = scene_parameters(3, seed=5, vary=["optics"], scene="plane")
    >>> b = scene_parameters(5, seed=5, vary=["optics"], scene="plane")
    >>> a == b[:3], a[0]["imaging"]["read_noise"] != a[1]["imaging"]["read_noise"]
    (True, True)
    """
    vary = check_vary(vary)
    out = []
    for i, child in enumerate(np.random.SeedSequence(seed).spawn(count)):
        params = draw(streams(child), vary, base=scene, camera_size=camera_size,
                      imaging=imaging)
        out.append({"index": i, "seed": seed, "spawn_key": list(child.spawn_key),
                    "vary": list(vary), **params})
    return out


def simulate_scene(params: dict[str, Any], methods: Sequence[str], compensated: bool,
                   out: str, prefix: str = BATCH_PREFIX, threads: int | None = 1
                   ) -> dict[str, Any]:
    """Render one scene of a data set into the folder ``out`` (replaced as a whole); runs on
    a worker. Returns ``{"name", "error", "seconds"}`` (error empty on success)."""
    start = time.perf_counter()
    name = Path(out).name
    try:
        rig, geometry, imaging = build(params)
        content = params.get("preset") or "objects"
        with replace_folder(out, prefix) as tmp:
            write_scene(tmp, rig, geometry, imaging, methods, compensated,
                        {"scene": content, "methods": list(methods), "compensated": compensated,
                         "parameters": params}, threads=threads)
        return {"name": name, "error": "", "seconds": round(time.perf_counter() - start, 3)}
    except BistairError as exc:
        return {"name": name, "error": str(exc), "seconds": None}
    except Exception as exc:  # a bug must not stop the data set
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        return {"name": name, "error": f"{type(exc).__name__}: {first}".rstrip(": "),
                "seconds": None}


def simulate_many(count: int, methods: Iterable[str], out: str | Path, seed: int = 0,
                  scene: str | None = None, vary: Iterable[str] = (),
                  camera_size: tuple[int, int] | None = None, compensated: bool = True,
                  workers: int | None = None, scheduler: str | None = None,
                  show_progress: bool = False, **imaging: Any) -> DataSetReport:
    """Render ``count`` scenes into ``out/scene-NNNN/`` (each in the layout of
    :func:`simulate`, its parameters in ``scene.json``) on Dask and write
    ``out/index.csv``: one row per capture set (:data:`INDEX_COLUMNS`; the captures,
    spec, calibration and out columns make it a ``bistair batch`` manifest).

    ``scene``: the preset of every scene, unless ``vary`` holds ``objects``; ``vary``:
    ``optics``, ``objects``, ``pose`` (:mod:`bistair.sim.variation`; drawn optics replace
    the ``imaging`` values of noise, blur, gamma and ambient). ``workers`` and
    ``scheduler`` as for :func:`~bistair.app.batch.run_batch`. The files are the same for
    a given ``seed`` whatever the number of workers. ``imaging``'s ``seed`` is not used:
    each scene's noise seed is drawn from ``seed``.

    Raises
    ------
    BistairError
        Bad parameters (checked before anything is rendered) or a scheduler that cannot be
        reached. Scenes that fail while rendering are reported in ``failed``.
    """
    started = time.perf_counter()
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise BistairError(f"--count must be 1 or more, got {count!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise BistairError(f"--seed must be a whole number of 0 or more, got {seed!r}")
    check_workers(workers, scheduler)
    vary = check_vary(vary)
    methods = check_methods(methods)
    if "objects" in vary and scene is not None:
        raise BistairError("--vary objects draws the scenes: leave out --scene")
    if scene == "calibration":
        raise BistairError("--count renders scenes; board captures come from --scene "
                           "calibration without --count")
    if scene is not None and scene not in scene_names():
        raise BistairError(f"unknown scene {scene!r} (known: {', '.join(scene_names())})")
    if camera_size is not None:
        camera_size = check_size(camera_size, "camera")
    imaging.pop("seed", None)
    make_imaging(compensated, imaging)
    params = scene_parameters(count, seed, vary, scene, camera_size, imaging)
    for p in params:  # drawn optics stay in range; check before any work
        make_imaging(compensated, p["imaging"])
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    digits = max(4, len(str(count - 1)))
    names = [f"scene-{i:0{digits}d}" for i in range(count)]
    remove_run_temporaries([out])
    prefix = run_prefix()
    results: dict[int, dict[str, Any]] = {}
    bar = tqdm(total=count, desc="scenes", unit="scene", disable=not show_progress,
               dynamic_ncols=True)
    used = 0
    try:
        with dask_client(workers, scheduler, tasks=count) as client:
            used = len(client.nthreads())

            def failed(i: int, message: str) -> dict[str, Any]:
                return {"name": names[i], "error": message, "seconds": None}

            def done(i: int, result: dict[str, Any]) -> None:
                results[i] = result
                bar.update()

            absolute = out.absolute()
            run_tasks(client, simulate_scene,
                      [(p, methods, compensated, str(absolute / n), prefix)
                       for p, n in zip(params, names, strict=True)], failed, done)
    finally:
        bar.close()
        remove_run_temporaries([out], prefix)
    rows = []
    for i, (p, name) in enumerate(zip(params, names, strict=True)):
        if results[i]["error"]:
            continue
        im = p["imaging"]
        for method in methods:
            rows.append({"captures": f"{name}/{method}", "spec": "",
                         "calibration": f"{name}/calibration.json", "out": f"{name}/{method}",
                         "scene": name, "method": method,
                         "content": p.get("preset") or "objects",
                         **{k: im.get(k, getattr(Imaging, k)) for k in
                            ("read_noise", "camera_blur", "gamma", "ambient")},
                         "noise_seed": im["seed"]})
    with output_file(out / "index.csv", prefix) as tmp, tmp.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, INDEX_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    failures = [(r["name"], r["error"]) for _, r in sorted(results.items()) if r["error"]]
    return DataSetReport(rows, failures, time.perf_counter() - started, used, out)
