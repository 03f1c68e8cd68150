"""``bistair batch``: decode (and with a calibration reconstruct) many capture sets on Dask.

The sets are every sub-folder of a folder (natural name order; hidden folders and the
output folder left out) or every row of a CSV manifest (:func:`read_manifest`). Each set
runs as one task (:func:`run_set`) that reads its own files and writes, atomically, into
``OUT/<set name>/`` the files ``bistair decode`` writes (``phase.npy``, ``coord.npy``, ...,
the previews, ``info.json``), with a calibration also ``cloud.ply``, ``depth.npy`` and
``depth.png`` (what ``bistair reconstruct`` writes), and last :data:`MARKER`.

Complete outputs: a set's outputs are complete when ``OUT/<set>/batch-set.json`` reads as
this format, was written for the same captures, spec, calibration and options, and every
file it lists is present. The marker is written last inside the temporary folder that
becomes ``OUT/<set>`` in one rename, so a set folder is either complete or absent;
``resume=True`` skips complete sets and redoes the others.

A set that fails (unreadable files, a frame count that does not fit the spec, dark
captures, ...) is recorded with its one-line error and the batch goes on. ``OUT/batch.csv``
(written atomically when the batch ends, also when it is interrupted) has one row per set:
``name, status (ok or error), error, valid_fraction, noise, seconds, resumed``.

Examples
--------
>>> import tempfile, pathlib
>>> from bistair.codecs import encode, make_spec
>>> from bistair.core.captures import to_bit_depth
>>> from bistair.io.atomic import write_image
>>> spec = make_spec("graycode", width=120, height=32, period=30)
>>> with tempfile.TemporaryDirectory() as tmp:
...     root = pathlib.Path(tmp) / "scans"
...     for name in ("a", "b"):
...         (root / name).mkdir(parents=True)
...         for i, img in enumerate(to_bit_depth(encode(spec), 8)):
...             write_image(root / name / f"{i:02d}.png", img)
...         _ = (root / name / "spec.json").write_text(spec.to_json())
...     report = run_batch(root, pathlib.Path(tmp) / "out", workers=1)
...     [(row["name"], row["status"], row["valid_fraction"]) for row in report.rows]
[('a', 'ok', 1.0), ('b', 'ok', 1.0)]
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from ..core.captures import check_min_modulation
from ..core.result import AxesResult, DecodeResult
from ..errors import BistairError
from ..geometry.calibration import Calibration, StereoCalibration, load_calibration
from ..geometry.triangulate import check_depth_range
from ..io.atomic import check_output, output_file, replace_folder
from ..io.jsonfile import read_json, write_json
from ..io.read import (
    IMAGE_SUFFIXES,
    capture_files,
    default_spec_path,
    list_images,
    load_spec,
    natural_key,
)
from .decode import decode_folder, reconstruct_folder
from .engine import (
    BATCH_PREFIX,
    check_workers,
    dask_client,
    remove_run_temporaries,
    run_prefix,
    run_tasks,
)
from .stereo import stereo_folder, stereo_pair

MARKER = "batch-set.json"  # written last into every complete set folder
MARKER_FORMAT = "bistair-batch-set"
COLUMNS = ("name", "status", "error", "valid_fraction", "noise", "seconds", "resumed")
MANIFEST_COLUMNS = ("captures", "spec", "calibration", "out")


@dataclass(frozen=True)
class SetJob:
    """One capture set: its name, captures (a folder, a ``.npy`` stack, an image file or a
    glob pattern), spec and calibration files (``None``: the captures' ``spec.json``; no
    reconstruction) and output folder, all as absolute paths."""

    name: str
    captures: str
    spec: str | None
    calibration: str | None
    out: str


@dataclass
class BatchReport:
    """What a batch did: one row per set (:data:`COLUMNS`), in the sets' order."""

    rows: list[dict[str, Any]]
    seconds: float
    workers: int | str
    out: Path
    interrupted: bool = False
    total: int = 0

    @property
    def ok(self) -> int:
        return sum(row["status"] == "ok" for row in self.rows)

    @property
    def failed(self) -> list[dict[str, Any]]:
        return [row for row in self.rows if row["status"] == "error"]

    @property
    def resumed(self) -> int:
        return sum(bool(row["resumed"]) for row in self.rows)

    def summary(self) -> str:
        """One line: sets ok, failed and skipped as complete, time and rate."""
        done = len(self.rows) - self.resumed
        rate = f", {done / self.seconds:.2f} sets/s" if done and self.seconds > 0 else ""
        head = (f"{len(self.rows)} of {self.total} sets" if self.interrupted
                else f"{len(self.rows)} sets")
        skipped = f" ({self.resumed} complete before, skipped)" if self.resumed else ""
        on = (f" on {self.workers} worker{'s' if self.workers != 1 else ''}" if self.workers
              else "")
        return (f"{head}: {self.ok} ok{skipped}, {len(self.failed)} failed; "
                f"{self.seconds:.1f} s{on}{rate}")


