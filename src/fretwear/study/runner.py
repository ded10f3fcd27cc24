"""Running the members of a study on Dask distributed, one task per member.

Each member is one task (:func:`run_member`) that writes ``member-XXXX/case.toml``, runs it
with :func:`fretwear.analyses.run.run_case` (``resume = True``: a wear member continues from
its checkpoint, a finished one is read back) into ``member-XXXX/``, where ``results.nc`` is
written atomically, and records ``member-XXXX/status.json`` (``ok``, ``not converged`` or
``failed`` with the message). The task also returns the results file's bytes, so the client
has every result even when the workers do not share its file system.

So a killed worker loses only the members it was running (the scheduler gives them to another
worker, which continues a wear member from its checkpoint), a killed client loses only the
members in flight, and a rerun skips the finished members (:func:`finished`). A member whose
worker died too often (Dask's ``KilledWorker``) is recorded as failed with that message, never
dropped.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import socket
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from fretwear.errors import FretwearError, InputError
from fretwear.files import atomic_write, damaged
from fretwear.resources import require_memory
from fretwear.study.members import CASE_FILE, Member
from fretwear.validate import ArgumentTypeError, whole

STATUS_FILE = "status.json"
RESULTS_FILE = "results.nc"
FINISHED = ("ok", "not converged")


@dataclass
class MemberRecord:
    """What happened to one member: ``status`` ("ok", "not converged", "failed"), the
    ``message`` (the run's summary or the error), ``seconds`` of wall time of the run, the
    ``worker`` host and process, and whether it was ``skipped`` (finished before)."""

    index: int
    status: str
    message: str = ""
    seconds: float = 0.0
    worker: str = ""
    skipped: bool = False
    case_sha256: str = ""
    warnings: str = ""
    results_sha256: str = ""

    def to_json(self) -> str:
        """The record as JSON, sealed: ``content_sha256`` is the SHA-256 of the other fields
        (:func:`record_digest`), checked on reading (:func:`read_status`)."""
        d = {k: getattr(self, k) for k in RECORD_FIELDS}
        d[SEAL_KEY] = record_digest(d)
        return json.dumps(d, indent=1) + "\n"


#: the fields of a status file (besides its seal, :data:`SEAL_KEY`)
RECORD_FIELDS = ("index", "status", "message", "seconds", "worker", "case_sha256", "warnings",
                 "results_sha256")
#: the key of a status file that holds the SHA-256 of its other fields
SEAL_KEY = "content_sha256"


def record_digest(d: dict) -> str:
    """SHA-256 of the fields of a status file (every key but :data:`SEAL_KEY`, sorted, as
    compact JSON)."""
    body = {k: v for k, v in d.items() if k != SEAL_KEY}
    return hashlib.sha256(json.dumps(body, sort_keys=True, separators=(",", ":"))
                          .encode("utf-8")).hexdigest()


def file_hash(path: Path) -> str:
    """The SHA-256 of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def case_hash(text: str) -> str:
    """The SHA-256 of a member's case text: the status of a member is the status of this
    exact case."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


@dataclass
class MemberPayload:
    """What a task sends back: its record and the bytes of its results file (None when
    there is none)."""

    record: MemberRecord
    results: bytes | None = field(default=None, repr=False)


def _write_text(path: Path, text: str) -> None:
    def write(tmp: Path) -> None:
        tmp.write_text(text, encoding="utf-8")

    atomic_write(path, write)


def _write_bytes(path: Path, data: bytes) -> None:
    def write(tmp: Path) -> None:
        tmp.write_bytes(data)

    atomic_write(path, write)


def write_case(folder: Path, text: str) -> Path:
    """``folder/case.toml`` holding ``text`` (rewritten only when it differs)."""
    path = folder / CASE_FILE
    if not (path.is_file() and path.read_text(encoding="utf-8") == text):
        _write_text(path, text)
    return path


def read_status(folder: Path) -> MemberRecord | None:
    """The recorded status of the member in ``folder`` (None: none, or not JSON: the member
    runs again and its status is written anew).

    Raises
    ------
    InputError
        A status whose content checksum (:data:`SEAL_KEY`) is missing while it records the
        case's hash (written by this fretwear), or does not match its fields: edited or
        corrupted after it was written; one line naming the file. A status of an earlier
        fretwear (no case hash, no checksum) is read as before (its case file is checked).
    """
    path = folder / STATUS_FILE
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(d, dict):
        raise damaged(path, "study member status", "not a JSON object")
    if SEAL_KEY in d or "case_sha256" in d:
        if d.get(SEAL_KEY) != record_digest(d):
            why = ("no content checksum" if SEAL_KEY not in d else "its content does not match "
                   "its checksum: it was edited or corrupted after it was written")
            raise damaged(path, "study member status", why)
    try:
        return MemberRecord(int(d["index"]), str(d["status"]), str(d.get("message", "")),
                            float(d.get("seconds", 0.0)), str(d.get("worker", "")),
                            case_sha256=str(d.get("case_sha256", "")),
                            warnings=str(d.get("warnings", "")),
                            results_sha256=str(d.get("results_sha256", "")))
    except (ValueError, KeyError, TypeError):
        raise damaged(path, "study member status", "a field is missing or of the wrong "
                      "kind") from None


def finished(folder: Path, text: str) -> MemberRecord | None:
    """The record of a member already run to the end with exactly this case text (ok or not
    converged, with its results file), else None: it must run (again)."""
    rec = read_status(folder)
    if rec is None or rec.status not in FINISHED or not (folder / RESULTS_FILE).is_file():
        return None
    if rec.results_sha256 and file_hash(folder / RESULTS_FILE) != rec.results_sha256:
        raise damaged(folder / RESULTS_FILE, "study member results file", "its content is not "
                      f"the one its status {STATUS_FILE} records: it was edited or replaced")
    if rec.case_sha256:
        if rec.case_sha256 != case_hash(text):  # the study changed this member since
            return None
    else:  # a status without the hash: the member's case file must hold this text
        case = folder / CASE_FILE
        if not case.is_file() or case.read_text(encoding="utf-8") != text:
            return None
    rec.skipped = True
    return rec


def warning_lines(caught) -> str:
    """Python warnings raised during a member's run as one line each, ``Category: message``
    (no file name and source line, which mean nothing to the user of a study), each once."""
    lines = [f"{w.category.__name__}: {' '.join(str(w.message).split())}" for w in caught]
    return "\n".join(dict.fromkeys(lines))


def run_member(index: int, text: str, folder: str) -> MemberPayload:
    """Run one member (on a worker): write its case file, run it into ``folder`` with
    ``resume = True``, record its status. Never raises for a failed run: the failure is the
    member's record."""
    from fretwear.analyses.run import run_case

    folder_path = Path(folder)
    start = time.perf_counter()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    results = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        try:
            case = write_case(folder_path, text)
            out = run_case(case, folder_path, progress=False, resume=True, echo=False)
            status = "ok" if out.success else "not converged"
            message = " ".join(str(out.summary or "").split())
            results = Path(out.results).read_bytes() if out.results else None
        except FretwearError as exc:
            status, message = "failed", " ".join(str(exc).split())
        except Exception as exc:  # recorded with its message, never dropped
            status, message = "failed", f"{type(exc).__name__}: {' '.join(str(exc).split())}"
    rec = MemberRecord(index, status, message, time.perf_counter() - start, worker,
                       case_sha256=case_hash(text), warnings=warning_lines(caught),
                       results_sha256="" if results is None else hashlib.sha256(
                           results).hexdigest())
    with contextlib.suppress(OSError):
        _write_text(folder_path / STATUS_FILE, rec.to_json())
    return MemberPayload(rec, results)


def keep_payload(folder: Path, payload: MemberPayload) -> MemberRecord:
    """On the client: the results file and the status of a finished task, written in
    ``folder`` (the worker may not share this file system)."""
    if payload.results is not None:
        path = folder / RESULTS_FILE
        if not (path.is_file() and path.read_bytes() == payload.results):
            _write_bytes(path, payload.results)
    _write_text(folder / STATUS_FILE, payload.record.to_json())
    return payload.record


def _lost(folder: Path, index: int, exc: BaseException | None) -> MemberRecord:
    """The record of a member whose task gave no result (its worker died too often, or its
    results could not be written on the client)."""
    what = f"{type(exc).__name__}: {exc}" if exc is not None else "no result"
    rec = MemberRecord(index, "failed", f"the task was lost ({' '.join(what.split())})")
    with contextlib.suppress(OSError):
        _write_text(folder / STATUS_FILE, rec.to_json())
    return rec


# --- the cluster ------------------------------------------------------------------------------
def check_scheduler_address(address: str) -> None:
    """A scheduler address Dask can connect to (``tcp://host:8786``, ``tls://...``,
    ``host:port``...): InputError naming it otherwise, before any connection is tried."""
    from distributed.comm import registry
    from distributed.comm.addressing import parse_address, parse_host_port

    expected = ("expected the address of a running scheduler, e.g. tcp://host:8786 "
                f"(protocols: {', '.join(sorted(registry.backends))})")
    try:
        scheme, location = parse_address(str(address))
        if scheme not in registry.backends:
            raise ValueError(f"unknown protocol {scheme!r}")
        if scheme in ("tcp", "tls", "ws", "wss", "ucx"):
            parse_host_port(location)
    except (ValueError, TypeError) as exc:
        raise InputError(f"scheduler = {address!r}: {exc}; {expected}") from None


@contextlib.contextmanager
def dask_client(scheduler=None, workers: int | None = None):
    """A ``distributed.Client``: ``scheduler`` is a Client (used as is), an address
    (``tcp://host:8786``: an existing cluster, e.g. ``dask scheduler`` / ``dask worker`` or
    dask-jobqueue), or None: a LocalCluster of ``workers`` processes (default: the number of
    cores) with one thread each. What is started here is closed on exit."""
    from distributed import Client

    if scheduler is not None and not isinstance(scheduler, str):
        yield scheduler
        return
    if scheduler is not None:
        check_scheduler_address(scheduler)
        try:
            client = Client(scheduler, timeout="30s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"cannot connect to the Dask scheduler {scheduler!r} ({exc}): "
                             "expected the address of a running scheduler, e.g. "
                             "tcp://host:8786") from None
        try:
            yield client
        finally:
            client.close()
        return
    cluster = local_cluster(workers or os.cpu_count() or 1)
    client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


# Dask's nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536 (its default
# ``distributed.nanny.pre-spawn-environ``). That fixes glibc's mmap threshold, so every numpy
# array above 128 KiB is mapped and unmapped afresh: a member of benchmarks/study_scaling.py
# took 6.9 s in such a worker against 5.0 s in a plain process (4.5 s with the variable
# unset). Workers started here leave glibc's adaptive default in place.
WORKER_ENVIRON = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}


