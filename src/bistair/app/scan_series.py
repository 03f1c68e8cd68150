"""``bistair scan --scans N``: the pattern set scanned N times in a row, each scan written and
(``--decode``) decoded on worker threads while the next is grabbed.

:func:`scan_series` writes::

    OUT/scan-0000/ ...   each a scan folder as 'bistair scan' writes it (NN.png, spec.json,
                         scan.json), with --decode its decode in decode/
    OUT/series.json      the devices, the counts, and per scan its folder, when it was
                         grabbed, its decode's seconds and valid share, or why it has none

Four threads: the grab loop (the caller's), a writer (each scan's captures, in grab order;
PNG stored, not deflated, unless ``compress_captures``: a fifth of the CPU time, the same
pixel values), a decoder (the kernels release the GIL, so it decodes while the next scan is
grabbed and written) and an outputs thread (each decode's files and previews, so that the
decoder goes on to the next scan). The grab loop never waits for a decode: a scan grabbed
while ``backlog`` scans already wait for the decoder is not decoded (its captures are
written; counted and said as scans the decode fell behind on; ``bistair batch OUT`` decodes
them later). It waits for the writer only when :data:`WRITE_BACKLOG` scans wait to be
written (the seconds it waited are counted); the decoder waits for the outputs when
:data:`OUTPUT_BACKLOG` decodes wait to be written. Before the first scan the decoder
decodes the spec's own patterns once, so that loading its kernels does not hold up the
first scans. ``series.json`` keeps each thread's CPU seconds (``cpu_s``): where the time
went.

``OUT`` is written as a temporary folder that replaces it as a whole at the end. Ctrl-C,
SIGTERM or a failing camera stops the grabbing: the scans grabbed are written whole, the
decode under way ends and is kept, the scans still waiting are not decoded (``stopped``),
``series.json`` says so and the folder is moved in, then the stop goes on (nothing is
written if no scan was grabbed). A scan's frames are never half-written: a scan cut off
mid-way is dropped.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair.codecs import make_spec
>>> spec = make_spec("graycode", width=1920, height=1080, period=30)
>>> with tempfile.TemporaryDirectory() as tmp:
...     report = scan_series(spec, "none", "sim:plane:64x48@200", pathlib.Path(tmp) / "s", 3,
...                          decode=True, previews=False)
...     sorted(p.name for p in report.out.iterdir()), report.count("decoded")
(['scan-0000', 'scan-0001', 'scan-0002', 'series.json'], 3)
"""

from __future__ import annotations

import contextlib
import os
import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..acquire import Scan, parse_camera, parse_display
from ..acquire.cameras import Camera, one_line
from ..acquire.displays import Display
from ..acquire.loop import pattern_images, scans
from ..codecs import decode as decode_stack
from ..core.jit import set_threads, thread_count
from ..errors import BistairError
from ..io.atomic import TEMP_PREFIX, check_output, output_folder, replace_folder, write_image
from ..io.jsonfile import to_jsonable, write_json
from ..io.read import load_spec
from ..io.writers import save_result
from ..spec import BaseSpec
from .decode import require_valid
from .scan import DECODE_FOLDER, check_out

SERIES_FILE = "series.json"
WRITE_BACKLOG = 8  # scans grabbed and not yet written before the grab loop waits
OUTPUT_BACKLOG = 2  # decodes not yet written before the decoder waits
MAX_BACKLOG = 100
MAX_SCANS = 1_000_000
# why a scan has no decode
BEHIND, STOPPED = "the decode fell behind", "stopped before its decode"
NOT_ASKED = "no --decode"
_NOT_FAILED = (None, BEHIND, STOPPED, NOT_ASKED)


@dataclass
class SeriesReport:
    """What a series wrote: the folder, the spec, one record per scan grabbed (``folder``,
    ``started`` and ``grabbed`` in seconds from the series' start, ``decoded``,
    ``decode_seconds``, ``valid``, ``not_decoded``: why not) and the series' ``info``."""

    out: Path
    spec: BaseSpec
    records: list[dict[str, Any]]
    info: dict[str, Any] = field(default_factory=dict)

    def count(self, what: str) -> int:
        """Scans ``decoded``, ``behind`` (the decode fell behind), ``stopped`` (waiting
        when the series stopped) or ``failed`` (the decode refused or failed)."""
        if what == "decoded":
            return sum(bool(r["decoded"]) for r in self.records)
        reasons = {"behind": (BEHIND,), "stopped": (STOPPED,)}
        if what in reasons:
            return sum(r["not_decoded"] in reasons[what] for r in self.records)
        if what == "failed":
            return sum(r["not_decoded"] not in _NOT_FAILED for r in self.records)
        raise ValueError(what)

    def to_dict(self) -> dict[str, Any]:
        """What ``series.json`` holds."""
        counts = {"decoded": self.count("decoded"), "behind": self.count("behind"),
                  "stopped_before_decode": self.count("stopped"), "failed": self.count("failed")}
        return {"format": "bistair-series", "version": 1, **self.info,
                "grabbed": len(self.records), **counts, "scans": self.records}


