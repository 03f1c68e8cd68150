"""The scenes whose decodes are pinned on their quality against the truth
(tests/data/pre_speed.json, tests/test_speed.py), and the code that records them:
``python tests/support/pre_speed.py``.

History: the fringe orders of these decodes were first recorded bit for bit before the
decoders were made fast, and recorded again when the robustness work settled the decoder
(only mugs-on-wall changed: its wrong orders against the truth 1,227 -> 901 at the same
coverage) and when the region orders had to be borne out by their surroundings (issue 21:
mugs-on-wall 901 -> 817 wrong orders, 3,171 fewer pixels decoded). Issue 32 rebuilt the
phase stage's arithmetic (a float32 arctangent: phases moved by ulps) and re-pinned them
once on quality against the truth: the wrong orders, the decoded pixels with a truth, and
the median and RMS phase error of the right ones, all as at 02b6580 (whose orders the
rebuilt stage still gave, every pixel of every scene). A decode that refuses its captures
is recorded as refused. Issue 31 read the stair levels where a projector response the
patterns do not compensate puts them (both hard scenes leave a gamma of 2.2 uncompensated):
recorded again (before the float32 front end: paper-sim 228 more pixels decoded, none wrong;
mugs-on-wall 3,432 more decoded, 68 fewer and 79 another order, its pixels more than half a
period off the truth 319 -> 422 of 310,112 decoded)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # conftest

import bistair  # noqa: E402
from bistair.sim import Imaging, expose, preset, trace  # noqa: E402
from bistair.sim.warp import render_warp  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "pre_speed.json"
HARD = dict(gamma=2.2, read_noise=0.03, camera_blur=1.2, projector_blur=1.0, ambient=0.15)
CODECS = {
    "bidirectional": ("bidirectional", dict(period=30), {}),
    "paper": ("bidirectional", dict(period=30), {"strategy": "paper"}),
    "lv": ("lv", dict(period=30), {}),
    "phase-coding": ("phase-coding", dict(period=30), {}),
    "phase-coding-pixel": ("phase-coding", dict(period=30, form="shifted"),
                           {"strategy": "pixel"}),
    "graycode": ("graycode", dict(period=30, complementary=1), {}),
    "graycode-region": ("graycode", dict(period=30), {"strategy": "region"}),
    "multifreq": ("multifreq", dict(periods=(1080, 180, 30)), {}),
    "heterodyne": ("multifreq", dict(periods=(42, 45, 48), steps=12), {}),
}


def cases():
    """(name, images, spec, options, truth coordinate, truth mask) of every pinned decode."""
    from conftest import warped_scene

    for seed, noise, blur in ((0, 0.01, 1.0), (1, 0.02, 1.5)):
        scene = warped_scene(seed, noise, blur)
        for label, (method, params, options) in CODECS.items():
            spec = bistair.make_spec(method, width=1080, height=1080, **params)
            images, truth = render_warp(spec, scene)
            yield f"warp{seed}-{label}", images, spec, options, truth.coord(spec), truth.mask
    for scene_name, optics, params in (
            ("paper-sim", HARD, dict(width=1080, height=1080)),
            ("mugs-on-wall", {}, dict(width=1920, height=1080, partitions=8, stairs=8))):
        rig, scene = preset(scene_name, camera_size=(640, 512))
        imaging = Imaging(**optics, seed=3)
        traced = trace(rig, scene, imaging)
        spec = bistair.make_spec("bidirectional", period=30, **params)
        yield (f"{scene_name}-bidirectional", expose(traced, bistair.encode(spec), imaging),
               spec, {}, traced.truth.coord_x, traced.truth.mask)


def quality(result, coord: np.ndarray, mask: np.ndarray) -> dict:
    """A decode against the truth: the pixels with a truth (``truth``), those decoded
    (``decoded``), those more than half a period off (``wrong``), and the median and RMS
    error of the others' absolute phase (radians)."""
    both = result.mask & mask
    err = (result.coord - coord)[both].astype(np.float64)
    wrong = np.abs(err) > result.period / 2
    right = (2 * np.pi / result.period) * err[~wrong]
    return {"truth": int(mask.sum()), "decoded": int(both.sum()), "wrong": int(wrong.sum()),
            "median_rad": float(np.median(right)), "rms_rad": float(np.sqrt(np.mean(right ** 2)))}


def record() -> None:
    table = {}
    for name, images, spec, options, coord, mask in cases():
        try:
            table[name] = quality(bistair.decode(images, spec, **options), coord, mask)
        except bistair.BistairError as exc:
            table[name] = {"refused": str(exc)}
        print(name, table[name])
    DATA.parent.mkdir(exist_ok=True)
    DATA.write_text(json.dumps(table, indent=1) + "\n")
    print(f"recorded {len(table)} decodes in {DATA}")


if __name__ == "__main__":
    record()
