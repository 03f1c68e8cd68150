"""``bistair batch``: many capture sets on Dask, on a local cluster and on a scheduler and a
worker started as separate processes; failing sets, --resume, Ctrl-C; the outputs equal a
plain loop over ``bistair decode`` / ``bistair reconstruct``."""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import PATIENCE, cli_run

from bistair.app import batch as batch_module
from bistair.app import engine
from bistair.app.batch import MARKER, Options, SetJob, find_sets, run_set
from bistair.app.simulate import simulate
from bistair.errors import BistairError
from bistair.geometry.calibration import Calibration, save_calibration
from bistair.io.atomic import replace_folder
from bistair.sim import preset

CAMERA = (160, 128)


@pytest.fixture(scope="module")
def scans(tmp_path_factory) -> Path:
    """ROOT with two good sets (a sphere and a plane, graycode, 160 x 128) and three bad:
    a frame missing, a corrupt image and dark captures."""
    root = tmp_path_factory.mktemp("scans")
    sim = root.parent / f"{root.name}-sim"
    for scene in ("sphere-on-plane", "plane"):
        simulate(scene, ["graycode"], sim / scene, camera_size=CAMERA, seed=3)
    shutil.copytree(sim / "sphere-on-plane" / "graycode", root / "sphere")
    shutil.copytree(sim / "plane" / "graycode", root / "plane")
    shutil.copytree(root / "plane", root / "short")
    (root / "short" / "10.png").unlink()
    shutil.copytree(root / "plane", root / "corrupt")
    (root / "corrupt" / "03.png").write_bytes(b"not a png")
    shutil.copytree(root / "plane", root / "dark")
    for png in (root / "dark").glob("*.png"):
        shutil.copy(sim / "plane" / "graycode" / "00.png", png)  # every frame alike: no fringes
    rig, _ = preset("sphere-on-plane", camera_size=CAMERA)
    save_calibration(Calibration.from_rig(rig), root.parent / f"{root.name}-calib.json")
    return root


def _calibration(scans: Path) -> Path:
    return scans.parent / f"{scans.name}-calib.json"


def _rows(out: Path) -> dict[str, dict[str, str]]:
    with (out / "batch.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["name", "status", "error", "valid_fraction", "noise", "seconds",
                             "resumed"]
    return {row["name"]: row for row in rows}


def _plain_loop(scans: Path, names, out: Path, monkeypatch, capsys, *extra) -> dict[str, str]:
    """``bistair decode`` per set: the errors of those that fail."""
    errors = {}
    for name in names:
        code, _, err = cli_run(monkeypatch, capsys, "decode", scans / name, "--out",
                               out / name, *extra)
        if code:
            assert code == 2 and err.startswith("Error: ")
            errors[name] = err.strip().removeprefix("Error: ")
    return errors


def _same_outputs(a: Path, b: Path) -> None:
    """The same files with the same contents (the batch's marker aside)."""
    names = sorted(p.name for p in a.iterdir() if p.name != MARKER)
    assert names == sorted(p.name for p in b.iterdir())
    for name in names:
        if name.endswith(".npy"):
            assert np.array_equal(np.load(a / name), np.load(b / name), equal_nan=True), name
        else:
            assert (a / name).read_bytes() == (b / name).read_bytes(), name


def _no_temporaries(folder: Path) -> None:
    assert not [p.name for p in folder.rglob(".bistair-*")]


