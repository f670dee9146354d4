"""`chargedesign verify [CASE]`: exact certificate of the theorem and audit of the printed
formulas; with a case file, the exact certificate of its claimed integral.

Without CASE: exit 0 when the certificate holds in all four cases of the paper's table and
the Larmor certificate holds (printed misprints are findings, reported but not failures), 1
otherwise. With CASE: exit 0 when the claimed integral is conserved and independent of H,
|gamma|^2 and I3, 1 otherwise (the JSON or the table says which, with a counterexample).
"""

from __future__ import annotations

import argparse
import json

from chargedesign.model.case_file import verify_case_file
from chargedesign.model.frame import certify_frame
from chargedesign.scene.case_file import read_case
from chargedesign.verification import verify


def run(args: argparse.Namespace) -> int:
    if args.case is not None:
        certificate = verify_case_file(args.case)
        if args.json:  # with the case's frame reading (model/frame.py), for every n
            data = json.loads(certificate.to_json())
            data["frame"] = certify_frame(read_case(args.case)).to_dict()
            print(json.dumps(data, indent=2))
        else:
            print(certificate)
        return 0 if certificate.holds and certificate.independent else 1
    report = verify()
    if args.json:
        print(json.dumps(report.data, indent=2))
    else:
        print(report)
    return 0 if report.holds else 1
