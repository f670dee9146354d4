"""`chargedesign bench`: what accuracy costs in time, as ratios to baselines of the same run."""

from __future__ import annotations

import argparse
import sys

from chargedesign.bench.runner import run_benchmarks, write_report
from chargedesign.commands.arguments import AREAS
from chargedesign.files import check_outputs


def run(args: argparse.Namespace) -> int:
    import json

    check_outputs([("--out", args.out, True)], writes=("benchmarks.md",))
    heartbeat = Heartbeat()

    def progress(area: str) -> None:
        heartbeat.area(area)

    try:
        tables = run_benchmarks(args.only or AREAS, quick=args.quick, progress=progress)
    finally:
        heartbeat.stop()
    if args.out:
        path = write_report(tables, args.out)
        print(f"bench: wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps([t.to_dict() for t in tables], indent=2, default=str))
    else:
        for table in tables:
            print(table.to_markdown())
    return 0


class Heartbeat:
    """Says on stderr which area runs, and every ``period`` seconds that it still runs."""

    def __init__(self, period: float = 15.0) -> None:
        import threading
        import time

        self._time = time.perf_counter
        self._period = period
        self._name = ""
        self._start = self._area_start = self._time()
        self._done = threading.Event()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._thread.start()

    def area(self, name: str) -> None:
        with self._lock:
            if self._name:
                self._say(f"bench: {self._name} done in {self._time() - self._area_start:.0f} s")
            self._name, self._area_start = name, self._time()
        self._say(f"bench: {name} ...")

    def stop(self) -> None:
        self._done.set()
        self._thread.join()
        if self._name:
            self._say(f"bench: {self._name} done in {self._time() - self._area_start:.0f} s")
        self._say(f"bench: all areas in {self._time() - self._start:.0f} s")

    def _beat(self) -> None:
        while not self._done.wait(self._period):
            with self._lock:
                self._say(
                    f"bench: {self._name} still running ({self._time() - self._area_start:.0f} s)"
                )

    @staticmethod
    def _say(text: str) -> None:
        print(text, file=sys.stderr, flush=True)
