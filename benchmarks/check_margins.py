"""How close every real capture in ../shared/data comes to each thresholded check's limit,
part by part (each axis, each code alone, each strategy): the false refusals the README's
table of checks counts.

Every part is decoded with ``force=True`` (a check that would refuse is recorded in
``info["forced"]``, the decode goes on); the figures the checks judge are printed beside
their limits. Run: ``python benchmarks/check_margins.py``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from support.real_parts import parts  # noqa: E402

import bistair  # noqa: E402
from bistair.io.read import read_with_spec  # noqa: E402


def main() -> None:
    rows, refused = [], 0
    for name, folder, spec, options in parts():
        start = time.perf_counter()
        stack, spec = read_with_spec(folder, spec)
        res = bistair.decode(stack, spec, force=True, **options)
        info = res.info
        links = info.get("jump_links", 0)
        share = info.get("jump_violations", 0) / links if links else 0.0
        forced = info.get("forced", [])
        refused += bool(forced)
        rows.append((name, f"{100 * res.mask.mean():5.1f}%", f"{100 * share:5.2f}% of {links}",
                     f"{100 * info.get('block_jumps', 0) / max(links, 1):5.2f}%",
                     f"{info.get('stair_misfit', float('nan')):.3f}",
                     f"{info.get('period_agreement', float('nan')):.3f}",
                     "; ".join(forced) or "-", f"{time.perf_counter() - start:.1f}s"))
    head = ("part", "valid", "wrong steps", "block", "misfit", "agree", "would refuse", "time")
    widths = [max(len(str(r[i])) for r in [head, *rows]) for i in range(len(head))]
    for row in [head, *rows]:
        print("  ".join(str(v).ljust(w) for v, w in zip(row, widths, strict=True)))
    print(f"\n{len(rows)} parts; false refusals: {refused}")


if __name__ == "__main__":
    main()
