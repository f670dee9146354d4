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
from chargedesign.commands import print_result
from chargedesign.errors import InputError
from chargedesign.vocabulary import PRECISIONS


def run(args: argparse.Namespace) -> int:
    # --tol, --orientations and --quadrature-order: their ranges are checked by the command
    # line before this runs (chargedesign.limits.OPTION_RANGES, shown in --help)
    if args.precision not in PRECISIONS:
        raise InputError(
            f"--precision: expected one of {', '.join(PRECISIONS)}, got {args.precision!r}"
        )
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
    print_result(report, args.json)
    return 0 if report.passed else 1
