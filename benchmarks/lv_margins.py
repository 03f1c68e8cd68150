"""How close lv's right decodes and its wrong specs come to the limits of its spec checks
(``bistair.codecs.lv.window_problem`` and ``levels_fit``): lv has no real capture, so its
checks are calibrated on renders.

Each scene is rendered on the virtual rig and decoded with ``force=True`` (a check that
would refuse is recorded, the decode goes on) with the spec that made it (``right``) and,
unless ``--right-only``, with wrong specs: the period x2, x1.5, x1.25, x0.75; levels + 1
and - 1; window + 1 and - 1; a projector half as wide; a 16:9-wider projector (with the
levels it needs); the other orientation; shifts the other way; a phase offset of pi.
Printed per decode: the judged code windows and how many are unknown to the sequence
(limit: over 15%, when no one misread region explains them: ``reg``, the misread regions
it takes), contradicted by their neighbours (limit: over 30% and over ``window + 2``) and
run past the spec's last fringe (limit: 2), the code phases' misfit on the spec's levels
and on the best other count (limit: 1.5 times, over 0.15), the valid share, the share of
valid pixels more than 5 projector pixels off the truth, and the checks that would refuse.
A right decode refused is a false refusal; a wrong spec not refused whose decode has over
1% more of its valid pixels off than the right spec's is a miss (``SILENTLY WRONG``).

Scenes: the presets (``--scenes``, default optics and, with ``--hard``, the hard optics of
``benchmarks/robustness.py``), and the scenes of a data set written by ``bistair simulate
--count N --vary optics,objects,pose --method lv`` (``--dataset FOLDER``).

    python benchmarks/lv_margins.py [--camera 640x512] [--seeds 0,1] [--hard] [--right-only]
    python benchmarks/lv_margins.py --dataset sim-set [--camera ...]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from robustness import DEFAULT, HARD

import bistair
from bistair.codecs import lv
from bistair.errors import BistairError
from bistair.sim import Imaging, expose, preset, trace
from bistair.sim.variation import build

SCENES = ("paper-sim", "two-masks", "mask-prism", "two-sculptures", "plane",
          "sphere-on-plane", "objects-on-plane", "mugs-on-wall")


def wrong_specs(spec) -> dict[str, dict]:
    """The changes of each wrong spec (those that do not validate are left out)."""
    wide = spec.width * 16 // 9
    changes = {
        "period x2": dict(period=spec.period * 2), "period x1.5": dict(period=spec.period * 1.5),
        "period x1.25": dict(period=spec.period * 1.25),
        "period x0.75": dict(period=spec.period * 0.75),
        "levels + 1": dict(levels=spec.levels + 1), "levels - 1": dict(levels=spec.levels - 1),
        "window + 1": dict(window=spec.window + 1), "window - 1": dict(window=spec.window - 1),
        "half as wide": dict(width=spec.width // 2),
        "wider": dict(width=wide, levels=lv.levels_for(math.ceil(wide / spec.period),
                                                      spec.window)),
        "rows": dict(orientation="rows"), "shifts reversed": dict(shift_sign=-1),
        "offset pi": dict(phase_offset=math.pi)}
    out = {}
    for name, change in changes.items():
        try:
            out[name] = spec.replace(**change)
        except BistairError:
            pass
    return out


def row(images, spec, truth) -> dict:
    """One decode's figures (``None`` where the decode raised)."""
    try:
        res = bistair.decode(images, spec, force=True)
    except BistairError as exc:
        return {"error": str(exc)}
    info = res.info
    both = res.mask & truth.mask
    coord = truth.coord_x if spec.orientation == "columns" else truth.coord_y
    wrong = float((np.abs(res.coord[both] - coord[both]) > 5).mean()) if both.any() else 0.0
    keys = ("code_windows", "unknown_windows", "unknown_regions", "past_windows",
            "contradicted_windows", "unsure_windows", "code_misfit", "other_misfit",
            "other_levels")
    return {**{k: info.get(k, 0) for k in keys}, "valid": float(res.mask.mean()),
            "wrong": wrong, "forced": list(info.get("forced", []))}


def decodes(rig, geometry, imaging, gamma: float, period: int, wrong: bool):
    """(case, figures) of the right spec and, with ``wrong``, of the wrong ones."""
    traced = trace(rig, geometry, imaging)
    w, h = rig.projector.size
    spec = bistair.make_spec("lv", width=w, height=h, gamma=gamma,
                             **lv.comparable(w, h, period, 4))
    images = expose(traced, bistair.encode(spec), imaging)
    yield "right", row(images, spec, traced.truth)
    for name, other in (wrong_specs(spec).items() if wrong else ()):
        yield name, row(images, other, traced.truth)