@dataclass(frozen=True)
class Options:
    """The settings of every set: decoder options, previews, reconstruction."""

    decode: dict[str, Any] = field(default_factory=dict)
    previews: bool = True
    min_depth: float = 0.0
    max_depth: float = math.inf
    epipolar_tolerance: float = 1.5

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["max_depth"] = None if math.isinf(self.max_depth) else self.max_depth
        return out


# -- the sets ------------------------------------------------------------------------------
def find_sets(root: str | Path, out: str | Path, spec: str | Path | None = None,
              calibration: str | Path | None = None) -> list[SetJob]:
    """The sets of a batch: every sub-folder of the folder ``root`` (natural name order,
    hidden ones and ``out`` left out; set name = folder name) or the rows of the manifest
    ``root`` (a ``.csv`` file, see :func:`read_manifest`); ``spec`` and ``calibration`` are
    the defaults.

    Raises
    ------
    BistairError
        ``root`` missing, the output folder is ``root`` itself, no sets (no sub-folder
        holds images or a stereo pair: the message points to the ``index.csv`` of a data
        set there), a bad manifest or two sets writing to the same folder.
    """
    root, out = Path(root), Path(out).absolute()
    spec = None if spec is None else str(Path(spec).absolute())
    calibration = None if calibration is None else str(Path(calibration).absolute())
    if not root.exists():
        raise BistairError(f"batch input {root} not found")
    if root.is_file():
        if root.suffix.lower() != ".csv":
            raise BistairError(f"batch input {root} must be a folder of capture sets or a "
                               ".csv manifest")
        jobs = read_manifest(root, out, spec, calibration)
    else:
        if root.resolve() == out.resolve():
            raise BistairError(f"the output folder {out} is the folder of the capture sets: "
                               "choose another (its set folders would be read as sets)")
        if out.parent.resolve() == root.resolve() and out.is_dir() and any(
                p.suffix.lower() in IMAGE_SUFFIXES or p.name == "spec.json"
                for p in out.iterdir()):
            raise BistairError(f"the output folder {out} is one of the capture sets in {root} "
                               "(it holds images or a spec.json): choose another")
        subs = sorted((p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")
                       and p.resolve() != out.resolve()), key=lambda p: natural_key(p.name))
        if not any(list_images(p) or stereo_pair(p) for p in subs):
            raise BistairError(_no_sets(root, subs))
        jobs = [SetJob(p.name, str(p.absolute()), spec, calibration, str(out / p.name))
                for p in subs]
    resolved = out.resolve()
    for job in jobs:
        folder = Path(job.captures)
        folder = folder if folder.is_dir() else folder.parent
        if folder.resolve() == resolved or folder.resolve() in resolved.parents:
            raise BistairError(f"the output folder {out} is inside the capture set {job.name} "
                               f"({folder}): choose another")
    seen: dict[str, str] = {}
    for job in jobs:
        key = str(Path(job.out).resolve())
        if key in seen:
            raise BistairError(f"sets {seen[key]} and {job.name} would both write to "
                               f"{job.out}: give them different out cells")
        seen[key] = job.name
    return jobs


