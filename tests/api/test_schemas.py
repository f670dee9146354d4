"""JSON Schemas: shipped, printed by the CLI, and every example and design validates."""

import json
import tomllib
from pathlib import Path

import jsonschema
import pytest

import chargedesign as cd
from chargedesign.cli import main
from chargedesign.scene import default_scene_text
from chargedesign.schemas import NAMES, schema, schema_text, shipped_schema_text, validate

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted(
    p
    for folder in ("examples", "examples/scenes", "tests/model/data")
    for p in (ROOT / folder).glob("*.toml")
)


@pytest.mark.parametrize("name", NAMES)
def test_schemas_are_valid_shipped_and_printed(name, capsys):
    jsonschema.Draft202012Validator.check_schema(schema(name))
    assert shipped_schema_text(name) == schema_text(name)  # regenerate: make schemas
    assert main(["schema", name]) == 0
    assert json.loads(capsys.readouterr().out) == schema(name)


def test_the_default_scene_validates():
    validate(tomllib.loads(default_scene_text()), "scene")


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.name)
def test_every_example_scene_validates(path):
    assert SCENES, "no scenes found"
    validate(tomllib.loads(path.read_text()), "scene")


def test_a_designed_and_a_physical_design_validate(default_result):
    validate(default_result.design.to_dict(), "design")
    physical = cd.Design(
        parameters=cd.Parameters(C=1.0),
        charge_positions=[[0.1, 0.0, 0.0]],
        charge_values=[1e-9],
        charge_radii=[0.01],
        charge_masses=[0.002],
        dipole_positions=[[0.0, 0.1, 0.0]],
        dipole_moments=[[0.0, 0.0, 0.01]],
        dipole_volumes=[1e-8],
        dipole_masses=[7.5e-5],
        further_keys={
            "medium": {"name": "air", "breakdown_V_per_m": 3e6, "safety": 0.5},
            "materials": {
                "magnet": {
                    "name": "NdFeB",
                    "remanent_magnetisation_A_per_m": 1.1e6,
                    "density_kg_per_m3": 7500.0,
                }
            },
        },
    )
    data = physical.to_dict()
    assert data["charges"]["radii"] == [0.01]
    validate(data, "design")


@pytest.mark.parametrize(
    ("name", "instance", "where"),
    [
        ("scene", {"paramters": {}}, "top level"),
        ("scene", {"design": {"realise": ["mu", "omega"]}}, "design.realise.1"),
        ("scene", {"fields": {"magnetic": {"a1": 1.0, "legendre": [1.0]}}}, "fields.magnetic"),
        ("design", {"parameters": {"C": -1.0}}, "parameters.C"),
        ("design", {"parameters": {}, "charges": {"value": [1.0]}}, "charges"),
        ("design", {"parameters": {}, "masses": {"values": [-1.0]}}, "masses.values.0"),
    ],
)
def test_bad_files_are_refused_naming_the_key(name, instance, where):
    with pytest.raises(cd.InputError, match=where.replace(".", r"\.")):
        validate(instance, name)
