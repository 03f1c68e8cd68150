"""How close every real capture in ../shared/data comes to each thresholded check's limit,
part by part (each axis, each code alone, each strategy): the false refusals the README's
table of checks counts.

Every part is decoded with ``force=True`` (a check that would refuse is recorded in
``info["forced"]``, the decode goes on); the figures the checks judge are printed beside
their limits. Run: ``python benchmarks/check_margins.py [--markdown docs/results/checks.md]``
(the page of the documentation is written so).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from support.real_parts import parts  # noqa: E402

import bistair  # noqa: E402
from bistair.io.read import read_with_spec  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", type=Path, default=None,
                        help="also write the table as a Markdown page")
    args = parser.parse_args()
    rows, refused = [], 0
    for name, folder, spec, options in parts():
        start = time.perf_counter()
        stack, spec = read_with_spec(folder, spec)
        res = bistair.decode(stack, spec, force=True, **options)
        for axis, part in ((None, res),) if not hasattr(res, "x") else (("x", res.x),
                                                                        ("y", res.y)):
            info = part.info
            links = info.get("jump_links", 0)
            share = info.get("jump_violations", 0) / links if links else 0.0
            forced = info.get("forced", [])
            refused += bool(forced)
            label = name if axis is None else f"{name} {axis}"
            modulated = info.get("valid_modulation")
            rows.append((label, f"{100 * part.mask.mean():.1f}%",
                         f"{100 * part.mask.sum() / modulated:.1f}%" if modulated else "-",
                         f"{100 * share:.2f}% of {links}",
                         f"{100 * info.get('block_jumps', 0) / max(links, 1):.2f}%",
                         _fmt(info.get("stair_misfit")), _fmt(info.get("period_agreement")),
                         _fmt(info.get("cell_steps_against", 0) / info["cell_steps"]
                              if info.get("cell_steps") else None),
                         _fmt(info.get("rotated_fit")), _fmt(info.get("exchange_fit")),
                         f"{100 * info['edge_jumps'] / info['edge_links']:.2f}% of "
                         f"{info['edge_links']}" if info.get("edge_links") else "-",
                         "; ".join(f[:60] for f in forced) or "-",
                         f"{time.perf_counter() - start:.1f}s"))
    head = ("part", "valid", "of modulated", "wrong steps", "block jumps", "stair misfit",
            "periods agree", "cells backwards", "rotated fit", "exchange fit",
            "edge jumps", "would refuse",
            "time")
    widths = [max(len(str(r[i])) for r in [head, *rows]) for i in range(len(head))]
    for row in [head, *rows]:
        print("  ".join(str(v).ljust(w) for v, w in zip(row, widths, strict=True)))
    print(f"\n{len(rows)} decodes; refused by a check: {refused}")
    if args.markdown is not None:
        lines = ["# The checks on the real captures", "",
                 "Written by `python benchmarks/check_margins.py --markdown "
                 f"{args.markdown.as_posix()}`: every real capture in `../shared/data`, "
                 "decoded whole, each axis and each code alone and with each strategy, "
                 "with `force=True`; the figures each thresholded check judges, and the "
                 "checks that would refuse (see the table of checks in the user guide).",
                 "", "| " + " | ".join(head[:-1]) + " |",
                 "| " + " | ".join("---" for _ in head[:-1]) + " |"]
        lines += ["| " + " | ".join(str(v) for v in row[:-1]) + " |" for row in rows]
        lines += ["", f"{len(rows)} decodes; refused by a check: {refused}."]
        args.markdown.write_text("\n".join(lines) + "\n")
        print(f"wrote {args.markdown}")


def _fmt(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f}"


if __name__ == "__main__":
    main()
