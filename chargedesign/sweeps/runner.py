"""Run a sweep on any ``concurrent.futures.Executor``; per-point folders; the summary table.

Layout of the output directory::

    DIR/sweep.json               the points (ids and keys), written first; --resume checks it
    DIR/points/<id>/             one folder per point, filled atomically
    DIR/points/<id>/result.json  written last: status, figures, seconds (its presence = done)
    DIR/summary.csv              one row per point (header row), rewritten at the end
    DIR/summary.parquet          the same table (needs pyarrow: chargedesign[parquet])

Workers write their points' folders themselves, so a point is safe on disk the moment it
finishes: Ctrl-C, a killed worker or a lost cluster loses only the points in flight, and
``resume=True`` runs only the points without a ``result.json`` of status ``ok``.
"""

from __future__ import annotations

import csv
import gc
import io
import json
import math
import os
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from chargedesign.errors import ChargeDesignError, InputError
from chargedesign.files import atomic_directory, atomic_path, write_json_atomic, write_text_atomic
from chargedesign.formatting import PLAIN, fmt
from chargedesign.params import Parameters
from chargedesign.results import Result
from chargedesign.scene import scene_from_dict
from chargedesign.scene.sweep_file import check_executor, check_sweep_out, scene_with
from chargedesign.simulation import simulate
from chargedesign.sweeps.registry import command_label, resolve
from chargedesign.sweeps.spec import SweepSpec

#: seconds to wait for a Dask scheduler given with ``scheduler=`` (``--scheduler-timeout``)
SCHEDULER_TIMEOUT = 5.0
#: the connecting thread's wait beyond the timeout Dask is given (its own handshake)
CONNECT_GRACE_S = 1.0
#: automatic chunks: about this many tasks per worker (load balance against per-task overhead)
TASKS_PER_WORKER = 16
MAX_CHUNK = 256
FIXED_COLUMNS = ("point", "status", "seconds", "reason")

Progress = Callable[[int, int, int], None]


# ------------------------------------------------------------------------------ workers
def warm_up() -> int:
    """Import the heavy packages once per worker (numpy, scipy, cvxpy, sympy, the core)."""
    import cvxpy  # noqa: F401
    import scipy.integrate
    import scipy.optimize  # noqa: F401

    # compile the theorem's evaluators (cached per process): a short run of the reduced model

    simulate(Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9), t_end=0.01, samples=2)
    return os.getpid()


def worker_memory() -> float:
    """Peak resident memory of this worker process, MB."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


@dataclass
class Chunk:
    """A task: some points of one sweep (everything a worker needs, picklable)."""

    command: str | Callable[..., dict[str, Any]]
    scene_data: dict[str, Any]
    scene_source: str
    options: dict[str, Any]
    out: str
    points: list[tuple[str, dict[str, Any]]]


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    msg = text[0] if text else ""
    if isinstance(exc, ChargeDesignError):
        return msg or type(exc).__name__
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


def run_point(
    command: str | Callable[..., dict[str, Any]],
    scene_data: dict[str, Any],
    scene_source: str,
    options: dict[str, Any],
    out: str,
    point_id: str,
    keys: dict[str, Any],
) -> dict[str, Any]:
    """Run one point and write its folder; never raises for a failing point."""

    target = Path(out) / "points" / point_id
    t0 = time.perf_counter()
    status, reason, figures = "ok", "", {}
    try:
        with atomic_directory(target) as stage:
            scene = scene_from_dict(scene_with(scene_data, keys), scene_source)
            figures = dict(resolve(command)(scene, stage, **options) or {})
    except KeyboardInterrupt:
        raise
    except Exception as exc:  # a failing point records its reason; the sweep goes on
        status, reason, figures = "failed", _one_line(exc), {}
        target.mkdir(parents=True, exist_ok=True)
        write_text_atomic(target / "error.txt", traceback.format_exc())
    record = {
        "point": point_id,
        "keys": keys,
        "status": status,
        "reason": reason,
        "figures": _json_safe(figures),
        "seconds": time.perf_counter() - t0,
    }
    write_json_atomic(target / "result.json", record)  # last: its presence means done
    return record


def run_chunk(chunk: Chunk) -> list[dict[str, Any]]:
    """Run a task's points in order (the function the executor runs)."""
    return [
        run_point(
            chunk.command, chunk.scene_data, chunk.scene_source, chunk.options, chunk.out, pid, keys
        )
        for pid, keys in chunk.points
    ]