def show(label: str, case: str, r: dict, tally: dict) -> None:
    if "error" in r:
        print(f"{label:32s} {case:16s} error: {r['error'][:70]}")
        return
    refused = bool(r["forced"])
    if case == "right":
        tally["right wrong"] = r["wrong"]
    silent = not refused and r["valid"] > 0 and r["wrong"] > tally["right wrong"] + 0.01
    if case == "right":
        tally["right"] += 1
        tally["false refusals"] += refused
        for key in ("unknown", "unknown regions", "past", "contradicted", "misfit ratio"):
            tally[f"right {key}"] = max(tally.get(f"right {key}", 0.0), _stat(r, key))
    else:
        tally["wrong"] += 1
        tally["refused"] += refused
        tally["silently wrong"] += silent
    n = max(r["code_windows"], 1)
    print(f"{label:32s} {case:16s} {r['code_windows']:4d} {r['unknown_windows']:4d} "
          f"({r['unknown_windows'] / n:4.2f}) {r['unknown_regions']:3d} {r['past_windows']:3d} "
          f"{r['contradicted_windows']:4d} ({r['contradicted_windows'] / n:4.2f}) "
          f"{r['code_misfit']:5.3f} {r['other_misfit']:5.3f}@{r['other_levels']:<2d} "
          f"{100 * r['valid']:5.1f}% {100 * r['wrong']:5.1f}% "
          + ("refused: " + r["forced"][0][:60] if refused else
             ("SILENTLY WRONG" if case != "right" and silent else "-")))


def _stat(r: dict, key: str) -> float:
    n = max(r["code_windows"], 1)
    return {"unknown": r["unknown_windows"] / n, "unknown regions": r["unknown_regions"],
            "past": r["past_windows"],
            "contradicted": r["contradicted_windows"] / n,
            "misfit ratio": r["code_misfit"] / max(r["other_misfit"], 1e-9)}[key]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="640x512")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--hard", action="store_true", help="also the hard optics")
    parser.add_argument("--right-only", action="store_true")
    parser.add_argument("--dataset", type=Path, default=None,
                        help="the scenes of a data set (bistair simulate --count)")
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    tally = dict.fromkeys(("right", "false refusals", "wrong", "refused", "silently wrong"),
                          0)
    print(f"{'scene':32s} {'spec':16s} wins unkn (shr) reg pst cont (shr) misfit other    "
          "valid  wrong  checks")
    if args.dataset is not None:
        for folder in sorted(args.dataset.glob("scene-*")):
            params = json.loads((folder / "scene.json").read_text())["parameters"]
            rig, geometry, imaging = build(params)
            label = f"{folder.name} {params.get('preset') or 'drawn'}"
            for case, r in decodes(rig, geometry, imaging, imaging.gamma, 30,
                                   not args.right_only):
                show(label, case, r, tally)
    else:
        optics = [("default", DEFAULT, True)] + ([("hard", HARD, False)] if args.hard else [])
        for name in args.scenes.split(","):
            period = 16 if name == "objects-on-plane" else 30  # robustness.py's cases
            for seed in (int(s) for s in args.seeds.split(",")):
                for label, values, compensated in optics:
                    rig, geometry = preset(name, camera_size=camera)
                    imaging = Imaging(**values, seed=seed)
                    for case, r in decodes(rig, geometry, imaging,
                                           2.2 if compensated else 1.0, period,
                                           not args.right_only):
                        show(f"{name} {label} s{seed}", case, r, tally)
    print(f"\nright decodes: {tally['right']}, refused (false refusals): "
          f"{tally['false refusals']}; most unknown {tally.get('right unknown', 0):.3f} "
          f"(misread regions {tally.get('right unknown regions', 0):.0f}), "
          f"past {tally.get('right past', 0):.0f}, contradicted "
          f"{tally.get('right contradicted', 0):.3f}, misfit / other "
          f"{tally.get('right misfit ratio', 0):.2f}")
    print(f"wrong specs: {tally['wrong']}, refused {tally['refused']}, silently wrong "
          f"(not refused, over 1% more of the valid pixels off than the right spec's): "
          f"{tally['silently wrong']}")


if __name__ == "__main__":
    main()
