"""Reading captures and specs, and writing outputs without leaving half-written results
behind.

Captures are given as folders, image files or quoted glob patterns (``'scan/pat*.png'``),
in the order given; a folder's or a pattern's images are taken in natural name order
(``2.bmp`` before ``10.bmp``), skipping files that are not PNG, TIFF or BMP images and hidden
files (such as macOS's ``._00.png``). Images are 8 or 16 bit, grey or colour (converted to
grey). One ``.npy`` stack of shape (frames, height, width) is an alternative. Frames the
spec marks ``ignore`` are not read. Outputs go to a temporary folder beside the destination
and are moved in only when every file is written.

Examples
--------
>>> sorted(["10.png", "2.png", "1.png"], key=natural_key)
['1.png', '2.png', '10.png']
"""

from __future__ import annotations

import contextlib
import glob
import os
import re
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import tifffile

from ..codecs import spec_from_dict
from ..errors import BistairError
from ..spec import BaseSpec
from .jsonfile import read_json

IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".bmp")


def natural_key(name: str) -> list:
    """Sort key that compares digit runs as numbers: ``2.png`` before ``10.png``.

    Parameters
    ----------
    name : str
        A file name (or any string).

    Returns
    -------
    list
        The text between digit runs, lower-cased (``str``), alternating with the digit runs
        as ``int``; lists compare element by element, so names sort in natural order.

    Examples
    --------
    >>> natural_key("Scan10.png")
    ['scan', 10, '.png']
    >>> sorted(["pat10.bmp", "pat2.bmp", "Pat1.bmp"], key=natural_key)
    ['Pat1.bmp', 'pat2.bmp', 'pat10.bmp']
    """
    return [int(part) if part.isdigit() else part.lower() for part in re.split(r"(\d+)", name)]


def _is_image(path: Path) -> bool:
    return (path.suffix.lower() in IMAGE_SUFFIXES and not path.name.startswith(".")
            and path.is_file())


def list_images(folder: Path) -> list[Path]:
    """The images in a folder, in natural name order (hidden files left out).

    Parameters
    ----------
    folder : Path
        An existing folder. Sub-folders are not searched.

    Returns
    -------
    list of Path
        The PNG, TIFF and BMP files directly in ``folder`` (suffix in any case), sorted by
        :func:`natural_key` of the name; files whose name starts with ``.`` are left out.
        Empty if there are none.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> for name in ("10.png", "2.PNG", "1.tif", "spec.json", ".hidden.png"):
    ...     _ = (tmp / name).write_bytes(b"")
    >>> [p.name for p in list_images(tmp)]
    ['1.tif', '2.PNG', '10.png']
    >>> shutil.rmtree(tmp)
    """
    return sorted((p for p in folder.iterdir() if _is_image(p)),
                  key=lambda p: natural_key(p.name))


def read_image(path: str | Path) -> np.ndarray:
    """One image as a 2-D array in its own dtype (colour converted to grey).

    TIFF files (``.tif``, ``.tiff``) are read with tifffile, anything else with Pillow.
    Colour images (RGB or RGBA; alpha ignored) become ``0.299 R + 0.587 G + 0.114 B``,
    rounded, in the image's dtype.

    Parameters
    ----------
    path : str or Path
        The image file: 8- or 16-bit PNG, TIFF or BMP, grey or colour.

    Returns
    -------
    numpy.ndarray
        ``(height, width)`` array in the file's dtype (e.g. ``uint8``, ``uint16``).

    Raises
    ------
    BistairError
        A missing, empty or unreadable file, or one that is not a 2-D grey or colour image.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> write_image(tmp / "rgb.png", np.array([[[255, 0, 0], [0, 255, 0]]], np.uint8))
    >>> read_image(tmp / "rgb.png")
    array([[ 76, 150]], dtype=uint8)
    >>> write_image(tmp / "deep.tif", np.array([[0, 4095]], np.uint16))
    >>> read_image(tmp / "deep.tif")
    array([[   0, 4095]], dtype=uint16)
    >>> shutil.rmtree(tmp)
    >>> read_image("/nonexistent/00.png")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: image /nonexistent/00.png not found
    """
    path = Path(path)
    try:
        if path.stat().st_size == 0:
            raise BistairError(f"image {path} is empty (0 bytes)")
        if path.suffix.lower() in (".tif", ".tiff"):
            img = tifffile.imread(path)
        else:
            img = iio.imread(path, plugin="pillow")
    except FileNotFoundError:
        raise BistairError(f"image {path} not found") from None
    except BistairError:
        raise
    except Exception as exc:  # the imaging libraries raise many kinds for bad files
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if "can not handle" in reason or "cannot identify" in reason:
            reason = "not a readable image (corrupt or of another format)"
        raise BistairError(f"cannot read image {path}: {reason}") from None
    img = np.asarray(img)
    if img.ndim == 3 and img.shape[-1] in (3, 4):
        rgb = img[..., :3].astype(np.float64)
        grey = rgb @ np.array([0.299, 0.587, 0.114])
        img = np.round(grey).astype(img.dtype)
    if img.ndim != 2:
        raise BistairError(f"image {path} has shape {img.shape}, expected a 2-D grey image")
    return img


