"""The scene's tables: declared once, closed schemas generated from the declarations, unknown
keys refused with one line, and the one Medium type round-tripping through design.json."""

from __future__ import annotations

import dataclasses
import json

import pytest

from chargedesign.body import Design, read_design, write_design
from chargedesign.designer.options import DesignOptions
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.physical.realism import realism_budget
from chargedesign.scene import (
    BodyReference,
    BodyRegion,
    Medium,
    load_scene,
    scene_from_dict,
    validated,
)
from chargedesign.scene.keys import BODY_REFERENCE_KEYS, REGION_KEYS, TABLE_KEYS, key_names
from chargedesign.scene.simulation import INITIAL_KEYS, OUTPUT_KEYS, SIMULATION_KEYS
from chargedesign.schemas import schema, schema_text, shipped_schema_text
from chargedesign.simulation.monitors import MONITORS
from chargedesign.vocabulary import MONITOR_ALIASES, MONITOR_NAMES, SCENE_TABLES

#: the smallest scene a table needs beside it to be read at all
NEEDS = {
    name: {"medium": {"name": "air"}}
    for name in ("carriers", "magnets", "ballast", "holder", "tolerance")
}


def _objects(node, path=""):
    """Every object schema below ``node`` with its path."""
    if isinstance(node, dict):
        if node.get("type") == "object":
            yield path, node
        for key, value in node.items():
            yield from _objects(value, f"{path}/{key}")
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _objects(value, f"{path}/{i}")


def test_every_scene_table_is_closed():
    scene = schema("scene")
    assert scene["additionalProperties"] is False
    assert set(scene["properties"]) == set(SCENE_TABLES)
    for path, node in _objects(scene):
        assert node.get("additionalProperties") is False, path


def test_the_shipped_scene_schema_is_the_generated_one():
    assert shipped_schema_text("scene") == schema_text("scene")


@pytest.mark.parametrize("table", sorted(TABLE_KEYS))
def test_schema_lists_exactly_the_declared_keys(table):
    props = schema("scene")["properties"][table]["properties"]
    assert list(props) == list(key_names(table))


def test_the_stages_accept_exactly_the_declared_keys():
    assert SIMULATION_KEYS == key_names("simulation")
    assert INITIAL_KEYS == key_names("initial")
    assert OUTPUT_KEYS == key_names("output")
    fields = {f.name for f in dataclasses.fields(DesignOptions)}
    assert fields == set(key_names("design"))
    region = {"shape", "carrier_radius"}.union(*REGION_KEYS.values())
    assert region | set(BODY_REFERENCE_KEYS) == set(key_names("body"))


@pytest.mark.parametrize("table", sorted(set(TABLE_KEYS) - {"body"}))
def test_unknown_key_is_refused_with_one_line_naming_it(table):
    data = {**NEEDS.get(table, {}), table: {"bogus_key": 1}}
    with pytest.raises(InputError) as info:
        validated(scene_from_dict(data))
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{table}.bogus_key:")
    # the message lists what the validator accepts: the declared keys, all of them
    for name in key_names(table):
        assert name in message


@pytest.mark.parametrize(
    "data, where",
    [
        ({"body": {"shape": "ball", "radius": 0.1, "bogus_key": 1}}, "body.bogus_key"),
        ({"body": {"design": "d.json", "bogus_key": 1}}, "body.bogus_key"),
        ({"parameters": {"bogus_key": 1}}, "parameters"),
        ({"fields": {"magnetic": {"a1": 1.0, "bogus_key": 1}}}, "fields.magnetic"),
        ({"bogus_table": {}}, "<dict>: key bogus_table"),
    ],
)
def test_unknown_keys_elsewhere_are_refused_with_one_line(data, where):
    with pytest.raises(InputError) as info:
        validated(scene_from_dict(data))
    message = str(info.value)
    assert "\n" not in message and message.startswith(where) and "bogus" in message