#: memory of one idle worker process of a LocalCluster (Python, numpy, scipy, numba, dask)
WORKER_BYTES = 300 * 2**20
#: the most worker processes per core of a LocalCluster
WORKERS_PER_CORE = 8


def check_workers(workers) -> int | None:
    """``workers`` (None: the default) after checking it is a whole number >= 1 that this
    machine can start: at most :data:`WORKERS_PER_CORE` per core, and their memory."""
    if workers is None:
        return None
    cores = os.cpu_count() or 1
    n = whole(workers, "workers", low=1, high=WORKERS_PER_CORE * cores)
    require_memory(n * WORKER_BYTES, f"workers = {n} (worker processes of about "
                   f"{WORKER_BYTES / 2**20:.0f} MiB each)")
    return n


def check_scheduler(scheduler) -> None:
    """``scheduler`` is None, an address (str) or a ``distributed.Client``."""
    if scheduler is None or isinstance(scheduler, str):
        return
    from distributed import Client

    if not isinstance(scheduler, Client):
        raise ArgumentTypeError(f"scheduler = {scheduler!r}; expected None, a scheduler address "
                                "(e.g. 'tcp://host:8786') or a distributed.Client")


def local_cluster(n: int):
    """A LocalCluster of ``n`` worker processes with one thread each (numpy and numba run
    single-threaded in them) and glibc's default memory trimming (:data:`WORKER_ENVIRON`)."""
    import logging

    import dask
    from distributed import LocalCluster

    check_workers(n)
    with dask.config.set(WORKER_ENVIRON):
        return LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.ERROR)


