"""A binocular sample in another tool's layout, reconstructed through the command line at
1280 x 1024 (issue 22): the capture set of ``tests/support/stereo_sample.py`` (12-step
sinusoid in the sine convention + complementary Gray code with inverses, white and black
first, BMP files, a hand-written spec, an OpenCV stereo YAML with the tool's key names and
14 distortion numbers, a pair not quite level, the projector's gamma uncompensated).

Runs ``bistair import-calibration --stereo --keys ...`` and ``bistair stereo`` as a user
would (subprocesses), then compares the depth with the truth and with an independent
reconstruction: ``bistair reconstruct`` of the left camera with the projector's calibration
(camera-projector triangulation, which the stereo path never uses). Target: within 0.2 mm
(median).

    python benchmarks/stereo_sample.py [--camera 1280x1024]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from support.stereo_sample import KEYS, write_sample  # noqa: E402


def bistair(*args: object) -> str:
    out = subprocess.run([sys.executable, "-m", "bistair", *map(str, args)], check=True,
                         capture_output=True, text=True)
    return out.stdout.strip()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="1280x1024")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.camera.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sample = write_sample(tmp / "sample", size)
        print("$ bistair import-calibration calib/stereo.yml --stereo --keys ...")
        print(bistair("import-calibration", sample["yml"], "--stereo", "--keys", KEYS,
                      "--out", tmp / "stereo.json"))
        start = time.perf_counter()
        print("$ bistair stereo L R --spec spec.json --calibration stereo.json --out res")
        print(bistair("stereo", sample["L"], sample["R"], "--spec", sample["spec"],
                      "--calibration", tmp / "stereo.json", "--out", tmp / "res"))
        print(f"({time.perf_counter() - start:.1f} s with the process start)")
        bistair("reconstruct", sample["L"], "--spec", sample["spec"], "--calibration",
                sample["mono"], "--out", tmp / "mono.ply", "--depth", tmp / "mono")
        depth = np.load(tmp / "res" / "depth.npy")
        truth = np.load(sample["truth"] / "depth.npy")
        mask = np.load(sample["truth"] / "mask.npy")
        mono = np.load(tmp / "mono" / "depth.npy")
        ok = np.isfinite(depth) & mask
        both = np.isfinite(depth) & np.isfinite(mono)
        print(f"points {int(np.isfinite(depth).sum())} ({100 * ok.sum() / mask.sum():.1f}% "
              f"of the truth mask); median |depth - truth| "
              f"{np.median(np.abs(depth[ok] - truth[ok])):.3f} mm, 99th percentile "
              f"{np.percentile(np.abs(depth[ok] - truth[ok]), 99):.3f} mm")
        print(f"against the camera-projector reconstruction ({int(both.sum())} pixels both "
              f"give): median {np.median(np.abs(depth[both] - mono[both])):.3f} mm, 99th "
              f"percentile {np.percentile(np.abs(depth[both] - mono[both]), 99):.3f} mm; "
              f"target median 0.2 mm")


if __name__ == "__main__":
    main()
