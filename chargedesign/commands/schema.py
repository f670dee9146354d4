"""`chargedesign schema design|scene`: print the JSON Schema of design.json or of scene files."""

from __future__ import annotations

import argparse

from chargedesign.schemas import schema_text


def run(args: argparse.Namespace) -> int:

    print(schema_text(args.name), end="")
    return 0
