"""`chargedesign catalogue`: the paper's integrable cases of (ep), each certified exactly.

Exit 0 when every case's claim holds and its integral is independent, 1 otherwise.
"""

from __future__ import annotations

import argparse

from chargedesign.model.catalogue import certify_catalogue


def run(args: argparse.Namespace) -> int:
    report = certify_catalogue()
    print(report.to_json() if args.json else report)
    return 0 if report.holds else 1
