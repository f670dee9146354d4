"""Each scene key declared once: its default is what the typed options hold when the key is
absent, the validator accepts it, it obeys the key's own JSON Schema, and the docs' words for
a schema say what the schema says."""

from __future__ import annotations

import math

import jsonschema
import pytest

from chargedesign.cli import build_parser
from chargedesign.errors import InputError
from chargedesign.limits import OPTION_RANGES
from chargedesign.scene import scene_from_dict, validated
from chargedesign.scene.design import DesignOptions
from chargedesign.scene.keys import (
    DECLARED,
    NO_DEFAULT,
    Key,
    check_value,
    declared,
    default_of,
)
from chargedesign.scene.medium import DEFAULT_SAFETY
from chargedesign.scene.physical import DEFAULT_SHELL_THICKNESS, DEFAULT_SURFACE_SAMPLES
from chargedesign.scene.simulation import OutputOptions, SimulationOptions
from chargedesign.schemas import value_text
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS

#: the typed options of each table whose defaults are read from the declarations
TYPED = {"design": DesignOptions, "simulation": SimulationOptions, "output": OutputOptions}


def _all_keys() -> list[tuple[str, Key]]:
    return [(table, key) for table, keys in DECLARED.items() for key in keys]


@pytest.mark.parametrize(("table", "key"), _all_keys(), ids=lambda x: getattr(x, "name", x))
def test_every_key_has_a_one_line_doc_and_a_default_its_schema_accepts(table: str, key: Key):
    assert key.doc and "\n" not in key.doc
    if key.has_default:
        value = list(key.default) if isinstance(key.default, tuple) else key.default
        jsonschema.validate(value, key.schema)
    else:
        assert key.default is NO_DEFAULT


@pytest.mark.parametrize("table", sorted(TYPED))
def test_the_typed_options_hold_the_declared_defaults(table: str):
    options = TYPED[table]()
    for key in DECLARED[table]:
        if key.has_default:
            assert getattr(options, key.name) == key.default, key.name


@pytest.mark.parametrize(
    "table", ["design", "simulation", "output", "medium", "carriers", "tolerance", "parameters"]
)
def test_a_key_given_its_declared_default_reads_as_the_key_left_out(table: str):
    """The validator accepts every default, and the scene it gives is the scene without it
    (read through the scene's own parser, not the declarations)."""
    given = {key.name: key.default for key in DECLARED[table] if key.has_default}
    given = {k: list(v) if isinstance(v, tuple) else v for k, v in given.items()}
    base = {"medium": {"name": "air"}}
    plain = validated(scene_from_dict({**base, table: {**base.get(table, {})}}))
    full = validated(scene_from_dict({**base, table: {**base.get(table, {}), **given}}))
    if table in TYPED:
        assert getattr(plain, table) == getattr(full, table)
    elif table == "parameters":
        assert plain.parameters == full.parameters
    else:
        assert plain.physical == full.physical


def test_the_owners_constants_are_the_declared_defaults():
    assert DEFAULT_SAFETY == default_of("medium", "safety") == 0.5
    assert DEFAULT_SHELL_THICKNESS == default_of("carriers", "shell_thickness")
    assert DEFAULT_SURFACE_SAMPLES == default_of("carriers", "samples")
    assert math.isinf(SimulationOptions().max_step)  # unbounded: no JSON default declared
    assert not declared("simulation", "max_step").has_default


@pytest.mark.parametrize(
    ("spec", "words", "inside", "outside"),
    [
        ({"type": "number", "exclusiveMinimum": 0}, "number > 0", 1e-9, 0.0),
        ({"type": "number", "minimum": 0, "exclusiveMaximum": 1}, "number in [0, 1)", 0.0, 1.0),
        ({"type": "number", "exclusiveMinimum": 0, "maximum": 1}, "number in (0, 1]", 1.0, 0.0),
        ({"type": "integer", "minimum": 2}, "integer >= 2", 2, 1),
        ({"enum": ["a", "b"]}, "`a` \\| `b`", "b", "c"),
    ],
)
def test_the_docs_words_for_a_range_are_the_schema_s(spec, words, inside, outside):
    assert value_text(spec) == words
    jsonschema.validate(inside, spec)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(outside, spec)


@pytest.mark.parametrize("key", ["name", "gas"])
@pytest.mark.parametrize("value", [["x"], [], {"a": 1}])
def test_a_medium_name_or_gas_that_is_no_text_is_one_line(key: str, value):
    """A list or table where a medium's name or gas belongs was a TypeError traceback (found by
    tools/scene_verdicts.py); it is the one-line error a wrong name gets."""
    with pytest.raises(InputError, match=rf"^medium\.{key}: expected one of air, sf6, oil, vacuum"):
        validated(scene_from_dict({"medium": {"name": "air", key: value}}))


#: command-line options that set a scene key: (command, option dest) -> (table, key)
SCENE_OPTIONS = {
    ("design", "n_charges"): ("design", "n_charges"),
    ("design", "max_charge"): ("design", "max_charge"),
    ("design", "total_charge"): ("design", "total_charge"),
    ("design", "total_mass"): ("design", "total_mass"),
    ("simulate", "t_end"): ("simulation", "t_end"),
    ("simulate", "tol"): ("simulation", "tol"),
    ("simulate", "rtol"): ("simulation", "rtol"),
    ("simulate", "atol"): ("simulation", "atol"),
    ("simulate", "step"): ("simulation", "step"),
    ("simulate", "samples"): ("simulation", "samples"),
    **{("tolerance", name): ("tolerance", name) for name in MATERIAL_ERROR_KEYS},
}


@pytest.mark.parametrize(("option", "key"), sorted(SCENE_OPTIONS.items()))
def test_an_option_that_sets_a_scene_key_stays_within_the_key_s_range(option, key):
    """The command line's range of such an option (chargedesign.limits.OPTION_RANGES, which
    cli.py checks and prints in --help) lies inside the key's declared range: the option never
    accepts what the scene would refuse. It may be narrower (a cap on work)."""
    bounds = OPTION_RANGES[option[0]][option[1]]
    spec = declared(*key).schema
    integer = spec.get("type") == "integer"
    step = 1 if integer else 1e-12 * max(1.0, abs(bounds.hi - bounds.lo))
    lo = bounds.lo + step if bounds.lo_open else bounds.lo
    hi = bounds.hi - step if bounds.hi_open else bounds.hi
    for value in (lo, hi):
        value = int(value) if integer else float(value)
        assert bounds.holds(value)
        check_value(*key, value)  # raises if the scene would refuse it


def test_an_option_s_help_is_its_key_s_declaration():
    commands = build_parser()._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    for (command, dest), key in SCENE_OPTIONS.items():
        helps = {a.dest: a.help for a in commands[command]._actions}
        assert helps[dest].startswith(declared(*key).doc), (command, dest)