Captures = str | Path | Sequence[str | Path]


def capture_files(captures: Captures) -> list[Path]:
    """The files of a capture set: folders, image files and glob patterns expanded in order
    (see the module docstring), or a single ``.npy`` stack.

    Nothing is read: image files named directly are taken as they are (their content is
    checked by :func:`read_image`).

    Parameters
    ----------
    captures : str, Path or sequence of str or Path
        A folder, an image file, a glob pattern (``'scan/pat*.png'``; ``*``, ``?`` or
        ``[``), a ``.npy`` stack, or a sequence of folders, files and patterns taken in the
        order given.

    Returns
    -------
    list of Path
        The image files in capture order, or the one ``.npy`` file.

    Raises
    ------
    BistairError
        Nothing given, a path that does not exist, a folder or pattern without images, a
        file that is neither an image nor a ``.npy`` stack, or a ``.npy`` stack with others.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     for name in ("10.png", "2.png", "notes.txt", "._2.png"):
    ...         _ = (pathlib.Path(tmp) / name).write_bytes(b"x")
    ...     [p.name for p in capture_files(pathlib.Path(tmp) / "*")]
    ['2.png', '10.png']
    """
    items = [captures] if isinstance(captures, str | Path) else list(captures)
    if not items:
        raise BistairError("no captures given")
    files: list[Path] = []
    for item in items:
        text = str(item)
        if any(c in text for c in "*?["):
            found = [Path(m) for m in glob.glob(text)]
            images = sorted((p for p in found if _is_image(p)), key=lambda p: natural_key(str(p)))
            if not images:
                raise BistairError(f"no PNG, TIFF or BMP images match {text}")
            files += images
            continue
        path = Path(item)
        if not path.exists():
            raise BistairError(f"captures {path} not found")
        if path.is_dir():
            images = list_images(path)
            if not images:
                raise BistairError(f"no PNG, TIFF or BMP images in {path}")
            files += images
        elif path.suffix.lower() in (*IMAGE_SUFFIXES, ".npy"):
            files.append(path)
        else:
            raise BistairError(f"captures {path} must be images (PNG, TIFF, BMP), a folder of "
                               "them or a .npy stack")
    if len(files) > 1 and any(f.suffix.lower() == ".npy" for f in files):
        raise BistairError("a .npy capture stack must be given alone")
    return files


