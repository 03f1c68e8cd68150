"""Reading captures and specs.

Captures are given as folders, image files or quoted glob patterns (``'scan/pat*.png'``),
in the order given; a folder's or a pattern's images are taken in natural name order
(``2.bmp`` before ``10.bmp``), skipping files that are not PNG, TIFF or BMP images and hidden
files (such as macOS's ``._00.png``). Images are 8 or 16 bit, grey or colour (converted to
grey). One ``.npy`` stack of shape (frames, height, width) is an alternative. Frames the
spec marks ``ignore`` are not read. Outputs are written by :mod:`.atomic`.

Examples
--------
>>> sorted(["10.png", "2.png", "1.png"], key=natural_key)
['1.png', '2.png', '10.png']
"""

from __future__ import annotations

import glob
import re
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import tifffile

from ..codecs import spec_from_dict
from ..codecs.base import frame_count_error
from ..errors import BistairError
from ..spec import BaseSpec
from .inputs import note
from .jsonfile import read_json

READ_THREADS = 3  # frames read at once (1.3 MP PNGs: 3 threads 35 ms, 1 thread 59 ms, 6 38)

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
    >>> from bistair.io.atomic import write_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> for name in ("10.png", "2.PNG", "1.tif", "spec.json", ".hidden.png"):
    ...     _ = (tmp / name).write_bytes(b"")
    >>> [p.name for p in list_images(tmp)]
    ['1.tif', '2.PNG', '10.png']
    >>> shutil.rmtree(tmp)
    """
    note(folder)  # an input of the running command (bistair.io.inputs)
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
    >>> from bistair.io.atomic import write_image
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
    note(path)
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
    note(*items)  # inputs of the running command (bistair.io.inputs), and their files below
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
    note(*files)
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
    >>> from bistair.io.atomic import write_image
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
    # the image libraries free the GIL while they decode: about 0.6 of the time on two cores
    with ThreadPoolExecutor(max_workers=max(1, min(len(files), READ_THREADS))) as pool:
        frames = list(pool.map(read_image, files))  # the first bad file's error, as in a loop
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
    >>> from bistair.io.atomic import write_image
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
        Captures or a spec file that cannot be read; no ``spec`` given and no
        ``spec.json`` beside the captures (the message names ``--spec``).

    Examples
    --------
    >>> import pathlib, shutil, tempfile
    >>> from bistair.codecs import make_spec
    >>> from bistair.io.atomic import write_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (tmp / "spec.json").write_text(make_spec("graycode", width=64, height=48,
    ...                                              period=16).to_json())
    >>> find_spec(tmp, tmp / "spec.json").method
    'graycode'
    >>> (tmp / "spec.json").unlink()
    >>> try:
    ...     find_spec(tmp, files=[tmp / "00.png"])
    ... except BistairError as exc:
    ...     print(*str(exc).replace(str(tmp), "caps").split(": "), sep="\\n")
    spec file caps/spec.json not found
    give the spec that made the patterns with --spec FILE (spec= from Python)
    >>> shutil.rmtree(tmp)
    """
    if isinstance(spec, BaseSpec):
        return spec
    if spec is None:
        spec = default_spec_path(captures, files)
        if not spec.exists():
            raise BistairError(f"spec file {spec} not found: give the spec that made the "
                               "patterns with --spec FILE (spec= from Python)")
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


def read_with_spec(captures: Captures, spec: BaseSpec | str | Path | None = None
                   ) -> tuple[np.ndarray, BaseSpec]:
    """The capture stack and the spec that describes it; ``bistair.read_captures``.

    The captures are given as ``bistair decode`` takes them: a folder, image files, quoted
    glob patterns (``"scan/pat*.png"``), a list of these, or a ``.npy`` stack. In a
    notebook: ``stack, spec = bistair.read_captures("caps/")``, then
    ``bistair.decode(stack, spec)``.

    ``spec`` defaults to ``spec.json`` in the captures' folder (the folder given, or the
    folder of the first file). Frames the spec marks ``ignore`` are not read: the spec
    returned lists the frames of the stack returned.

    Parameters
    ----------
    captures : str, Path or sequence of str or Path
        Folders, image files, glob patterns or a ``.npy`` stack (see
        :func:`capture_files`).
    spec : BaseSpec, str, Path or None, optional
        The spec itself, the path of its JSON file, or ``None`` (the default) for
        ``spec.json`` beside the captures.

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
    >>> from bistair.io.atomic import write_image
    >>> tmp = pathlib.Path(tempfile.mkdtemp())
    >>> spec = make_spec("graycode", width=120, height=16, period=30)
    >>> spec = spec.replace(frame_order=("ignore", *spec.frames))
    >>> _ = (tmp / "spec.json").write_text(spec.to_json())
    >>> for i in range(spec.frame_count):
    ...     write_image(tmp / f"{i:02d}.png", np.full((3, 5), i, np.uint8))
    >>> stack, used = read_with_spec(tmp)
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
        raise frame_count_error(spec, count)
    if npy:
        stack = np.delete(stack, skip, axis=0) if skip else stack
    else:
        stack = read_captures(files, skip)
    if skip:
        spec = spec.replace(frame_order=tuple(n for n in spec.frames if n != "ignore"))
    return stack, spec


