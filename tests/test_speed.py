"""The fast decoders give the orders the decoders gave before they were made fast
(recorded in tests/data/pre_speed.npz by tests/pre_speed.py), and their phases agree with
the plain NumPy N-step phase to 1e-5 rad."""

from __future__ import annotations

import numpy as np
import pytest
from pre_speed import DATA, cases

from bistair import decode
from bistair.core.captures import prepare
from bistair.core.phase import TWO_PI, wrapped_phase

RECORDED = np.load(DATA)
CASES = list(cases())


@pytest.mark.parametrize(("name", "images", "spec", "options"), CASES,
                         ids=[c[0] for c in CASES])
def test_same_orders_and_phases_as_before(name, images, spec, options):
    res = decode(images, spec, **options)
    assert np.array_equal(res.order, RECORDED[name].astype(np.int32))
    frames = prepare(images, spec.frame_count, spec.method).frames
    if spec.method == "multifreq":  # the shortest period's set
        i = spec.periods.index(min(spec.periods))
        frames = frames[i * spec.steps:(i + 1) * spec.steps]
    phi = wrapped_phase(frames[:spec.steps], spec.shift_sign, spec.phase_offset)[0]
    ok = res.mask
    diff = np.abs(res.wrapped[ok].astype(np.float64) - phi[ok])
    assert np.minimum(diff, TWO_PI - diff).max() < 1e-5
    # the absolute phase is the wrapped one plus its orders (to float32 rounding)
    whole = res.wrapped[ok].astype(np.float64) + TWO_PI * res.order[ok]
    assert np.abs(res.phase[ok] - whole).max() < 5e-7 * np.abs(whole).max() + 1e-6
