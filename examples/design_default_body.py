"""The Python API end to end: scene -> conditions -> design -> check -> design.json + picture.

Does what `chargedesign design` and `chargedesign check` do, step by step. Run::

    .venv/bin/python examples/design_default_body.py [OUT_DIR] [SCENE]

OUT_DIR defaults to $CHARGEDESIGN_OUT, else out/examples/design; SCENE to the embedded
default scene. Writes OUT_DIR/design.json and OUT_DIR/design.png.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from chargedesign.body import read_design, write_design
from chargedesign.candidates import candidates_from_table
from chargedesign.checker import check_design
from chargedesign.designer import DesignOptions, design_body
from chargedesign.moment_conditions import conditions_for_scene
from chargedesign.scene import load_scene
from chargedesign.viz import render_screenshot


def main(out_dir: str | None = None, scene_path: str | None = None) -> int:
    out = Path(out_dir or os.environ.get("CHARGEDESIGN_OUT") or "out/examples/design")
    scene = load_scene(scene_path)  # None: the embedded default scene
    print(f"scene {scene.source}: {scene.parameters}")

    # 1. the linear conditions on the moments of charges, dipoles and masses
    conditions = conditions_for_scene(scene)
    for source in ("charges", "dipoles", "masses"):
        print(f"conditions on {source}: {len(conditions.for_source(source))}")
    print(f"fields used: {conditions.fields}")

    # 2. candidate points from the scene's [body] table, then the design (l1: sparse)
    candidates = candidates_from_table(scene.table("body"))
    options = DesignOptions.from_table(scene.table("design"))
    result = design_body(scene.parameters, conditions, candidates, options)
    design = result.design
    print(
        f"designed on {len(candidates)} candidates: {len(design.charge_values)} charges, "
        f"{len(design.dipole_moments)} dipoles, {len(design.mass_values)} masses"
    )
    print(f"residual after polish: {result.residual_after:.2e} (tolerance {options.tolerance:g})")
    for note in result.notes:
        print(f"note: {note}")

    # 3. the forward check: rotate the body through the fields, compare with the theorem
    report = check_design(design)
    for name, quantity in report.quantities.items():
        print(f"check {name:<18} rel_err {quantity.rel_err:.2e}")
    # (the mathematical case: point elements, no [medium], so no verdict on buildability)
    print(
        "check: "
        + (
            "theorem reproduced"
            if report.reproduced
            else "NOT reproduced: " + ", ".join(report.failures)
        )
    )

    # 4. design.json (read back to show the round trip) and a picture
    out.mkdir(parents=True, exist_ok=True)
    write_design(design, out / "design.json")
    again = read_design(out / "design.json")
    assert again.n_elements == design.n_elements
    picture = render_screenshot(design, out / "design.png", window_size=(800, 600))
    print(f"wrote {out / 'design.json'} and {picture}")
    return 0 if report.passed else 1


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
