"""A stream of frames decoded window by window (issue 34): the single-period spec, ``decode
--window N|N+K --starts``, and ``simulate --frames N --continuous --steps --period``, against
the renderer's truth."""

import json

import numpy as np
import pytest
from conftest import cli_run

from bistair.app.decode_stream import decode_stream
from bistair.app.simulate_motion import simulate_motion
from bistair.codecs import decode, encode, make_spec
from bistair.core.motion import compensate, compensate_modulation, window_phases
from bistair.core.phase import TWO_PI, wrap
from bistair.errors import BistairError
from bistair.io.read import load_spec

CAMERA = (96, 80)
PERIOD = 120


@pytest.fixture(scope="module")
def moving(tmp_path_factory):
    """A 12-frame stream (4 steps, period PERIOD: about 6 camera px a fringe at this size)
    of a plane moving 5 mm away every frame (about 5 projector px: 0.26 rad a frame)."""
    out = tmp_path_factory.mktemp("stream") / "sim"
    return simulate_motion("plane", ["multifreq"], out, "0,0,5mm", moves="scene", frames=12,
                           continuous=True, camera_size=CAMERA, period=PERIOD)


def truth_phase(sim, times, period):
    """The wrapped phase of the truth at the mean of the frames ``times`` (a constant
    velocity: the time between them), NaN where a frame has no truth or the frames see
    different objects there (an edge moved across)."""
    frames = [sim / "truth" / f"frame-{t:04d}" for t in times]
    coords = np.stack([np.load(f / "coord.npy") for f in frames])
    ids = np.stack([np.load(f / "object_id.npy") for f in frames])
    mean = coords.mean(0)
    mean[(ids != ids[0]).any(0)] = np.nan
    return np.mod(TWO_PI * mean / period, TWO_PI)


def rms_error(phi, truth):
    both = np.isfinite(phi) & np.isfinite(truth)
    assert both.sum() > 0.5 * phi.size
    return float(np.sqrt(np.mean(wrap(phi[both] - truth[both]) ** 2)))


def test_a_single_period_spec_loads_and_decode_alone_refuses_it(moving, tmp_path, monkeypatch,
                                                                 capsys):
    """``patterns multifreq --periods 30`` loads; ``decode`` refuses it in one line that says
    why (no fringe order) and what to use, and writes nothing: a set of its 4 frames, and a
    stream of 12 (before counting them against the set's)."""
    pats = tmp_path / "p"
    code, _, _ = cli_run(monkeypatch, capsys, "patterns", "multifreq", "--periods", "30",
                         "--out", pats)
    assert code == 0
    spec = load_spec(pats / "spec.json")
    assert spec.periods == (30,) and spec.single_period and spec.frame_count == 4
    for captures in (pats, moving / "multifreq"):
        code, out, err = cli_run(monkeypatch, capsys, "decode", captures, "--out",
                                 tmp_path / "d")
        assert code == 2 and out == "" and len(err.splitlines()) == 1, err
        assert "gives no fringe order" in err and "decode --window" in err
        assert "stereo --depth-range" in err and not (tmp_path / "d").exists()
    with pytest.raises(BistairError, match="gives no fringe order"):  # the library too
        decode(encode(spec), spec)
    # one period covering the projector is still a decodable set; several still refuse
    assert not make_spec("multifreq", width=300, height=20, periods=(300,)).single_period
    with pytest.raises(BistairError, match="beat"):
        make_spec("multifreq", width=1080, height=20, periods=(30, 31), unwrap="heterodyne")


