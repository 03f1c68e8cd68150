"""Writing outputs without leaving half-written results behind.

Outputs go to a temporary folder or file beside the destination (named with
:data:`TEMP_PREFIX` and the process id) and are moved in only when every file is written; a
folder is replaced as a whole. An output that is, holds or mixes with an input of the
running command is refused first (:func:`check_output`, :mod:`.inputs`). Temporaries left
by a killed process are removed by the next run that writes beside them
(:func:`remove_stale`), never those of a process still running.

Examples
--------
>>> import tempfile
>>> with tempfile.TemporaryDirectory() as tmp:
...     with output_folder(Path(tmp) / "result") as folder:
...         _ = (folder / "a.txt").write_text("done")
...     sorted(p.name for p in Path(tmp, "result").iterdir())
['a.txt']
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

import cv2
import imageio.v3 as iio
import numpy as np
import tifffile

from ..errors import BistairError
from .inputs import noted
from .read import IMAGE_SUFFIXES, Captures


def _reason(path: Path, exc: OSError) -> str:
    """Why ``path`` cannot be written: the file standing where one of its folders should
    be, else the system's reason.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (Path(tmp) / "a").write_text("a file")
    ...     _reason(Path(tmp) / "a" / "b" / "c.json", FileExistsError(17, "File exists"))
    'a is a file, not a folder'
    """
    for folder in path.parents:
        if folder.exists():
            if not folder.is_dir():
                return f"{folder.name or folder} is a file, not a folder"
            break
    return str(exc.strerror or exc)


# grey PNG through OpenCV: deflated (level 1, run-length matches), or stored (level 0 and no
# filter: the image's bytes with a row's filter byte and the checksums, about 2 ms a 1.3 MP
# frame against 21 ms deflated, in a file 2.2 times as big, on the sim camera's captures)
_PNG_DEFLATED = [cv2.IMWRITE_PNG_COMPRESSION, 1, cv2.IMWRITE_PNG_STRATEGY,
                 cv2.IMWRITE_PNG_STRATEGY_RLE]
_PNG_STORED = [cv2.IMWRITE_PNG_COMPRESSION, 0, cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_NONE]


def write_image(path: str | Path, image: np.ndarray, *, compress: bool = True) -> None:
    """Write an 8- or 16-bit image (PNG, TIFF or BMP by suffix).

    TIFF (``.tif``, ``.tiff``) is written with tifffile, grey PNG with OpenCV (deflate at
    its fastest level with run-length matches only: a 1.3 MP camera frame in an eighth of
    imageio's time, in a file no larger; with ``compress=False`` stored, neither filtered
    nor deflated: a tenth of that time again, in a file of the image's own size), other
    images with imageio. Either PNG reads back to the same pixel values. The file is
    written in place (not atomically): use :func:`output_folder` or :func:`output_file`
    for that.

    Parameters
    ----------
    path : str or Path
        The file to write (replaced if it exists); its suffix chooses the format.
    image : numpy.ndarray
        ``(height, width)`` grey or ``(height, width, 3)`` RGB, ``uint8`` or ``uint16``
        (BMP takes ``uint8`` only).
    compress : bool
        Deflate a grey PNG (``True``) or store it as it is (``False``: what a series of
        scans at a camera's rate writes); other images are written as without it.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.io.read import read_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> write_image(tmp / "ramp.png", np.arange(6, dtype=np.uint16).reshape(2, 3) * 1000)
    >>> read_image(tmp / "ramp.png").tolist()
    [[0, 1000, 2000], [3000, 4000, 5000]]
    >>> write_image(tmp / "stored.png", np.arange(6, dtype=np.uint16).reshape(2, 3) * 1000,
    ...             compress=False)
    >>> read_image(tmp / "stored.png").tolist()
    [[0, 1000, 2000], [3000, 4000, 5000]]
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    if path.suffix.lower() in (".tif", ".tiff"):
        tifffile.imwrite(path, image)
    elif path.suffix.lower() == ".png" and image.ndim == 2 and image.dtype in _GREY:
        ok, data = cv2.imencode(".png", np.ascontiguousarray(image), _PNG_DEFLATED if compress
                                else _PNG_STORED)
        if not ok:  # (OpenCV said no: imageio's own message)
            iio.imwrite(path, image)
            return
        path.write_bytes(data.tobytes())
    else:
        iio.imwrite(path, image)


_GREY = (np.dtype(np.uint8), np.dtype(np.uint16))


def slug(label: str) -> str:
    """A file name for a label: every run of characters other than letters, digits, ``.``,
    ``_`` and ``-`` becomes one ``-`` (no spaces, parentheses or slashes in names).

    Parameters
    ----------
    label : str
        A method's or factor's label, e.g. ``"bidirectional (paper decoder)"``.

    Returns
    -------
    str
        The label as a file name stem (``"-"`` for a label with nothing to keep).

    Examples
    --------
    >>> slug("bidirectional (paper decoder)"), slug("gamma (uncompensated)"), slug("a/b c")
    ('bidirectional-paper-decoder', 'gamma-uncompensated', 'a-b-c')
    """
    return re.sub(r"[^A-Za-z0-9._-]+", "-", label).strip("-") or "-"


def check_output(out: str | Path, captures: Captures | None = None, *,
                 file: bool = False) -> Path:
    """Refuse an output path that is empty, or that is, holds or mixes with an input of the
    running command; returns it as a Path.

    The inputs are ``captures`` and those noted by the running command
    (:func:`bistair.io.inputs.reading`: what its command line names and what it has read).
    Refused: an output that is an input (a capture folder, a spec, a calibration file, ...),
    a folder that holds one (writing there would replace it, or leave the outputs beside
    it: ``--out SET`` for captures in ``SET/left``, ``--out .`` for captures in the current
    folder), and an image file written straight into a capture folder (the folder's next
    read would take it as a capture). Paths are compared resolved (symbolic links
    followed); an output inside an input folder is otherwise allowed (``--out
    scan/decoded``).

    Parameters
    ----------
    out : str or Path
        The output folder or file.
    captures : str, Path, sequence of str or Path, or None, optional
        Inputs besides the noted ones (as for :func:`capture_files`): folders, files or
        glob patterns (a pattern stands for its folder).
    file : bool
        ``out`` is a file (else a folder).

    Returns
    -------
    Path
        ``out`` as a :class:`~pathlib.Path`.

    Raises
    ------
    BistairError
        If ``out`` is empty (or blank), is an input, holds one, or is an image file in a
        capture folder.

    Examples
    --------
    >>> check_output("result", "scan/*.png")
    PosixPath('result')
    >>> check_output("scan", "scan/*.png")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the output scan is the input scan: choose another output ...
    >>> check_output(".", ["set/left", "set/right"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the output . holds the input set/left: choose another ...
    >>> check_output(" ")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the output path is empty
    """
    if str(out).strip() == "":
        raise BistairError("the output path is empty")
    out = Path(out)
    items = [] if captures is None else \
        [captures] if isinstance(captures, str | Path) else list(captures)
    inputs = noted(items)
    if not inputs:
        return out
    target = out.resolve()
    why = "choose another output (writing there would replace the input or mix with it)"
    for path, given in inputs.items():
        if target == path:
            raise BistairError(f"the output {out} is the input {given}: {why}")
        if target in path.parents:
            raise BistairError(f"the output {out} holds the input {given}: {why}")
        if (file and target.parent == path and target.suffix.lower() in IMAGE_SUFFIXES
                and not target.name.startswith(".") and path.is_dir()):
            raise BistairError(f"the output {out} lies in the capture folder {given}: choose "
                               "another output (the folder's next read would take it as a "
                               "capture)")
    return out


TEMP_PREFIX = ".bistair-"  # the names of every temporary beside an output


@contextlib.contextmanager
def output_folder(out: str | Path, prefix: str | None = None) -> Iterator[Path]:
    """Yield a temporary folder; on success its files are moved into ``out`` (created if
    needed, other files in it left alone); on any error nothing reaches ``out``.

    The temporary folder (``.bistair-<pid>-...``) is made inside ``out``, or beside it if
    ``out`` does not exist yet, so the moves stay on one file system; temporaries left by
    killed processes there are removed first (:func:`remove_stale`). A new ``out`` is the
    temporary folder renamed; into an existing ``out`` each item is moved, replacing a
    file or folder of the same name.

    Parameters
    ----------
    out : str or Path
        The output folder.
    prefix : str, optional
        The temporary folder's name prefix (it must start with :data:`TEMP_PREFIX`); by
        default ``.bistair-<pid>-``. A batch run gives its own, to find its leftovers.

    Yields
    ------
    Path
        The temporary folder to write into; it is removed afterwards in every case.

    Raises
    ------
    BistairError
        If ``out`` is, holds or mixes with an input of the running command
        (:func:`check_output`), exists and is not a folder, or the folder cannot be created
        or written (any ``OSError``, also one raised in the ``with`` block, in one line).
        Other errors in the ``with`` block propagate unchanged.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.io.read import read_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> with output_folder(tmp / "out") as work:
    ...     _ = (work / "a.txt").write_text("a")
    >>> sorted(p.name for p in tmp.iterdir()), (tmp / "out" / "a.txt").read_text()
    (['out'], 'a')
    >>> with output_folder(tmp / "out") as work:
    ...     _ = (work / "b.txt").write_text("b")
    ...     raise RuntimeError("interrupted")
    Traceback (most recent call last):
    ...
    RuntimeError: interrupted
    >>> sorted(p.name for p in (tmp / "out").iterdir())
    ['a.txt']
    >>> shutil.rmtree(tmp)
    """
    out = check_output(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    parent = out if out.exists() else out.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        remove_stale(parent)
        tmp = Path(tempfile.mkdtemp(prefix=prefix or _prefix(), dir=parent))
        tmp.chmod(0o777 & ~_umask())  # mkdtemp makes it private; outputs are not
    except OSError as exc:
        raise BistairError(f"cannot write output folder {out}: {_reason(out, exc)}") from None
    try:
        yield tmp
        if not out.exists():
            os.replace(tmp, out)
            return
        for item in tmp.iterdir():
            target = out / item.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            os.replace(item, target)
    except OSError as exc:
        raise BistairError(f"cannot write output folder {out}: {exc.strerror}") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def replace_folder(out: str | Path, prefix: str = TEMP_PREFIX) -> Iterator[Path]:
    """Yield a temporary folder beside ``out`` that replaces ``out`` as a whole on success.

    Unlike :func:`output_folder`, files already in ``out`` do not survive: the old folder
    is renamed aside (``prefix`` + random letters) just before the new one is renamed in,
    then deleted, so ``out`` is at every moment absent, the old folder or the new one,
    never a mixture. On any error ``out`` is left as it was.

    Parameters
    ----------
    out : str or Path
        The folder to replace (created with its parents if missing).
    prefix : str
        Name prefix of the temporary and of the old folder set aside.

    Yields
    ------
    Path
        The new folder's contents go here; removed afterwards if not renamed in.

    Raises
    ------
    BistairError
        If ``out`` is, holds or mixes with an input of the running command
        (:func:`check_output`), exists and is not a folder, or the folders cannot be made or
        renamed (in one line; the old folder is put back).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = pathlib.Path(tmp) / "set"
    ...     out.mkdir(); _ = (out / "old.txt").write_text("old")
    ...     with replace_folder(out) as new:
    ...         _ = (new / "new.txt").write_text("new")
    ...     sorted(p.name for p in pathlib.Path(tmp).rglob("*"))
    ['new.txt', 'set']
    """
    out = check_output(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=prefix, dir=out.parent))
        tmp.chmod(0o777 & ~_umask())
    except OSError as exc:
        raise BistairError(f"cannot write output folder {out}: {_reason(out, exc)}") from None
    old = None
    try:
        yield tmp
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=prefix, dir=out.parent))
            os.replace(out, old)  # an empty folder is replaced by a rename
        os.replace(tmp, out)
    except OSError as exc:
        if old is not None and not out.exists():
            os.replace(old, out)  # put the old folder back
            old = None
        raise BistairError(f"cannot write output folder {out}: {exc.strerror}") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def remove_temporaries(folder: str | Path, prefix: str = TEMP_PREFIX) -> list[Path]:
    """Delete the temporaries named ``prefix*`` directly inside ``folder`` (left behind by a
    process killed while writing).

    Parameters
    ----------
    folder : str or Path
        Where to look (a missing folder has nothing to delete).
    prefix : str
        The temporaries' name prefix; it must start with :data:`TEMP_PREFIX`.

    Returns
    -------
    list of Path
        What was deleted.

    Raises
    ------
    ValueError
        If ``prefix`` does not start with :data:`TEMP_PREFIX` (a guard against deleting
        anything else).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     (pathlib.Path(tmp) / ".bistair-abc").mkdir()
    ...     _ = (pathlib.Path(tmp) / "result").mkdir()
    ...     [p.name for p in remove_temporaries(tmp)], sorted(os.listdir(tmp))
    (['.bistair-abc'], ['result'])
    """
    folder = Path(folder)
    if not prefix.startswith(TEMP_PREFIX):
        raise ValueError(f"temporaries are named {TEMP_PREFIX}*, not {prefix}*")
    try:
        found = sorted(p for p in folder.iterdir() if p.name.startswith(prefix))
    except OSError:  # no folder, nothing left behind
        return []
    for path in found:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                path.unlink()
    return found


