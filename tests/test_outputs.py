"""No output replaces, holds or mixes with an input (issue 31): the rule of
``io.atomic.check_output``, the writers that apply it to the running command's inputs
(``io.inputs``), and the outputs beside or inside inputs that stay allowed. The refusals of
each command are rows of ``test_bad_input.py``."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import cli_run

import bistair
from bistair.app.patterns import save_patterns
from bistair.errors import BistairError
from bistair.io.atomic import check_output, output_file, output_folder, replace_folder
from bistair.io.inputs import reading


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """``set/left`` (a capture folder with ``00.png``), ``set/right``, ``calib.json`` and a
    symbolic link ``link`` to ``set/left``; the working directory is ``tmp_path``."""
    for side in ("left", "right"):
        (tmp_path / "set" / side).mkdir(parents=True)
        (tmp_path / "set" / side / "00.png").write_bytes(b"png")
    (tmp_path / "calib.json").write_text("{}")
    (tmp_path / "link").symlink_to(tmp_path / "set" / "left", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    return tmp_path


INPUTS = ["set/left", "set/right/*.png", "calib.json"]


@pytest.mark.parametrize(("out", "file", "message"), [
    ("set/left", False, "the output set/left is the input set/left: choose another output"),
    ("set/right", False, "is the input set/right"),  # a glob pattern stands for its folder
    ("calib.json", True, "the output calib.json is the input calib.json"),
    ("set", False, "the output set holds the input set/left: choose another output"),
    (".", False, "the output . holds the input set/left"),
    ("set/left/..", False, "the output set/left/.. holds the input set/left"),
    ("link", False, "the output link is the input set/left"),  # symbolic links followed
    ("link/../..", False, "holds the input set/left"),
    ("set/left/01.png", True, "the output set/left/01.png lies in the capture folder "
                              "set/left: choose another output (the folder's next read"),
    ("link/x.TIF", True, "lies in the capture folder set/left"),
])
def test_outputs_that_are_hold_or_mix_with_an_input_are_refused(tree, out, file, message):
    with pytest.raises(BistairError) as exc:
        check_output(out, INPUTS, file=file)
    assert message in str(exc.value)


@pytest.mark.parametrize(("out", "file"), [
    ("result", False), ("set/left/decoded", False), ("set/left/.png", False),
    ("set/left/cloud.ply", True), ("set/left/gamma.json", True), ("set/left/.hidden.png", True),
    ("set/stereo.json", True), ("set/left/sub/00.png", True), ("link/decoded", False),
])
def test_outputs_beside_or_inside_an_input_are_allowed(tree, out, file):
    """Inside an input folder, what its next read would not take is fine (a folder, a file
    that is not an image, a hidden one); beside the inputs too."""
    assert check_output(out, INPUTS, file=file) == Path(out)


def test_the_writers_refuse_the_running_commands_inputs(tree):
    """Within a command's scope each writer refuses first and writes nothing; outside one
    (Python code) it writes what it is asked to."""
    before = sorted(p.relative_to(tree).as_posix() for p in tree.rglob("*"))
    with reading("set/left", "set/right"):
        for write, out in ((output_folder, "set"), (replace_folder, "set/right"),
                           (output_file, "set/left/00.png"), (output_folder, "link")):
            with pytest.raises(BistairError, match="choose another output"):
                with write(out) as tmp:
                    (tmp / "x" if tmp.is_dir() else tmp).write_text("new")
        with output_folder("set/left/decoded") as tmp:
            (tmp / "phase.npy").write_text("x")
    assert sorted(p.relative_to(tree).as_posix() for p in tree.rglob("*")) == \
        sorted([*before, "set/left/decoded", "set/left/decoded/phase.npy"])
    with replace_folder("set/right") as tmp:  # no command runs: nothing is an input
        (tmp / "new.txt").write_text("new")
    assert [p.name for p in (tree / "set" / "right").iterdir()] == ["new.txt"]


def test_the_command_line_writes_inside_an_input_folder(tmp_path, monkeypatch, capsys):
    """``--out scan/decoded`` (again: it replaces its earlier self) and a JSON file in the
    capture folder: the usual places, not refused."""
    pats = tmp_path / "pats"
    save_patterns(bistair.make_spec("graycode", width=64, height=48, period=16), pats)
    for _ in range(2):
        code, _, err = cli_run(monkeypatch, capsys, "decode", pats, "--out", pats / "decoded",
                               "--no-previews")
        assert code == 0, err
    code, _, err = cli_run(monkeypatch, capsys, "decode", pats, "--out", pats, "--no-previews")
    assert code == 2 and "pats is the input " in err
    assert sorted(p.name for p in pats.iterdir() if not p.suffix == ".png") == \
        ["decoded", "spec.json"]
