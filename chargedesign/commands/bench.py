"""`chargedesign bench`: what accuracy costs in time, as ratios to baselines of the same run."""

from __future__ import annotations

import argparse
import sys

AREAS = ("certificate", "fields", "design", "physical", "check", "simulate")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print the tables as JSON")
    parser.add_argument(
        "--quick", action="store_true", help="small sizes: a smoke run of a few seconds per area"
    )
    parser.add_argument(
        "--only", choices=AREAS, action="append", help="run only these areas (repeatable)"
    )
    parser.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="write benchmarks.md and plots into DIR (e.g. docs); default: print only",
    )


def run(args: argparse.Namespace) -> int:
    import json

    from chargedesign.bench.runner import run_benchmarks, write_report

    def progress(area: str) -> None:
        print(f"bench: {area} ...", file=sys.stderr, flush=True)

    tables = run_benchmarks(args.only or AREAS, quick=args.quick, progress=progress)
    if args.out:
        path = write_report(tables, args.out)
        print(f"bench: wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps([t.to_dict() for t in tables], indent=2, default=str))
    else:
        for table in tables:
            print(table.to_markdown())
    return 0