def scan_series(spec: BaseSpec | str | Path, display: Display | str, camera: Camera | str,
                out: str | Path, count: int, *, decode: bool = False, backlog: int = 2,
                previews: bool = True, compress_captures: bool = False,
                progress: Callable[[str], None] | None = None, **options: Any) -> SeriesReport:
    """Scan ``spec`` ``count`` times with ``display`` and ``camera`` into ``out`` (see the
    module's description); ``decode`` decodes each scan while the next is grabbed, with at
    most ``backlog`` scans waiting for the decoder (``previews``: the decodes' PNG
    previews, which take about twice the CPU time of a decode; ``compress_captures``: the
    captures' PNG deflated as one scan writes them, else stored: the same pixel values,
    files 2.2 times as big, a fifth of the CPU time). ``options`` go to
    :func:`bistair.acquire.scan` (``settle_ms``, ``average``, ``drop``, ``exposure``,
    ``gain``, ``pixel_format``, ``latency_file``). ``display`` and ``camera``: device
    strings or device objects (not yet open)."""
    say = _throttled(progress or (lambda text: None))
    for name, value, top in (("--scans", count, MAX_SCANS), ("--backlog", backlog, MAX_BACKLOG)):
        if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= top:
            raise BistairError(f"{name} must be a whole number from 1 to {top}, got {value!r}")
    out = check_output(out)
    check_out(out)
    if not isinstance(spec, BaseSpec):
        spec = load_spec(spec)
    settings = [options.pop(k, None) for k in ("exposure", "gain", "pixel_format")]
    devices = (parse_display(display) if isinstance(display, str) else display,
               parse_camera(camera, *settings) if isinstance(camera, str) else camera)
    start = time.monotonic()
    with replace_folder(out, prefix=f"{TEMP_PREFIX}{os.getpid()}-") as tmp:
        pipe = _Pipeline(tmp, spec, count, decode, backlog, previews, start,
                         compress_captures)
        stopped: BaseException | None = None
        try:
            if decode:
                say("loading the decoder's kernels (a decode of the patterns)")
                pipe.warm_up()
            with contextlib.closing(scans(spec, *devices, count, progress=say,
                                          **options)) as each:
                for grabbed in each:
                    pipe.add(grabbed)
        except BaseException as exc:  # Ctrl-C, SIGTERM, a camera that fails: keep what is
            stopped = exc             # grabbed, then stop as asked
        say("writing the last scans" + (" and their decodes" if decode else ""))
        pipe.finish(stop=stopped is not None)
        if not pipe.records and stopped is not None:
            raise stopped  # nothing grabbed: nothing written
        report = SeriesReport(out, spec, pipe.records, {
            "method": spec.method, "display": devices[0].describe(),
            "camera": devices[1].describe(), "decode": decode, "backlog": backlog,
            "compress_captures": compress_captures,
            "seconds": round(time.monotonic() - start, 3), **pipe.figures(),
            "stopped": None if stopped is None else (one_line(stopped) if isinstance(
                stopped, BistairError) else type(stopped).__name__)})
        write_json(tmp / SERIES_FILE, to_jsonable(report.to_dict()))
    if isinstance(stopped, BistairError):
        raise BistairError(f"{stopped} (the {len(pipe.records)} scans grabbed before are in "
                           f"{out})") from None
    if stopped is not None:
        raise stopped
    return report


