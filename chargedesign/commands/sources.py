"""`chargedesign sources [--json]`: the table of every physical figure the tool uses, with
its source, locator and whether it was checked (chargedesign/data/sources.toml)."""

from __future__ import annotations

import argparse

from chargedesign.commands import print_result
from chargedesign.physical.sources import table


def run(args: argparse.Namespace) -> int:
    print_result(table(), args.json, end="")
    return 0
