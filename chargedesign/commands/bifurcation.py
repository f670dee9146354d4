"""`chargedesign bifurcation [SCENE] [--h-range LO HI] [--out DIR]`: the shape of the motion.

The critical set of the momentum map (H, I4) on the level ``I3 = 0, |gamma| = 1`` of the
scene's parameters, its image (the bifurcation diagram) with the stability type of each
branch, and the number of Liouville tori in each chamber. Writes ``DIR/bifurcation.csv``
(``h, k, branch, type, p, q, r, gamma1, gamma2, gamma3``; consecutive rows of a branch are
neighbours along it) and ``DIR/bifurcation.png`` (default DIR ``out/``). lambda or rho != 0
is refused (see docs/bifurcation.md).
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: embedded"
    )
    parser.add_argument(
        "--h-range",
        nargs=2,
        type=float,
        metavar=("LO", "HI"),
        default=None,
        help="energy range in J (default: from the least energy on the level to the top of "
        "the amended potential plus half its span)",
    )
    parser.add_argument("--out", default="out", metavar="DIR", help="output folder (default out/)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.add_argument("--quiet", action="store_true", help="no progress message on stderr")


def run(args: argparse.Namespace) -> int:
    from chargedesign.files import check_outputs
    from chargedesign.scene import load_scene
    from chargedesign.topology.diagram import bifurcation_diagram, check_energy_range

    check_outputs(
        [("--out", args.out, True)],
        inputs=[args.scene],
        writes=("bifurcation.csv", "bifurcation.png"),
    )
    scene = load_scene(args.scene)
    h_range = None if args.h_range is None else (args.h_range[0], args.h_range[1])
    check_energy_range(scene.parameters, h_range)
    if not args.quiet:
        print("bifurcation: critical set, continuation, chambers ...", file=sys.stderr, flush=True)
    diagram = bifurcation_diagram(scene.parameters, h_range)
    diagram.write(args.out)
    if args.json:
        print(diagram.to_json())
    else:
        print(str(diagram), end="")
        print(f"wrote {args.out}/bifurcation.csv, {args.out}/bifurcation.png")
    return 0