def _no_sets(root: Path, subs: list[Path]) -> str:
    """Why a folder given to a batch holds no capture set, and what to give instead: the
    ``index.csv`` of a data set (``bistair simulate --count``: its sets lie one level
    deeper), the folder itself to ``bistair decode``, or a manifest."""
    index = root / "index.csv"
    what = (f"none of its {len(subs)} sub-folders holds images (or L/ and R/)" if subs
            else "it has no sub-folders (each set is a sub-folder of images)")
    if index.is_file():
        return (f"no capture sets in {root}: {what}; {index} lists the sets of a data set: "
                f"bistair batch {index}")
    if list_images(root):
        return (f"no capture sets in {root}: {what}; it is one capture set itself: bistair "
                f"decode {root}")
    pair = stereo_pair(root)
    if pair is not None:
        return (f"no capture sets in {root}: {what}; it is one set of two cameras itself: "
                f"bistair stereo {pair[0]} {pair[1]}")
    if subs:
        return (f"no capture sets in {root}: {what} (for sets further down, list them in a "
                ".csv manifest: see bistair batch --help)")
    return (f"no capture sets in {root}: it has no sub-folders (each set is a sub-folder of "
            "images, or a row of a .csv manifest)")


def read_manifest(path: str | Path, out: str | Path, spec: str | None = None,
                  calibration: str | None = None) -> list[SetJob]:
    """The sets of a CSV manifest with a header row naming the columns ``captures``
    (required), ``spec``, ``calibration`` and ``out`` (others are ignored, e.g. those of
    ``bistair simulate --count``'s ``index.csv``).

    Paths in the cells are relative to the manifest's folder; an empty cell takes the
    default: ``spec`` and ``calibration`` those of the command line (the spec then
    defaulting to the captures' ``spec.json``), ``out`` the name of the captures' folder (or
    stack file without suffix). The ``out`` cell is also the set's name; a relative one lies
    in the batch's output folder ``out``. Blank lines and lines starting with ``#`` are
    skipped.

    Raises
    ------
    BistairError
        An unreadable file, no header with ``captures``, a row without captures or no rows.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     m = pathlib.Path(tmp) / "sets.csv"
    ...     _ = m.write_text("captures,spec,out\\nscan1,,first\\nscan2/,pats/spec.json,\\n")
    ...     jobs = read_manifest(m, pathlib.Path(tmp) / "out")
    ...     [(j.name, pathlib.Path(j.out).name, j.spec is None) for j in jobs]
    [('first', 'first', True), ('scan2', 'scan2', False)]
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise BistairError(f"cannot read manifest {path}: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise BistairError(f"manifest {path} is not a text (UTF-8) CSV file") from None
    lines = [(n, line) for n, line in enumerate(text.splitlines(), 1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise BistairError(f"manifest {path} is empty")
    rows = list(csv.reader(io.StringIO("\n".join(line for _, line in lines))))
    header = [cell.strip().lower() for cell in rows[0]]
    if "captures" not in header:
        raise BistairError(f"manifest {path} needs a header row with a 'captures' column "
                           f"(and optionally {', '.join(MANIFEST_COLUMNS[1:])}), got "
                           f"{','.join(header) or 'nothing'}")
    base = path.parent.absolute()
    out = Path(out).absolute()
    jobs = []
    for (number, _), row in zip(lines[1:], rows[1:], strict=True):
        cells = {name: (row[i].strip() if i < len(row) else "")
                 for i, name in enumerate(header) if name in MANIFEST_COLUMNS}
        if not cells.get("captures"):
            raise BistairError(f"manifest {path} line {number}: no captures")
        captures = _under(base, cells["captures"])
        name = cells.get("out") or _default_name(cells["captures"])
        target = (out / name).resolve()
        if target == out.resolve() or out.resolve() not in target.parents:
            raise BistairError(f"manifest {path} line {number}: the out cell {name!r} must name "
                               f"a folder inside the output folder {out}")
        jobs.append(SetJob(
            name, captures,
            _under(base, cells["spec"]) if cells.get("spec") else spec,
            _under(base, cells["calibration"]) if cells.get("calibration") else calibration,
            str(out / name)))
    if not jobs:
        raise BistairError(f"manifest {path} lists no capture sets")
    return jobs


def _under(base: Path, cell: str) -> str:
    """A manifest cell as an absolute path (glob patterns kept)."""
    return str(Path(cell) if Path(cell).is_absolute() else base / cell)


def _default_name(captures: str) -> str:
    """A set's name from its captures: the folder's name, a stack's or image's stem, a glob
    pattern's folder."""
    p = Path(captures.rstrip("/\\"))
    if any(c in captures for c in "*?["):
        return p.parent.name or "captures"
    return p.stem if p.suffix.lower() in (".npy", ".png", ".tif", ".tiff", ".bmp") else p.name


