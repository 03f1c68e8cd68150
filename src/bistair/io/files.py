"""Reading captures and specs, and writing outputs without leaving half-written results
behind.

Captures are a folder of PNG/TIFF/BMP images taken in name order (numbers inside names are
compared as numbers), 8 or 16 bit, grey or colour (converted to grey), or one ``.npy`` stack.
Outputs go to a temporary folder beside the destination and are moved in only when every
file is written.

Examples
--------
>>> sorted(["10.png", "2.png", "1.png"], key=natural_key)
['1.png', '2.png', '10.png']
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
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


def list_images(folder: Path) -> list[Path]:
    files = [p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES]
    return sorted(files, key=lambda p: natural_key(p.name))


def read_image(path: str | Path) -> np.ndarray:
    """One image as a 2-D array in its own dtype (colour converted to grey)."""
    path = Path(path)
    try:
        if path.suffix.lower() in (".tif", ".tiff"):
            img = tifffile.imread(path)
        else:
            img = iio.imread(path, plugin="pillow")
    except FileNotFoundError:
        raise BistairError(f"image {path} not found") from None
    except Exception as exc:  # the imaging libraries raise many kinds for bad files
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise BistairError(f"cannot read image {path}: {reason}") from None
    img = np.asarray(img)
    if img.ndim == 3 and img.shape[-1] in (3, 4):
        rgb = img[..., :3].astype(np.float64)
        grey = rgb @ np.array([0.299, 0.587, 0.114])
        img = np.round(grey).astype(img.dtype)
    if img.ndim != 2:
        raise BistairError(f"image {path} has shape {img.shape}, expected a 2-D grey image")
    return img


def read_captures(path: str | Path) -> np.ndarray:
    """A capture stack (frames, height, width) from a folder of images or a ``.npy`` file."""
    path = Path(path)
    if not path.exists():
        raise BistairError(f"captures {path} not found")
    if path.is_file():
        if path.suffix.lower() != ".npy":
            raise BistairError(f"captures {path} must be a folder of images or a .npy stack")
        try:
            stack = np.load(path, allow_pickle=False)
        except Exception as exc:
            raise BistairError(f"cannot read {path}: {str(exc).splitlines()[0]}") from None
        if stack.ndim != 3:
            raise BistairError(f"{path} holds shape {stack.shape}, expected (frames, H, W)")
        return stack
    files = list_images(path)
    if not files:
        raise BistairError(f"no PNG, TIFF or BMP images in {path}")
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


def read_with_spec(captures: str | Path, spec: BaseSpec | str | Path | None
                   ) -> tuple[np.ndarray, BaseSpec]:
    """The capture stack and its spec (``CAPTURES/spec.json``, or beside a ``.npy`` stack,
    unless given)."""
    captures = Path(captures)
    if not captures.exists():
        raise BistairError(f"captures {captures} not found")
    if spec is None:
        spec = captures / "spec.json" if captures.is_dir() else captures.with_name("spec.json")
    if not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    return read_captures(captures), spec


def write_image(path: str | Path, image: np.ndarray) -> None:
    """Write an 8- or 16-bit image (PNG, TIFF or BMP by suffix)."""
    path = Path(path)
    if path.suffix.lower() in (".tif", ".tiff"):
        tifffile.imwrite(path, image)
    else:
        iio.imwrite(path, image)


@contextlib.contextmanager
def output_folder(out: str | Path) -> Iterator[Path]:
    """Yield a temporary folder; on success its files are moved into ``out`` (created if
    needed, other files in it left alone); on any error nothing reaches ``out``."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    parent = out if out.exists() else out.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=".bistair-", dir=parent))
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
def output_file(path: str | Path) -> Iterator[Path]:
    """Yield a temporary file path beside ``path``; it replaces ``path`` only on success."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=".bistair-", suffix=path.suffix, dir=path.parent)
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


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
