"""`chargedesign check DESIGN`: forward check of a design by rotating it through the fields.

Exit status 0 when every quantity the design claims is verified within ``--tol``, 1 when one
is not (beyond the tolerance, or unverifiable: its contributions cancel so far that the
rounding floor of the evaluation exceeds the tolerance), 2 on bad input (unreadable design,
bad options).
"""

from __future__ import annotations

import argparse

from chargedesign.errors import InputError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.limits import MAX_ORIENTATIONS, MAX_QUADRATURE_ORDER
from chargedesign.validation import as_count
from chargedesign.vocabulary import CHECK_DEFAULT_ORIENTATIONS as DEFAULT_ORIENTATIONS
from chargedesign.vocabulary import CHECK_DEFAULT_TOL as DEFAULT_TOL
from chargedesign.vocabulary import PRECISIONS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("design", metavar="DESIGN", help="design.json to check")
    parser.add_argument("--json", action="store_true", help="print JSON (contract keys first)")
    parser.add_argument(
        "--tol",
        type=float,
        default=DEFAULT_TOL,
        metavar="T",
        help=f"relative tolerance for the claimed quantities (default {fmt(DEFAULT_TOL, PLAIN)})",
    )
    parser.add_argument(
        "--orientations",
        type=int,
        default=DEFAULT_ORIENTATIONS,
        metavar="N",
        help=f"orientations gamma sampled (default {DEFAULT_ORIENTATIONS}, at most "
        "chargedesign.limits.MAX_ORIENTATIONS = 1000000)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="seed of the random orientations (default 0)"
    )
    parser.add_argument(
        "--quadrature-order",
        type=int,
        default=None,
        metavar="D",
        help="degree of exactness for continuous bodies (default: exact for the check)",
    )
    parser.add_argument(
        "--precision",
        default="auto",
        metavar="P",
        help="arithmetic of the sums: " + ", ".join(PRECISIONS) + " (default auto: "
        "double-double where a claimed quantity's contributions cancel too far for double "
        "precision to decide it)",
    )


def run(args: argparse.Namespace) -> int:
    import json
    import math

    from chargedesign.body import read_design
    from chargedesign.checker import check_design

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
