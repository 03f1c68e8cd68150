"""Captures from rigs with other conventions: phase offsets, shift directions, frame orders,
extra frames, fractional periods, shifted Gray codes, heterodyne beats at the projector's
edges. Each is decoded right with a spec that says so, and refused (or warned about, where
the captures alone cannot tell) with a spec that does not."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import cli_run, warped_scene

import bistair
from bistair.errors import BistairError
from bistair.evaluation.metrics import score
from bistair.sim.warp import Blob, WarpScene, render_warp

CODECS = [("bidirectional", dict(period=30)), ("graycode", dict(period=30)),
          ("graycode", dict(period=30, complementary=1)),
          ("graycode", dict(period=30, gray_offset=0.5)), ("phase-coding", dict(period=30)),
          ("lv", dict(period=30)), ("multifreq", dict(periods=(42, 45, 48)))]
IDS = [f"{m}-{'-'.join(f'{k}{v}' for k, v in p.items())}" for m, p in CODECS]
SCENE = warped_scene(0, noise=0.01, blur=1.0)


def _render(method, params, **convention):
    spec = bistair.make_spec(method, width=1080, height=1080, **params, **convention)
    images, truth = render_warp(spec, SCENE)
    return spec, images, truth


def _right(result, truth, spec, tolerance=0.001):
    m = score(result, truth.coord(spec), truth.mask)
    assert m["coverage"] > 0.9, m
    assert m["order_error_rate"] <= tolerance, m


@pytest.mark.parametrize(("offset", "sign"), [(np.pi, 1), (-2 * np.pi / 3, 1), (0.0, -1),
                                               (1.0, -1)])
@pytest.mark.parametrize(("method", "params"), CODECS, ids=IDS)
def test_a_spec_that_names_the_convention_decodes_it(method, params, offset, sign):
    spec, images, truth = _render(method, params, phase_offset=offset, shift_sign=sign)
    _right(bistair.decode(images, spec), truth, spec)


@pytest.mark.parametrize(("offset", "sign", "hint"), [
    (np.pi, 1, "phase_offset pi"), (-2 * np.pi / 3, 1, "phase_offset -2*pi/3"),
    (0.0, -1, "shift_sign -1")])
@pytest.mark.parametrize(("method", "params"), CODECS[:-1], ids=IDS[:-1])
def test_a_spec_with_the_wrong_convention_is_refused(method, params, offset, sign, hint):
    _, images, _ = _render(method, params, phase_offset=offset, shift_sign=sign)
    plain = bistair.make_spec(method, width=1080, height=1080, **params)
    if method == "lv" and sign == -1:  # Lv's code does not grow with x: no window fits
        with pytest.raises(BistairError, match="not in the spec's code sequence"):
            bistair.decode(images, plain)
        return
    with pytest.raises(BistairError, match="do not fit the spec") as info:
        bistair.decode(images, plain)
    assert hint in str(info.value)


@pytest.mark.parametrize("periods", [(42, 45, 48), (1080, 180, 30)])
def test_multifrequency_with_the_wrong_convention(periods):
    """Offsets break the agreement of the periods (refused); a sign flip of every set is a
    mirrored projector to the captures: warned about where the mirrored coordinates land on
    the projector, else refused or left empty (42, 45 and 48 px: the 21 pixels whose periods
    agree by chance are dim, their misses' noise 0.4-1.1 fringe, and are left out; the
    command line refuses an empty decode)."""
    _, images, _ = _render("multifreq", dict(periods=periods), phase_offset=np.pi)
    plain = bistair.make_spec("multifreq", width=1080, height=1080, periods=periods)
    with pytest.raises(BistairError, match="periods agree on"):
        bistair.decode(images, plain)
    _, images, truth = _render("multifreq", dict(periods=periods), shift_sign=-1)
    try:
        result = bistair.decode(images, plain)
    except BistairError as exc:
        assert "read on only" in str(exc) or "outside the 1080-px projector" in str(exc)
    else:
        assert result.mask.sum() == 0 or (
            result.mask.sum() > 1000 and "shift_sign -1" in result.info["warnings"][0])


def test_frames_in_another_order_with_black_and_ignored_frames():
    spec = bistair.make_spec("bidirectional", width=1080, height=1080, period=30, white=1)
    images, truth = render_warp(spec, SCENE)
    order = [5, 0, 3, 1, 6, 2, 4]  # stair-sin, shift-0, shift-3, shift-1, white, ...
    names = [spec.frames[i] for i in order]
    dark = np.zeros_like(images[:1])
    stack = np.concatenate([dark, images[order[:3]], dark, images[order[3:]]])
    frames = ["black", *names[:3], "ignore", *names[3:]]
    custom = bistair.spec_from_dict({**spec.to_dict(), "frames": frames})
    result = bistair.decode(stack, custom)
    _right(result, truth, spec)
    assert result.texture is not None and float(result.texture.max()) > 0.5
    # the same captures read with the spec's own order are refused, not decoded wrong
    with pytest.raises(BistairError):
        wrong = bistair.spec_from_dict({**spec.to_dict(),
                                        "frames": [*spec.frames[:6], "black", "ignore"]})
        bistair.decode(stack, wrong)


def test_frames_list_errors():
    base = bistair.make_spec("graycode", width=480, height=64, period=30).to_dict()
    for frames, reason in ((base["frames"][:-1], "misses"),
                           ([*base["frames"], "black", "black"], "more than once"),
                           ([*base["frames"], "white"], "white")):
        with pytest.raises(BistairError, match=reason):
            bistair.spec_from_dict({**base, "frames": frames})


@pytest.mark.parametrize(("method", "params"), [
    ("bidirectional", dict(period="1920/58", partitions=8, stairs=8)),
    ("graycode", dict(period="1920/58", complementary=1)),
    ("phase-coding", dict(period="1920/58")),
    ("multifreq", dict(periods=("1920/1", "1920/8", "1920/58")))])
def test_fractional_periods(method, params):
    numbers = {k: (tuple(eval(v) for v in x) if isinstance(x, tuple) else eval(x))
               if k.startswith("period") else x for k, x in params.items()}
    data = {**bistair.make_spec(method, width=1920, height=1080, **numbers).to_dict(), **params}
    data.pop("frames")
    spec = bistair.spec_from_dict(data)
    if method == "multifreq":
        assert spec.frames[-1] == "T33.1034-shift-3"
    else:
        assert spec.period == 1920 / 58 and spec.fringes == 58
    pats = bistair.encode(spec)
    res = bistair.decode(pats, spec)
    assert res.mask.all()
    assert np.abs(res.coord - np.arange(1920)[None, :]).max() < 1e-2
    assert bistair.spec_from_dict(spec.to_dict()) == spec


def _read_errors(result, truth, spec) -> float:
    """The share of the pixels read whose order, as the code reads it, is off."""
    read = truth.mask & (result.code >= 0)
    phase = result.wrapped + 2 * np.pi * result.code
    return float((read & (np.abs(phase - 2 * np.pi * truth.coord(spec) / spec.period)
                          > np.pi)).sum() / read.sum())


@pytest.mark.parametrize("offset", [0.0, 0.5])
def test_gray_code_misreads_beside_its_edges_are_outvoted(offset):
    """Plain and shifted codes misread beside their edges (at the phase jumps, or mid-fringe
    for the shifted one): 1.6% of the pixels as read. Per pixel the evidence test leaves
    them out of the plain code (no order error, 1.6% fewer pixels); voting per fringe region
    gives them their orders, and so does the shifted code's pixel rule beside its edges
    (:mod:`bistair.codecs.graycode_edges`: mid-fringe the phase is continuous)."""
    scene = warped_scene(1, noise=0.02, blur=1.5)
    spec = bistair.make_spec("graycode", width=1080, height=1080, period=30,
                             gray_offset=offset)
    images, truth = render_warp(spec, scene)
    results = {s: bistair.decode(images, spec, strategy=s) for s in ("pixel", "region")}
    found = {s: score(r, truth.coord(spec), truth.mask) for s, r in results.items()}
    assert _read_errors(results["pixel"], truth, spec) > 0.005
    assert found["pixel"]["order_error_rate"] < 0.0005 and found["pixel"]["coverage"] > 0.97
    assert found["region"]["order_error_rate"] < 0.0005 and found["region"]["coverage"] > 0.99
    if offset:
        assert found["pixel"]["coverage"] > 0.99 and results["pixel"].info["edge_orders"] > 0
    else:
        assert found["pixel"]["coverage"] < found["region"]["coverage"]
    assert bistair.make_spec("graycode", width=1080, height=1080, period=30,
                             gray_offset=0.5).code_bits == 6  # 37 levels


def test_gray_code_checked_by_a_second_period():
    """The kamino layout: 3-step sets at 100 and 200/3 px, Gray cells of 100 px, inverses.
    Without the second period 1.1% of the pixels read one order off; the evidence test
    leaves them out, the second period reads them right."""
    spec = bistair.make_spec("graycode", width=1920, height=1080, period=100, steps=3,
                             second_period=200 / 3, inverse=1)
    plain = spec.replace(second_period=0.0, frame_order=())
    scene = WarpScene(size=(400, 640), stretch=2.5, noise=0.02, blur=1.5, seed=3)
    images, truth = render_warp(spec, scene)
    checked = score(bistair.decode(images, spec), truth.coord(spec), truth.mask)
    keep = [spec.frames.index(n) for n in plain.frames]
    result = bistair.decode(images[keep], plain)
    alone = score(result, truth.coord(spec), truth.mask)
    assert _read_errors(result, truth, plain) > 0.005
    assert alone["order_error_rate"] < 0.0005 and alone["coverage"] > 0.97
    assert checked["order_error_rate"] < 0.0005 and checked["coverage"] > 0.97
    assert alone["coverage"] < checked["coverage"]
    with pytest.raises(BistairError, match="whole number"):
        spec.replace(second_period=50.0)


def test_heterodyne_beats_at_the_projector_edges():
    """Periods 42/45/48 (beats 630, 720 and 5040) on a 1920-px projector: pixels seeing
    its first columns decode near 0, not a beat period up; nothing lands off the projector."""
    spec = bistair.make_spec("multifreq", width=1920, height=1080, periods=(42, 45, 48),
                             steps=12)  # the CFPE layout
    for offset in (-25.0, 1600.0):  # the left edge, then the right edge in view
        scene = WarpScene(size=(240, 400), offset=offset, noise=0.02, blur=1.0, seed=5)
        images, truth = render_warp(spec, scene)
        res = bistair.decode(images, spec)
        assert np.nanmax(res.coord) < 1920 and np.nanmin(res.coord) >= 0
        m = score(res, truth.coord(spec), truth.mask)
        assert m["order_error_rate"] == 0 and m["coverage"] > 0.95, m
        edge = truth.mask & ((truth.coord(spec) < 15) | (truth.coord(spec) > 1905))
        assert (res.mask & edge).sum() > 0.9 * edge.sum() > 0


def test_three_step_noise_estimate():
    spec = bistair.make_spec("graycode", width=1080, height=1080, period=30, steps=3)
    for noise in (0.005, 0.02):
        scene = WarpScene(size=(300, 400), blobs=(Blob(200, 150, 180, 130),), noise=noise,
                          blur=0.7, bits=None, seed=2)
        images, _ = render_warp(spec, scene)
        est = bistair.get_codec("graycode").phase_map(images, spec).noise
        assert 0.8 * noise < est < 1.25 * noise


def test_white_and_black_frames_mask_low_contrast():
    """A pixel whose white and black frames barely differ is in shadow, however its fringe
    frames happen to vary."""
    spec = bistair.make_spec("graycode", width=480, height=64, period=30, white=1)
    frames = [*spec.frames, "black"]
    spec = bistair.spec_from_dict({**spec.to_dict(), "frames": frames})
    pats = bistair.encode(spec)
    pats[-2, :, :40] = 0.008  # white barely above black on the left
    res = bistair.decode(pats, spec)
    assert not res.mask[:, :40].any() and res.mask[:, 40:].all()


def test_cli_takes_globs_files_and_folders(tmp_path, monkeypatch, capsys):
    spec = bistair.make_spec("graycode", width=480, height=64, period=30)
    pats = bistair.encode(spec)
    caps = tmp_path / "scan"
    caps.mkdir()
    from bistair.io.atomic import write_image

    for i, img in enumerate(pats):  # names that sort wrong as text: pat2 before pat10
        write_image(caps / f"pat{i * 5}.png", np.round(img * 255).astype(np.uint8))
    (caps / "notes.txt").write_text("not an image")
    (caps / "._pat0.png").write_bytes(b"\0\0")  # macOS resource fork
    (tmp_path / "spec.json").write_text(spec.to_json())
    for args in ([str(caps / "pat*.png")], [caps],
                 [caps / f"pat{i * 5}.png" for i in range(len(pats))]):
        out = tmp_path / "out"
        code, stdout, err = cli_run(monkeypatch, capsys, "decode", *args, "--spec",
                                    tmp_path / "spec.json", "--out", out)
        assert code == 0, err
        coord = np.load(out / "coord.npy")
        assert np.abs(coord - np.arange(480)).max() < 0.05  # 8-bit patterns
