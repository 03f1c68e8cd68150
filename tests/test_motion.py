"""core/motion.py: the windows of a stream whose shift advances one step per frame, binomial
self-compensation (batch and stream), against phases known exactly."""

import numpy as np
import pytest

from bistair.core.motion import (
    PhaseStream,
    binomial_weights,
    compensate,
    compensate_modulation,
    pair_mean,
    window_phases,
)
from bistair.core.phase import TWO_PI, wrap
from bistair.errors import BistairError


def stream(x, steps, count, speed=0.0, period=30.0, shift_sign=1, phase_offset=0.0):
    """Frame i of a stream: shift i mod steps, the scene moved ``speed`` px per frame."""
    return np.stack([0.5 + 0.4 * np.cos(TWO_PI * (x + speed * i) / period + phase_offset
                                        + shift_sign * TWO_PI * (i % steps) / steps)
                     for i in range(count)])


@pytest.mark.parametrize("steps,shift_sign,phase_offset", [(4, 1, 0.0), (3, -1, 0.7),
                                                            (5, 1, -2.0)])
def test_every_window_gives_the_still_phase_with_its_own_shift_offset_removed(
        steps, shift_sign, phase_offset):
    x = np.linspace(0, 90, 37)[None, :]
    frames = stream(x, steps, steps + 5, shift_sign=shift_sign, phase_offset=phase_offset)
    phi, mod = window_phases(frames, steps, shift_sign, phase_offset)
    assert phi.shape == (6, 1, 37)
    truth = (TWO_PI * x / 30) % TWO_PI
    assert np.abs(wrap(phi - truth)).max() < 2e-5
    assert np.allclose(mod, 0.4, atol=1e-5)


def test_pairwise_means_are_the_binomial_average_also_across_the_wrap():
    rng = np.random.default_rng(3)
    centre = rng.uniform(0, TWO_PI, (1, 50))
    spread = rng.uniform(-0.4, 0.4, (5, 50))
    phases = ((centre + spread) % TWO_PI).astype(np.float32)  # many straddle 0 / 2 pi
    assert ((phases < 0.4).any(axis=0) & (phases > TWO_PI - 0.4).any(axis=0)).sum() >= 3
    expected = (centre[0] + binomial_weights(4) @ spread) % TWO_PI
    got = compensate(phases, 4)
    assert got.shape == (1, 50)
    assert np.abs(wrap(got[0] - expected)).max() < 1e-5
    assert np.array_equal(compensate(phases, 0), phases)
    assert float(pair_mean(np.float32(6.2), np.float32(0.2))) == pytest.approx(0.0584, abs=1e-3)


def test_compensation_removes_the_ripple_of_linear_motion_order_by_order():
    """A scene moving 0.3 period-px per frame: the first window's error is a ripple at twice
    the fringe frequency; each order cuts it (order 4 to far below a tenth)."""
    x = np.linspace(0, 60, 241)[None, :]
    frames = stream(x, 4, 8, speed=0.3)
    phi, _ = window_phases(frames, 4)
    worst = []
    for order in range(5):
        t = (4 + order - 1) / 2
        truth = (TWO_PI * (x + 0.3 * t) / 30) % TWO_PI
        est = compensate(phi[:order + 1], order)[0]
        worst.append(float(np.abs(wrap(est - truth)).max()))
    assert worst[0] > 0.02  # motion does leave an error
    assert all(b < a for a, b in zip(worst, worst[1:], strict=False))
    assert worst[4] < worst[0] / 10


@pytest.mark.parametrize("steps,order", [(4, 0), (4, 1), (4, 4), (3, 2), (6, 3)])
def test_stream_equals_the_batch_form(steps, order):
    rng = np.random.default_rng(steps * 10 + order)
    x = rng.uniform(0, 90, (6, 9))
    frames = np.clip(stream(x, steps, steps + order + 23, speed=0.7)
                     + rng.normal(0, 0.02, (steps + order + 23, 6, 9)), 0, 1)
    frames = np.round(frames * 255).astype(np.uint8)
    phi, mod = window_phases(frames, steps)
    want_phi, want_mod = compensate(phi, order), compensate_modulation(mod, order)
    s = PhaseStream(steps, order)
    got = [s.push(f) for f in frames]
    first = steps + order - 1
    assert all(g is None for g in got[:first])
    assert len(got[first:]) == len(want_phi)
    for (p, m), wp, wm in zip(got[first:], want_phi, want_mod, strict=True):
        assert np.abs(wrap(p - wp)).max() < 1e-5
        assert np.allclose(m, wm, atol=1e-5)
    assert s.lag == (steps + order - 1) / 2
    buffer = np.empty_like(frames[0])  # a camera grabbing every frame into one buffer
    reused = PhaseStream(steps, order)
    for f in frames:
        buffer[...] = f
        last = reused.push(buffer)
    assert np.abs(wrap(last[0] - want_phi[-1])).max() < 1e-5


