"""How far right decodes and captures in the wrong frame order come from the frame-order
limits: every method of the robustness cases (benchmarks/robustness.py) rendered right,
one frame late (``01..N,00``), one frame early (``N,00..``), with ``shift-2``/``shift-3``
exchanged and (Gray codes) each pair of neighbouring code frames exchanged; each decoded
with ``force=True``, its ``rotated_fit``, ``exchange_fit``, ``edge_jumps`` of
``edge_links`` and the checks that would refuse it printed.

    python benchmarks/frame_order_margins.py [--camera 320x256] [--cases paper,hard]
"""

from __future__ import annotations

import argparse

from robustness import CASES, case_specs

import bistair
from bistair.sim import Imaging, preset, trace
from bistair.sim.render import expose

LABELS = ["graycode", "graycode (shifted)", "graycode (shifted, cyclic)", "multifreq",
          "bidirectional", "phase-coding", "lv"]


def orders(spec, frames: int) -> dict[str, list[int]]:
    """The frame orders tried: right, one over either way, two frames exchanged."""
    out = {"right": list(range(frames)), "late": [*range(1, frames), 0],
           "early": [frames - 1, *range(frames - 1)]}
    swapped = list(range(frames))
    swapped[2], swapped[3] = 3, 2
    out["shift 2/3"] = swapped
    if spec.method == "graycode":
        for a in range(spec.steps, frames - 1):
            pair = list(range(frames))
            pair[a], pair[a + 1] = a + 1, a
            out[f"frames {a}/{a + 1}"] = pair
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="320x256")
    parser.add_argument("--cases", default=",".join(CASES))
    args = parser.parse_args()
    camera = tuple(int(v) for v in args.camera.split("x"))
    for name in args.cases.split(","):
        scene_name, optics, compensated, period, ps, _ = CASES[name]
        rig, scene = preset(scene_name, camera_size=camera)
        imaging = Imaging(**optics, seed=1)
        traced = trace(rig, scene, imaging)
        specs = case_specs(rig.projector.size, period, ps, compensated)
        for label in LABELS:
            spec, options = specs[label]
            images = expose(traced, bistair.encode(spec), imaging)
            strategies = ["pixel", "region"] if spec.method == "graycode" else [None]
            for strategy in strategies:
                extra = {"strategy": strategy} if strategy else {}
                for kind, order in orders(spec, len(images)).items():
                    try:
                        info = bistair.decode(images[order], spec, force=True, **options,
                                              **extra).info
                    except bistair.BistairError as exc:
                        print(f"{name} | {label} {strategy or ''} | {kind} | error: {exc}")
                        continue
                    edges = (f"{info['edge_jumps']}/{info['edge_links']}"
                             if "edge_links" in info else "-")
                    refused = "; ".join(f[:60] for f in info.get("forced", [])) or "-"
                    print(f"{name} | {label} {strategy or ''} | {kind} | rotated "
                          f"{info.get('rotated_fit', '-')} exchange "
                          f"{info.get('exchange_fit', '-')} edge jumps {edges} | {refused}",
                          flush=True)


if __name__ == "__main__":
    main()