class _Pipeline:
    """The writer and decoder threads of a series, and its records."""

    def __init__(self, tmp: Path, spec: BaseSpec, count: int, decode: bool, backlog: int,
                 previews: bool, start: float, compress: bool) -> None:
        self.tmp, self.spec, self.decoding, self.backlog = tmp, spec, decode, backlog
        self.previews, self.start, self.compress = previews, start, compress
        # CPU seconds from the first scan: each thread's (the decoder's without numba's
        # worker threads, previews encoded on a pool thread) and the process's
        self.cpu = {"grab": 0.0, "write": 0.0, "decode": 0.0, "outputs": 0.0, "process": 0.0}
        self.cpu_start = (0.0, 0.0)  # the grab loop's and the process's, at the first scan
        self.digits = max(4, len(str(count - 1)))
        self.entries: list[tuple[dict[str, Any], threading.Event]] = []  # handed on or not
        self.records: list[dict[str, Any]] = []  # those written (made by finish)
        self.writes: queue.Queue = queue.Queue(maxsize=WRITE_BACKLOG)
        self.decodes: queue.Queue = queue.Queue()
        self.outputs: queue.Queue = queue.Queue(maxsize=OUTPUT_BACKLOG)
        self.lock = threading.Lock()
        self.waiting = self.most_waiting = 0
        self.waited = 0.0  # seconds the grab loop waited for the writer
        self.stop = threading.Event()
        self.warm_seconds: float | None = None
        self.warnings: list[str] = []  # the scan loop's (a settle time never measured)
        self.threads = [threading.Thread(target=self._writer, daemon=True)]
        if decode:
            self.threads += [threading.Thread(target=self._decoder, args=(thread_count(),),
                                              daemon=True),
                             threading.Thread(target=self._outputs, daemon=True)]
        for thread in self.threads:
            thread.start()

    def warm_up(self) -> None:
        """Decode (a corner of) the spec's own patterns on the decoder thread and wait:
        its kernels are loaded before the first scan."""
        done = threading.Event()
        self.decodes.put((None, None, done))
        done.wait()

    def add(self, grabbed: Scan) -> None:
        """A scan is grabbed: hand it to the writer and, if there is room, the decoder. A
        stop (Ctrl-C) between any two steps leaves what :meth:`finish` sorts out."""
        index = len(self.entries)
        if index == 0:
            self.warnings = list(grabbed.info.get("warnings", []))
            self.cpu_start = (time.thread_time(), time.process_time())
        now = time.monotonic() - self.start
        record = {"index": index, "folder": f"scan-{index:0{self.digits}d}",
                  "started": round(now - grabbed.info["seconds"], 4),
                  "grabbed": round(now, 4), "decoded": False, "decode_seconds": None,
                  "valid": None, "not_decoded": None if self.decoding else NOT_ASKED}
        written = threading.Event()  # set by the writer once the captures are written
        self.entries.append((record, written))
        t0 = time.monotonic()
        self.writes.put((record, grabbed, written))  # waits only when WRITE_BACKLOG wait
        self.waited += time.monotonic() - t0
        if self.decoding:
            with self.lock:
                if self.waiting < self.backlog:
                    self.waiting += 1
                    self.most_waiting = max(self.most_waiting, self.waiting)
                    self.decodes.put((record, grabbed, written))
                else:
                    record["not_decoded"] = BEHIND

    def finish(self, stop: bool) -> None:
        """Write every scan handed on; with ``stop``, decode none that has not begun. Then
        the records: a scan stopped before it reached the writer is left out, one stopped
        before it reached the decoder is listed as stopped."""
        self.cpu["grab"] = time.thread_time() - self.cpu_start[0]
        if stop:
            self.stop.set()
        self.writes.put(None)
        self.decodes.put(None)
        for thread in self.threads:
            thread.join()
        self.cpu["process"] = time.process_time() - self.cpu_start[1]
        self.records = [record for record, written in self.entries if written.is_set()]
        for record in self.records:
            if not record["decoded"] and record["not_decoded"] is None:
                record["not_decoded"] = STOPPED

    def figures(self) -> dict[str, Any]:
        """The series' rates and waits, for ``series.json`` and the summary."""
        grabbed = [r["grabbed"] for r in self.records]
        span = grabbed[-1] - self.records[0]["started"] if grabbed else 0.0
        seconds = [r["decode_seconds"] for r in self.records if r["decoded"]]
        return {"scans_per_s": round(len(grabbed) / span, 3) if span > 0 else None,
                "decode_median_s": round(float(np.median(seconds)), 4) if seconds else None,
                "most_waiting": self.most_waiting, "waited_for_writer_s": round(self.waited, 3),
                "warm_up_s": self.warm_seconds, "warnings": self.warnings,
                "cpu_s": {k: round(v, 3) for k, v in self.cpu.items()}}

    def _writer(self) -> None:
        t0 = time.thread_time()
        while (item := self.writes.get()) is not None:
            record, grabbed, written = item
            try:
                files = [f"{i:02d}.png" for i in range(len(grabbed.frames))]
                with output_folder(self.tmp / record["folder"]) as folder:
                    for name, image in zip(files, grabbed.frames, strict=True):
                        write_image(folder / name, image, compress=self.compress)
                    (folder / "spec.json").write_text(self.spec.to_json())
                    write_json(folder / "scan.json", to_jsonable(grabbed.to_dict(files)))
            except Exception as exc:  # recorded; the series goes on
                record["not_decoded"] = record["write_error"] = one_line(exc)
            finally:
                written.set()
        self.cpu["write"] = time.thread_time() - t0

    def _decoder(self, threads: int) -> None:
        set_threads(threads)  # numba's count is per thread: the caller's
        while (item := self.decodes.get()) is not None:
            record, grabbed, written = item
            if record is None:  # the warm-up
                self._warm(written)
                continue
            t_cpu = time.thread_time()
            with self.lock:
                self.waiting -= 1
            if self.stop.is_set():
                record["not_decoded"] = STOPPED
                continue
            try:
                t0 = time.perf_counter()
                result = require_valid(decode_stack(grabbed.frames, self.spec))
                record["decode_seconds"] = round(time.perf_counter() - t0, 4)
            except Exception as exc:  # a refusal or failure of this scan: the series goes on
                record["not_decoded"] = one_line(exc)
                continue
            finally:
                self.cpu["decode"] += time.thread_time() - t_cpu
            self.outputs.put((record, result, written))  # waits when OUTPUT_BACKLOG wait
        self.outputs.put(None)

    def _outputs(self) -> None:
        """Each decode's files and previews, once its scan's captures are written: off the
        decoder's thread, which goes on to the next scan."""
        t0 = time.thread_time()
        while (item := self.outputs.get()) is not None:
            record, result, written = item
            written.wait()
            if "write_error" in record:
                continue
            try:
                save_result(result, self.tmp / record["folder"] / DECODE_FOLDER,
                            previews=self.previews)
            except Exception as exc:  # recorded; the series goes on
                record["not_decoded"] = one_line(exc)
                continue
            record.update(decoded=True, not_decoded=None, valid=round(float(
                result.mask.mean()), 6), warnings=_warnings(result))
        self.cpu["outputs"] = time.thread_time() - t0

    def _warm(self, done: threading.Event) -> None:
        t0 = time.perf_counter()
        corner = np.ascontiguousarray(pattern_images(self.spec)[:, :256, :512])
        with contextlib.suppress(Exception):  # a corner it refuses has loaded most kernels
            decode_stack(corner, self.spec)
        self.warm_seconds = round(time.perf_counter() - t0, 3)
        done.set()


