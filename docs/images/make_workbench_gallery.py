"""The workbench gallery's table: every catalogue case with its certificate time and, where
masses in gravity realise its forces, the body ``chargedesign design`` makes of it (a ball of
radius 1 m, spacing 0.25 m; the refusal's reason otherwise). Prints Markdown.

    python docs/images/make_workbench_gallery.py docs/images/workbench_kowalevski_body.png

With a path, the Kowalevski body is also designed by the command line (``chargedesign design``
of a scene holding the catalogue's ``[case]`` and the ball) and its design.png copied there.
"""

import json
import shutil
import sys
import tempfile
from pathlib import Path

from chargedesign.cli import main
from chargedesign.designer.pipeline import design_from_scene
from chargedesign.errors import ChargeDesignError
from chargedesign.model.catalogue import catalogue_entries, certify_catalogue, entry_table
from chargedesign.scene import scene_from_dict

BODY = {"shape": "ball", "radius": 1.0, "spacing": 0.25}

report = certify_catalogue()
seconds = {c.name: c.seconds for c in report.certificates}
print("| case | certificate s | body (masses in gravity, or charges, dipoles and masses) |")
print("| --- | --- | --- |")
for entry in catalogue_entries():
    table = entry_table(entry)
    scene = scene_from_dict({"case": table, "body": dict(BODY)}, f"<{table['name']}>")
    try:
        result = design_from_scene(scene)
    except ChargeDesignError as exc:
        reason = str(exc).split(": ", 1)[1] if ": " in str(exc) else str(exc)
        outcome = f"refused: {reason.split(';')[0].split(' (')[0]}"
    else:
        design = result.design
        fields = "; ".join(
            f"{kind} [{', '.join(f'{x:.4g}' for x in v)}]" for kind, v in design.fields.items() if v
        )
        checks = design.further_keys["case"]["checks"]
        outcome = (
            f"{len(design.charge_values)} charges, {len(design.dipole_moments)} "
            f"dipoles, {len(design.mass_values)} masses; {fields}; inertia err "
            f"{checks['inertia_rel_err']:.0e}, torque err {checks['torque_rel_err']:.0e}"
        )
    print(f"| {table['name']} | {seconds[table['name']]:.2f} | {outcome} |")
print(f"\n{len(report.certificates)} cases certified in {report.seconds:.1f} s")

if len(sys.argv) > 1:
    entry = next(e for e in catalogue_entries() if entry_table(e)["name"] == "kowalevski")
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "kowalevski.toml"
        table = entry_table(entry)
        # TOML's strings, numbers and lists are JSON's for these plain ASCII values
        lines = ["[case]"] + [
            f"{k} = {json.dumps(v)}" for k, v in table.items() if k != "parameters"
        ]
        lines += ["[case.parameters]"] + [
            f"{k} = {json.dumps(v)}" for k, v in table["parameters"].items()
        ]
        lines += ["[body]"] + [f"{k} = {json.dumps(v)}" for k, v in BODY.items()]
        scene.write_text("\n".join(lines) + "\n", "utf-8")
        assert main(["design", str(scene), "--out", f"{tmp}/out", "--quiet"]) == 0
        shutil.copy(Path(tmp) / "out" / "design.png", sys.argv[1])
