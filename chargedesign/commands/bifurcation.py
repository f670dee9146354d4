"""`chargedesign bifurcation [SCENE] [--h-range LO HI] [--out DIR]`: the shape of the motion.

The critical set of the momentum map (H, I4) on the level ``I3 = 0, |gamma| = 1`` of the
scene's parameters, its image (the bifurcation diagram) with the stability type of each
branch, and the number of Liouville tori in each chamber. Writes ``DIR/bifurcation.csv``
(``h, k, branch, type, p, q, r, gamma1, gamma2, gamma3``; consecutive rows of a branch are
neighbours along it) and ``DIR/bifurcation.png`` (default DIR ``out/``). With ``--at H``
also ``DIR/bifurcation_at.png``: the diagram with the line h = H beside the Poincare atlas
on I3 = 0 (the orbits on critical values of k marked) and the FLI map at 64 x 48 (heyoka;
about a minute). lambda or rho != 0 is refused (see docs/bifurcation.md).
"""

from __future__ import annotations

import argparse
import sys

from chargedesign.errors import InputError
from chargedesign.files import atomic_directory, check_outputs
from chargedesign.formatting import CELL, PLAIN, fmt
from chargedesign.scene import load_theorem_scene
from chargedesign.topology.diagram import bifurcation_diagram, energy_range
from chargedesign.topology.links import linked_pictures


def run(args: argparse.Namespace) -> int:
    check_outputs(
        [("--out", args.out, True)],
        inputs=[args.scene],
        writes=("bifurcation.csv", "bifurcation.png", "bifurcation_at.png"),
    )
    scene = load_theorem_scene(args.scene, "bifurcation")
    h_range = None if args.h_range is None else (args.h_range[0], args.h_range[1])
    lo, hi = energy_range(scene.parameters, h_range)
    if args.at is not None and not lo < args.at < hi:
        raise InputError(
            f"--at: expected an energy inside {fmt(lo, CELL)} .. {fmt(hi, CELL)} J, got"
            f" {fmt(args.at, PLAIN)}"
        )
    if not args.quiet:
        print("bifurcation: critical set, continuation, chambers ...", file=sys.stderr, flush=True)
    diagram = bifurcation_diagram(scene.parameters, h_range)
    linked = None
    if args.at is not None:
        linked = linked_pictures(diagram, args.at, orbits=20, t_end=200.0, fli_t_end=10.0)
    # every file or none; a picture at another energy from an earlier run is not kept
    stale = () if linked is not None else ("bifurcation_at.png",)
    with atomic_directory(args.out, drop=stale) as stage:
        diagram.write(args.out)
        if linked is not None:
            linked.plot().savefig(stage / "bifurcation_at.png", dpi=90)
    if args.json:
        print(diagram.to_json())
    else:
        print(str(diagram), end="")
        if linked is not None:
            print(str(linked), end="")
        names = ["bifurcation.csv", "bifurcation.png"] + (["bifurcation_at.png"] if linked else [])
        print("wrote " + ", ".join(f"{args.out}/{name}" for name in names))
    return 0
