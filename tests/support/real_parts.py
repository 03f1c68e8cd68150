"""Every real capture in ../shared/data, whole and in the parts a spec can decode alone
(each axis, each code alone), with the decoder strategies that apply: the set on which
the thresholded checks are calibrated (tests/test_no_false_refusals.py,
benchmarks/check_margins.py).

A part is ``(name, captures folder, spec, decode options)``; every part's spec describes
the folder's files as they are (frames of other parts are ``ignore``).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import bistair
from bistair.spec import BaseSpec

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data"
EXAMPLES = ROOT / "examples"


def _axes(name: str, folder: Path, spec: BaseSpec, options: dict) -> Iterator[tuple]:
    """The part on both axes as one spec, then each axis alone."""
    if spec.orientation != "both":
        yield name, folder, spec, options
        return
    for axis, sub in spec.axes():
        yield f"{name} ({axis})", folder, sub, options


def parts() -> Iterator[tuple[str, Path, BaseSpec, dict]]:
    """The real captures present under ../shared/data, part by part."""
    cfpe = SHARED / "cfpe"
    for scene in ("plate", "david"):
        if (cfpe / scene).is_dir():
            spec = bistair.make_spec("multifreq", width=1920, height=1080, periods=(42, 45, 48),
                                     steps=12, unwrap="heterodyne", white=1,
                                     offset=128 / 255, amplitude=96 / 255)
            yield f"cfpe/{scene}", cfpe / scene, spec, {}
    kamino = SHARED / "kamino-object1"
    if kamino.is_dir():
        full = json.loads((EXAMPLES / "kamino-object1.json").read_text())
        gray = bistair.load_spec(EXAMPLES / "kamino-object1-graycode.json")
        # the 3-step set at T = 100 px with the Gray code, its second period ignored
        plain = bistair.spec_from_dict({**full, "second_period": 0, "frames": [
            "ignore" if "second" in f else f for f in full["frames"]]})
        for strategy in ("pixel", "region"):
            yield from _axes(f"kamino/full {strategy}", kamino, bistair.spec_from_dict(full),
                             {"strategy": strategy})
            yield from _axes(f"kamino/T100+gray {strategy}", kamino, plain,
                             {"strategy": strategy})
        yield from _axes("kamino/gray alone", kamino, gray, {})
    procam = SHARED / "procam-calibration"
    if procam.is_dir():
        spec = bistair.load_spec(EXAMPLES / "procam-graycode.json")
        for pose in sorted(procam.glob("capture_*")):
            yield from _axes(f"procam/{pose.name}", pose, spec, {})
