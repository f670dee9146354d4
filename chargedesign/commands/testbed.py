"""`chargedesign testbed [SCENE] [--out DIR] [--json]`: an air-bearing platform whose reaction
wheels make it move as the theorem says, or as a ``[case]`` of (ep) says (issue 34).

Designs the ballast that gives the platform A = B = 2C with the centre of mass at O, sizes
the wheels from the motion, runs the sampled loop (ZOH and predictive commands, noise-free;
the scene's command with sensors, disturbances and quantisation over noise seeds) and the
requirements sweep (gyro grade x control rate), and writes ``DIR/testbed.json``,
``DIR/report.md`` and pictures (docs/testbed.md). Default DIR: ``out/testbed``.
"""

from __future__ import annotations

import argparse

from chargedesign.airbearing.report import OUTPUTS, write_testbed
from chargedesign.airbearing.run import default_testbed_scene, testbed_from_scene
from chargedesign.commands import print_result
from chargedesign.commands.progress import progress_bar
from chargedesign.files import check_outputs
from chargedesign.scene import load_scene


def run(args: argparse.Namespace) -> int:
    check_outputs([("--out", args.out, True)], inputs=[args.scene], writes=OUTPUTS)

    # the sampled runs counted against their total, with the time left (--quiet: nothing)
    with progress_bar("testbed", "runs", args.quiet) as bar:

        def progress(message: str) -> None:
            if bar is not None:
                bar.say(f"testbed: {message}")

        result = testbed_from_scene(
            load_scene(args.scene or default_testbed_scene()),
            progress=progress,
            tally=None if bar is None else bar.update,
        )
        written = write_testbed(result, args.out)
        progress(f"wrote {args.out}/: {', '.join(written)}")
    print_result(result, args.json, end="")
    return 0
