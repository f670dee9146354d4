"""`chargedesign conditions [SCENE]`: the linear conditions on moments a body must meet (for a
scene with ``[case]``: the masses' conditions in gravity, ``chargedesign.designer.case_design``).
"""

from __future__ import annotations

import argparse
from typing import Any

from chargedesign.designer.pipeline import larmor_of_scene
from chargedesign.formatting import PRECISE, fmt
from chargedesign.larmor import body_parameters
from chargedesign.moment_conditions import conditions_for_scene
from chargedesign.moment_conditions.text import format_conditions
from chargedesign.scene import load_scene


def run(args: argparse.Namespace) -> int:
    import json

    scene = load_scene(args.scene)  # the whole file, every table (scene.validate_tables)
    if scene.case is not None:  # a case of (ep): the masses' conditions in gravity
        from chargedesign.designer.case_design import case_conditions  # sympy: a case only

        result = case_conditions(scene)
        reading = None
    else:
        # the reading design uses (pipeline.larmor_of_scene), so both state the same fields
        # and conditions: with `frame` the body realises n = 0 (its I_xx condition is 0)
        larmor, why, _ = larmor_of_scene(scene.design, scene.parameters, scene.physical is not None)
        realised = body_parameters(scene.parameters, larmor)
        result = conditions_for_scene(scene, exact=args.exact, parameters=realised)
        reading = {"reading": larmor.reading, "rate": larmor.rate, "why": why}
    if args.json:
        out = result.to_dict()
        out["scene"] = scene.source
        if scene.case is None:
            out["parameters"] = scene.parameters.as_dict()
            out["larmor"] = reading
        else:
            out["case"] = scene.case.name
        print(json.dumps(out, indent=2))
    else:
        text = format_conditions(result, scene.source)
        if reading is not None:
            first, _, rest = text.partition("\n")
            text = f"{first}\n{reading_line(reading)}\n{rest}"
        print(text)
    return 0


def reading_line(reading: dict[str, Any]) -> str:
    """The Larmor reading the conditions are derived in, and why (as design.json's
    ``larmor`` and ``larmor_why`` and the report's "Larmor reading" line say it)."""
    if reading["reading"] == "frame":
        how = (
            f"the body realises n = 0; its motion read in axes turning at n = "
            f"{fmt(reading['rate'], PRECISE)} 1/s about Z is the theorem's"
        )
    else:
        how = "the charges' second moments carry n (the paper's (p6) reading)"
    return f"Larmor reading: {reading['reading']}: {how}\n  why: {reading['why']}"
