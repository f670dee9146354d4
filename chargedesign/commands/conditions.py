"""`chargedesign conditions [SCENE]`: the linear conditions on moments a body must meet."""

from __future__ import annotations

import argparse
from typing import Any


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scene", nargs="?", default=None, help="scene file (TOML); default: the embedded scene"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.add_argument(
        "--exact",
        action="store_true",
        help="read the inputs as the decimals they print as and report exact rational values",
    )


def _human(result: Any, scene_source: str) -> str:
    from chargedesign.moment_conditions.text import format_conditions

    return format_conditions(result, scene_source)


def run(args: argparse.Namespace) -> int:
    import json

    from chargedesign.moment_conditions import conditions_for_scene
    from chargedesign.scene import load_scene

    scene = load_scene(args.scene)  # the whole file, every table (scene.validate_tables)
    result = conditions_for_scene(scene, exact=args.exact)
    if args.json:
        out = result.to_dict()
        out["scene"] = scene.source
        out["parameters"] = scene.parameters.as_dict()
        print(json.dumps(out, indent=2))
    else:
        print(_human(result, scene.source))
    return 0