def test_the_windows_are_the_batch_form_of_the_frames_on_disk(moving, tmp_path):
    """Every window's wrapped phase and modulation, read from OUT/<start>/, are the batch
    form's (window_phases + compensate) of the frames as written; info.json says which."""
    from bistair.io.read import read_captures

    out = decode_stream(moving / "multifreq", None, tmp_path / "o", "4+2")
    frames = read_captures(moving / "multifreq").astype(np.float32) / 255
    phi, mod = window_phases(frames, 4)
    want, want_mod = compensate(phi, 2), compensate_modulation(mod, 2)
    assert sorted(p.name for p in out.iterdir()) == [f"{s:04d}" for s in range(12 - 5)]
    for s in range(7):
        got = np.load(out / f"{s:04d}" / "wrapped.npy")
        got_mod = np.load(out / f"{s:04d}" / "modulation.npy")
        info = json.loads((out / f"{s:04d}" / "info.json").read_text())
        valid = np.isfinite(got)
        assert got.dtype == np.float32 and valid.mean() > 0.7
        assert np.abs(wrap(got[valid] - want[s][valid])).max() < 1e-4
        assert np.allclose(got_mod, want_mod[s], atol=1e-5)
        assert np.array_equal(valid, got_mod >= info["threshold"])
        assert (info["start"], info["frames"], info["order"], info["lag"], info["time"]) == \
            (s, [s, s + 5], 2, 2.5, s + 2.5)
        assert not (out / f"{s:04d}" / "phase.npy").exists()  # one period: no order


def test_compensation_removes_most_of_the_motion_error_against_the_truth(moving, tmp_path):
    """Against the truth at the time each result describes: plain four-step (window 2,
    frames 2..5, time 3.5) and orders 2 and 4 (frames 2..7, 2..9: times 4.5, 5.5); the
    compensated errors are under half the plain one, near a still stream's, and a still
    stream of 3 steps decodes to the truth."""
    def error(window, times):
        out = decode_stream(moving / "multifreq", None, tmp_path / window, window, starts="2")
        return rms_error(np.load(out / "0002" / "wrapped.npy"),
                         truth_phase(moving, times, PERIOD))

    plain, order2, order4 = error("4", (3, 4)), error("4+2", (4, 5)), error("4+4", (5, 6))
    still = simulate_motion("plane", ["multifreq"], tmp_path / "still", None, frames=4,
                            continuous=True, camera_size=CAMERA, steps=3, period=90)
    out = decode_stream(still / "multifreq", None, tmp_path / "s", "3")
    floor = rms_error(np.load(out / "0000" / "wrapped.npy"), truth_phase(still, (0,), 90))
    assert floor < 0.05 and plain > 2 * floor, (floor, plain)
    assert order2 < 0.5 * plain and order4 < 0.45 * plain, (plain, order2, order4)
    spec = load_spec(still / "multifreq" / "spec.json")
    assert (spec.steps, spec.periods) == (3, (90,))