def test_batch_on_a_local_cluster_equals_a_plain_loop(scans, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    code, text, err = cli_run(monkeypatch, capsys, "batch", scans, "--out", out,
                              "--workers", 2)
    assert code == 3, err  # some sets failed (0: all decoded, 2: bad input)
    rows = _rows(out)
    assert list(rows) == ["corrupt", "dark", "plane", "short", "sphere"]  # natural order
    errors = _plain_loop(scans, rows, tmp_path / "loop", monkeypatch, capsys)
    assert sorted(errors) == ["corrupt", "dark", "short"]
    for name, row in rows.items():
        if name in errors:  # the same one-line message as bistair decode's
            assert row["status"] == "error" and row["error"] == errors[name]
            assert not (out / name).exists()
            assert f"failed {name}: {errors[name]}" in text
        else:
            assert row["status"] == "ok" and row["error"] == "" and row["resumed"] == "no"
            _same_outputs(out / name, tmp_path / "loop" / name)
            info = json.loads((out / name / "info.json").read_text())
            assert float(row["valid_fraction"]) == pytest.approx(
                np.load(out / name / "mask.npy").mean(), abs=1e-6)
            assert float(row["noise"]) == pytest.approx(info["noise"], abs=1e-6)
            assert float(row["seconds"]) > 0
    assert "frames" in rows["short"]["error"] and "03.png" in rows["corrupt"]["error"]
    assert "5 sets: 2 ok, 3 failed" in text and "on 2 workers" in text
    _no_temporaries(out)


def test_resume_skips_complete_sets_and_redoes_the_rest(scans, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    code, _, err = cli_run(monkeypatch, capsys, "batch", scans, "--out", out, "--workers", 1,
                           "--no-previews")
    assert code == 3, err
    plane_marker = (out / "plane" / MARKER).stat().st_mtime_ns
    (out / "sphere" / "order.npy").unlink()  # incomplete: redone
    (out / ".bistair-batch-0123456789ab-x").mkdir()  # a killed run's temporary
    code, text, err = cli_run(monkeypatch, capsys, "batch", scans, "--out", out, "--workers", 1,
                              "--no-previews", "--resume")
    assert code == 3, err
    rows = _rows(out)
    assert rows["plane"]["resumed"] == "yes" and rows["sphere"]["resumed"] == "no"
    assert (out / "plane" / MARKER).stat().st_mtime_ns == plane_marker
    assert (out / "sphere" / "order.npy").exists()
    assert all(rows[n]["status"] == "error" and rows[n]["resumed"] == "no"
               for n in ("corrupt", "dark", "short"))  # failed sets are tried again
    assert "(1 complete before, skipped)" in text
    _no_temporaries(out)
    # other options make other outputs: nothing is complete for them
    code, text, _ = cli_run(monkeypatch, capsys, "batch", scans, "--out", out, "--workers", 1,
                            "--resume")
    assert code == 3 and "complete before" not in text
    assert (out / "plane" / "phase.png").exists()


def test_manifest_with_defaults_and_a_calibration(scans, tmp_path, monkeypatch, capsys):
    calib = _calibration(scans)
    manifest = tmp_path / "sets.csv"
    rel = os.path.relpath(scans, tmp_path)
    manifest.write_text("# captures relative to this file\n"
                        "captures,spec,calibration,out,notes\n"
                        f"{rel}/sphere,,,ball,anything\n"
                        f"{rel}/plane,{rel}/plane/spec.json,,,\n\n"
                        f"{rel}/sphere,,{calib},nested/ball2,\n")
    out = tmp_path / "out"
    code, text, err = cli_run(monkeypatch, capsys, "batch", manifest, "--out", out,
                              "--calibration", calib, "--workers", 1)
    assert code == 0, err
    rows = _rows(out)
    assert list(rows) == ["ball", "plane", "nested/ball2"]
    assert all(row["status"] == "ok" for row in rows.values())
    code, _, err = cli_run(monkeypatch, capsys, "reconstruct", scans / "sphere",
                           "--calibration", calib, "--out", tmp_path / "loop" / "cloud.ply")
    assert code == 0, err
    loop = tmp_path / "loop"
    assert (out / "ball" / "cloud.ply").read_bytes() == (loop / "cloud.ply").read_bytes()
    assert np.array_equal(np.load(out / "ball" / "depth.npy"),
                          np.load(loop / "cloud-depth" / "depth.npy"), equal_nan=True)
    assert (out / "nested" / "ball2" / "cloud.ply").exists()
    assert (out / "plane" / "depth.npy").exists()


def test_batch_refuses_bad_input_with_one_line(scans, tmp_path, monkeypatch, capsys):
    def refused(*args) -> str:
        code, out, err = cli_run(monkeypatch, capsys, "batch", *args)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
        assert err.startswith("Error: ")
        return err

    out = tmp_path / "out"
    assert "not found" in refused(tmp_path / "nothing", "--out", out)
    assert "is the input " in refused(scans, "--out", scans)
    assert "holds the input " in refused(scans / "plane", "--out", scans)
    assert "--depth-range applies to the reconstruction: give --calibration too" in \
        refused(scans, "--out", out, "--depth-range", "0:100")
    assert "--workers must be 1 or more" in refused(scans, "--out", out, "--workers", 0)
    assert "with --scheduler" in refused(scans, "--out", out, "--workers", 2, "--scheduler",
                                         "tcp://127.0.0.1:1")
    assert "spec file" in refused(scans, "--out", out, "--spec", tmp_path / "none.json")
    assert "between 0 and 1" in refused(scans, "--out", out, "--min-modulation", 2)
    (tmp_path / "empty").mkdir()
    assert "no capture sets" in refused(tmp_path / "empty", "--out", out)
    bad = tmp_path / "bad.csv"
    bad.write_text("folder,spec\nscans/plane,\n")
    assert "'captures' column" in refused(bad, "--out", out)
    bad.write_text(f"captures,out\n{scans}/plane,x\n{scans}/sphere,x\n")
    assert "both write to" in refused(bad, "--out", out)
    monkeypatch.setattr(engine, "CONNECT_TIMEOUT", 1)
    assert "cannot reach the Dask scheduler" in refused(scans, "--out", out, "--scheduler",
                                                        "tcp://127.0.0.1:1")
    assert not out.exists()


def test_sets_of_a_folder_leave_out_hidden_folders_and_the_output(scans, tmp_path):
    root = tmp_path / "root"
    for name in ("s10", "s2", ".hidden", "out"):
        (root / name).mkdir(parents=True)
    for name in ("s10", "s2", ".hidden"):
        (root / name / "00.png").write_bytes(b"x")  # listed, not read
    (root / "notes.txt").write_text("x")
    assert [j.name for j in find_sets(root, root / "out")] == ["s2", "s10"]
    (root / "s2" / "00.png").unlink()  # a set folder without images: still a set (it fails)
    assert [j.name for j in find_sets(root, root / "out")] == ["s2", "s10"]
    (root / "s10" / "00.png").unlink()
    with pytest.raises(BistairError, match=r"none of its 2 sub-folders holds images \(or L/"):
        find_sets(root, root / "out")
    (root / "s2" / "L").mkdir()
    (root / "s2" / "R").mkdir()  # a stereo set (two cameras): a set
    assert [j.name for j in find_sets(root, root / "out")] == ["s2", "s10"]
    pair = f"bistair stereo {root / 's2' / 'L'} {root / 's2' / 'R'}"
    with pytest.raises(BistairError, match="it is one set of two cameras itself: "
                                           + re.escape(pair)):
        find_sets(tmp_path / "root" / "s2", tmp_path / "o")


# -- Ctrl-C ----------------------------------------------------------------------------------
def _bistair(*args, **kwargs) -> subprocess.Popen:
    """``bistair ...`` in a new session (its own process group, as on a terminal)."""
    return subprocess.Popen([sys.executable, "-m", "bistair", *map(str, args)],
                            start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **kwargs)


def _group_alive(pgid: int) -> bool:
    """Whether a process of the group ``pgid`` still runs."""
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def _end(proc: subprocess.Popen) -> None:
    """End a process group this test started, if it still runs."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 1), (signal.SIGTERM, 143)],
                         ids=["ctrl-c", "sigterm"])
def test_ctrl_c_leaves_no_half_written_set_and_resume_goes_on(scans, tmp_path, sig, code):
    """Ctrl-C (the terminal's whole process group) and SIGTERM (``kill``: this process
    alone; until issue 31 it left no batch.csv) alike: batch.csv lists the finished sets."""
    root = tmp_path / "root"
    names = [f"s{i:02d}" for i in range(24)]
    for name in names:
        shutil.copytree(scans / "sphere", root / name)
    out = tmp_path / "out"
    proc = _bistair("batch", root, "--out", out, "--workers", 1)
    try:
        deadline = time.monotonic() + PATIENCE
        while not list(out.glob(f"*/{MARKER}")) and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.01)
        # the group frozen while the interrupt is sent: the batch cannot finish in between,
        # so an exit code of 0 can only mean a handler that swallowed it
        os.killpg(proc.pid, signal.SIGSTOP)
        unfinished = len(list(out.glob(f"*/{MARKER}"))) < len(names)
        if sig == signal.SIGINT:
            os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C on the terminal: the whole group
        else:
            proc.send_signal(signal.SIGTERM)
        os.killpg(proc.pid, signal.SIGCONT)
        _, err = proc.communicate(timeout=PATIENCE)
    finally:
        _end(proc)
    if not unfinished:
        pytest.skip("the batch finished every set before it was stopped")
    assert proc.returncode == code and "Interrupted" in err and "Traceback" not in err, err
    deadline = time.monotonic() + 30  # no worker outlives the batch (its process group)
    while _group_alive(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _group_alive(proc.pid), "a worker process outlived the batch"
    _no_temporaries(out)
    done = {p.parent.name for p in out.glob(f"*/{MARKER}")}
    assert {p.name for p in out.iterdir()} == done | {"batch.csv"}  # no half-written set
    assert set(_rows(out)) == done
    proc = _bistair("batch", root, "--out", out, "--workers", 1, "--resume")
    try:
        text, err = proc.communicate(timeout=PATIENCE)
    finally:
        _end(proc)
    assert proc.returncode == 0, err
    rows = _rows(out)
    assert list(rows) == names and all(r["status"] == "ok" for r in rows.values())
    assert {n for n, r in rows.items() if r["resumed"] == "yes"} == done
    _no_temporaries(out)


# -- a scheduler and a worker as separate processes --------------------------------------------
@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """``dask scheduler`` and ``dask worker`` (one process, one thread) on 127.0.0.1, ended
    when the tests of this module are done, whatever happened."""
    folder = tmp_path_factory.mktemp("dask")
    info = folder / "scheduler.json"
    procs: list[subprocess.Popen] = []

    def start(*args) -> None:
        log = (folder / f"{args[0]}.log").open("w")
        procs.append(subprocess.Popen([sys.executable, "-m", "dask", *map(str, args)],
                                      cwd=folder, stdout=log, stderr=subprocess.STDOUT,
                                      start_new_session=True))

    try:
        start("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
              "--scheduler-file", info, "--idle-timeout", "600")
        deadline = time.monotonic() + PATIENCE
        address = None
        while address is None and time.monotonic() < deadline:
            assert procs[0].poll() is None, (folder / "scheduler.log").read_text()
            try:  # the file appears before the scheduler has written it
                address = json.loads(info.read_text())["address"]
            except (OSError, ValueError, KeyError):
                time.sleep(0.05)
        assert address is not None, (folder / "scheduler.log").read_text()
        start("worker", address, "--nthreads", 1, "--nworkers", 1, "--no-dashboard",
              "--host", "127.0.0.1", "--death-timeout", 60, "--local-directory", folder)
        yield address
    finally:
        for proc in reversed(procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGTERM)
                try:
                    proc.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait(timeout=15)


def test_batch_on_a_separate_scheduler_and_worker(scans, scheduler, tmp_path, monkeypatch,
                                                  capsys):
    out = tmp_path / "out"
    code, text, err = cli_run(monkeypatch, capsys, "batch", scans, "--out", out, "--scheduler",
                              scheduler)
    assert code == 3, err
    assert "on 1 worker" in text
    rows = _rows(out)
    errors = _plain_loop(scans, rows, tmp_path / "loop", monkeypatch, capsys)
    for name, row in rows.items():
        assert row["error"] == errors.get(name, "")
        if name not in errors:
            _same_outputs(out / name, tmp_path / "loop" / name)
    shutil.rmtree(out / "plane")
    code, text, err = cli_run(monkeypatch, capsys, "batch", scans, "--out", out, "--scheduler",
                              scheduler, "--resume")
    assert code == 3, err
    rows = _rows(out)
    assert rows["sphere"]["resumed"] == "yes" and rows["plane"]["resumed"] == "no"
    _same_outputs(out / "plane", tmp_path / "loop" / "plane")
    _no_temporaries(out)


def test_replace_folder_keeps_the_old_folder_on_error(tmp_path):
    out = tmp_path / "set"
    out.mkdir()
    (out / "old.npy").write_bytes(b"old")
    with pytest.raises(RuntimeError), replace_folder(out, ".bistair-batch-test-") as tmp:
        (tmp / "new.npy").write_bytes(b"new")
        raise RuntimeError("interrupted")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]
    assert [p.name for p in out.iterdir()] == ["old.npy"]


def test_a_set_that_breaks_the_decoder_is_an_error_row(scans, tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("something unforeseen\nwith a second line")

    monkeypatch.setattr(batch_module, "decode_folder", broken)
    job = SetJob("plane", str(scans / "plane"), None, None, str(tmp_path / "out" / "plane"))
    row = run_set(job, Options())
    assert row["status"] == "error"
    assert row["error"] == "RuntimeError: something unforeseen"
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


def test_a_set_never_replaces_its_own_inputs(scans, tmp_path):
    """A set's folder is replaced as a whole: one that holds the set's spec or calibration
    (a manifest can say so) is an error row, and they stay (issue 31)."""
    out = tmp_path / "out" / "plane"
    out.mkdir(parents=True)
    spec = shutil.copy(scans / "plane" / "spec.json", out / "spec.json")
    row = run_set(SetJob("plane", str(scans / "plane"), str(spec), None, str(out)), Options())
    assert row["status"] == "error" and "plane holds the input " in row["error"], row
    assert [p.name for p in out.iterdir()] == ["spec.json"]


@pytest.mark.parametrize("cell", ["../victim", "{abs}", ".", "a/../.."])
def test_a_manifest_out_cell_must_stay_inside_out(cell, tmp_path):
    """An out cell that leaves OUT would replace (delete) a folder the batch does not own."""
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "thesis.txt").write_text("important")
    (tmp_path / "caps").mkdir()
    manifest = tmp_path / "sets.csv"
    manifest.write_text(f"captures,out\ncaps,{cell.format(abs=victim)}\n")
    with pytest.raises(BistairError, match="must name a folder inside the output folder"):
        find_sets(manifest, tmp_path / "out")
    assert (victim / "thesis.txt").read_text() == "important"


def test_an_output_folder_inside_a_capture_set_is_refused(tmp_path):
    root = tmp_path / "scans"
    for name in ("s0", "s1"):
        (root / name).mkdir(parents=True)
        (root / name / "00.png").write_bytes(b"")
    with pytest.raises(BistairError, match="is one of the capture sets"):
        find_sets(root, root / "s0")
    with pytest.raises(BistairError, match="is inside the capture set s1"):
        find_sets(root, root / "s1" / "results")
    assert [job.name for job in find_sets(root, root / "results")] == ["s0", "s1"]


def test_resume_redoes_a_set_whose_captures_or_spec_changed(scans, tmp_path):
    root = tmp_path / "root"
    for name in ("a", "b"):
        shutil.copytree(scans / "plane", root / name)
    options, out = Options(previews=False), tmp_path / "out"
    jobs = find_sets(root, out)
    for job in jobs:
        assert run_set(job, options)["status"] == "ok"
    assert all(batch_module.complete_row(job, options) is not None for job in jobs)
    shutil.copy(scans / "sphere" / "01.png", root / "a" / "01.png")  # other captures
    spec = root / "b" / "spec.json"
    spec.write_text(spec.read_text() + "\n")  # the set's own spec file rewritten
    assert [batch_module.complete_row(job, options) for job in jobs] == [None, None]
