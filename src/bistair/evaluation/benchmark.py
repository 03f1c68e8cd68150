"""The benchmark: every method on the same virtual scene, scored against ground truth and the
reference.

The scene is ray-cast once (:func:`bistair.sim.trace`) and exposed with each method's
patterns, so all methods see the same geometry, noise model and camera. Scores: coverage of
the truth pixels, fringe-order error rate, phase RMSE against the truth, RMSE against the
three-frequency twelve-step reference (the paper's Fig. 17/20 figure) and the share of each
object decoded right.

Examples
--------
>>> specs = method_specs((1080, 1080))
>>> [(label, specs[label][0].frame_count) for label in specs]  # doctest: +NORMALIZE_WHITESPACE
[('bidirectional', 6), ('bidirectional (paper decoder)', 6), ('lv', 6), ('phase-coding', 6),
 ('graycode', 11), ('multifreq', 36)]
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..codecs import REGISTRY, decode, encode, make_spec
from ..core.phase import TWO_PI
from ..core.result import DecodeResult, make_result
from ..errors import BistairError
from ..sim import expose
from ..spec import BaseSpec
from .metrics import score

REFERENCE = "multifreq"


def method_specs(projector_size: tuple[int, int], period: int = 30, gamma: float = 1.0,
                 steps: int = 4, methods: Iterable[str] | None = None
                 ) -> dict[str, tuple[BaseSpec, dict[str, Any]]]:
    """The comparable pattern set of every method for a projector: label -> (spec, options).

    Every registered codec gives its own comparable parameters at the fringe period
    ``period`` (the paper's 30 px) with ``steps`` phase shifts (:attr:`Codec.comparable
    <bistair.codecs.base.Codec.comparable>`), and each of its decoder variants is a row of
    its own, labelled ``"method (variant)"``. ``methods`` selects labels.
    """
    width, height = projector_size
    table: dict[str, tuple[str, dict, dict]] = {}
    for name, codec in REGISTRY.items():
        params = codec.comparable(width, height, period, steps) if codec.comparable else {}
        table[name] = (name, params, {})
        for variant, options in codec.variants.items():
            table[f"{name} ({variant})"] = (name, params, options)
    wanted = set(table if methods is None else methods)
    unknown = wanted - set(table)
    if unknown:
        raise ValueError(f"unknown method(s) {sorted(unknown)} (known: {sorted(table)})")
    common = dict(width=width, height=height, gamma=gamma)
    return {label: (make_spec(method, **common, **params), options)
            for label, (method, params, options) in table.items() if label in wanted}


@dataclass
class Row:
    """One method's scores."""

    label: str
    spec: BaseSpec
    result: DecodeResult
    scores: dict[str, Any]
    rmse_reference: float = float("nan")

    @property
    def frames(self) -> int:
        return self.spec.frame_count


@dataclass
class Comparison:
    rows: list[Row]
    truth: Any  # bistair.sim.Truth
    objects: list[int] = field(default_factory=list)  # object ids, largest first


def run(trace: Any, specs: dict[str, tuple[BaseSpec, dict[str, Any]]],
        progress: Callable[[str], None] | None = None, imaging: Any = None) -> Comparison:
    """Expose ``trace`` with every spec's patterns (under ``imaging``, default the trace's
    own: noise, blur, gamma and light do not change the geometry), decode and score. A
    decode that refuses the captures scores as nothing decoded (``info["refused"]`` says
    why)."""
    truth = trace.truth
    rows = []
    for label, (spec, options) in specs.items():
        if progress:
            progress(label)
        images = expose(trace, encode(spec), imaging or trace.imaging)
        try:
            result = decode(images, spec, **options)
        except BistairError as exc:  # a refusal: nothing decoded, and why
            shape = images.shape[1:]
            result = make_result(spec.method, np.zeros(shape), np.full(shape, -1), spec.period,
                                 np.zeros(shape), info={"refused": str(exc)})
        scores = score(result, truth.coord(spec), truth.mask, truth.object_id)
        rows.append(Row(label, spec, result, scores))
    ref = next((r for r in rows if r.spec.method == REFERENCE), None)
    if ref is not None:
        for row in rows:
            row.rmse_reference = rmse_against(row.result, ref.result)
    sizes = {i: int((truth.object_id[truth.mask] == i).sum())
             for i in np.unique(truth.object_id[truth.mask])}
    objects = sorted(sizes, key=lambda i: -sizes[i])
    return Comparison(rows, truth, [int(i) for i in objects])


def rmse_against(result: DecodeResult, reference: DecodeResult) -> float:
    """RMSE (radians of ``result``'s period) where both are valid and agree on the fringe."""
    both = result.mask & reference.mask
    ref_phase = reference.coord * np.float32(TWO_PI / result.period)
    err = (result.phase - ref_phase)[both]
    err = err[np.abs(err) < np.pi]  # an order error is counted as such, not in the RMSE
    return float(np.sqrt(np.mean(err**2))) if err.size else float("nan")


def table(comparison: Comparison) -> list[dict[str, Any]]:
    """The comparison as plain rows (method, frames, coverage, ..., objects, and
    ``refused``: the reason a decode refused the captures, else ``None``)."""
    out = []
    for row in comparison.rows:
        s = row.scores
        out.append({
            "method": row.label,
            "frames": row.frames,
            "coverage": s["coverage"],
            "order_error_rate": s["order_error_rate"],
            "phase_rmse": s["phase_rmse"],
            "rmse_vs_reference": row.rmse_reference,
            "objects": {i: s.get("objects", {}).get(i, 0.0) for i in comparison.objects},
            "refused": row.result.info.get("refused"),  # why the decode refused, or None
        })
    return out


def format_table(rows: list[dict[str, Any]], objects: list[int]) -> str:
    """A fixed-width text table of :func:`table` rows (small objects = all but the largest);
    a refused decode reads ``refused`` and why, not 0% coverage."""
    small = objects[1:]
    head = (f"{'method':<30} {'frames':>6} {'coverage':>9} {'order err':>10} "
            f"{'RMSE truth':>11} {'RMSE ref':>9}  " + " ".join(f"{'obj ' + str(i):>7}"
                                                             for i in small))
    lines = [head, "-" * len(head)]
    for r in rows:
        if r.get("refused"):
            lines.append(f"{r['method']:<30} {r['frames']:>6}   refused: {r['refused']}")
            continue
        lines.append(
            f"{r['method']:<30} {r['frames']:>6} {100 * r['coverage']:8.2f}% "
            f"{100 * r['order_error_rate']:9.3f}% {r['phase_rmse']:9.4f}rad "
            f"{r['rmse_vs_reference']:7.4f}rad  "
            + " ".join(f"{100 * r['objects'][i]:6.1f}%" for i in small))
    return "\n".join(lines)