@contextlib.contextmanager
def output_file(path: str | Path, prefix: str | None = None) -> Iterator[Path]:
    """Yield a temporary file path beside ``path``; it replaces ``path`` only on success.

    The temporary file (``.bistair-<pid>-...`` with ``path``'s suffix, so writers that go
    by the suffix work) is made in ``path``'s folder, which is created if needed; temporaries
    left there by killed processes are removed first (:func:`remove_stale`). On success it
    gets the usual permissions (``0o666`` less the umask) and is renamed onto ``path``.

    Parameters
    ----------
    path : str or Path
        The file to write.
    prefix : str, optional
        The temporary file's name prefix, as for :func:`output_folder`.

    Yields
    ------
    Path
        The temporary file (created empty) to write; it is removed if still there afterwards.

    Raises
    ------
    BistairError
        If ``path`` is, holds or mixes with an input of the running command
        (:func:`check_output`), the folder or the temporary file cannot be made, or the
        rename fails (any ``OSError``, also one raised in the ``with`` block, in one line).
        Other errors in the ``with`` block propagate unchanged.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.io.read import read_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> with output_file(tmp / "sub" / "info.txt") as work:
    ...     _ = work.write_text("done")
    >>> [p.name for p in (tmp / "sub").iterdir()], (tmp / "sub" / "info.txt").read_text()
    (['info.txt'], 'done')
    >>> shutil.rmtree(tmp)
    """
    path = check_output(path, file=True)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(path.parent)
        fd, name = tempfile.mkstemp(prefix=prefix or _prefix(), suffix=path.suffix,
                                    dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise BistairError(f"cannot write {path}: {_reason(path, exc)}") from None
    tmp = Path(name)
    try:
        yield tmp
        tmp.chmod(0o666 & ~_umask())
        os.replace(tmp, path)
    except OSError as exc:
        raise BistairError(f"cannot write {path}: {exc.strerror}") from None
    finally:
        tmp.unlink(missing_ok=True)


def _prefix() -> str:
    """Temporary outputs are named ``.bistair-<pid>-...``: whose they are stays known."""
    return f".bistair-{os.getpid()}-"


def remove_stale(folder: str | Path) -> int:
    """Remove temporary outputs (``.bistair-<pid>-*``) in ``folder`` left by processes that
    no longer run (killed while writing); returns how many were removed.

    Temporaries of running processes (this one included) are left alone.

    Parameters
    ----------
    folder : str or Path
        The folder to clean (not searched recursively).

    Returns
    -------
    int
        How many files or folders were removed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (pathlib.Path(tmp) / ".bistair-999999999-x").mkdir()
    ...     remove_stale(tmp), list(pathlib.Path(tmp).iterdir())
    (1, [])
    """
    removed = 0
    for item in Path(folder).glob(".bistair-*-*"):
        pid = item.name.split("-")[1]
        if not pid.isdigit() or _running(int(pid)):
            continue
        if item.is_dir() and not item.is_symlink():
            shutil.rmtree(item, ignore_errors=True)
        else:
            item.unlink(missing_ok=True)
        removed += 1
    return removed


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return pid < 2**22  # someone else's process, or no process at all
    return True


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
