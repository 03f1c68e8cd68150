"""Every command the README and the user guide show runs as written and prints what they
show (issue 25): the docs cannot go stale.

In a Markdown file, a fenced block of language ``sh`` is a script: each line that is not a
comment is a command (``\\`` continues it), and the ``# `` lines right after a command are
its output, line for line (``...`` in a line stands for any text; an output that starts
with ``Error: `` is a refusal: exit code 2); a ``python`` block runs as one script and must
succeed. The blocks of a file run in order, and the files one after another in the order a
new user reads them (the README, getting started, the guide's pages as its index lists
them), all in one working directory, beside a ``shared`` folder that points at
``../shared`` (the real captures) and with ``examples/`` of the repository, so the commands
read as a user types them from a clone and no page may trip over what an earlier one left
(the scanning guide's board scans went into the calibration guide's ``calib/``: eight
refusals, then the old poses calibrated). A block right after ``<!-- not run: REASON -->``
(installing, hardware, a user's own files) is not run; its reason is printed. A block right
after ``<!-- file: NAME -->`` (a calibration file, a board) is written to ``NAME`` for the
commands after it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from bistair.app.progress import COMPILE_NOTICE

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
GUIDE = ROOT / "docs" / "guide"


def reading_order() -> list[Path]:
    """The README, getting started, then the guide's pages in its index's order (any page
    the index does not list after them, by name)."""
    listed = [GUIDE / f"{line.strip()}.md" for line in (GUIDE / "index.md").read_text()
              .split("```{toctree}")[1].split("```")[0].splitlines()
              if line.strip() and not line.startswith(":")]
    rest = sorted(set(GUIDE.glob("*.md")) - set(listed))
    return [ROOT / "README.md", ROOT / "docs" / "getting-started.md", *listed, *rest]


DOCS = reading_order()
FENCE = re.compile(r"^```\s*([\w{}-]*)")
NOT_RUN = re.compile(r"<!--\s*not run:\s*(.*?)\s*-->")
FILE = re.compile(r"<!--\s*file:\s*(\S+)\s*-->")


def blocks(path: Path) -> list[tuple[int, str | None, str, list[str]]]:
    """``(first line, reason not run or None, language, lines)`` of every ``sh`` and
    ``python`` block of a file, and of every block shown as a file (language ``file:NAME``)."""
    out, lines = [], path.read_text().splitlines()
    i = 0
    while i < len(lines):
        match = FENCE.match(lines[i])
        if match is None:
            i += 1
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j].startswith("```")),
                   len(lines))
        before = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        named = FILE.search(before)
        if named:  # a file the commands after it read, written as shown
            out.append((i + 1, None, f"file:{named.group(1)}", lines[i + 1:end]))
        elif match.group(1) in ("sh", "python"):
            skip = NOT_RUN.search(before)
            out.append((i + 1, skip.group(1) if skip else None, match.group(1),
                        lines[i + 1:end]))
        i = end + 1
    return out


def commands(lines: list[str]) -> list[tuple[str, list[str]]]:
    """``(command, expected output lines)`` of a block: the ``# `` lines right after a
    command (no blank line between) are its output; other comment lines are comments."""
    out: list[tuple[str, list[str]]] = []
    pending, collecting = "", False
    for line in lines:
        if pending:
            pending += " " + line.strip()
        elif line.startswith("#"):
            if collecting:
                out[-1][1].append(line[2:])
            continue
        elif line.strip():
            pending = line.strip()
        else:
            collecting = False
            continue
        if pending.endswith("\\"):
            pending = pending[:-1].rstrip()
            continue
        out.append((pending.split("  #")[0].rstrip(), []))  # a comment after the command
        pending, collecting = "", True
    return out


def matches(expected: str, got: str) -> bool:
    pattern = ".*".join(re.escape(part) for part in expected.split("..."))
    return re.fullmatch(pattern, got) is not None


def printed_as_shown(expected: list[str], printed: list[str]) -> bool:
    """Each shown line matches a printed one in order; a shown line of only ``...`` stands
    for any number of printed lines."""
    if not expected:
        return not printed
    if expected[0].strip() == "...":
        return any(printed_as_shown(expected[1:], printed[i:]) for i in range(len(printed) + 1))
    return bool(printed) and matches(expected[0], printed[0]) and \
        printed_as_shown(expected[1:], printed[1:])


CASES = [pytest.param(path, id=path.relative_to(ROOT).as_posix())
         for path in DOCS if path.exists() and any(b[1] is None for b in blocks(path))]


def _steps(language: str, lines: list[str]) -> list[tuple[list[str], str, list[str]]]:
    """``(argv, shown command, expected output)`` of a block: a ``python`` block is one
    script."""
    if language == "python":
        return [([sys.executable, "-c", "\n".join(lines)], "python script", [])]
    return [(["bash", "-c", command], command, expected)
            for command, expected in commands(lines)]


@pytest.fixture(scope="module")
def work(tmp_path_factory) -> Path:
    """The one working directory of every page: a clone's, beside ``shared``."""
    root = tmp_path_factory.mktemp("user")
    work = root / "clone"
    work.mkdir()
    (work / "examples").symlink_to(ROOT / "examples")
    if SHARED.is_dir():
        (root / "shared").symlink_to(SHARED)
    return work