def test_refusals():
    with pytest.raises(ValueError, match="order"):
        compensate(np.zeros((3, 2), np.float32), -1)
    with pytest.raises(ValueError, match="needs 4 windows"):
        compensate(np.zeros((3, 2), np.float32), 3)
    with pytest.raises(ValueError, match="4 frames or more"):
        window_phases(np.zeros((3, 2, 2)), 4)
    with pytest.raises(ValueError, match="N >= 3"):
        PhaseStream(2)
    with pytest.raises(BistairError, match="shift_sign must be"):
        PhaseStream(4, shift_sign=2)
    stream = PhaseStream(4)
    stream.push(np.zeros((4, 6)))
    with pytest.raises(BistairError, match=r"frame 1 is \(4, 5\), the stream's frames are"):
        stream.push(np.zeros((4, 5)))


def numpy_stream(frames, steps, order, shift_sign, phase_offset):
    """The NumPy steps PhaseStream took before its compiled pass: float64 running sums,
    ``phase_of_sums`` of their float32 values, rounds of ``pair_mean``."""
    from bistair.core.motion import stream_shifts
    from bistair.core.phase import phase_of_sums

    shifts = stream_shifts(steps, steps, shift_sign)
    sin, cos = np.sin(shifts), np.cos(shifts)
    num = np.zeros(frames.shape[1:])
    den = np.zeros(frames.shape[1:])
    levels, mods, out = [None] * (order + 1), [None] * (order + 1), []
    for i, frame in enumerate(frames):
        diff = frame.astype(np.float64) - (frames[i - steps] if i >= steps else 0)
        num -= sin[i % steps] * diff
        den += cos[i % steps] * diff
        if i < steps - 1:
            continue
        new, new_mod = phase_of_sums(num.astype(np.float32), den.astype(np.float32), steps,
                                     phase_offset)
        for level in range(order + 1):
            previous, previous_mod = levels[level], mods[level]
            levels[level], mods[level] = new, new_mod
            if level == order:
                out.append((new, new_mod))
                break
            if previous is None:
                break
            new = pair_mean(previous, new, reduce=level == order - 1)
            new_mod = (previous_mod + new_mod) * np.float32(0.5)
    return out


@pytest.mark.parametrize("steps,order,shift_sign,phase_offset", [
    (4, 0, 1, 0.0), (4, 2, 1, 0.0), (4, 3, -1, 0.7), (3, 1, 1, -2.0), (6, 4, -1, 0.3)])
def test_the_compiled_pass_gives_the_numpy_steps_bit_for_bit(steps, order, shift_sign,
                                                               phase_offset):
    """Every window of a moving uint8 stream of 64 x 80 (past 4096 pixels, where ``wrap``
    is its compiled pass), through every level of the compensation."""
    rng = np.random.default_rng(steps + 7 * order)
    x = np.tile(np.linspace(0, 200, 80), (64, 1)) + rng.uniform(0, 5, (64, 1))
    count = steps + order + 12
    frames = stream(x, steps, count, speed=1.3, period=24.0, shift_sign=shift_sign,
                    phase_offset=phase_offset) + rng.normal(0, 0.02, (count, 64, 80))
    frames = np.round(np.clip(frames, 0, 1) * 255).astype(np.uint8)
    want = numpy_stream(frames, steps, order, shift_sign, phase_offset)
    s = PhaseStream(steps, order, shift_sign, phase_offset)
    got = [r for r in (s.push(f) for f in frames) if r is not None]
    assert len(got) == len(want) == count - steps - order + 1
    for (p, m), (wp, wm) in zip(got, want, strict=True):
        assert p.dtype == m.dtype == np.float32
        assert np.array_equal(p, wp) and np.array_equal(m, wm)
    assert s.state is not None and s.update(frames[0]) and s.state.phase.shape == (64, 80)
