"""No thresholded check refuses a right decode of the real captures in ../shared/data, part
by part (each axis, each code alone, each strategy: tests/support/real_parts.py); and
``--force`` decodes where a check would refuse, saying so, while hard errors stay errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import cli_run
from support.real_parts import parts

import bistair
from bistair.io.atomic import write_image
from bistair.io.read import read_with_spec

PARTS = list(parts())
# no part is refused (kamino's rows axis as a plain 3-step + Gray code by regions was, rightly,
# while parts of regions were decoded on codes their pixels' evidence did not carry: 47% of its
# pixels one order off; tests/test_graycode_region_real.py holds both axes to the rig's decode)
WRONG: set[str] = set()


@pytest.mark.skipif(not PARTS, reason="no real captures under ../shared/data")
@pytest.mark.parametrize(("name", "folder", "spec", "options"), PARTS,
                         ids=[p[0] for p in PARTS])
def test_real_captures_are_not_refused(name, folder, spec, options):
    stack, spec = read_with_spec(folder, spec)
    if name in WRONG:
        with pytest.raises(bistair.BistairError, match="do not step by one"):
            bistair.decode(stack, spec, **options)
        return
    result = bistair.decode(stack, spec, **options)
    results = [result.x, result.y] if hasattr(result, "x") else [result]
    for res in results:
        assert res.mask.mean() > 0.4 and "forced" not in res.info


def _swapped_gray(tmp_path):
    """Gray code + phase captures with two code frames exchanged (the orders jump by whole
    blocks: refused), written as a capture folder."""
    spec = bistair.make_spec("graycode", width=480, height=64, period=30)
    images = np.round(bistair.encode(spec) * 200 + 20).astype(np.uint8)
    images[[4, 5]] = images[[5, 4]]
    folder = tmp_path / "caps"
    folder.mkdir()
    for i, image in enumerate(images):
        write_image(folder / f"{i:02d}.png", image)
    (folder / "spec.json").write_text(spec.to_json())
    return folder


def test_force_decodes_where_a_check_refuses(tmp_path, monkeypatch, capsys):
    folder = _swapped_gray(tmp_path)
    code, _, err = cli_run(monkeypatch, capsys, "decode", folder, "--out", tmp_path / "a")
    assert code == 2 and "jump by whole blocks" in err and not (tmp_path / "a").exists()
    code, text, err = cli_run(monkeypatch, capsys, "decode", folder, "--out", tmp_path / "b",
                              "--force")
    assert code == 0, err
    assert "Warning: forced past a check: the fringe orders jump by whole blocks" in err
    info = json.loads((tmp_path / "b" / "info.json").read_text())
    assert len(info["forced"]) >= 1 and "whole blocks" in info["forced"][0]
    assert np.load(tmp_path / "b" / "order.npy").max() >= 0


def test_force_keeps_hard_errors(tmp_path, monkeypatch, capsys):
    folder = _swapped_gray(tmp_path)
    (folder / "07.png").unlink()  # a frame fewer than the spec says
    code, _, err = cli_run(monkeypatch, capsys, "decode", folder, "--out", tmp_path / "c",
                           "--force")
    assert code == 2 and "needs 8 frames" in err and not (tmp_path / "c").exists()
