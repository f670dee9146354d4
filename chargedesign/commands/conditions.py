"""`chargedesign conditions [SCENE]`: the linear conditions on moments a body must meet (for a
scene with ``[case]``: the masses' conditions in gravity, ``chargedesign.designer.case_design``).
"""

from __future__ import annotations

import argparse
from typing import Any

from chargedesign.moment_conditions import conditions_for_scene
from chargedesign.moment_conditions.text import format_conditions
from chargedesign.scene import load_scene


def _human(result: Any, scene_source: str) -> str:

    return format_conditions(result, scene_source)


def run(args: argparse.Namespace) -> int:
    import json

    scene = load_scene(args.scene)  # the whole file, every table (scene.validate_tables)
    if scene.case is not None:  # a case of (ep): the masses' conditions in gravity
        from chargedesign.designer.case_design import case_conditions  # sympy: a case only

        result = case_conditions(scene)
    else:
        result = conditions_for_scene(scene, exact=args.exact)
    if args.json:
        out = result.to_dict()
        out["scene"] = scene.source
        if scene.case is None:
            out["parameters"] = scene.parameters.as_dict()
        else:
            out["case"] = scene.case.name
        print(json.dumps(out, indent=2))
    else:
        print(_human(result, scene.source))
    return 0