def _throttled(say: Callable[[str], None], seconds: float = 1.0) -> Callable[[str], None]:
    """``say``, passing on a stage at most every ``seconds`` (a scan's stage among many)."""
    last = [-np.inf]

    def told(text: str) -> None:
        now = time.monotonic()
        if now - last[0] >= seconds or not text.startswith("scan "):
            last[0] = now
            say(text)

    return told


def summary_lines(report: SeriesReport) -> tuple[list[str], list[str]]:
    """What ``bistair scan --scans N`` prints: the summary lines and the warnings (the scan
    loop's, scans not decoded and why, the grabbing held up by the writing, the decodes'
    own warnings once each)."""
    info, n, out = report.info, len(report.records), report.out
    camera = info["camera"]
    size = f"{camera['size'][0]}x{camera['size'][1]} " if camera.get("size") else ""
    rate = info["scans_per_s"]
    lines = [f"scanned {n} {report.spec.method} pattern sets with {info['display']['name']} "
             f"and {camera['name']} in {info['seconds']:.1f} s ("
             f"{'-' if rate is None else f'{rate:.1f}'} scans/s{', ' + size if size else ''}"
             f"frames); wrote {out}"]
    warnings = list(info.get("warnings", []))
    if info["decode"]:
        decoded = report.count("decoded")
        median = info["decode_median_s"]
        each = "" if median is None else f"median {1e3 * median:.0f} ms a decode; "
        lines.append(f"decoded {decoded} of {n} while the next was grabbed ({each}at most "
                     f"{info['most_waiting']} waiting for the decoder); wrote "
                     f"{out}/scan-*/{DECODE_FOLDER}")
        behind = report.count("behind")
        if behind:
            period = f", one every {1e3 / rate:.0f} ms" if rate else ""
            warnings.append(f"{behind} of {n} scans not decoded: the decode ({each.rstrip('; ')}"
                            f") fell behind the scans ({rate or 0:.1f} scans/s{period}); their "
                            f"captures are in {out} ('bistair batch {out} --out RESULT' decodes "
                            "them)")
        failed = [r for r in report.records if r["not_decoded"] not in _NOT_FAILED]
        if failed:
            warnings.append(f"{len(failed)} scans not decoded ({failed[0]['folder']}: "
                            f"{failed[0]['not_decoded']}; see {out}/{SERIES_FILE})")
        seen = sorted({w for r in report.records for w in r.get("warnings", [])})
        warnings += [f"decode: {w}" for w in seen]
    if info["waited_for_writer_s"] > 0.05:
        warnings.append(f"the grabbing waited {info['waited_for_writer_s']:.1f} s for the "
                        "captures to be written (the disk or the CPU is slower than the "
                        "camera)")
    return lines, warnings


def _warnings(result: Any) -> list[str]:
    infos = [result.info] if not hasattr(result, "x") else [result.x.info, result.y.info]
    return [w for info in infos for w in info.get("warnings", [])]