# -- one set (runs on a worker) --------------------------------------------------------------
def run_set(job: SetJob, options: Options, prefix: str = BATCH_PREFIX) -> dict[str, Any]:
    """Decode one set (and reconstruct it with a calibration) into ``job.out``, atomically:
    the folder is replaced as a whole, with :data:`MARKER` written last. Never raises for a
    failing set: returns its row of ``batch.csv`` (status ``error`` and the one-line
    message)."""
    start = time.perf_counter()
    try:
        check_output(job.out, [job.captures, job.spec, job.calibration])  # (None: none)
        calibration = None if job.calibration is None else load_calibration(job.calibration)
        if isinstance(calibration, StereoCalibration) or stereo_pair(job.captures):
            return _stereo_set(job, calibration, options, prefix, start)
        with replace_folder(job.out, prefix) as tmp:
            result = decode_folder(job.captures, tmp, job.spec, previews=options.previews,
                                   **options.decode)
            if calibration is not None:
                reconstruct_folder(job.captures, job.spec, calibration, tmp / "cloud.ply",
                                   depth_dir=tmp, min_depth=options.min_depth,
                                   max_depth=options.max_depth,
                                   epipolar_tolerance=options.epipolar_tolerance,
                                   decoded=result)
            row = _row(job.name, "ok", valid_fraction=round(float(result.mask.mean()), 6),
                       noise=_noise(result), seconds=round(time.perf_counter() - start, 3))
            files = sorted(p.name for p in tmp.iterdir())
            write_json(tmp / MARKER, {"format": MARKER_FORMAT, "version": 1,
                                      **_inputs(job, options), "files": files,
                                      "row": row, "warnings": _warnings(result),
                                      "run": prefix})
        return row
    except BistairError as exc:
        return _row(job.name, "error", str(exc), seconds=time.perf_counter() - start)
    except MemoryError:
        return _row(job.name, "error", "not enough memory for these captures",
                    seconds=time.perf_counter() - start)
    except Exception as exc:  # a bug must not stop the batch: record it with its type
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        return _row(job.name, "error", f"{type(exc).__name__}: {first}".rstrip(": "),
                    seconds=time.perf_counter() - start)


def _stereo_set(job: SetJob, calibration: Calibration | StereoCalibration | None,
                options: Options, prefix: str,
                start: float) -> dict[str, Any]:
    """:func:`run_set` for a stereo set (``L/`` and ``R/``) with a stereo calibration: what
    ``bistair stereo`` writes, and the marker. ``valid_fraction``: the share of the left
    camera's pixels with a point; ``noise``: the left decode's."""
    pair = stereo_pair(job.captures)
    if pair is None:
        raise BistairError(f"a stereo calibration needs a stereo set: {job.captures} holds no "
                           "L/ and R/ folders")
    if not isinstance(calibration, StereoCalibration):
        raise BistairError(f"{job.captures} holds L/ and R/: a stereo set needs "
                           "--calibration with a stereo calibration (two cameras)")
    with replace_folder(job.out, prefix) as tmp:
        result = stereo_folder(*pair, tmp, calibration, job.spec,
                               min_depth=options.min_depth, max_depth=options.max_depth,
                               previews=options.previews, **options.decode)
        row = _row(job.name, "ok", valid_fraction=round(float(result.mask.mean()), 6),
                   noise=_noise(result.left), seconds=round(time.perf_counter() - start, 3))
        files = sorted(str(p.relative_to(tmp)) for p in tmp.rglob("*") if p.is_file())
        write_json(tmp / MARKER, {"format": MARKER_FORMAT, "version": 1,
                                  **_inputs(job, options), "files": files, "row": row,
                                  "warnings": result.info.get("warnings", []), "run": prefix})
    return row


