"""Sweep benchmarks: parallel efficiency, per-task overhead and worker memory.

Points are real ``simulate`` runs of the theorem's reduced model (a grid over ``parameters.n``)
whose ``t_end`` is calibrated so that one point takes about 1 s (8 points of 0.05 s with ``quick``).
Efficiency is ``T1 / (p * Tp)``: ``T1`` the serial in-process time of the same points
(measured on a subset and scaled), ``Tp`` the wall time on ``p`` warmed-up workers (the
start-up of the pool or cluster and the warm-up imports are reported apart). The overhead per
task is the wall time of no-op points times ``p`` over their number: scheduling, pickling, the
point folder and its result.json.
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.bench.common import UNIT_SCALE, BenchTable
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.scene.keys import KEY
from chargedesign.sweeps import SweepSpec, make_executor, run_point, run_sweep, warm_up

SCENE: dict[str, dict[str, Any]] = {
    "parameters": UNIT_SCALE.as_dict(),
    "simulation": {"effects": ["theorem"], KEY.t_end: 100.0, "samples": 201},
    "output": {"trajectory": False, "plot": False},
}


def idle(scene: Any, point_dir: Path) -> dict[str, Any]:
    """A no-op point (for the per-task overhead)."""
    return {"n": scene.parameters.n}


def _spec(n_points: int, t_end: float, command: Any = "simulate", chunk: int = 0) -> Any:
    data = {k: dict(v) for k, v in SCENE.items()}
    data["simulation"][KEY.t_end] = t_end
    values = [float(x) for x in np.linspace(0.5, 0.9, n_points)]
    return SweepSpec(
        source="<bench>",
        scene_data=data,
        scene_source="<dict>",
        command=command,
        keys=["parameters.n"],
        points=[{"parameters.n": v} for v in values],
        chunk=chunk,
    )


T_END_LIMIT = 1e7  # s of motion: a bound, so that a noisy timing can never ask for a run of days


def _calibrate(target: float) -> float:
    """t_end (s of motion) for which one point takes about ``target`` seconds.

    A point costs a fixed part (scene, set-up, its folder) plus a part that grows with
    ``t_end``. The first point also compiles the integrator, so it is run untimed. Then
    ``t_end`` doubles from 1 s until a point takes at least ``target``, and the answer is
    interpolated between the two bracketing runs. Each timing is the best of two, and t_end
    stays below ``T_END_LIMIT``: a fit on timings of a few ms (a slope from noise) once asked
    for 6e9 s of motion, and the sweep it fed ran past CI's time limit.
    """

    warm_up()

    def seconds(t_end: float, repeats: int = 2) -> float:
        spec = _spec(1, t_end)
        with tempfile.TemporaryDirectory() as tmp:
            times = [
                run_point("simulate", spec.scene_data, "<dict>", {}, tmp, f"p{i}", spec.points[0])[
                    "seconds"
                ]
                for i in range(repeats)
            ]
        return min(times)

    seconds(1.0, repeats=1)  # compiles the integrator; not timed
    t_low, s_low = 1.0, seconds(1.0)
    if s_low >= target:
        return t_low
    t_high = t_low
    while t_high < T_END_LIMIT:
        t_high = min(2.0 * t_low, T_END_LIMIT)
        s_high = seconds(t_high)
        if s_high >= target:
            fraction = (target - s_low) / (s_high - s_low)
            return t_low + fraction * (t_high - t_low)
        t_low, s_low = t_high, s_high
    return T_END_LIMIT


def run(quick: bool = False) -> list[BenchTable]:
    n_points = 8 if quick else 200
    per_point = 0.05 if quick else 1.0
    workers = 2
    t_end = _calibrate(per_point)
    # serial baseline on a subset (best of two runs), scaled to all points
    subset = 2 if quick else 20
    attempts = 2  # the first run pays one-time work (the best of two is warm)
    load_serial = os.getloadavg()[0]
    serial_per_point = math.inf
    for attempt in range(attempts):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            run_sweep(_spec(subset, t_end), Path(tmp) / f"s{attempt}")
            serial_per_point = min(serial_per_point, (time.perf_counter() - t0) / subset)
    t1 = serial_per_point * n_points
    table = BenchTable(
        title=f"Sweep: {n_points} points of about {fmt(per_point, PLAIN)} s on {workers} local"
        " workers",
        columns=[
            "executor",
            "workers",
            "start-up s",
            "wall s",
            "serial T1 s",
            "efficiency T1/(p Tp)",
            "busy fraction sum(t)/(p Tp)",
            "load avg 1 min",
            "overhead/task ms (chunk 1)",
            "overhead/task ms (auto chunk)",
            "peak RSS/worker MB",
        ],
        notes=[
            "points: chargedesign simulate of the theorem's reduced model, t_end ="
            f" {fmt(t_end, PRECISE)} s "
            f"of motion (calibrated to about {fmt(per_point, PLAIN)} s per point), a grid over"
            " parameters.n",
            f"T1: {subset} of the points run serially in-process (best of {attempts} runs), "
            f"{fmt(serial_per_point)} s per point, scaled to all points (load avg before: "
            f"{load_serial:.1f})",
            "busy fraction: the points' own seconds (timed inside the workers) over p x wall: "
            "the share of worker time spent in points, insensitive to other jobs on the machine "
            "(load avg: the machine's 1-minute load before and after the run, 2 cores)",
            "overhead: no-op points (chargedesign.bench.sweep:idle), wall x workers / points, "
            "including each point's folder and result.json; start-up (pool or LocalCluster and "
            "the warm-up imports) is not in the wall time",
        ],
    )
    # quick (the smoke test): the process pool only; the Dask LocalCluster costs ~10 s to start
    for kind in ("process",) if quick else ("process", "dask"):
        t0 = time.perf_counter()
        try:
            handle = make_executor(kind, workers)
        except Exception as exc:  # dask not installed: say so in the table
            nan = float("nan")
            table.rows.append([kind, workers, nan, str(exc)[:60], t1, nan, nan, "", nan, nan, nan])
            continue
        startup = time.perf_counter() - t0
        try:
            with tempfile.TemporaryDirectory() as tmp:
                load0 = os.getloadavg()[0]
                t0 = time.perf_counter()
                result = run_sweep(_spec(n_points, t_end), Path(tmp) / "a", executor=handle)
                wall = time.perf_counter() - t0
                load1 = os.getloadavg()[0]
                busy = sum(r["seconds"] or 0.0 for r in result.rows)
                if result.failed or result.lost:
                    raise RuntimeError(f"sweep bench: {result.failed} failed, {result.lost} lost")
                overhead = []
                for chunk in (1, 0):
                    spec = _spec(n_points, t_end, idle, chunk)
                    t0 = time.perf_counter()
                    run_sweep(spec, Path(tmp) / f"idle{chunk}", executor=handle)
                    overhead.append((time.perf_counter() - t0) * handle.workers / n_points * 1e3)
                memory = max(handle.memory_mb() or [float("nan")])
        finally:
            handle.close()
        table.rows.append(
            [
                kind,
                handle.workers,
                startup,
                wall,
                t1,
                t1 / (handle.workers * wall),
                busy / (handle.workers * wall),
                f"{load0:.1f} -> {load1:.1f}",
                overhead[0],
                overhead[1],
                memory,
            ]
        )
    return [table]
