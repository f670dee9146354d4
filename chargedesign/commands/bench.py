"""`chargedesign bench`: what accuracy costs in time, as ratios to baselines of the same run."""

from __future__ import annotations

import argparse
import sys
import time

from chargedesign.bench.runner import run_benchmarks, write_report
from chargedesign.commands.arguments import AREAS
from chargedesign.commands.progress import Progress
from chargedesign.files import check_outputs


def run(args: argparse.Namespace) -> int:
    import json

    check_outputs([("--out", args.out, True)], writes=("benchmarks.md",))
    areas = list(args.only or AREAS)
    bar = Progress("bench", unit="areas")  # bench has no --quiet: always said
    try:
        said = AreaLines(bar, len(areas))
        tables = run_benchmarks(areas, quick=args.quick, progress=said.start)
        said.end()
    finally:
        bar.close()  # its heartbeat is a thread
    if args.out:
        path = write_report(tables, args.out)
        print(f"bench: wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps([t.to_dict() for t in tables], indent=2, default=str))
    else:
        for table in tables:
            print(table.to_markdown())
    return 0


class AreaLines:
    """Which area runs and how long each took, said through the command's one
    :class:`~chargedesign.commands.progress.Progress` (its heartbeat says every few seconds
    that a long area still runs, with the count of areas done and the time left)."""

    def __init__(self, bar: Progress, total: int) -> None:
        self.bar = bar
        self.total = total
        self.done = 0
        self.name = ""
        self.t0 = self.area_t0 = time.perf_counter()

    def start(self, name: str) -> None:
        """``name`` starts: the area before it is done."""
        self._close_area()
        self.name, self.area_t0 = name, time.perf_counter()
        self.bar.say(f"bench: {name} ...")
        self.bar.update(self.done, self.total, extra=name)

    def end(self) -> None:
        """Every area ran."""
        self._close_area()
        self.bar.update(self.done, max(self.done, 1))
        self.bar.say(f"bench: all areas in {time.perf_counter() - self.t0:.0f} s")

    def _close_area(self) -> None:
        if self.name:
            self.done += 1
            took = time.perf_counter() - self.area_t0
            self.bar.say(f"bench: {self.name} done in {took:.0f} s")
            self.name = ""