def _json_safe(figures: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in figures.items():
        if hasattr(v, "item"):
            v = v.item()
        if isinstance(v, float) and not math.isfinite(v):
            v = None
        if v is None or isinstance(v, (bool, int, float, str)):
            out[str(k)] = v
        else:
            out[str(k)] = str(v)
    return out


# ---------------------------------------------------------------------------- executors
class SerialExecutor(Executor):
    """Runs each task at submission, in this process (for tests and debugging)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        future: Future[Any] = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                raise
            future.set_exception(exc)
        return future


@dataclass
class ExecutorHandle:
    """An executor, how many workers it has, and how to close what was started for it."""

    executor: Executor
    workers: int
    kind: str
    close: Callable[[], None] = field(default=lambda: None)
    memory_mb: Callable[[], list[float]] = field(default=lambda: [])


def _connect(client_type: Any, scheduler: str, timeout: float) -> Any:
    """A Dask client of the scheduler at ``scheduler``, or one line saying why not.

    Dask's own ``timeout`` bounds the TCP connection only: a server that accepts and never
    answers holds ``Client()`` without end, and one that answers another protocol (HTTP)
    makes it read a frame length of exabytes and raise ``MemoryError``. So the connection
    and a first round trip run in a daemon thread given ``timeout`` seconds, and every
    failure of the client, whatever its type, becomes one :class:`InputError`.
    """
    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            client = client_type(scheduler, timeout=f"{timeout}s", set_as_default=False)
            box["client"] = client
            client.scheduler_info()
            box["ready"] = True
        except BaseException as exc:  # any failure of the client is the user's one line
            box["error"] = exc

    # a Client that failed to connect raises again in its __del__ ("Exception ignored in
    # Client.__del__ ... TimeoutError"): collect it here, with that report silenced
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _report: None
    try:
        thread = threading.Thread(target=attempt, name="dask-connect", daemon=True)
        thread.start()
        thread.join(timeout + CONNECT_GRACE_S)
        if "ready" in box:
            return box["client"]
        error = box.pop("error", None)
        reason = type(error).__name__ if error is not None else "no reply"
        if isinstance(error, MemoryError):
            reason = "the server does not speak Dask's protocol"
        # the exception's traceback holds the half-made client: drop both, then collect
        del error
        box.clear()
        gc.collect()
    finally:
        sys.unraisablehook = hook
    raise scheduler_unreachable(scheduler, timeout, None if thread.is_alive() else reason)


def make_executor(
    kind: str = "process",
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float = SCHEDULER_TIMEOUT,
) -> ExecutorHandle:
    """A warmed-up executor: ``process`` (local pool), ``dask`` (LocalCluster, or the running
    cluster at ``scheduler``), ``serial``.

    Raises
    ------
    InputError
        Unknown kind, bad worker count, Dask not installed, or no scheduler reachable within
        ``timeout`` seconds.
    """
    if scheduler is not None:
        kind = "dask"
    n = check_executor(kind, workers)
    if kind == "serial":
        return ExecutorHandle(SerialExecutor(), 1, "serial")
    if kind == "process":
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        pool = ProcessPoolExecutor(
            max_workers=n, mp_context=multiprocessing.get_context("spawn"), initializer=warm_up
        )

        # start every worker now (each runs warm_up once), so the first points do not wait
        for f in [pool.submit(worker_memory) for _ in range(n)]:
            f.result()

        def pool_memory() -> list[float]:
            futures = [pool.submit(worker_memory) for _ in range(n)]
            return [f.result() for f in futures]

        return ExecutorHandle(
            pool,
            n,
            "process",
            close=lambda: pool.shutdown(cancel_futures=True),
            memory_mb=pool_memory,
        )
    try:
        import logging

        from distributed import Client, LocalCluster
    except ImportError:
        raise dask_missing() from None
    cluster = None
    if scheduler is not None:
        client = _connect(Client, scheduler, timeout)
    else:
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
        client = Client(cluster, set_as_default=False)
    client.run(warm_up)
    n_workers = len(client.scheduler_info().get("workers", {})) or n

    closed: list[bool] = []

    def close() -> None:
        if closed:
            return
        closed.append(True)
        client.close()
        if cluster is not None:
            cluster.close()

    def dask_memory() -> list[float]:
        return [float(v) for v in client.run(worker_memory).values()]

    return ExecutorHandle(client.get_executor(), n_workers, "dask", close, dask_memory)


# ------------------------------------------------------------------------------ running
@dataclass(repr=False)
class SweepResult(Result):
    """What a sweep did: counts, timings and the summary rows (one per point)."""

    out: Path
    rows: list[dict[str, Any]]
    ran: int
    skipped: int
    failed: int
    lost: int
    lost_reason: str
    seconds: float
    workers: int
    executor: str
    parquet: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "out": str(self.out),
            "points": len(self.rows),
            "ran": self.ran,
            "skipped": self.skipped,
            "failed": self.failed,
            "not_run": self.lost,
            "not_run_reason": self.lost_reason,
            "seconds": self.seconds,
            "workers": self.workers,
            "executor": self.executor,
            "parquet": self.parquet,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "points": len(self.rows),
            "ran": self.ran,
            "failed": self.failed,
            "not_run": self.lost,
            "seconds": self.seconds,
            "executor": self.executor,
            "out": str(self.out),
        }

    def _text(self) -> str:
        lines = [
            f"sweep: {len(self.rows)} points in {self.out} ({self.ran} run, {self.skipped} "
            f"already done, {self.failed} failed) in {fmt(self.seconds)} s on {self.workers} "
            f"{self.executor} worker(s)"
        ]
        if self.lost:
            lines.append(
                f"{self.lost} points not run ({self.lost_reason}); run again with --resume"
            )
        if self.parquet != "written":
            lines.append(f"summary.parquet: {self.parquet}")
        return "\n".join(lines)


def auto_chunk(n_points: int, workers: int) -> int:
    return max(1, min(MAX_CHUNK, n_points // max(1, workers * TASKS_PER_WORKER)))


def _done(out: Path, pid: str) -> dict[str, Any] | None:
    path = out / "points" / pid / "result.json"
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None


def _plan(spec: SweepSpec, out: Path, resume: bool) -> list[tuple[str, dict[str, Any]]]:
    ids = spec.point_ids()
    plan = {
        "format": "chargedesign.sweep/1",
        "source": spec.source,
        "command": command_label(spec.command),
        "scene": spec.scene_source,
        "points": [
            {"point": pid, "keys": keys} for pid, keys in zip(ids, spec.points, strict=True)
        ],
    }
    check_sweep_out(out, plan["points"], command_label(spec.command), resume)
    plan_path = out / "sweep.json"
    out.mkdir(parents=True, exist_ok=True)
    write_json_atomic(plan_path, plan)
    todo = []
    for pid, keys in zip(ids, spec.points, strict=True):
        rec = _done(out, pid) if resume else None
        if rec is not None and rec.get("status") == "ok":
            continue
        todo.append((pid, keys))
    return todo


def run_sweep(
    spec: SweepSpec,
    out: str | os.PathLike[str],
    *,
    executor: Executor | ExecutorHandle | None = None,
    workers: int | None = None,
    resume: bool = False,
    chunk: int | None = None,
    progress: Progress | None = None,
) -> SweepResult:
    """Run every point of a sweep (those not done yet with ``resume``).

    Parameters
    ----------
    spec : SweepSpec
    out : path
        The output directory.
    executor : Executor or ExecutorHandle, optional
        Any ``concurrent.futures.Executor`` (default: a serial in-process one). Warm its
        workers up with :func:`warm_up` first (:func:`make_executor` does).
    workers : int, optional
        Workers of ``executor`` (for the automatic chunk size).
    resume : bool
        Skip points already done (status ``ok``); required when ``out`` holds a sweep.
    chunk : int, optional
        Points per task (default: the sweep file's ``chunk``, else automatic).
    progress : callable, optional
        ``progress(done, total, failed)`` after each task.

    Returns
    -------
    SweepResult
        Points not run because the executor broke (a killed worker, a lost cluster) are
        counted in ``lost``; run again with ``resume=True``.
    """
    out_path = Path(out)
    t0 = time.perf_counter()
    if isinstance(executor, ExecutorHandle):
        ex: Executor = executor.executor
        n_workers = executor.workers if workers is None else workers
        kind = executor.kind
    else:
        ex = executor if executor is not None else SerialExecutor()
        n_workers = workers or 1
        kind = type(ex).__name__
    todo = _plan(spec, out_path, resume)
    skipped = len(spec.points) - len(todo)
    size = chunk or spec.chunk or auto_chunk(len(todo), n_workers)
    chunks = [todo[i : i + size] for i in range(0, len(todo), size)]
    ran = failed = lost = 0
    lost_reason = ""
    done_points = 0
    futures: dict[Future[Any], list[tuple[str, dict[str, Any]]]] = {}
    try:
        for part in chunks:
            task = Chunk(
                spec.command, spec.scene_data, spec.scene_source, spec.options, str(out_path), part
            )
            futures[ex.submit(run_chunk, task)] = part
        for fut in as_completed(futures):
            part = futures[fut]
            try:
                records = fut.result()
            except Exception as exc:  # the executor broke: these points are not run
                lost += len(part)
                lost_reason = lost_reason or _one_line(exc)
                continue
            for rec in records:
                # workers without the client's filesystem (a remote cluster without a shared
                # DIR): the client keeps the record, so the summary is complete anyway
                local = out_path / "points" / rec["point"] / "result.json"
                if not local.exists():
                    local.parent.mkdir(parents=True, exist_ok=True)
                    write_json_atomic(local, rec)
            ran += len(records)
            failed += sum(r["status"] != "ok" for r in records)
            done_points += len(records)
            if progress is not None:
                progress(done_points + lost, len(todo), failed)
    finally:
        for fut in futures:
            fut.cancel()
        rows = summary_rows(spec, out_path)
        parquet = write_summary(rows, spec.keys, out_path)
    return SweepResult(
        out=out_path,
        rows=rows,
        ran=ran,
        skipped=skipped,
        failed=failed,
        lost=lost,
        lost_reason=lost_reason,
        seconds=time.perf_counter() - t0,
        workers=n_workers,
        executor=kind,
        parquet=parquet,
    )


# ------------------------------------------------------------------------------ summary
def summary_rows(spec: SweepSpec, out: Path) -> list[dict[str, Any]]:
    """One row per point from the points' result.json (``not run`` where there is none)."""
    rows = []
    for pid, keys in zip(spec.point_ids(), spec.points, strict=True):
        rec = _done(out, pid)
        row: dict[str, Any] = {"point": pid, **{f"{k}": v for k, v in keys.items()}}
        if rec is None:
            row.update({"status": "not run", "seconds": None, "reason": ""})
        else:
            row["status"] = rec.get("status", "failed")
            row.update({f: v for f, v in (rec.get("figures") or {}).items() if f not in row})
            row["seconds"] = rec.get("seconds")
            row["reason"] = rec.get("reason", "")
        rows.append(row)
    return rows


def _columns(rows: Sequence[dict[str, Any]], keys: Iterable[str]) -> list[str]:
    cols = ["point", *keys, "status"]
    for row in rows:
        for k in row:
            if k not in cols and k not in FIXED_COLUMNS:
                cols.append(k)
    return [*cols, "seconds", "reason"]


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return str(v)


def write_summary(rows: Sequence[dict[str, Any]], keys: Iterable[str], out: Path) -> str:
    """Write summary.csv and summary.parquet atomically; returns the parquet's status."""
    cols = _columns(rows, list(keys))
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(cols)
    for row in rows:
        writer.writerow([_cell(row.get(c)) for c in cols])
    write_text_atomic(out / "summary.csv", buf.getvalue())
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return "not written: pyarrow is not installed (pip install 'chargedesign[parquet]')"
    arrays = {}
    for c in cols:
        values = [row.get(c) for row in rows]
        kinds = {type(v) for v in values if v is not None}
        if kinds <= {int, float} and kinds != {int} and kinds:
            values = [None if v is None else float(v) for v in values]
        elif len(kinds) > 1 or (kinds and not kinds <= {int, float, bool, str}):
            values = [None if v is None else str(v) for v in values]
        arrays[c] = pa.array(values)
    table = pa.table(arrays)
    with atomic_path(out / "summary.parquet") as tmp:
        pq.write_table(table, tmp)
    return "written"


def scheduler_unreachable(scheduler: str, timeout: float, reason: str | None) -> InputError:
    """The one line of ``--scheduler ADDRESS`` that did not connect: no answer within the
    timeout (``reason`` None) or the connection's failure (``reason``: the exception's name)."""
    option = f"(--scheduler-timeout, now {fmt(timeout, PLAIN)} s)"
    if reason is None:
        return InputError(f"--scheduler {scheduler}: no answer from a Dask scheduler {option}")
    return InputError(f"--scheduler {scheduler}: no Dask scheduler reachable {option} ({reason})")


def dask_missing() -> InputError:
    """``--executor dask`` without Dask installed."""
    return InputError("--executor dask: Dask is not installed (pip install 'chargedesign[dask]')")
