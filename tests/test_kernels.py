"""The compiled kernels: the list compiled at install time covers what every codec's decode
runs, kernels compiled into a folder load from it in a new process without compiling, and
the command line says once that it compiles when it must (and not when it need not)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import bistair
from bistair.app.kernels import parse_type, read_signatures, type_name
from bistair.app.progress import COMPILE_NOTICE
from bistair.core.jit import compiled_kernels
from bistair.core.result_jit import _assemble

SRC = Path(__file__).resolve().parents[1] / "src"


def test_every_listed_type_reads_back():
    listed = read_signatures()
    assert sum(len(s) for s in listed.values()) > 40
    for sigs in listed.values():
        for sig in sigs:
            for name in sig:
                assert type_name(parse_type(name)) == name


# every codec and strategy, 8 and 16 bit, float captures, the rows axis and both axes
DECODES = [
    ("bidirectional", {}, {}, np.uint8), ("bidirectional", {}, {"strategy": "paper"}, np.uint8),
    ("bidirectional", {"orientation": "rows"}, {}, np.uint16),
    ("bidirectional", {"steps": 3}, {}, np.float32),
    ("multifreq", {"periods": (240, 40, 30)}, {}, np.uint8),
    ("multifreq", {"periods": (42, 45, 48), "steps": 12}, {}, np.uint16),
    ("phase-coding", {}, {}, np.uint8), ("phase-coding", {"form": "shifted"},
                                         {"strategy": "pixel"}, np.uint8),
    ("lv", {}, {}, np.uint8), ("graycode", {"complementary": 1}, {}, np.uint8),
    ("graycode", {}, {"strategy": "region"}, np.float64),
    ("graycode", {"orientation": "both"}, {}, np.uint8),
]


@pytest.mark.parametrize(("method", "params", "options", "dtype"), DECODES,
                         ids=[f"{m}-{i}" for i, (m, *_) in enumerate(DECODES)])
def test_a_decode_needs_only_listed_kernels(method, params, options, dtype):
    spec = bistair.make_spec(method, width=240, height=96,
                             **({"period": 20} if method != "multifreq" else {}), **params)
    if method == "bidirectional":
        spec = spec.replace(partitions=3, stairs=4, group_rows=16, local_rows=10)
    images = bistair.encode(spec)
    if np.issubdtype(dtype, np.integer):
        images = np.round(images * np.iinfo(dtype).max).astype(dtype)
    else:
        images = images.astype(dtype)
    try:
        bistair.decode(images, spec, **options)
    except bistair.BistairError:
        pass  # refused or not: its kernels ran
    listed = read_signatures()
    for key, sigs in compiled_kernels().items():
        for sig in sigs:
            assert tuple(type_name(t) for t in sig) in listed.get(key, []), (key, sig)


def test_a_decode_reading_moved_stair_levels_needs_only_listed_kernels():
    """A projector gamma the patterns do not compensate: the stair phase is mapped where the
    levels read (core.stair_jit.relinearize32), as no capture above needs."""
    spec = bistair.make_spec("bidirectional", width=240, height=96, period=20, partitions=3,
                             stairs=4, group_rows=16, local_rows=10)
    images = np.round(bistair.encode(spec) ** 2.2 * 255).astype(np.uint8)
    assert "stair_response" in bistair.decode(images, spec).info
    listed = read_signatures()
    for key, sigs in compiled_kernels().items():
        for sig in sigs:
            assert tuple(type_name(t) for t in sig) in listed.get(key, []), (key, sig)


def _python(code: str, env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, text=True,
                          capture_output=True, timeout=900)


def test_kernels_compiled_into_a_folder_load_without_compiling(tmp_path):
    """What the install does (``python -m bistair.app.kernels FOLDER``), for one module:
    a new process with an empty numba cache loads the kernel from the folder."""
    env = {**os.environ, "PYTHONPATH": str(SRC), "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    build = subprocess.run([sys.executable, "-m", "bistair.app.kernels", str(tmp_path / "k"),
                            "--only", "bistair.core.result_jit"], env=env, text=True,
                           capture_output=True, timeout=900)
    assert build.returncode == 0, build.stderr
    assert any(p.suffix == ".nbc" for p in (tmp_path / "k").iterdir())
    code = ("from bistair.core import jit\n"
            "from bistair.core.result_jit import _assemble\n"
            "jit.on_compile(lambda: print('compiled'))\n"
            "import numpy as np\n"
            "phi = np.zeros((4, 5), np.float32)\n"
            "_assemble(phi, np.zeros((4, 5), np.int32), np.ones((4, 5), bool), False, 30.0,"
            " 100, 1.0, False)\n"
            "print(sum(jit.dispatcher(_assemble)._cache_hits.values()))\n")
    sig = read_signatures()[f"{_assemble.py_func.__module__}._assemble"][0]
    assert sig[3:] == ("bool", "float64", "int64", "float64", "bool")  # as called above
    out = _python(code, {**env, "BISTAIR_KERNELS": str(tmp_path / "k")}, tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["1"]  # loaded, not compiled
    out = _python(code, {**env, "BISTAIR_KERNELS": "none",
                         "NUMBA_CACHE_DIR": str(tmp_path / "empty")}, tmp_path)
    assert out.stdout.split() == ["compiled", "0"]


def test_the_command_line_says_once_that_it_compiles(tmp_path):
    """With no kernel compiled anywhere, ``bistair decode`` prints the notice once (not once
    per kernel); run again, the kernels load from numba's cache and it prints nothing."""
    spec = bistair.make_spec("graycode", width=120, height=32, period=30)
    np.save(tmp_path / "caps.npy", np.round(bistair.encode(spec) * 255).astype(np.uint8))
    (tmp_path / "spec.json").write_text(spec.to_json())
    env = {**os.environ, "PYTHONPATH": str(SRC), "BISTAIR_KERNELS": "none",
           "NUMBA_CACHE_DIR": str(tmp_path / "numba"), "BISTAIR_PROGRESS_DELAY": "100"}
    runs = []
    for i in range(2):
        runs.append(subprocess.run(
            [sys.executable, "-m", "bistair", "decode", str(tmp_path / "caps.npy"), "--spec",
             str(tmp_path / "spec.json"), "--out", str(tmp_path / f"out{i}")],
            env=env, text=True, capture_output=True, timeout=1800))
        assert runs[-1].returncode == 0, runs[-1].stderr
    assert runs[0].stderr.count(COMPILE_NOTICE) == 1, runs[0].stderr
    assert runs[1].stderr.count(COMPILE_NOTICE) == 0, runs[1].stderr
