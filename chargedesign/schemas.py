"""JSON Schemas of design.json and of scene files, built from the vocabulary (one source).

:func:`schema` returns a schema as a mapping; ``chargedesign schema design|scene`` prints it;
the package ships the same text as ``chargedesign/data/schemas/<name>.schema.json`` for tools
that do not run Python (a test keeps the files equal to :func:`schema`).

The schemas describe the files; the validator (:mod:`chargedesign.scene`) remains the judge
of a file's meaning (e.g. array lengths that must agree, keys that depend on a body's shape).
Every scene table is closed (``additionalProperties: false``) and generated from the key
lists the validators use (:mod:`chargedesign.scene.keys`), so the two cannot drift. The top
level of design.json stays open (further keys are welcome there by the contract); its element
blocks and ``medium`` are closed, as the readers refuse unknown keys there.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from importlib import resources
from typing import Any

from chargedesign.airbearing.schema import output_schema as testbed_output_schema
from chargedesign.errors import InputError
from chargedesign.physical.materials import GAS_PROPERTIES
from chargedesign.scene.design_materials import MATERIAL_KEYS
from chargedesign.scene.design_realism import MAP_KEY, PART_SIZES_KEY, WINDOW_KEY
from chargedesign.scene.keys import (
    BODY_REFERENCE_KEYS,
    DECLARED,
    FIELD,
    PARAMETERS,
    REGION_KEYS,
    TABLE_KEYS,
    Key,
    range_words,
    table_schema,
)
from chargedesign.validation import input_error
from chargedesign.vocabulary import (
    DESIGN_FORMAT,
    FIELD_KINDS,
    LARMOR_READINGS,
    PARAMETER_NAMES,
    REALISABLE,
    SCENE_TABLES,
    SUPPORT_STATES,
    VERDICT_STATES,
)

DRAFT = "https://json-schema.org/draft/2020-12/schema"
NAMES = ("design", "scene", "testbed")

_NUMBER = {"type": "number"}
_NONNEG = {"type": "number", "minimum": 0}
_POSITIVE = {"type": "number", "exclusiveMinimum": 0}
_VECTOR = {"type": "array", "items": _NUMBER, "minItems": 3, "maxItems": 3}
_POINTS = {"type": "array", "items": _VECTOR}
_NUMBERS = {"type": "array", "items": _NUMBER}
_NONNEGS = {"type": "array", "items": _NONNEG}


def _parameters() -> dict[str, Any]:
    props: dict[str, Any] = {key.name: key.json_schema() for key in PARAMETERS}
    assert tuple(props) == PARAMETER_NAMES
    return {
        "type": "object",
        "description": "the theorem's parameters (SI units); omitted ones are 0, C is 1",
        "properties": props,
        "additionalProperties": False,
    }


def _medium() -> dict[str, Any]:
    """design.json's ``medium`` (what :meth:`chargedesign.scene.Medium.to_dict` writes)."""
    return {
        "type": "object",
        "description": "what surrounds the body; surface fields stay <= safety * breakdown",
        "properties": {
            "name": {"type": "string", "description": "vacuum, air, sf6, oil, ..."},
            "breakdown_V_per_m": _POSITIVE,
            "safety": {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
            "gas": {
                "enum": list(GAS_PROPERTIES),
                "description": "whose density and viscosity the drag estimate uses",
            },
        },
        "required": ["name", "breakdown_V_per_m", "safety"],
        "additionalProperties": False,
    }


def _materials() -> dict[str, Any]:
    material = {
        "type": "object",
        "properties": {key.name: key.json_schema() for key in MATERIAL_KEYS},
        "additionalProperties": True,
    }
    return {
        "type": "object",
        "description": "materials by role (magnet, carrier, ballast, ...); ballast may be a "
        "list of materials (then masses.material names each ballast part's)",
        "properties": {
            "ballast": {"oneOf": [material, {"type": "array", "items": material, "minItems": 1}]}
        },
        "additionalProperties": material,
    }


def _realism() -> dict[str, Any]:
    """design.json's ``realism``: the budget's items and the report's figure blocks
    (:mod:`chargedesign.scene.design_realism`); open, as the budget grows."""
    span = {
        "type": "object",
        "properties": {
            "count": {"type": "integer", "minimum": 1},
            "smallest_m": _NUMBER,
            "largest_m": _NUMBER,
        },
    }
    return {
        "type": "object",
        "description": "the realism budget: items (value, unit, verdict, note) and the figures "
        "the report prints",
        "properties": {
            PART_SIZES_KEY: {
                "type": "object",
                "description": "carriers' and ballast spheres' radii, magnets' cube edges "
                "against their continuum size, m",
                "properties": {"carriers": span, "ballast": span, "magnets": {"type": "object"}},
            },
            MAP_KEY: {
                "type": "array",
                "description": "each term of V and mu: its mechanisms, this body's, its size "
                "(N m; null: unbounded) and the parasitics over it",
                "items": {"type": "object", "required": ["key", "where", "term", "size_N_m"]},
            },
            WINDOW_KEY: {
                "type": ["object", "null"],
                "description": "the realised window's items at the design's rate over the "
                "fraction (null: not buildable)",
                "required": ["fraction", "term_key", "items"],
                "properties": {
                    "fraction": _NUMBER,
                    "term_key": {"type": "string"},
                    "items": {
                        "type": "array",
                        "items": {
                            "type": "object",
                            "required": ["key", "label", "over_fraction"],
                        },
                    },
                    "apparatus": {"type": ["object", "null"]},
                    "apparatus_summary": {"type": ["string", "null"]},
                    "support": {"type": ["object", "null"]},
                },
            },
        },
        "additionalProperties": True,
    }


def _verdict() -> dict[str, Any]:
    """design.json's ``verdict``: judged once when the design is accepted
    (:mod:`chargedesign.verdict`; CONTRACT.md "The verdict record")."""
    item = {
        "type": "object",
        "required": ["name", "value", "limit", "unit", "met"],
        "properties": {
            "name": {"type": "string"},
            "unit": {"type": "string"},
            "met": {"type": "boolean"},
            "source": {"type": "string"},
            "checked": {"type": "boolean"},
        },
    }
    return {
        "type": "object",
        "description": "the verdict, judged once when the design is accepted; every output "
        "renders it",
        "required": ["state", "binding", "factor", "change", "support", "items"],
        "properties": {
            "state": {"enum": list(VERDICT_STATES)},
            "binding": {"type": "string"},
            "factor": {"type": ["number", "null"]},
            "change": {"type": "string"},
            "support": {
                "type": "object",
                "required": ["style", "state"],
                "properties": {
                    "style": {"type": ["string", "null"]},
                    "state": {"enum": list(SUPPORT_STATES)},
                },
            },
            "items": {"type": "array", "items": item},
            "rows": {"type": "array", "items": {"type": "object"}},
        },
        "additionalProperties": True,
    }


def design_schema() -> dict[str, Any]:
    """The schema of design.json (format ``chargedesign.design/1``)."""
    legendre_field = {
        "type": "object",
        "required": ["legendre"],
        "properties": {"legendre": _NUMBERS},
        "additionalProperties": False,
    }
    return {
        "$schema": DRAFT,
        "$id": "chargedesign/schemas/design.schema.json",
        "title": f"design.json ({DESIGN_FORMAT})",
        "description": "A designed body: charges on carriers, magnets and ballast masses in "
        "body axes (SI units), its target parameters and fields. Further keys (provenance, "
        "residuals, solver, timings, units, ...) are welcome.",
        "type": "object",
        "required": ["parameters"],
        "properties": {
            "format": {"const": DESIGN_FORMAT},
            "parameters": _parameters(),
            "fields": {
                "type": "object",
                "propertyNames": {"enum": list(FIELD_KINDS)},
                "additionalProperties": legendre_field,
            },
            "charges": {
                "type": "object",
                "properties": {
                    "positions": _POINTS,
                    "values": _NUMBERS,
                    "radii": {**_NONNEGS, "description": "carrier sphere radii, m"},
                    "masses": {**_NONNEGS, "description": "carrier masses, kg"},
                },
                "additionalProperties": False,
            },
            "dipoles": {
                "type": "object",
                "properties": {
                    "positions": _POINTS,
                    "moments": {**_POINTS, "description": "magnetic moments, A m^2"},
                    "volumes": {**_NONNEGS, "description": "magnet volumes, m^3"},
                    "masses": {**_NONNEGS, "description": "magnet masses, kg"},
                },
                "additionalProperties": False,
            },
            "masses": {
                "type": "object",
                "description": "the ballast",
                "properties": {
                    "positions": _POINTS,
                    "values": _NONNEGS,
                    "material": {
                        "type": "array",
                        "items": {"type": "string"},
                        "description": "each part's ballast material (several materials)",
                    },
                },
                "additionalProperties": False,
            },
            "realises": {
                "type": "array",
                "items": {"enum": list(REALISABLE)},
                "uniqueItems": True,
            },
            "continuous": {"type": "array", "items": {"type": "object"}},
            "medium": _medium(),
            "materials": _materials(),
            "realism": _realism(),
            "verdict": _verdict(),
            "larmor": {
                "type": "object",
                "description": "how the body realises n: charges (the paper's (p6) reading) "
                "or frame (the elements realise n = 0; the motion is read in axes turning at "
                "rate about Z); absent means charges",
                "required": ["reading", "rate"],
                "properties": {
                    "reading": {"enum": list(LARMOR_READINGS)},
                    "rate": {**_NUMBER, "description": "the theorem's n, 1/s"},
                },
                "additionalProperties": False,
            },
        },
        "additionalProperties": True,
    }


def _field_table() -> dict[str, Any]:
    return {
        "type": "object",
        "description": "the paper's a1/a2 (Phi = a1 Z + a2 (3 Z^2 - R^2)) or legendre = [...]",
        "properties": {key.name: key.json_schema() for key in FIELD},
        "not": {"anyOf": [{"required": ["legendre", "a1"]}, {"required": ["legendre", "a2"]}]},
        "additionalProperties": False,
    }


_TABLE_DESCRIPTIONS = {
    "body": "where elements may be placed (a region with shape and its sizes), or the body to "
    "simulate (design = path, or inline charges/masses/dipoles)",
    "design": "design options (docs/design.md)",
    "simulation": "integration options (docs/simulate.md)",
    "initial": "initial state: omega and gamma, or level with gamma, p and q, or states / file",
    "output": "what a simulation writes",
    "medium": "what surrounds the body; surface fields stay <= safety * breakdown",
    "carriers": "the charge carriers (material or density, wall, surface samples)",
    "magnets": "the magnets (material, or magnetisation and density; coercivity)",
    "ballast": "the ballast masses (material or a list of materials, or density)",
    "holder": "the holder: a sphere about O with a bore for each part (its material)",
    "tolerance": "the materials' relative property errors (one standard deviation, one draw "
    "per material) that tolerance analyses",
    "case": "any case of (ep) with its claimed integral, instead of [parameters] "
    "(docs/workbench.md)",
    "testbed": "the air-bearing testbed (docs/testbed.md): platform, ballast, wheels, "
    "sampled loop, sensors, disturbances, requirements",
    "support": "how the body is held: free fall in a drop tower, orbit, an air bearing or an "
    "electrostatic suspension (docs/flight.md)",
}


def scene_schema() -> dict[str, Any]:
    """The schema of a scene file (TOML, as the mapping it parses to): every table closed,
    generated from the key lists the validators use (:mod:`chargedesign.scene.keys`)."""
    tables: dict[str, Any] = {
        "parameters": _parameters(),
        "fields": {
            "type": "object",
            "properties": {kind: _field_table() for kind in FIELD_KINDS},
            "additionalProperties": False,
        },
    }
    for name, description in _TABLE_DESCRIPTIONS.items():
        tables[name] = table_schema(name, description)
    assert set(tables) == set(SCENE_TABLES)  # one list of tables: the vocabulary's
    assert set(TABLE_KEYS) | {"parameters", "fields"} == set(SCENE_TABLES)
    return {
        "$schema": DRAFT,
        "$id": "chargedesign/schemas/scene.schema.json",
        "title": "chargedesign scene (TOML)",
        "description": "A scene: the theorem's parameters, the fields, where the body may be "
        "and what each stage should do. Every table is optional.",
        "type": "object",
        "properties": {name: tables[name] for name in SCENE_TABLES},
        "additionalProperties": False,
    }


def value_text(spec: Mapping[str, Any]) -> str:
    """A key's JSON Schema in words, for the docs' key tables ("number > 0", "[x, y, z]")."""
    if "enum" in spec:
        return " \\| ".join(f"`{v}`" for v in spec["enum"])
    if "anyOf" in spec:
        return " or ".join(value_text(s) for s in spec["anyOf"])
    kind = spec.get("type")
    if kind in ("number", "integer"):
        return range_words(spec, kind)
    if kind == "boolean":
        return "true \\| false"
    if kind == "string":
        return "text"
    if kind == "object":
        return (
            "table of " + ", ".join(spec.get("properties", {})) if "properties" in spec else "table"
        )
    if kind == "array":
        items = spec.get("items", {})
        if spec.get("minItems") == spec.get("maxItems") == 3 and items.get("type") == "number":
            return "[x, y, z]"
        count = spec.get("minItems") if spec.get("minItems") == spec.get("maxItems") else None
        head = f"{count} " if count else ""
        return f"list of {head}{value_text(items) if items else 'values'}"
    return "value"


def default_text(key: Key, *, source: bool = True) -> str:
    """A key's default and its source in words (the docs' tables; the options' help, where
    a default given as a value goes without its source)."""
    value = key.default
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, (tuple, list)):
        text = "[" + ", ".join(str(v) for v in value) + "]"
    elif key.has_default:
        text = f"`{value}`" if isinstance(value, str) else f"{value:g}"
    else:
        text = ""
    if key.source and (source or not text):
        text = f"{text} ({key.source})" if text else key.source
    return text or "-"


