"""Heterodyne periods as people write them (issue 33, item 4).

1920/64, 1920/58, 1920/53 beat at exactly 1920 px; written to 10 significant digits they
beat at 1919.99996 px, to 6 at 1920.28, to 4 at 1953.86, to 3 at 1870.27. The first three
are accepted (the 10-digit beat because its digits, +-5e-9 px, allow 1920.000008 px), the
3-digit one is refused: its digits allow up to 2468 px, but patterns generated with 33.1
and 36.2 repeat 50 px inside the axis. Periods that really beat at 1919 px are refused.

The decode is judged against the virtual rig's truth where the axis starts and ends (a
camera zoomed to 4 camera pixels per projector pixel on the first and last 40 columns):
before, a few pixels at projector column 0 whose top beat's noise carried it across its
wrap decoded 1920 px up (order 63), with the exact fractions (16 of 9728 pixels at seed 0)
and with 4 digits (7).
"""

import numpy as np
import pytest

from bistair.codecs import decode, make_spec
from bistair.codecs.beats import beat_reach, stated_precision, wrap_shift
from bistair.errors import BistairError
from bistair.sim.warp import WarpScene, render_warp

FRINGES = (64, 58, 53)


def written(digits: int) -> tuple[float, ...]:
    """1920/64, 1920/58, 1920/53 to ``digits`` significant digits, as a user types them."""
    return tuple(float(f"{1920 / k:.{digits}g}") for k in FRINGES)


@pytest.mark.parametrize(("digits", "top"), [(10, 1919.99996), (6, 1920.28244),
                                             (4, 1953.85814)])
def test_written_periods_are_accepted(digits, top):
    spec = make_spec("multifreq", width=1920, height=32, periods=written(digits), steps=4)
    assert spec.unwrap == "heterodyne"
    assert beat_reach(spec.periods)[0] == pytest.approx(top, abs=1e-5)


def test_ten_digits_explain_the_shortfall_only_just():
    periods = written(10)
    assert [stated_precision(t) for t in periods] == [0.0, 5e-9, 5e-9]
    top, reach = beat_reach(periods)
    assert top < 1920 < reach < 1920 + 1e-5
    assert beat_reach(periods, precision=1e-9)[1] < 1920  # 10 x tighter digits would not


def test_three_digits_repeat_inside_the_axis():
    with pytest.raises(BistairError, match=r"is 1870.2705\d* px, narrower than the 1920-px "
                       r"coded axis by more than half a pixel, so patterns with these "
                       r"periods repeat within it; periods known to only \+-0.0037 px could "
                       r"beat at 1920 px, as these are written: write them to more digits"):
        make_spec("multifreq", width=1920, height=32, periods=written(3))


def test_a_real_shortfall_is_refused():
    exact = tuple(1919 / k for k in FRINGES)
    with pytest.raises(BistairError, match=r"^the beat of periods \(29.984375, "
                       r"33.08620689655172, 36.20754716981132\) is 1919 px, narrower than "
                       r"the 1920-px coded axis by more than half a pixel.*\+-7.3e-05 px "
                       r"could beat at 1920 px, these are "
                       r"written to \+-5e-07 px$"):
        make_spec("multifreq", width=1920, height=32, periods=exact)
    near = (1919.75 / 64, 1919.75 / 58, 1919.75 / 53)  # 0.25 px short, digits +-5e-9 px
    with pytest.raises(BistairError, match=r"is 1919.75 px, narrower than the 1920-px coded "
                       r"axis; periods known to only \+-1.8e-05 px could beat at 1920 px, "
                       r"these are written to \+-5e-09 px$"):
        make_spec("multifreq", width=1920, height=32, periods=near)


def test_a_second_reading_only_where_the_periods_nearly_repeat():
    assert wrap_shift(written(10)) == (1920.0, pytest.approx(0.0, abs=1e-6))
    assert wrap_shift((42, 45, 48)) == (5040.0, 0.0)
    assert wrap_shift((42, 45, 50))[1] == 0.5


def edge_errors(periods, offset, seed=0):
    """Decode a camera that sees projector columns ``offset .. offset + 160`` at four camera
    pixels per column (1% noise, blur of 0.5 camera pixels): (valid pixels more than 1.5
    projector pixels off, valid pixels, pixels wholly inside the projector, the largest
    truth coordinate of a valid pixel)."""
    spec = make_spec("multifreq", width=1920, height=64, periods=periods, steps=4)
    scene = WarpScene(size=(16, 640), stretch=0.25, offset=offset, blur=0.5, noise=0.01,
                      seed=seed, row_offset=10)
    images, _ = render_warp(spec, scene)
    res = decode(images, spec)
    x = np.broadcast_to(offset + 0.25 * np.arange(640), res.coord.shape)  # the warp's truth
    off = res.mask & ~(np.abs(res.coord - x) < 1.5)
    assert (res.order[~res.mask] == -1).all() and np.isnan(res.coord[~res.mask]).all()
    inside = (x >= 0) & (x <= 1919)
    return int(off.sum()), int(res.mask.sum()), int(inside.sum()), float(x[res.mask].max())


@pytest.mark.parametrize("digits", [10, 6, 4])
def test_decode_at_both_ends_of_the_axis_against_truth(digits):
    """No valid pixel a fringe off at either end; at least 85% of the pixels decoded (the
    others' top beat is read across its wrap and left invalid), up to the last column."""
    for offset in (-8.0, 1880.0):
        wrong, valid, inside, last = edge_errors(written(digits), offset)
        assert wrong == 0, (digits, offset, wrong)
        assert valid >= 0.85 * inside, (digits, offset, valid, inside)
        if offset > 0:
            assert last >= 1919.0
