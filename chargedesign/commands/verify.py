"""`chargedesign verify`: exact certificate of the theorem and audit of the printed formulas.

Exit 0 when the certificate holds in all four cases of the paper's table and the Larmor
certificate holds (printed misprints are findings, reported but not failures), 1 otherwise.
"""

from __future__ import annotations

import argparse
import json

from chargedesign.model.verification import CERTIFICATE_CASES as CERTIFICATE_CASES
from chargedesign.model.verification import VerificationReport
from chargedesign.model.verification import collect as collect
from chargedesign.model.verification import format_report as format_report


def run(args: argparse.Namespace) -> int:

    report = collect()
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(VerificationReport(report))
    return 0 if VerificationReport(report).holds else 1