def test_the_scene_is_typed_at_load():
    scene = load_scene()
    assert isinstance(scene.design, DesignOptions)
    assert isinstance(scene.body, BodyRegion)
    assert scene.simulation.t_end > 0
    designed = scene_from_dict({"body": {"design": "body.json"}})
    assert isinstance(designed.body, BodyReference)
    assert designed.body.design_path == "body.json"
    physical = scene_from_dict({"medium": {"name": "sf6", "safety": 0.25}})
    assert physical.medium == Medium("sf6", 8.9e6, 0.25)
    assert physical.carriers.name == "aluminium"


def test_the_region_to_design_in_is_read_once_or_refused_in_one_line():
    scene = load_scene()
    assert scene.region_spec() is scene.region_spec()  # its values checked once
    assert (scene.region_spec().shape, scene.region_spec().radius) == ("ball", 0.05)
    with pytest.raises(InputError) as refused:
        scene_from_dict({}).region_spec()
    assert str(refused.value).startswith("body: the scene has no [body] table; give one")
    with pytest.raises(InputError, match=r"^body\.design: expected a key of shape 'ball'"):
        scene_from_dict({"body": {"design": "body.json"}}).region_spec()
    case = dataclasses.replace(scene_from_dict({}), tables={"case": {}}, source="s.toml")
    with pytest.raises(InputError) as refused:
        case.region_spec()
    assert str(refused.value) == (
        "s.toml: a [case] scene needs a [body] region (shape, size) to place the elements in"
    )


def _design(medium: Medium) -> Design:
    return Design(
        parameters=Parameters(C=1e-6, n=2.0, K=1.0),
        charge_positions=[[0.0, 0.0, 0.01], [0.0, 0.0, -0.01]],
        charge_values=[1e-9, 1e-9],
        fields={"magnetic": (1.0, 0.5)},
        medium=medium,
    )


def test_custom_breakdown_medium_round_trips_and_drags_its_gas(tmp_path):
    medium = scene_from_dict({"medium": {"breakdown": 2e6, "gas": "air"}}).medium
    assert medium == Medium("custom", 2e6, 0.5, gas="air")
    design = _design(medium)
    path = tmp_path / "design.json"
    write_design(design, path)
    assert json.loads(path.read_text())["medium"] == {
        "name": "custom",
        "breakdown_V_per_m": 2e6,
        "safety": 0.5,
        "gas": "air",
    }
    back = read_design(path)
    assert back.medium == medium
    drag = realism_budget(back)["drag_torque_fraction"]
    assert drag["value"] > 0  # air's viscosity, not vacuum's zero
    air = realism_budget(_design(Medium("air", 3e6)))["drag_torque_fraction"]
    assert drag["value"] == pytest.approx(air["value"])
    assert "air" in drag["note"]


def test_custom_medium_without_gas_says_it_has_none():
    medium = scene_from_dict({"medium": {"breakdown": 2e6}}).medium
    assert medium.gas_properties is None
    drag = realism_budget(_design(medium))["drag_torque_fraction"]
    assert drag["value"] is None
    assert drag["verdict"] == "not estimated"
    assert "names no gas" in drag["note"]


def test_old_design_json_medium_stays_readable():
    design = Design.from_dict(
        {
            "parameters": {"C": 1.0},
            "medium": {"name": "air", "breakdown_V_per_m": 3e6, "safety": 0.5},
        }
    )
    assert design.medium == Medium("air", 3e6, 0.5)
    assert design.medium.breakdown == 3e6
    assert "gas" not in design.to_dict()["medium"]


def test_unknown_gas_is_refused():
    with pytest.raises(InputError, match=r"^medium\.gas: "):
        validated(scene_from_dict({"medium": {"breakdown": 2e6, "gas": "helium"}}))


def test_load_scene_parses_every_table_at_load(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text('[parameters]\nn = 0.5\n\n[output]\nfolder = "x"\n', encoding="utf-8")
    with pytest.raises(InputError, match=r"^output\.folder: "):
        load_scene(path)


def test_the_monitor_names_the_scene_accepts_are_the_registry() -> None:
    """``[simulation] monitors`` is parsed with the vocabulary's names, the registry holds one
    monitor per name, in the same order (the error message lists them)."""
    assert tuple(MONITORS) == MONITOR_NAMES
    assert set(MONITOR_ALIASES.values()) <= set(MONITOR_NAMES)
