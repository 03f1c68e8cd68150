"""The one small interface every method implements, and the shared encode/decode plumbing.

A codec is a spec class plus two functions on the coded axis laid out along image columns:
``encode_columns(spec) -> (F, other, coded)`` float patterns in [0, 1] and
``decode_columns(prepared, spec, **options) -> DecodeResult``. The plumbing here handles the
rows orientation (by transposing), projector gamma pre-compensation, bit depth and the checks
every capture goes through.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..captures import Prepared, prepare
from ..errors import BistairError
from ..result import DecodeResult
from ..spec import BaseSpec

EncodeFn = Callable[[Any], np.ndarray]
DecodeFn = Callable[..., DecodeResult]


@dataclass(frozen=True)
class Codec:
    """A method: its name, spec class, encoder and decoder (on column-coded data)."""

    name: str
    spec_class: type[BaseSpec]
    encode_columns: EncodeFn
    decode_columns: DecodeFn
    summary: str
    options: tuple[str, ...] = ()  # decode keyword options the codec accepts

    def encode(self, spec: BaseSpec) -> np.ndarray:
        """Patterns as float32 in [0, 1], shape (frames, height, width), gamma pre-compensated."""
        pats = np.asarray(self.encode_columns(spec), dtype=np.float64)
        pats = np.clip(pats, 0.0, 1.0)
        if spec.white:
            pats = np.concatenate([pats, np.ones((1, *pats.shape[1:]))])
        if spec.gamma != 1.0:
            pats = pats ** (1.0 / spec.gamma)
        if spec.orientation == "rows":
            pats = pats.transpose(0, 2, 1)
        order = [spec.default_frames().index(name) for name in spec.frames]
        return np.ascontiguousarray(pats[order], dtype=np.float32)

    def decode(self, images: np.ndarray, spec: BaseSpec, **options: Any) -> DecodeResult:
        unknown = set(options) - set(self.options)
        if unknown:
            raise BistairError(
                f"the {self.name} decoder has no option(s) {', '.join(sorted(unknown))}"
            )
        prepared = prepare(images, spec.frame_count, self.name)
        order = [spec.frames.index(name) for name in spec._frames()]  # the method's own
        same = order == list(range(len(order)))
        frames = prepared.frames[:len(order)] if same else prepared.frames[order]
        clipped = prepared.clipped
        if spec.orientation == "rows":
            frames = frames.transpose(0, 2, 1)
            clipped = clipped.T
        result = self.decode_columns(Prepared(frames, clipped, prepared.full_scale), spec,
                                     **options)
        result.info.setdefault("full_scale", prepared.full_scale)
        if spec.orientation == "rows":
            result = result.transposed()
        if spec.white:
            result.texture = prepared.frames[spec.frames.index("white")]
        return result


def quantize_patterns(patterns: np.ndarray, bits: int) -> np.ndarray:
    """Float patterns in [0, 1] to uint8 or uint16 images."""
    top = (1 << bits) - 1
    data = np.round(np.clip(patterns, 0.0, 1.0) * top)
    return data.astype(np.uint8 if bits == 8 else np.uint16)


def along_columns(profiles: np.ndarray, spec: BaseSpec) -> np.ndarray:
    """Patterns that vary along the coded axis only: (frames, coded) -> (frames, other, coded)."""
    rows = np.asarray(profiles, dtype=np.float32)[:, None, :]
    return np.broadcast_to(rows, (rows.shape[0], spec.other_length, rows.shape[2]))