def test_the_pages_run_in_reading_order():
    names = [p.relative_to(ROOT).as_posix() for p in DOCS]
    assert names[:4] == ["README.md", "docs/getting-started.md",
                         "docs/guide/describing-a-rig.md", "docs/guide/spec-fields.md"]
    assert names.index("docs/guide/calibration.md") < names.index("docs/guide/scanning.md")
    assert sorted(names[2:]) == sorted(p.relative_to(ROOT).as_posix()
                                       for p in GUIDE.glob("*.md"))


@pytest.mark.parametrize("path", CASES)
def test_commands_print_what_the_docs_show(path, work):
    env = {**os.environ, "BISTAIR_PROGRESS_DELAY": "3600", "COLUMNS": "100",
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    mismatches = []  # every output the page shows otherwise, said at the end of the page
    for start, skip, language, lines in blocks(path):
        if skip is not None:
            print(f"{path.name}:{start}: not run ({skip})")
            continue
        if language.startswith("file:"):
            (work / language[5:]).write_text("\n".join(lines) + "\n")
            continue
        for argv, command, expected in _steps(language, lines):
            if "../shared" in " ".join(argv) and not SHARED.is_dir():
                pytest.skip("../shared is not here")
            proc = subprocess.run(argv, cwd=work, env=env, text=True, timeout=600,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
            where = f"{path.name}:{start}: {command}"
            refused = any(line.startswith("Error: ") for line in expected)  # shown refused
            assert proc.returncode == (2 if refused else 0), \
                f"{where}\n{proc.stdout}"
            # what the docs show is printed once the kernels are compiled (by the install;
            # a kernel the install left out is test_kernels.py's business): a kernel compiled
            # now, as in a checkout whose numba cache is cold, says so in a line of its own
            printed = [line for line in proc.stdout.splitlines()
                       if line.strip() and line != f"bistair: {COMPILE_NOTICE}"]
            if expected and not printed_as_shown([e.strip() for e in expected],
                                                 [g.strip() for g in printed]):
                mismatches.append(f"{where}\nshown:\n" + "\n".join(expected) +
                                  "\nprinted:\n" + "\n".join(printed))
    assert not mismatches, "\n\n".join(mismatches)


def test_the_parser_reads_commands_outputs_and_continuations():
    lines = ["bistair a \\", "    --b 1   # a comment", "# out 1", "# out 2", "",
             "# a comment line", "bistair c"]
    assert commands(lines) == [("bistair a --b 1", ["out 1", "out 2"]), ("bistair c", [])]
    assert matches("wrote 7 ... to pats", "wrote 7 bidirectional patterns to pats")
    assert not matches("wrote 7", "wrote 8")
    assert printed_as_shown(["a", "...", "d"], ["a", "b", "c", "d"])
    assert not printed_as_shown(["a", "d"], ["a", "b", "d"])
    assert _steps("python", ["x = 1  # one", "print(x)"])[0][0][-1] == "x = 1  # one\nprint(x)"
