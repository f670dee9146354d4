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
    from chargedesign.conditions.text import format_conditions

    return format_conditions(result, scene_source)


def _validate_other_tables(scene: Any) -> None:
    """Every command knows every key: unknown [body] keys and the [design] table get the
    design command's one-line errors (bad [body] values stay a note: the conditions only
    take the body's length from it)."""
    from chargedesign.candidates import check_body_keys
    from chargedesign.design import DesignOptions

    DesignOptions.from_table(scene.table("design"))
    body = scene.table("body")
    if "shape" in body:  # a region (without a shape, [body] may be simulate's inline body)
        check_body_keys(body)


def run(args: argparse.Namespace) -> int:
    import json

    from chargedesign.conditions import conditions_for_scene
    from chargedesign.scene import load_scene

    scene = load_scene(args.scene)
    _validate_other_tables(scene)
    result = conditions_for_scene(scene, exact=args.exact)
    if args.json:
        out = result.to_dict()
        out["scene"] = scene.source
        out["parameters"] = scene.parameters.as_dict()
        print(json.dumps(out, indent=2))
    else:
        print(_human(result, scene.source))
    return 0
