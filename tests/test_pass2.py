"""Pass 2 of a decode (issue 32): the orders filled a chunk of targets at a time give what the
whole-image fill gave, bit for bit; the result's arrays are its own (none shares memory with
another or with the captures, which a decode leaves as they were) and hold 22 bytes a pixel
with an int8 code."""

from __future__ import annotations

import numpy as np
import pytest

import bistair
from bistair.core import regions
from bistair.core.phase import TWO_PI, order_from_reference
from bistair.core.result import PIXEL_FIELDS


def _fill_whole(phi, order, target, max_distance=3.0):
    """fill_orders as it was before the chunks (every target's candidates at once)."""
    out = np.array(order, dtype=np.int32)
    ty, tx = np.nonzero(target & (out < 0))
    r = int(np.floor(max_distance))
    dy, dx = np.mgrid[-r:r + 1, -r:r + 1]
    dist = np.hypot(dy, dx).ravel()
    near = np.argsort(dist, kind="stable")
    near = near[(dist[near] > 0) & (dist[near] <= max_distance)]
    dy, dx = dy.ravel()[near], dx.ravel()[near]
    h, w = out.shape
    yy = np.clip(ty[:, None] + dy[None, :], 0, h - 1)
    xx = np.clip(tx[:, None] + dx[None, :], 0, w - 1)
    found = order[yy, xx] >= 0
    first, has = found.argmax(axis=1), found.any(axis=1)
    pick_y, pick_x = yy[np.arange(ty.size), first][has], xx[np.arange(ty.size), first][has]
    ref = phi[pick_y, pick_x] + TWO_PI * order[pick_y, pick_x]
    out[ty[has], tx[has]] = order_from_reference(phi[ty[has], tx[has]], ref)
    return out


@pytest.mark.parametrize("chunk", [1, 7, 8192])
def test_fill_in_chunks_is_the_whole_fill(monkeypatch, chunk):
    """Targets whose nearest sources are other targets (filled in an earlier chunk) still
    take them from the orders given only, in place or not, whatever the chunk."""
    rng = np.random.default_rng(32)
    phi = rng.uniform(0, 2 * np.pi, (40, 50)).astype(np.float32)
    order = np.where(rng.random(phi.shape) < 0.3, rng.integers(0, 9, phi.shape), -1)
    order = order.astype(np.int32)
    target = rng.random(phi.shape) < 0.8
    monkeypatch.setattr(regions, "FILL_CHUNK", chunk)
    want = _fill_whole(phi, order, target)
    assert np.array_equal(regions.fill_orders(phi, order, target), want)
    given = order.copy()
    got = regions.fill_orders(phi, given, target, in_place=True)
    assert got is given and np.array_equal(got, want)
    assert (want >= 0).sum() > (order >= 0).sum() and (want[target] < 0).any()


def _own(result):
    """The arrays a result holds (its coordinate is computed when asked for, its code
    widened when read)."""
    assert vars(result).get("_coord") is None
    return [vars(result)["_code"] if name == "code" else getattr(result, name)
            for name in PIXEL_FIELDS if name != "coord"]


@pytest.mark.parametrize("method", ["bidirectional", "graycode", "multifreq"])
@pytest.mark.parametrize("dtype", [np.uint8, np.float32])
def test_result_owns_its_arrays_and_leaves_the_captures(method, dtype):
    spec = bistair.make_spec(method, width=320, height=64)
    images = bistair.encode(spec)
    images = (images * 255).round().astype(np.uint8) if dtype == np.uint8 else images
    given = images.copy()
    res = bistair.decode(images, spec)
    assert np.array_equal(images, given)  # the captures as they were
    arrays = [*_own(res), images]
    for i, a in enumerate(arrays):
        for b in arrays[i + 1:]:
            assert not np.shares_memory(a, b)
    # the code stored narrow, read as int32 (arithmetic on it never wraps around)
    assert vars(res)["_code"].dtype == np.int8 and res.order.dtype == np.int32
    assert res.code.dtype == np.int32 and np.array_equal(res.code, vars(res)["_code"])
    assert sum(a.nbytes for a in _own(res)) == 22 * res.mask.size
    # the coordinate: float32 from the phase, NaN where invalid, a new array each time
    assert res.coord.dtype == np.float32 and res.coord is not res.coord
    assert np.array_equal(np.isnan(res.coord), ~res.mask)
    assert np.abs(res.coord[res.mask] - res.phase[res.mask] * spec.period / TWO_PI).max() < 1e-3
