"""`chargedesign sources [--json]`: the table of every physical figure the tool uses, with
its source, locator and whether it was checked (chargedesign/data/sources.toml)."""

from __future__ import annotations

import argparse
import json

from chargedesign.physical.sources import table


def run(args: argparse.Namespace) -> int:
    result = table()
    if args.json:
        print(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    else:
        print(str(result), end="")
    return 0
