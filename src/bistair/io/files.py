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
    """Sort key that compares digit runs as numbers: ``2.png`` before ``10.png``."""
    return [int(part) if part.isdigit() else part.lower() for part in re.split(r"(\d+)", name)]


def _is_image(path: Path) -> bool:
    return (path.suffix.lower() in IMAGE_SUFFIXES and not path.name.startswith(".")
            and path.is_file())


def list_images(folder: Path) -> list[Path]:
    """The images in a folder, in natural name order (hidden files left out)."""
    return sorted((p for p in folder.iterdir() if _is_image(p)),
                  key=lambda p: natural_key(p.name))


def read_image(path: str | Path) -> np.ndarray:
    """One image as a 2-D array in its own dtype (colour converted to grey).

    Raises
    ------
    BistairError
        A missing, empty or unreadable file, or one that is not a 2-D grey or colour image.
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

    Raises
    ------
    BistairError
        What :func:`capture_files` and :func:`read_image` refuse, and frames of different
        sizes or bit depths.
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
    """Read and validate a ``spec.json``."""
    return spec_from_dict(read_json(path, "spec file"))


def find_spec(captures: Captures, spec: BaseSpec | str | Path | None = None,
              files: Sequence[Path] | None = None) -> BaseSpec:
    """The spec of a capture set, read as its file says (frames marked ``ignore`` kept):
    ``spec`` itself, the file it names, or by default ``spec.json`` in the captures' folder
    (the folder given, or the folder of the first file). ``files``: the captures' files if
    already listed (:func:`capture_files`).

    Raises
    ------
    BistairError
        Captures or a spec file that cannot be read.
    """
    if isinstance(spec, BaseSpec):
        return spec
    if spec is None:
        files = capture_files(captures) if files is None else files
        first = captures if isinstance(captures, str | Path) else next(iter(captures))
        first = Path(first)
        spec = first / "spec.json" if first.is_dir() else files[0].parent / "spec.json"
    return load_spec(spec)


def read_with_spec(captures: Captures, spec: BaseSpec | str | Path | None
                   ) -> tuple[np.ndarray, BaseSpec]:
    """The capture stack and the spec that describes it.

    ``spec`` defaults to ``spec.json`` in the captures' folder (the folder given, or the
    folder of the first file). Frames the spec marks ``ignore`` are not read: the spec
    returned lists the frames of the stack returned.

    Raises
    ------
    BistairError
        A spec that cannot be read, captures that cannot be read, or a frame count that
        differs from the spec's.
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
    """Write an 8- or 16-bit image (PNG, TIFF or BMP by suffix)."""
    path = Path(path)
    if path.suffix.lower() in (".tif", ".tiff"):
        tifffile.imwrite(path, image)
    else:
        iio.imwrite(path, image)


def check_output(out: str | Path, captures: Captures | None = None) -> Path:
    """Refuse an output path that is empty or is the captures' own folder (writing there
    would add files to the next decode of that folder); returns it as a Path."""
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

    The temporary folder is named ``prefix`` + random letters (it starts with
    :data:`TEMP_PREFIX`) and lies in ``out``'s parent, or in ``out`` if that exists (its
    files are then moved in one by one)."""
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
    process killed while writing); returns what was deleted.

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
    """Yield a temporary file path beside ``path`` (named ``prefix`` + random letters); it
    replaces ``path`` only on success."""
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
