"""`chargedesign frontier [SCENE] [--json] [--scan --out DIR]`: where the buildable stops.

Finds the largest time rate ``s`` (n, K x s; kappa, lambda, rho x s^2) for which the scene's
body realises the theorem within every limit of its medium and materials and passes the
design's acceptance (limits, balance under gravity, forward check), and the limit that binds
just above it. With the ``frame`` Larmor reading (the default with ``[medium]``) the body
realises n = 0, n is free and the frontier is ``K_max``; with ``charges`` it is ``n_max``.
Under gravity it also gives the lowest rate whose balance the check confirms, and fails in
one line when that lies above ``s_max``. ``--scan`` also sweeps the body's size and the
medium (and the magnetic field and the carriers' density), plots ``K_max`` (or ``n_max``)
against size (log-log, one line per medium) and fits the scaling law, printing the
exponents and the fit's residual.
"""

from __future__ import annotations

import argparse
import sys

from chargedesign.designer.frontier_scan import scan_frontier, write_scan
from chargedesign.designer.pipeline import frontier_from_scene
from chargedesign.errors import InputError
from chargedesign.files import check_outputs
from chargedesign.scene import load_theorem_scene


def run(args: argparse.Namespace) -> int:
    import json

    if args.out is not None and not args.scan:
        raise InputError("--out: only --scan writes files; give --scan too, or drop --out")
    check_outputs(
        [("--out", args.out, True)],
        inputs=[args.scene],
        writes=("frontier_scan.csv", "frontier_scan.png"),
    )

    def progress(message: str) -> None:
        if not args.quiet:
            print(f"frontier: {message}", file=sys.stderr, flush=True)

    scene = load_theorem_scene(args.scene, "frontier")
    if args.scan:
        from pathlib import Path

        scan = scan_frontier(scene, progress=progress)
        if args.out is not None:
            write_scan(scan, Path(args.out))
            progress(f"wrote {args.out}/frontier_scan.csv, frontier_scan.png")
        print(json.dumps(scan.to_dict(), indent=2, allow_nan=False) if args.json else str(scan))
        return 0
    result = frontier_from_scene(scene, progress=progress)
    if args.json:
        print(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    else:
        print(str(result), end="")
    return 0
