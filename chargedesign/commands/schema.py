"""`chargedesign schema design|scene`: print the JSON Schema of design.json or of scene files."""

from __future__ import annotations

import argparse

from chargedesign.schemas import NAMES


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "name", choices=NAMES, help="design (design.json), scene (TOML) or testbed (testbed.json)"
    )


def run(args: argparse.Namespace) -> int:
    from chargedesign.schemas import schema_text

    print(schema_text(args.name), end="")
    return 0