def keys_markdown(table: str) -> str:
    """The docs' table of a scene table's keys, generated from their declarations
    (:mod:`chargedesign.scene.keys`); ``[body]`` adds the shapes each key belongs to."""
    body = table == "body"
    head = ["key", *(["shapes"] if body else []), "value", "unit", "default", "meaning"]
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for key in DECLARED[table]:
        row = [f"`{key.name}`"]
        if body:
            shapes = [s for s, names in REGION_KEYS.items() if key.name in names]
            row.append(
                "all"
                if len(shapes) == len(REGION_KEYS) or key.name == "shape"
                else ", ".join(shapes)
                or ("a body to simulate" if key.name in BODY_REFERENCE_KEYS else "regions")
            )
        row += [value_text(key.schema), key.unit or "-", default_text(key), key.doc]
        lines.append(
            "| "
            + " | ".join(cell.replace("|", "\\|") if "\\|" not in cell else cell for cell in row)
            + " |"
        )
    return "\n".join(lines) + "\n"


def schema(name: str) -> dict[str, Any]:
    """The JSON Schema ``design`` (design.json), ``scene`` (scene files) or ``testbed``
    (testbed.json).

    Returns
    -------
    dict
        A JSON Schema (draft 2020-12).
    """
    if name == "design":
        return design_schema()
    if name == "scene":
        return scene_schema()
    if name == "testbed":
        return testbed_output_schema()
    raise input_error("schema", "one of " + ", ".join(NAMES), name)


def schema_text(name: str) -> str:
    """The schema as the JSON text shipped in the package."""
    return json.dumps(schema(name), indent=2) + "\n"


def shipped_schema_text(name: str) -> str:
    """The text of ``chargedesign/data/schemas/<name>.schema.json``."""
    path = resources.files("chargedesign").joinpath(f"data/schemas/{name}.schema.json")
    return path.read_text("utf-8")


def validate(instance: Any, name: str) -> None:
    """Validate ``instance`` against a schema (needs the ``jsonschema`` package).

    Raises
    ------
    InputError
        With the path of the first offending key and the reason.
    """
    import jsonschema

    validator = jsonschema.Draft202012Validator(schema(name))
    errors = sorted(validator.iter_errors(instance), key=lambda e: list(e.absolute_path))
    if errors:
        error = errors[0]
        where = ".".join(str(p) for p in error.absolute_path) or "(top level)"
        raise InputError(f"{name} schema: {where}: {error.message}")


__all__ = [
    "NAMES",
    "default_text",
    "design_schema",
    "keys_markdown",
    "scene_schema",
    "schema",
    "schema_text",
    "shipped_schema_text",
    "validate",
]
