"""``conditions`` and ``design`` agree on the same scene: the same Larmor reading, named by
both, the same fields and the same conditions (on the default scene they once differed in the
fields and in I_xx: -C n against 0)."""

from __future__ import annotations

import json

from chargedesign.cli import main
from chargedesign.designer.pipeline import larmor_of_scene
from chargedesign.larmor import body_parameters
from chargedesign.moment_conditions import derive_conditions
from chargedesign.moment_conditions.scene import scene_length
from chargedesign.scene import load_scene


def test_conditions_states_the_designs_reading_fields_and_conditions(capsys) -> None:
    assert main(["conditions", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    scene = load_scene(None)
    larmor, why, _ = larmor_of_scene(scene.design, scene.parameters, scene.physical is not None)
    assert out["larmor"] == {"reading": "frame", "rate": scene.parameters.n, "why": why}
    # the design's route: the body's parameters (n = 0 in the frame reading), its length
    length, _ = scene_length(scene)
    params = body_parameters(scene.parameters, larmor)
    design = derive_conditions(params, scene.fields, ["mu", "V", "inertia"], length=length)
    fields = {k: v["legendre"] for k, v in out["fields"].items()}
    assert fields == {k: list(v) for k, v in design.fields.items()}
    assert out["charges"] == design.to_dict()["charges"]
    assert out["charges"]["xx"] == 0.0  # not -C n: the frame body realises n = 0
    assert main(["conditions"]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[1].startswith("Larmor reading: frame: the body realises n = 0")
    assert max(len(line) for line in text.splitlines()[:4]) <= 160