def test_decode_window_writes_the_starts_asked_for_and_drops_an_earlier_runs(
        moving, tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    code, text, err = cli_run(monkeypatch, capsys, "decode", moving / "multifreq", "--window",
                              "4", "--out", out)
    assert code == 0 and "decoded 9 windows" in text, err
    code, text, _ = cli_run(monkeypatch, capsys, "decode", moving / "multifreq", "--window",
                            "4+3", "--starts", "0,4", "--out", out)
    assert code == 0 and "decoded 2 windows" in text
    assert sorted(p.name for p in out.iterdir()) == ["0000", "0004"]
    assert json.loads((out / "0004" / "info.json").read_text())["frames"] == [4, 10]


@pytest.mark.parametrize("args, says", [
    (["--window", "4+9"], "needs 13 frames, the stream has 12"),
    (["--window", "4", "--starts", "0,9"], "--starts 9 is beyond the stream"),
    (["--window", "5"], "--window must be 4 (plain 4-step) or 4+K"),
    (["--window", "4+0"], "--window must be 4"),
    (["--window", "four"], "--window must be 4"),
    (["--window", "4", "--starts", "a"], "--starts must be frame numbers"),
    (["--starts", "0"], "--starts needs --window"),
    (["--window", "4", "--strategy", "region"], "does not apply to a stream"),
    (["--window", "4", "--spec", "periods"], "got 2 periods (1080, 30)"),
    (["--window", "4", "--spec", "graycode"], "got the method graycode"),
])
def test_a_stream_that_does_not_fit_is_refused_in_one_line(moving, tmp_path, monkeypatch,
                                                           capsys, args, says):
    specs = {"periods": make_spec("multifreq", width=1080, height=1080, periods=(1080, 30)),
             "graycode": make_spec("graycode", width=1080, height=1080, period=30)}
    if "--spec" in args:
        name = args[-1]
        (tmp_path / f"{name}.json").write_text(specs[name].to_json())
        args = [*args[:-1], tmp_path / f"{name}.json"]
    code, out, err = cli_run(monkeypatch, capsys, "decode", moving / "multifreq", *args,
                             "--out", tmp_path / "o")
    assert code == 2 and out == "" and len(err.splitlines()) == 1, err
    assert says in err, err
    assert not (tmp_path / "o").exists()


def test_simulate_takes_the_streams_steps_and_period(tmp_path, monkeypatch, capsys):
    code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                           "multifreq", "--frames", "5", "--continuous", "--steps", "5",
                           "--period", "20", "--camera", "48x40", "--out", tmp_path / "s")
    assert code == 0, err
    spec = load_spec(tmp_path / "s" / "multifreq" / "spec.json")
    assert (spec.steps, spec.periods, spec.single_period) == (5, (20,), True)
    assert len(list((tmp_path / "s" / "multifreq").glob("*.png"))) == 5
    for args, says in ((["--steps", "3"], "--steps applies to a stream"),
                       (["--frames", "3", "--continuous", "--steps", "4"],
                        "--frames must be at least 4"),
                       (["--frames", "4", "--continuous", "--period", "5000"],
                        "covers the")):
        code, _, err = cli_run(monkeypatch, capsys, "simulate", "--scene", "plane", "--method",
                               "multifreq", *args, "--camera", "48x40",
                               "--out", tmp_path / "bad")
        assert code == 2 and says in err and len(err.splitlines()) == 1, err
        assert not (tmp_path / "bad").exists()


def test_one_period_covering_the_projector_gives_the_absolute_phase(tmp_path):
    """A stream of one period as wide as the projector: its wrapped phase is absolute, so
    each window writes phase.npy too (the projector column times 2*pi/T), NaN where the
    modulation is too low."""
    spec = make_spec("multifreq", width=200, height=16, periods=(200,), steps=4)
    assert not spec.single_period
    x = np.arange(200.0)[None, :].repeat(16, 0)
    lit = np.where(x < 190, 0.4, 0.0)  # the last columns unlit
    frames = np.stack([0.5 + lit * np.cos(TWO_PI * (x + 0.5) / 200 + np.pi * i / 2)
                       for i in range(6)])
    out = decode_stream(frames, spec, tmp_path / "o", "4+1")
    phase = np.load(out / "0001" / "phase.npy")
    assert np.isnan(phase[:, 190:]).all()
    assert np.abs(phase[:, :190] - TWO_PI * (x[:, :190] + 0.5) / 200).max() < 1e-4
    assert json.loads((out / "0001" / "info.json").read_text())["absolute_phase"] is True


def test_a_stream_with_a_nan_frame_is_refused_and_nothing_is_written(tmp_path):
    spec = make_spec("multifreq", width=200, height=16, periods=(20,), steps=4)
    x = np.arange(200.0)[None, :].repeat(16, 0)
    frames = np.stack([0.5 + 0.4 * np.cos(TWO_PI * x / 20 + np.pi * i / 2) for i in range(6)])
    frames[5, 3, 3] = np.nan  # after the first set
    with pytest.raises(BistairError, match="NaN or infinite"):
        decode_stream(frames, spec, tmp_path / "o", "4")
    assert not (tmp_path / "o").exists()