def _row(name: str, status: str, error: str = "", valid_fraction: float | None = None,
         noise: float | None = None, seconds: float | None = None,
         resumed: bool = False) -> dict[str, Any]:
    return {"name": name, "status": status, "error": " ".join(error.split()),
            "valid_fraction": valid_fraction, "noise": noise,
            "seconds": None if seconds is None else round(seconds, 3), "resumed": resumed}


def _noise(result: DecodeResult | AxesResult) -> float | None:
    """The decode's camera noise estimate (fraction of full scale; both axes: the larger)."""
    infos = [result.info] if isinstance(result, DecodeResult) else [result.x.info,
                                                                    result.y.info]
    values = [float(i["noise"]) for i in infos if isinstance(i.get("noise"), int | float)]
    return round(max(values), 6) if values else None


def _warnings(result: DecodeResult | AxesResult) -> list[str]:
    infos = [result.info] if isinstance(result, DecodeResult) else [result.x.info,
                                                                    result.y.info]
    return [w for i in infos for w in i.get("warnings", [])]


def _inputs(job: SetJob, options: Options) -> dict[str, Any]:
    """What a set's outputs were made from (compared by :func:`complete_row`): the paths,
    the options and each input file's size and modification time, so that captures, a
    spec or a calibration changed since are decoded again."""
    return {"name": job.name, "captures": job.captures, "spec": job.spec,
            "calibration": job.calibration, "options": options.to_dict(),
            "files_stamp": _stamp(job)}


def _stamp(job: SetJob) -> list[list[Any]]:
    """(path, size, mtime in ns) of a set's capture files, its spec file (the given one or
    the captures' ``spec.json``) and its calibration; an unreadable set gives []."""
    try:
        pair = stereo_pair(job.captures)
        files = (capture_files(job.captures) if pair is None
                 else [f for side in pair for f in capture_files(side)])
    except BistairError:
        return []
    if not files:
        return []
    first = job.captures if pair is None else pair[0]
    spec = Path(job.spec) if job.spec else default_spec_path(first, files)
    stamp = []
    for path in [*files, spec, *([Path(job.calibration)] if job.calibration else [])]:
        with contextlib.suppress(OSError):
            info = path.stat()
            stamp.append([str(path), info.st_size, info.st_mtime_ns])
    return stamp


def complete_row(job: SetJob, options: Options, run: str | None = None
                 ) -> dict[str, Any] | None:
    """The ``batch.csv`` row of a set whose outputs are complete (see the module's
    docstring), marked ``resumed`` unless the run ``run`` (its temporaries' prefix) wrote
    them; ``None`` if they are not complete."""
    folder = Path(job.out)
    try:
        data = read_json(folder / MARKER, "marker", state=True)
    except BistairError:
        return None
    if not isinstance(data, dict) or data.get("format") != MARKER_FORMAT:
        return None
    if any(data.get(k) != v for k, v in _inputs(job, options).items()):
        return None
    files, row = data.get("files"), data.get("row")
    if not isinstance(files, list) or not isinstance(row, dict) or row.get("status") != "ok":
        return None
    if not all(isinstance(f, str) and (folder / f).is_file() for f in files):
        return None
    return {**_row(job.name, "ok"), **{k: row.get(k) for k in COLUMNS if k in row},
            "resumed": run is None or data.get("run") != run}