def read_captures(captures: Captures, skip: Sequence[int] = ()) -> np.ndarray:
    """A capture stack (frames, height, width) from :func:`capture_files`; the frames at
    the indices ``skip`` are left out (not read).

    Parameters
    ----------
    captures : str, Path or sequence of str or Path
        Folders, image files, glob patterns or a single ``.npy`` stack of shape
        ``(frames, height, width)`` (see :func:`capture_files`).
    skip : sequence of int, optional
        Indices (in capture order) of the frames to leave out; indices past the end are
        ignored.

    Returns
    -------
    numpy.ndarray
        ``(frames, height, width)`` in the images' own dtype (colour converted to grey), or
        the ``.npy`` stack's dtype; C-contiguous.

    Raises
    ------
    BistairError
        What :func:`capture_files` and :func:`read_image` refuse, a ``.npy`` file that
        cannot be read or is not 3-D, and frames of different sizes or bit depths.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> for i in range(3):
    ...     write_image(tmp / f"{i}.png", np.full((2, 4), 10 * i, np.uint8))
    >>> stack = read_captures(tmp, skip=[1])
    >>> stack.shape, stack.dtype, stack[:, 0, 0].tolist()
    ((2, 2, 4), dtype('uint8'), [0, 20])
    >>> write_image(tmp / "3.png", np.zeros((4, 4), np.uint8))
    >>> read_captures(tmp)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: frame 3.png is 4x4 but 0.png is 4x2
    >>> shutil.rmtree(tmp)
    """
    files = capture_files(captures)
    skip = set(skip)
    if files[0].suffix.lower() == ".npy":
        path = files[0]
        try:
            stack = np.load(path, allow_pickle=False, mmap_mode="r")
        except Exception as exc:
            raise BistairError(f"cannot read {path}: {str(exc).splitlines()[0]}") from None
        if stack.ndim != 3:
            raise BistairError(f"{path} holds shape {stack.shape}, expected (frames, H, W)")
        keep = [i for i in range(stack.shape[0]) if i not in skip]
        return np.ascontiguousarray(stack[keep] if skip else stack)
    files = [f for i, f in enumerate(files) if i not in skip]
    frames = [read_image(f) for f in files]
    first = frames[0]
    for f, img in zip(files, frames, strict=True):
        if img.shape != first.shape:
            raise BistairError(
                f"frame {f.name} is {img.shape[1]}x{img.shape[0]} but {files[0].name} is "
                f"{first.shape[1]}x{first.shape[0]}"
            )
        if img.dtype != first.dtype:
            raise BistairError(
                f"frame {f.name} is {img.dtype} but {files[0].name} is {first.dtype}"
            )
    return np.stack(frames)


def load_spec(path: str | Path) -> BaseSpec:
    """Read and validate a ``spec.json``.

    Parameters
    ----------
    path : str or Path
        The spec file (JSON, as written by ``spec.to_json()`` next to the patterns).

    Returns
    -------
    BaseSpec
        The spec of the method the file names, validated.

    Raises
    ------
    BistairError
        Raised by the readers it calls: a missing, unreadable or malformed file
        (:func:`~bistair.io.jsonfile.read_json`) or an invalid spec
        (:func:`bistair.codecs.spec_from_dict`).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.codecs import make_spec
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> spec = make_spec("graycode", width=120, height=16, period=30)
    >>> _ = (tmp / "spec.json").write_text(spec.to_json())
    >>> load_spec(tmp / "spec.json") == spec
    True
    >>> shutil.rmtree(tmp)
    """
    return spec_from_dict(read_json(path, "spec file"))


def find_spec(captures: Captures, spec: BaseSpec | str | Path | None = None,
              files: Sequence[Path] | None = None) -> BaseSpec:
    """The spec of a capture set, read as its file says (frames marked ``ignore`` kept).

    Parameters
    ----------
    captures : str, Path or sequence of them
        A folder, image files or glob patterns, or a ``.npy`` stack.
    spec : BaseSpec, str, Path or None
        The spec itself, the file it names, or by default ``spec.json`` in the captures'
        folder (the folder given, or the folder of the first file).
    files : sequence of Path, optional
        The captures' files if already listed (:func:`capture_files`).

    Returns
    -------
    BaseSpec

    Raises
    ------
    BistairError
        Captures or a spec file that cannot be read.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.codecs import make_spec
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (tmp / "spec.json").write_text(make_spec("graycode", width=64, height=48,
    ...                                              period=16).to_json())
    >>> find_spec(tmp, tmp / "spec.json").method
    'graycode'
    >>> shutil.rmtree(tmp)
    """
    if isinstance(spec, BaseSpec):
        return spec
    if spec is None:
        spec = default_spec_path(captures, files)
    return load_spec(spec)


