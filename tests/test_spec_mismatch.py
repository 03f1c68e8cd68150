"""A spec that does not fit the captures is refused, never decoded into wrong numbers
(issue 14, defect 1), for every codec.

Each codec's captures of one scene are decoded with specs that differ from the one that
made them: the other orientation, a wider projector, another period, other levels, another
method's spec with the same frame count, code frames or shift frames swapped, a shift frame
exchanged with a code frame. Each decode
must either be refused with a one-line :class:`BistairError` or be right (at most 1% of the
valid pixels more than 5 projector pixels off the truth of the spec's coded axis).

Not caught, by design: a period so close to the true one that the code reads the same
(a stair sequence that is a prefix of a longer one, a Gray code of the same length). The
captures alone cannot tell these apart; the README says so.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import bistair
from bistair.app.decode import require_valid
from bistair.codecs import REGISTRY, lv
from bistair.errors import BistairError
from bistair.sim import Imaging, expose, preset, trace

COMMON = ["rows", "wider projector", "another method", "swapped code frames",
          "swapped shift frames", "shift and code frames swapped"]
OWN = {
    "bidirectional": ["period x1.5", "period 2000", "stairs - 1", "partitions + 1"],
    "graycode": ["period x1.5", "not complementary"],
    "lv": ["period x1.5", "levels + 1", "window + 1"],
    "multifreq": ["periods reversed", "middle period off"],
    "phase-coding": ["period x1.5", "period 2000"],
}


@pytest.fixture(scope="module")
def scene() -> Any:
    rig, geometry = preset("objects-on-plane", camera_size=(480, 384))
    imaging = Imaging(read_noise=0.01, camera_blur=1.0, seed=1)
    return rig, imaging, trace(rig, geometry, imaging)


def _spec(method: str, rig: Any, imaging: Any) -> Any:
    """The codec's pattern set for the rig, pre-compensating the projector's gamma."""
    width, height = rig.projector.size
    params = REGISTRY[method].comparable(width, height, 30, 4)
    return bistair.make_spec(method, width=width, height=height, gamma=imaging.gamma, **params)


def _changes(spec: Any, case: str) -> dict[str, Any]:
    """The spec fields a case changes: always a valid spec (its other fields adjusted where
    the change alone would not validate), so that every case decodes or is refused."""
    p = getattr(spec, "periods", None)
    wide = spec.width * 16 // 9
    if case == "wider projector":
        if spec.method == "bidirectional":  # more partitions to cover the wider axis
            return {"width": wide, "partitions": math.ceil(wide / (spec.stairs * spec.period))}
        if spec.method == "lv":
            return {"width": wide, "levels": lv.levels_for(math.ceil(wide / spec.period),
                                                           spec.window)}
        if spec.method == "multifreq":  # its longest period covers the wider axis
            return {"width": wide, "periods": (float(wide), *p[1:])}
        return {"width": wide}
    if case == "period 2000":  # a period longer than the code can cover: fewest fringes
        return {"period": spec.coded_length / 2.0}
    return {
        "rows": {"orientation": "rows"},
        "period x1.5": {"period": getattr(spec, "period", 0) * 1.5},
        "periods reversed": {"periods": tuple(reversed(p or ()))},
        "middle period off": {"periods": (p[0], p[1] * 1.2, *p[2:])} if p else {},
        "stairs - 1": {"stairs": getattr(spec, "stairs", 0) - 1,
                       "partitions": getattr(spec, "partitions", 0) + 2},
        "partitions + 1": {"partitions": getattr(spec, "partitions", 0) + 1},
        "levels + 1": {"levels": getattr(spec, "levels", 0) + 1},
        "window + 1": {"window": getattr(spec, "window", 0) + 1},
        "not complementary": {"complementary": 0},
    }[case]


def _same_frames(method: str, spec: Any) -> Any:
    """Another method's spec with the same frame count as ``spec`` (its steps chosen so)."""
    frames = spec.frame_count
    other = {"bidirectional": frames - 2, "phase-coding": frames // 2, "lv": frames - 2}
    steps = other.get(method)
    if steps is None or steps < 3 or (method == "phase-coding" and frames % 2):
        return None
    try:
        made = bistair.make_spec(method, width=spec.width, height=spec.height,
                                 **REGISTRY[method].comparable(spec.width, spec.height, 30,
                                                               steps))
    except BistairError:
        return None
    return made if made.frame_count == frames else None


# Mismatches no check catches yet, measured on this scene
KNOWN_GAPS = {  # each an xfail(strict): a fix shows as XPASS, which fails
    ("phase-coding", "shift and code frames swapped"):
        "shift-0 exchanged with code-cos or code-sin: 15% and 10% of the modulated pixels "
        "decoded, 88% and 92% of them wrong; the orders step by one at every phase jump and "
        "the four-step residual (0.38 of the modulation) is no larger than a right decode's "
        "under an uncompensated gamma of 2.8 (0.39)",
}

CASES = [pytest.param(method, case, id=f"{method}-{case}",
                      marks=[pytest.mark.xfail(strict=True, raises=AssertionError,
                                               reason=KNOWN_GAPS[method, case])]
                      if (method, case) in KNOWN_GAPS else [])
         for method in sorted(REGISTRY) for case in COMMON + OWN.get(method, [])]

# What a refusal of a spec that does not fit must name: one of the fit checks (the message
# of every thresholded check starts so), or the frame count; never e.g. "captures are dark"
FIT = ("the captures do not fit the spec", "frames, the captures have")


def _truth(spec: Any, truth: Any) -> np.ndarray:
    return truth.coord_x if spec.orientation == "columns" else truth.coord_y


def _refused_or_right(images: np.ndarray, spec: Any, truth: Any) -> str:
    try:
        result = bistair.decode(images, spec)
    except BistairError as exc:
        message = str(exc)
        assert message and "\n" not in message
        assert any(reason in message for reason in FIT), f"refused for another reason: {message}"
        return "refused"
    both = result.mask & truth.mask
    assert both.sum() > 1000, "a decode that answers for almost no pixel"
    wrong = np.abs(result.coord[both] - _truth(spec, truth)[both]) > 5.0
    # phase coding's 36 stair levels misread one region of this scene by one order even
    # with the right spec (1.3% of the valid pixels, measured): its own limit, not a mismatch
    limit = 0.02 if spec.method == "phase-coding" else 0.01
    assert wrong.mean() <= limit, f"{100 * wrong.mean():.1f}% of the valid pixels wrong"
    return "right"


@pytest.mark.parametrize(("method", "case"), CASES)
def test_a_spec_that_does_not_fit_is_refused(scene: Any, method: str, case: str) -> None:
    rig, imaging, traced = scene
    spec = _spec(method, rig, imaging)
    images = expose(traced, bistair.encode(spec), imaging)
    code = [i for i, name in enumerate(spec.frames) if "shift" not in name]
    if case == "another method":
        others = [_spec(m, rig, imaging) for m in sorted(REGISTRY) if m != method]
        wrong_specs = [s for s in others if s.frame_count == spec.frame_count]
        if not wrong_specs:  # another method made with as many frames
            wrong_specs = [s for s in (_same_frames(m, spec) for m in sorted(REGISTRY)
                                       if m != method) if s is not None][:1]
        assert wrong_specs, f"no other method can have {spec.frame_count} frames"
        for other in wrong_specs:
            _refused_or_right(images, other, traced.truth)
        return
    if case == "swapped code frames":
        frames = code if len(code) >= 2 else list(range(spec.steps, spec.steps * 2))
        for i in range(0, len(frames) - 1, 2):
            swapped = images.copy()
            swapped[[frames[i], frames[i + 1]]] = swapped[[frames[i + 1], frames[i]]]
            _refused_or_right(swapped, spec, traced.truth)
        return
    if case == "shift and code frames swapped":  # shift-0 with the first and the last
        frames = code or list(range(spec.steps, spec.frame_count))
        for other in sorted({frames[0], frames[-1]}):
            swapped = images.copy()
            swapped[[0, other]] = swapped[[other, 0]]
            try:
                answer = bistair.decode(swapped, spec)
            except BistairError:
                answer = None  # judged below
            if answer is not None and not answer.mask.any():
                # nothing answered (lv, shift-0 with its last code frame): an answer the
                # command line refuses, exit code 2 (tests/test_bad_input.py)
                with pytest.raises(BistairError, match="^no pixel decoded"):
                    require_valid(answer)
                continue
            _refused_or_right(swapped, spec, traced.truth)
        return
    if case == "swapped shift frames":
        swapped = images.copy()
        swapped[[0, 1]] = swapped[[1, 0]]
        _refused_or_right(swapped, spec, traced.truth)
        return
    wrong = spec.replace(**_changes(spec, case))
    _refused_or_right(images, wrong, traced.truth)


@pytest.mark.parametrize("method", sorted(REGISTRY))
def test_the_right_spec_decodes_the_same_scene(scene: Any, method: str) -> None:
    """The baseline of the table above: with its own spec each codec decodes this scene."""
    rig, imaging, traced = scene
    spec = _spec(method, rig, imaging)
    images = expose(traced, bistair.encode(spec), imaging)
    assert _refused_or_right(images, spec, traced.truth) == "right"