# -- the batch -------------------------------------------------------------------------------
def run_batch(source: str | Path, out: str | Path, spec: str | Path | None = None,
              calibration: str | Path | None = None, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, previews: bool = True,
              min_depth: float = 0.0, max_depth: float = math.inf,
              epipolar_tolerance: float = 1.5, show_progress: bool = False,
              **decode_options: Any) -> BatchReport:
    """Decode (and with a calibration reconstruct) every set of ``source`` into
    ``out/<set name>/`` on Dask and write ``out/batch.csv``.

    ``source``: a folder whose sub-folders are the sets, or a CSV manifest
    (:func:`read_manifest`). ``spec`` and ``calibration``: the defaults of every set.
    ``workers``: processes of a local cluster (default: the cores); ``scheduler``: the
    address of an existing cluster's scheduler instead (``tcp://HOST:PORT``; its workers
    must see the same paths). ``resume``: skip sets whose outputs are complete.
    ``decode_options`` (``strategy``, ``min_modulation``) go to the decoder, ``min_depth``,
    ``max_depth`` and ``epipolar_tolerance`` to the reconstruction. ``show_progress``: a
    progress bar on the terminal.

    Failing sets are rows with status ``error``; the batch goes on. On Ctrl-C
    (``KeyboardInterrupt``) or SIGTERM (``SystemExit``, as the command line raises it) the
    sets not finished are cancelled, the cluster is closed, ``batch.csv`` lists the finished
    ones and the exception propagates; no set folder is left half-written and no temporary
    is left behind.

    Raises
    ------
    BistairError
        Bad input for the whole batch (see :func:`find_sets`, a spec or calibration file
        given that cannot be read, bad options, a scheduler that cannot be reached).
    """
    started = time.perf_counter()
    check_workers(workers, scheduler)
    check_min_modulation(decode_options.get("min_modulation"))
    check_depth_range(min_depth, max_depth)
    if not epipolar_tolerance > 0:
        raise BistairError(f"the epipolar tolerance must be positive, got {epipolar_tolerance}")
    if spec is not None:
        load_spec(spec)  # refuse a bad default spec once, not once per set
    if calibration is not None:
        load_calibration(calibration)  # either kind; refused once, not once per set
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise BistairError(f"output {out} exists and is not a folder")
    jobs = find_sets(source, out, spec, calibration)
    options = Options(dict(decode_options), previews, min_depth, max_depth, epipolar_tolerance)
    parents = [out, *(Path(job.out).parent for job in jobs)]
    remove_run_temporaries(parents)  # left by an earlier run that was killed
    rows: dict[int, dict[str, Any]] = {}
    if resume:
        for i, job in enumerate(jobs):
            row = complete_row(job, options)
            if row is not None:
                rows[i] = row
    todo = [i for i in range(len(jobs)) if i not in rows]
    prefix = run_prefix()
    bar = tqdm(total=len(jobs), initial=len(rows), desc="batch", unit="set",
               disable=not show_progress, dynamic_ncols=True)
    workers_used: int | str = 0

    def report(interrupted: bool = False) -> BatchReport:
        ordered = [rows[i] for i in sorted(rows)]
        write_batch_csv(out / "batch.csv", ordered, prefix)
        return BatchReport(ordered, time.perf_counter() - started, workers_used, out,
                           interrupted, len(jobs))

    try:
        if todo:
            with dask_client(workers, scheduler, tasks=len(todo)) as client:
                workers_used = len(client.nthreads())

                def failed(k: int, message: str) -> dict[str, Any]:
                    return _row(jobs[todo[k]].name, "error", message)

                def done(k: int, row: dict[str, Any]) -> None:
                    rows[todo[k]] = row
                    bar.update()
                    errors = sum(r["status"] == "error" for r in rows.values())
                    if errors:
                        bar.set_postfix_str(f"{errors} failed")

                run_tasks(client, run_set, [(jobs[i], options, prefix) for i in todo],
                          failed, done)
    except (KeyboardInterrupt, SystemExit):  # Ctrl-C, or SIGTERM (the command line's exit)
        bar.close()
        remove_run_temporaries(parents, prefix)  # of workers killed mid-write
        for i in todo:  # sets finished while the interrupt came
            row = None if i in rows else complete_row(jobs[i], options, prefix)
            if row is not None:
                rows[i] = row
        if rows:
            report(interrupted=True)
        raise
    finally:
        bar.close()
        remove_run_temporaries(parents, prefix)
    return report()


def write_batch_csv(path: str | Path, rows: Sequence[Mapping[str, Any]],
                    prefix: str = BATCH_PREFIX) -> Path:
    """Write the rows (:data:`COLUMNS`) as CSV, atomically; numbers as written by
    :func:`repr`, empty cells for none."""
    with output_file(path, prefix) as tmp, tmp.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(COLUMNS)
        for row in rows:
            writer.writerow([_cell(row.get(k)) for k in COLUMNS])
    return Path(path)


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool | np.bool_):
        return "yes" if value else "no"
    return str(value)