def default_spec_path(captures: Captures, files: Sequence[Path] | None = None) -> Path:
    """Where a capture set's spec is when none is named: ``spec.json`` in the folder given,
    or in the folder of the first file.

    Parameters
    ----------
    captures : str, Path or sequence of them
        A folder, image files or glob patterns, or a ``.npy`` stack.
    files : sequence of Path, optional
        The captures' files if already listed (:func:`capture_files`).

    Returns
    -------
    Path

    Raises
    ------
    BistairError
        Captures that cannot be listed (:func:`capture_files`).

    Examples
    --------
    >>> default_spec_path("/data/scan-1/pat*.png", [Path("/data/scan-1/pat0.png")]).as_posix()
    '/data/scan-1/spec.json'
    """
    files = capture_files(captures) if files is None else files
    first = Path(captures if isinstance(captures, str | Path) else next(iter(captures)))
    return first / "spec.json" if first.is_dir() else files[0].parent / "spec.json"


def read_with_spec(captures: Captures, spec: BaseSpec | str | Path | None
                   ) -> tuple[np.ndarray, BaseSpec]:
    """The capture stack and the spec that describes it.

    ``spec`` defaults to ``spec.json`` in the captures' folder (the folder given, or the
    folder of the first file). Frames the spec marks ``ignore`` are not read: the spec
    returned lists the frames of the stack returned.

    Parameters
    ----------
    captures : str, Path or sequence of str or Path
        Folders, image files, glob patterns or a ``.npy`` stack (see
        :func:`capture_files`).
    spec : BaseSpec, str, Path or None
        The spec itself, the path of its JSON file, or ``None`` for ``spec.json`` beside
        the captures.

    Returns
    -------
    stack : numpy.ndarray
        ``(frames, height, width)`` captures without the ``ignore`` frames, in their own
        dtype (see :func:`read_captures`).
    spec : BaseSpec
        The spec, its frame order without ``ignore`` if it had any.

    Raises
    ------
    BistairError
        A spec that cannot be read, captures that cannot be read, or a frame count that
        differs from the spec's.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.codecs import make_spec
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> spec = make_spec("graycode", width=120, height=16, period=30)
    >>> spec = spec.replace(frame_order=("ignore", *spec.frames))
    >>> _ = (tmp / "spec.json").write_text(spec.to_json())
    >>> for i in range(spec.frame_count):
    ...     write_image(tmp / f"{i:02d}.png", np.full((3, 5), i, np.uint8))
    >>> stack, used = read_with_spec(tmp, None)
    >>> stack.shape, stack[:, 0, 0].tolist(), used.frames[0]
    ((6, 3, 5), [1, 2, 3, 4, 5, 6], 'shift-0')
    >>> read_with_spec(sorted(tmp.glob("*.png"))[:3], spec)
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the graycode spec needs 7 frames, the captures have 3
    >>> shutil.rmtree(tmp)
    """
    files = capture_files(captures)
    spec = find_spec(captures, spec, files)
    skip = [i for i, name in enumerate(spec.frames) if name == "ignore"]
    npy = files[0].suffix.lower() == ".npy"
    stack = read_captures(files) if npy else None
    count = stack.shape[0] if npy else len(files)
    if count != spec.frame_count:
        raise BistairError(f"the {spec.method} spec needs {spec.frame_count} frames, the "
                           f"captures have {count}")
    if npy:
        stack = np.delete(stack, skip, axis=0) if skip else stack
    else:
        stack = read_captures(files, skip)
    if skip:
        spec = spec.replace(frame_order=tuple(n for n in spec.frames if n != "ignore"))
    return stack, spec


