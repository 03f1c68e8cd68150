"""``bistair bench`` (issue 32): one run prints a row per codec with its figures against the
OpenCV floor timed in the same run, the floor's row and the machine's line, and writes the
same figures with --json; bad options are refused in one line before any work. Never
asserted: how fast anything is (the figures are checked against each other)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import cli_run

from bistair.evaluation.speed import CASES, opencv_floor, speed_captures, speed_cases

NUMBER = r"\s+(-?[\d.]+)"
ROOT = Path(__file__).resolve().parents[1]


def _rows(out: str) -> dict[str, list[float]]:
    """The codec rows of the table: label -> decoded %, ms, scans/s, MP/s, / floor,
    / default."""
    rows = {}
    for case in CASES:
        for line in out.splitlines():
            if line.startswith(case.label):
                rest = line[len(case.label):].replace("%", "")
                rows[case.label] = [float(v) for v in re.findall(NUMBER, rest)]
    return rows


def test_bench_prints_every_codec_against_the_floor_of_the_same_run(tmp_path, monkeypatch,
                                                                    capsys):
    figures = tmp_path / "bench.json"
    code, out, err = cli_run(monkeypatch, capsys, "bench", "--camera", "256x192", "--runs", 2,
                             "--json", figures, "--quiet")
    assert code == 0, err
    assert out == ""  # --quiet: the figures go to the file alone
    data = json.loads(figures.read_text())
    code, out, err = cli_run(monkeypatch, capsys, "bench", "--camera", "256x192", "--runs", 1)
    assert code == 0, err
    rows = _rows(out)
    assert list(rows) == [case.label for case in CASES]  # every codec, the default first
    for label, (decoded, ms, scans, mpix, ratio, to_default) in rows.items():
        assert decoded > 40, f"{label} decoded {decoded}% of the scene: no real decode"
        assert scans == pytest.approx(1e3 / ms, rel=0.02, abs=0.06)
        assert mpix == pytest.approx(256 * 192 / 1e3 / ms, rel=0.02, abs=0.06)
        assert to_default == pytest.approx(ratio / rows[CASES[0].label][4], rel=0.02, abs=0.01)
    assert rows[CASES[0].label][5] == 1.0
    assert re.search(r"^floor \(OpenCV 4-step pass\)\s+[\d.]+", out, re.M)
    assert re.search(r"^machine: \d+ cores, \d+ kernel threads, \d+ OpenCV threads; .+; numba "
                     r"threading layer (omp|tbb|workqueue)", out, re.M)
    assert "256x192" in out and "not timed" in out
    # the file: the same codecs, each ratio the median of its runs' own
    assert data["camera"] == [256, 192] and data["runs"] == 2
    assert data["first_decode_timed"] is False
    assert [c["label"] for c in data["codecs"]] == [case.label for case in CASES]
    for c in data["codecs"]:
        assert len(c["ratios"]) == 2 and c["ratio"] == pytest.approx(np.median(c["ratios"]))
        assert c["to_default"] == pytest.approx(c["ratio"] / data["codecs"][0]["ratio"])
        assert c["decoded"] > 0.4


def test_one_method_is_timed_beside_the_default(monkeypatch, capsys):
    code, out, err = cli_run(monkeypatch, capsys, "bench", "--camera", "256x192", "--runs", 1,
                             "--method", "lv")
    assert code == 0, err
    assert list(_rows(out)) == ["bidirectional 8x8 (region)", "lv 64 fringes"]


@pytest.mark.parametrize(("args", "message"), [
    (["--camera", "160x120"], "camera 160x120 is too small for the speed scene"),
    (["--camera", "9000x9000"], "camera 9000x9000 is too large"),
    (["--camera", "1280"], "expected WIDTHxHEIGHT"),
    (["--runs", "0"], "--runs must be a whole number from 1 to 1000, got 0"),
    (["--method", "lw"], "unknown method 'lw' (known: bidirectional, lv, "),
    (["--method", "lv,graycod"], "unknown method 'graycod'"),
    (["--json", "{tmp}/a-file/bench.json"], "a-file is a file, not a folder"),
])
def test_bad_options_are_refused_in_one_line_before_any_work(tmp_path, monkeypatch, capsys,
                                                             args, message):
    (tmp_path / "a-file").write_text("not a folder")
    args = [a.format(tmp=tmp_path) for a in args]
    code, out, err = cli_run(monkeypatch, capsys, "bench", *args)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def test_the_floor_is_the_four_step_phase_and_modulation():
    """The floor computes what a 4-step decode must: the phase of (I0 - I2, I3 - I1) and
    twice the modulation, on the frames the codecs decode."""
    case = speed_cases(["bidirectional"])[0]
    frames = speed_captures(case.spec(), (192, 256))
    phase, magnitude = opencv_floor(frames)
    f = frames.astype(np.float64)
    want = np.mod(np.arctan2(f[3] - f[1], f[0] - f[2]), 2 * np.pi)
    diff = np.abs(phase - want)
    assert np.minimum(diff, 2 * np.pi - diff).max() < 1e-3  # cv2.phase: 0.3 degree accuracy
    assert np.allclose(magnitude, np.hypot(f[3] - f[1], f[0] - f[2]), rtol=1e-5)


def test_where_the_time_goes_counts_every_stage_and_puts_the_code_back(monkeypatch):
    """benchmarks/stage_times.py (the speed page's five rows): the default decode's time
    split into five stages that add up to the instrumented decode, each stage holding some
    of it, every function named by a pattern; the decode's answer unchanged by the timers,
    and every module's functions put back afterwards."""
    import sys

    import bistair.codecs

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))  # as `python benchmarks/...` runs
    from stage_times import STAGES, instrumented, stage_times

    case = CASES[0]
    spec = case.spec()
    frames = speed_captures(spec, (192, 256))
    plain = bistair.codecs.decode(frames, spec)
    before = {name: {k: v for k, v in vars(m).items() if callable(v)}
              for name, m in sys.modules.items() if name.startswith("bistair")}

    def timers() -> int:
        return sum(hasattr(v, "stage") for name, m in list(sys.modules.items())
                   if name.startswith("bistair") for v in list(vars(m).values()))

    with instrumented() as clock:
        timed = bistair.codecs.decode(frames, spec)
        assert timers() > 50
    assert timers() == 0
    assert np.array_equal(timed.order, plain.order)
    assert np.array_equal(timed.phase, plain.phase, equal_nan=True)
    assert list(clock.seconds) == list(STAGES) and len(STAGES) == 5
    for stage, seconds in clock.seconds.items():
        assert seconds > 0, f"nothing counted in {stage}"
    assert sum(clock.seconds.values()) == pytest.approx(clock.total)
    assert clock.unassigned(share=0.0) == []
    for name, attrs in before.items():
        module = vars(sys.modules[name])
        assert all(module[k] is v for k, v in attrs.items() if k in module), name
    seconds, total, unassigned = stage_times(bistair.codecs.decode, frames, spec, {}, runs=1)
    assert sum(seconds.values()) == pytest.approx(total) and unassigned == []
