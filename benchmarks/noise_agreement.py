"""Pass 0's camera noise (``bistair.core.sample.set_noise``: no fit, the fit's projection;
N = 3: second differences on the sample grid) against the fitted residual's figure it
replaced (``bistair.core.measure.noise_level`` on the phase, average and modulation of
``wrapped_phase``), for every N-step set of every real capture in ../shared/data and of the
rendered scenes whose decodes tests/test_speed.py pins: the table and the largest relative
difference.

    python benchmarks/noise_agreement.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from support.pre_speed import cases  # noqa: E402
from support.real_parts import parts  # noqa: E402

from bistair.codecs import get_codec  # noqa: E402
from bistair.core.captures import ScaledStack  # noqa: E402
from bistair.core.measure import noise_level  # noqa: E402
from bistair.core.phase import wrapped_phase  # noqa: E402
from bistair.core.sample import set_noise  # noqa: E402
from bistair.io.read import read_with_spec  # noqa: E402


def set_starts(spec) -> list[int]:
    """The first frame of every N-step set a decode of ``spec`` measures."""
    n = spec.steps
    if spec.method == "multifreq":
        return [i * n for i in range(len(spec.periods))]
    if spec.method == "graycode":
        return [] if n == 0 else [0, n] if spec.second_period else [0]
    return [0]


def scenes():
    """(name, images, spec) of every real capture (once a folder and spec) and render."""
    seen = set()
    for name, folder, spec, _ in parts():
        key = (str(folder), spec.to_json())
        if key not in seen:
            seen.add(key)
            yield (name.split(" (")[0].removesuffix(" pixel"), *read_with_spec(folder, spec))
    for name, images, spec, *_ in cases():
        yield name, images, spec


def main() -> None:
    worst = 0.0
    print(f"{'scene':<34} {'axis':<8} {'set':>4} {'N':>3} {'fitted':>10} {'pass 0':>10} "
          f"{'rel. diff':>10}")
    for name, images, spec in scenes():
        for axis, sub in spec.axes():
            _, cols = get_codec(sub.method)._columns(images, sub)
            for start in set_starts(sub):
                n = sub.steps
                frames = ScaledStack(cols.raw[start:start + n], float(cols.scale))
                fit = wrapped_phase(frames[...], sub.shift_sign, sub.phase_offset)
                fitted = noise_level(frames, *fit, sub.shift_sign, sub.phase_offset)
                now = set_noise(cols, start, n)
                diff = now / fitted - 1 if fitted else 0.0
                worst = max(worst, abs(diff))
                print(f"{name:<34} {axis:<8} {start:>4} {n:>3} {fitted:10.6f} {now:10.6f} "
                      f"{diff:+10.2e}", flush=True)
    print(f"largest relative difference: {worst:.2e}")


if __name__ == "__main__":
    main()
