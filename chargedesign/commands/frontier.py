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

Beside ``s_max`` it gives the realised window [s_low, s_high]
(:mod:`chargedesign.physical.window`): the rates at which every parasitic is below
``--realised-fraction`` of each realised term. ``--out DIR`` (without ``--scan``) writes
``DIR/realised_window.png``: each parasitic over the fraction against the rate, the window
shaded. ``--recommend PATH`` searches the field, the materials, the size and the medium for
the widest window (:mod:`chargedesign.designer.recommend`) and writes that scene to PATH.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from chargedesign.commands.progress import progress_bar
from chargedesign.designer.frontier import WindowOptions, write_window_picture
from chargedesign.designer.frontier_scan import scan_frontier, write_scan
from chargedesign.designer.pipeline import design_and_frontier_from_scene
from chargedesign.designer.recommend import recommend
from chargedesign.errors import InputError
from chargedesign.files import check_outputs
from chargedesign.physical.support import scene_window_gravity
from chargedesign.report import wrapped_text
from chargedesign.scene import load_scene
from chargedesign.verdict import verdict_state_line, verdict_text_table


def run(args: argparse.Namespace) -> int:
    import json

    if args.recommend is not None and args.scan:
        raise InputError("--recommend: give it without --scan (they are two searches)")
    check_outputs(
        [("--out", args.out, True), ("--recommend", args.recommend, False)],
        inputs=[args.scene],
        writes=("frontier_scan.csv", "frontier_scan.png")
        if args.scan
        else ("realised_window.png",),
    )

    def progress(message: str) -> None:
        if not args.quiet:
            print(f"frontier: {message}", file=sys.stderr, flush=True)

    scene = load_scene(args.scene)
    if scene.case is not None and (args.scan or args.recommend is not None):
        raise InputError(
            f"{scene.source}: --scan and --recommend vary the theorem's [parameters], not a "
            "[case] scene yet (its frontier and window: without them)"
        )
    # --realised-* are range-checked with every option (limits.OPTION_RANGES) before the run;
    # the scene's [design] keys fill what is not given
    window = WindowOptions(
        scene.design.realised_fraction
        if args.realised_fraction is None
        else args.realised_fraction,
        scene_window_gravity(scene) if args.realised_gravity is None else args.realised_gravity,
    )
    if args.scan:
        scan = scan_frontier(scene, progress=progress)
        if args.out is not None:
            write_scan(scan, Path(args.out))
            progress(f"wrote {args.out}/frontier_scan.csv, frontier_scan.png")
        return _print(scan, args.json)
    if args.recommend is not None:
        # the probes counted against the most the search makes, with the time left
        with progress_bar("frontier --recommend", "probes", args.quiet) as bar:
            found = recommend(
                scene,
                window,
                progress=None if bar is None else (lambda m: bar.say(f"frontier: {m}")),
                tally=None if bar is None else bar.update,
            )
        found.write(Path(args.recommend))
        progress(f"wrote {args.recommend}")
        return _print(found, args.json)
    # the body at the scene's rate (its recorded verdict) and the frontier: one setup, one
    # derivation of the conditions, the frontier located once (as `design` locates it)
    designed, result = design_and_frontier_from_scene(
        scene,
        progress=progress,
        realised_fraction=args.realised_fraction,
        realised_gravity=args.realised_gravity,
    )
    body = None if designed is None else designed.design
    if args.out is not None and result.realised is not None:
        write_window_picture(result, Path(args.out))
        progress(f"wrote {args.out}/realised_window.png")
    verdict = None if body is None else body.verdict
    if args.json:
        data = result.to_dict()
        if verdict is not None:
            data["verdict"] = {k: v for k, v in verdict.items() if k != "rows"}
        print(json.dumps(data, indent=2, allow_nan=False))
    else:
        if verdict is not None:
            print("Verdict at the scene's rate (s = 1): " + verdict_state_line(verdict))
            print("\n".join(verdict_text_table(verdict)) + "\n")
        print(wrapped_text(str(result)), end="")
    return 0


def _print(result: Any, as_json: bool) -> int:
    """A search's result on stdout: its ``to_dict`` as JSON, or its text wrapped."""
    import json

    print(
        json.dumps(result.to_dict(), indent=2, allow_nan=False)
        if as_json
        else wrapped_text(str(result))
    )
    return 0