def write_image(path: str | Path, image: np.ndarray) -> None:
    """Write an 8- or 16-bit image (PNG, TIFF or BMP by suffix).

    TIFF (``.tif``, ``.tiff``) is written with tifffile, other suffixes with imageio. The
    file is written in place (not atomically): use :func:`output_folder` or
    :func:`output_file` for that.

    Parameters
    ----------
    path : str or Path
        The file to write (replaced if it exists); its suffix chooses the format.
    image : numpy.ndarray
        ``(height, width)`` grey or ``(height, width, 3)`` RGB, ``uint8`` or ``uint16``
        (BMP takes ``uint8`` only).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> write_image(tmp / "ramp.png", np.arange(6, dtype=np.uint16).reshape(2, 3) * 1000)
    >>> read_image(tmp / "ramp.png").tolist()
    [[0, 1000, 2000], [3000, 4000, 5000]]
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    if path.suffix.lower() in (".tif", ".tiff"):
        tifffile.imwrite(path, image)
    else:
        iio.imwrite(path, image)


def check_output(out: str | Path, captures: Captures | None = None) -> Path:
    """Refuse an output path that is empty or is the captures' own folder (writing there
    would add files to the next decode of that folder); returns it as a Path.

    Parameters
    ----------
    out : str or Path
        The output folder.
    captures : str, Path, sequence of str or Path, or None, optional
        The captures it is made from (as for :func:`capture_files`): a folder, the folder
        of a file or the folder part of a glob pattern counts as their own folder. Paths
        are compared resolved.

    Returns
    -------
    Path
        ``out`` as a :class:`~pathlib.Path`.

    Raises
    ------
    BistairError
        If ``out`` is empty (or blank) or is the captures' own folder.

    Examples
    --------
    >>> check_output("result", "scan/*.png")
    PosixPath('result')
    >>> check_output("scan", "scan/*.png")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the output folder scan is the captures' own folder: ...
    >>> check_output(" ")
    Traceback (most recent call last):
    ...
    bistair.errors.BistairError: the output path is empty
    """
    if str(out).strip() == "":
        raise BistairError("the output path is empty")
    out = Path(out)
    if captures is not None:
        items = [captures] if isinstance(captures, str | Path) else list(captures)
        folders = {Path(i).resolve() if Path(i).is_dir() else Path(i).resolve().parent
                   for i in items if not any(c in str(i) for c in "*?[")}
        folders |= {Path(str(i)).parent.resolve() for i in items if any(c in str(i) for c in "*?[")}
        if out.resolve() in folders:
            raise BistairError(f"the output folder {out} is the captures' own folder: choose "
                               "another (the outputs would be read as captures next time)")
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
        If ``out`` exists and is not a folder, or the folder cannot be created or written
        (any ``OSError``, also one raised in the ``with`` block, in one line). Other errors
        in the ``with`` block propagate unchanged.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
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
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    parent = out if out.exists() else out.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        remove_stale(parent)
        tmp = Path(tempfile.mkdtemp(prefix=prefix or _prefix(), dir=parent))
        tmp.chmod(0o777 & ~_umask())  # mkdtemp makes it private; outputs are not
    except OSError as exc:
        raise BistairError(f"cannot write output folder {out}: {exc.strerror}") from None
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
        If ``out`` exists and is not a folder, or the folders cannot be made or renamed
        (in one line; the old folder is put back).

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
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=prefix, dir=out.parent))
        tmp.chmod(0o777 & ~_umask())
    except OSError as exc:
        raise BistairError(f"cannot write output folder {out}: {exc.strerror}") from None
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
        If the folder or the temporary file cannot be made, or the rename fails (any
        ``OSError``, also one raised in the ``with`` block, in one line). Other errors in
        the ``with`` block propagate unchanged.

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> with output_file(tmp / "sub" / "info.txt") as work:
    ...     _ = work.write_text("done")
    >>> [p.name for p in (tmp / "sub").iterdir()], (tmp / "sub" / "info.txt").read_text()
    (['info.txt'], 'done')
    >>> shutil.rmtree(tmp)
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale(path.parent)
        fd, name = tempfile.mkstemp(prefix=prefix or _prefix(), suffix=path.suffix,
                                    dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise BistairError(f"cannot write {path}: {exc.strerror}") from None
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
