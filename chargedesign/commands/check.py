"""`chargedesign check DESIGN`: forward check of a design by rotating it through the fields.

Exit status 0 when every quantity the design claims is verified within ``--tol``, 1 when one
is not (beyond the tolerance, or unverifiable: its contributions cancel so far that the
rounding floor of the evaluation exceeds the tolerance), 2 on bad input (unreadable design,
bad options).
"""

from __future__ import annotations

import argparse

from chargedesign.body import read_design
from chargedesign.checker import check_design
from chargedesign.errors import InputError
from chargedesign.limits import MAX_ORIENTATIONS, MAX_QUADRATURE_ORDER
from chargedesign.validation import as_count
from chargedesign.vocabulary import PRECISIONS


def run(args: argparse.Namespace) -> int:
    import json
    import math

    if not math.isfinite(args.tol) or args.tol <= 0.0:
        raise InputError(f"--tol: expected a number > 0, got {args.tol!r}")
    if args.precision not in PRECISIONS:
        raise InputError(
            f"--precision: expected one of {', '.join(PRECISIONS)}, got {args.precision!r}"
        )

    as_count(args.orientations, "--orientations", minimum=1, cap=MAX_ORIENTATIONS)
    if args.quadrature_order is not None:
        as_count(args.quadrature_order, "--quadrature-order", minimum=0, cap=MAX_QUADRATURE_ORDER)
    # a file without "realises" claims nothing: it must not pass (docs/reliability.md)
    design = read_design(args.design, required=("realises",))
    report = check_design(
        design,
        n_orientations=args.orientations,
        tol=args.tol,
        seed=args.seed,
        quadrature_order=args.quadrature_order,
        precision=args.precision,
    )
    if args.json:
        print(json.dumps(report.to_dict(), indent=2, allow_nan=False))
    else:
        print(report)
    return 0 if report.passed else 1
