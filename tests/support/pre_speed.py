"""The scenes whose decoded fringe orders are recorded (tests/data/pre_speed.npz), and the
code that records them: ``python tests/support/pre_speed.py``.

The orders were first recorded before the decoders were made fast, and recorded again
when the robustness work settled the decoder (regions cut where two surfaces meet, faint
regions taking the order their neighbours demand, stacked surfaces split at the band the
edge cut short): only mugs-on-wall changed, 1,247 pixels (413 decoded that were not, 517
undecided that were, 317 another order), its wrong orders against the truth 1,227 -> 901
at the same coverage; and again when the region orders had to be borne out by their
surroundings (issue 21: faint regions whose neighbours demand two orders, or that no chain
of agreeing links ties to a region that decides itself, undecided): only mugs-on-wall
changed, 3,171 fewer pixels decoded, its wrong orders 901 -> 817; and again when the stair
levels were read where a projector response the patterns do not compensate puts them (issue
31: both scenes leave the gamma of 2.2 uncompensated): paper-sim 228 more pixels decoded,
none wrong; mugs-on-wall 3,432 more decoded, 68 fewer and 79 another order, its pixels
more than half a period off the truth 319 -> 422 (of 310,112 decoded). Any speed-up must
give the same orders (tests/test_speed.py); a decode that refuses its captures is not
recorded."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # conftest

import bistair  # noqa: E402
from bistair.sim import Imaging, expose, preset, trace  # noqa: E402
from bistair.sim.warp import render_warp  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "pre_speed.npz"
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
    """(name, images, spec, options) of every recorded decode."""
    from conftest import warped_scene

    for seed, noise, blur in ((0, 0.01, 1.0), (1, 0.02, 1.5)):
        scene = warped_scene(seed, noise, blur)
        for label, (method, params, options) in CODECS.items():
            spec = bistair.make_spec(method, width=1080, height=1080, **params)
            yield f"warp{seed}-{label}", render_warp(spec, scene)[0], spec, options
    for scene_name, optics, params in (
            ("paper-sim", HARD, dict(width=1080, height=1080)),
            ("mugs-on-wall", {}, dict(width=1920, height=1080, partitions=8, stairs=8))):
        rig, scene = preset(scene_name, camera_size=(640, 512))
        imaging = Imaging(**optics, seed=3)
        traced = trace(rig, scene, imaging)
        spec = bistair.make_spec("bidirectional", period=30, **params)
        yield f"{scene_name}-bidirectional", expose(traced, bistair.encode(spec), imaging), \
            spec, {}


def record() -> None:
    orders = {}
    for name, images, spec, options in cases():
        try:
            orders[name] = bistair.decode(images, spec, **options).order.astype(np.int16)
        except bistair.BistairError as exc:
            print(f"{name}: refused ({exc})")
    DATA.parent.mkdir(exist_ok=True)
    np.savez_compressed(DATA, **orders)
    print(f"recorded {len(orders)} decodes in {DATA} ({DATA.stat().st_size} bytes)")


if __name__ == "__main__":
    record()
