"""`chargedesign sweep SWEEP.toml --out DIR`: run many points of a scene through one command.

Executors: ``process`` (default: a local process pool of ``--workers``), ``dask`` (a Dask
LocalCluster of ``--workers``, or the running cluster at ``--scheduler tcp://...``; needs
``chargedesign[dask]``), ``serial`` (in this process). Exit status 0 when every point ran
and succeeded, 1 when some failed or were not run (``--resume`` completes them), 2 on bad
input. See docs/sweep.md.
"""

from __future__ import annotations

import argparse

from chargedesign.commands import print_result
from chargedesign.commands.progress import progress_bar
from chargedesign.errors import InputError
from chargedesign.files import check_outputs
from chargedesign.scene.sweep_file import check_executor
from chargedesign.sweeps import (
    load_sweep,
    make_executor,
    run_sweep,
    summary_rows,
    write_summary,
)

#: what a sweep writes into --out (``points/`` holds one folder per point)
SWEEP_FILES = ("sweep.json", "summary.csv", "summary.parquet", "points")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    check_executor(args.executor, args.workers)  # before any file is read
    if args.scheduler_timeout is not None and args.scheduler is None:
        raise InputError("--scheduler-timeout: needs --scheduler (the Dask cluster it waits for)")
    timeout = 5.0 if args.scheduler_timeout is None else args.scheduler_timeout
    if args.chunk is not None and args.chunk < 1:
        raise InputError(f"--chunk: expected an integer >= 1, got {args.chunk}")
    check_outputs([("--out", args.out, True)], inputs=[args.sweep], writes=SWEEP_FILES)
    spec = load_sweep(args.sweep, max_points=args.max_points)
    check_outputs(
        [("--out", args.out, True)],
        inputs=[args.sweep, None if spec.scene_source.startswith("<") else spec.scene_source],
        writes=SWEEP_FILES,
    )
    handle = make_executor(args.executor, args.workers, args.scheduler, timeout=timeout)
    # the points counted against their total, with the time left (a line every few seconds
    # without a terminal)
    with progress_bar("sweep", "points", args.quiet) as bar:
        if bar is not None:
            bar.update(0, len(spec.points))  # the count from the start (a point may take minutes)

        def tally(done: int, total: int, failed: int) -> None:
            assert bar is not None
            bar.update(done, total, f"{failed} failed" if failed else "")

        try:
            result = run_sweep(
                spec,
                args.out,
                executor=handle,
                resume=args.resume,
                chunk=args.chunk,
                progress=None if bar is None else tally,
            )
        except KeyboardInterrupt:
            # let the points in flight finish or stop, then list every point on disk
            handle.close()
            out = Path(args.out)
            if (out / "sweep.json").is_file():
                write_summary(summary_rows(spec, out), spec.keys, out)
            raise
        finally:
            handle.close()
    print_result(result, args.json)
    return 0 if result.failed == 0 and result.lost == 0 else 1
