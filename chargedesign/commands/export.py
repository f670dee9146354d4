"""`chargedesign export DESIGN --out PATH [--format json|csv|vtp|vtu]`: a design as a file.

The format follows the file name's extension unless ``--format`` is given.
"""

from __future__ import annotations

import argparse
import json

from chargedesign.export import export_design, load_any_design
from chargedesign.files import check_outputs
from chargedesign.readers import resolve_format


def run(args: argparse.Namespace) -> int:

    check_outputs([("--out", args.out, False)], inputs=[args.design])
    fmt = resolve_format(args.format, args.out)
    design = load_any_design(args.design)
    path = export_design(design, fmt, args.out)
    summary = {
        "path": str(path),
        "format": fmt,
        "charges": len(design.charge_values),
        "masses": len(design.mass_values),
        "dipoles": len(design.dipole_moments),
        "continuous": len(design.continuous),
    }
    if args.json:
        print(json.dumps(summary))
    else:
        print(
            f"wrote {path} ({fmt}: {summary['charges']} charges, {summary['masses']} masses, "
            f"{summary['dipoles']} dipoles, {summary['continuous']} continuous bodies)"
        )
    return 0