@dataclass
class RunReport:
    """The records of every member (in member order) and the wall time of the run."""

    records: list
    seconds: float


def run_members(members: list[Member], outdir: Path, client, progress: bool = True,
                on_record: Callable[[MemberRecord], None] | None = None) -> RunReport:
    """Run the members not finished yet on ``client`` (a ``distributed.Client``); members
    already finished with the same case text are skipped. Returns every member's record.
    ``client = None`` runs nothing: the members not finished are recorded as "not run"
    (a look at a study still running elsewhere)."""
    from distributed import as_completed
    from tqdm.auto import tqdm

    start = time.perf_counter()
    records: dict[int, MemberRecord] = {}
    todo = []
    for m in members:
        folder = outdir / m.folder_name
        folder.mkdir(parents=True, exist_ok=True)
        rec = finished(folder, m.text)
        write_case(folder, m.text)
        if rec is not None:
            records[m.index] = rec
        else:
            todo.append(m)
    if client is None:
        for m in todo:
            rec = read_status(outdir / m.folder_name)
            why = f" (last record: {rec.status}: {rec.message})" if rec is not None else ""
            records[m.index] = MemberRecord(m.index, "not run", f"no finished result{why}")
        return RunReport([records[m.index] for m in members], time.perf_counter() - start)
    futures = {}
    bar = tqdm(total=len(members), initial=len(members) - len(todo), unit="member",
               desc="study", disable=not progress, file=sys.stderr, smoothing=0.0)
    try:
        for m in todo:
            f = client.submit(run_member, m.index, m.text, str(outdir / m.folder_name),
                              pure=False, key=f"fretwear-{outdir.name}-{m.folder_name}-"
                              f"{time.time_ns()}")
            futures[f] = m
        for f in as_completed(list(futures)):
            m = futures[f]
            folder = outdir / m.folder_name
            if f.status == "finished":
                try:
                    rec = keep_payload(folder, f.result())
                except OSError as exc:
                    rec = _lost(folder, m.index, exc)
            else:
                rec = _lost(folder, m.index, f.exception() if f.status == "error" else None)
            records[m.index] = rec
            if on_record is not None:
                on_record(rec)
            bar.update(1)
            f.release()
    except BaseException:
        for f in futures:
            with contextlib.suppress(Exception):
                f.cancel()
        raise
    finally:
        bar.close()
    return RunReport([records[m.index] for m in members], time.perf_counter() - start)
