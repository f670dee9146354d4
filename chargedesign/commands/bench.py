"""`chargedesign bench` (not implemented yet)."""

from __future__ import annotations

import argparse

from chargedesign.errors import ChargeDesignError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace) -> int:
    raise ChargeDesignError("command 'bench' is not implemented yet")
