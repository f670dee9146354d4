"""The tolerance report of a ``[case]`` scene's design: measured against the theorem's mu, V
and inertia, so taken for a case of the theorem's form (its body and parameters are the
theorem's) and refused in one line for any other (before, a Kowalevski body's report measured
its V = C a gamma1 against the placeholder parameters' V = 0: a nominal error of 77 %)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from case_tables import kowalevski_table

import chargedesign as cd
from chargedesign.errors import InputError
from chargedesign.model.catalogue import THEOREM_FILE, entry_table
from chargedesign.scene import scene_from_dict
from chargedesign.tolerancing import tolerance_report

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
BODY = {"shape": "ball", "radius": 0.5, "spacing": 0.125}


def test_a_case_of_another_form_is_refused_in_one_line() -> None:
    table = tomllib.loads(kowalevski_table("kowalevski-tolerance", 0.3, 2.5))
    design = cd.design(scene_from_dict({**table, "body": BODY}, "kowalevski")).design
    with pytest.raises(InputError) as caught:
        tolerance_report(design)
    message = str(caught.value)
    assert message.startswith("design: tolerance takes a design of the theorem, not of a case")
    assert "kowalevski-tolerance" in message and "\n" not in message


def test_a_case_of_the_theorems_form_gets_the_theorems_tolerances() -> None:
    data = tomllib.loads((EXAMPLES / "unit_scale.toml").read_text("utf-8"))
    theorem = cd.design(scene_from_dict(data, "unit scale")).design
    # the catalogue's entry of the theorem at the scene's parameters, as a [case] table
    case = entry_table({"file": THEOREM_FILE, "parameters": theorem.parameters.as_dict()})
    tables = {k: v for k, v in data.items() if k not in ("parameters", "simulation")}
    twin = cd.design(scene_from_dict({**tables, "case": case}, "unit scale as a case")).design
    assert "case" in twin.further_keys
    assert tolerance_report(twin).to_dict() == tolerance_report(theorem).to_dict()
