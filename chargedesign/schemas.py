"""JSON Schemas of design.json and of scene files, built from the vocabulary (one source).

:func:`schema` returns a schema as a mapping; ``chargedesign schema design|scene`` prints it;
the package ships the same text as ``chargedesign/data/schemas/<name>.schema.json`` for tools
that do not run Python (a test keeps the files equal to :func:`schema`).

The schemas describe the files; the validator (:mod:`chargedesign.validation` and the
stages that read each table) remains the judge of a file's meaning (e.g. array lengths that
must agree). Tables that other parts of the program are still growing are left open
(``additionalProperties: true``): ``[simulation]``, ``[initial]``, ``[output]``, ``[design]``,
``[body]``, ``[medium]``, ``[carriers]``, ``[magnets]``, ``[ballast]`` and the
top level of design.json (further keys are welcome there by the contract). The element blocks
of design.json and ``[parameters]`` are closed, as the readers refuse unknown keys there.
"""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

from chargedesign.airbearing.options import table_schema as testbed_table_schema
from chargedesign.airbearing.schema import output_schema as testbed_output_schema
from chargedesign.vocabulary import (
    BODY_SHAPES,
    DESIGN_FORMAT,
    EFFECTS,
    FIELD_KINDS,
    LARMOR_READINGS,
    MATERIAL_ERROR_KEYS,
    OBJECTIVES,
    PARAMETER_NAMES,
    REALISABLE,
    SCENE_TABLES,
    SIMULATION_AXES,
    SOURCES,
    STATE_NAMES,
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
    props: dict[str, Any] = {name: dict(_NUMBER) for name in PARAMETER_NAMES}
    props["C"] = {**_POSITIVE, "description": "moment of inertia about the symmetry axis, kg m^2"}
    return {
        "type": "object",
        "description": "the theorem's parameters (SI units); omitted ones are 0, C is 1",
        "properties": props,
        "additionalProperties": False,
    }


def _medium(scene: bool = False) -> dict[str, Any]:
    """The medium: a scene's ``[medium]`` names it or gives ``breakdown`` (what
    physical/spec.py reads); design.json records ``breakdown_V_per_m`` (what body.py reads)."""
    breakdown = "breakdown" if scene else "breakdown_V_per_m"
    out: dict[str, Any] = {
        "type": "object",
        "description": "what surrounds the body; surface fields stay <= safety * breakdown",
        "properties": {
            "name": {"type": "string", "description": "vacuum, air, sf6, oil, ..."},
            breakdown: _POSITIVE,
            "safety": {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
        },
        "additionalProperties": False,
    }
    if not scene:
        out["required"] = ["name", "breakdown_V_per_m", "safety"]
    return out


def _materials() -> dict[str, Any]:
    material = {
        "type": "object",
        "properties": {
            "name": {"type": "string"},
            "remanent_magnetisation_A_per_m": _POSITIVE,
            "density_kg_per_m3": _POSITIVE,
            "intrinsic_coercivity_A_per_m": _POSITIVE,
            "volume_susceptibility": {"type": "number", "exclusiveMinimum": -1},
            "conductivity_S_per_m": {"type": "number", "minimum": 0},
        },
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


def design_schema() -> dict[str, Any]:
    """The schema of design.json (format ``chargedesign.designer/1``)."""
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
        "properties": {
            "a1": _NUMBER,
            "a2": _NUMBER,
            "legendre": _NUMBERS,
            "max": {**_POSITIVE, "description": "largest |field| over the body"},
        },
        "not": {"anyOf": [{"required": ["legendre", "a1"]}, {"required": ["legendre", "a2"]}]},
        "additionalProperties": False,
    }


def _open(description: str, properties: dict[str, Any] | None = None) -> dict[str, Any]:
    return {
        "type": "object",
        "description": description,
        "properties": properties or {},
        "additionalProperties": True,
    }


def scene_schema() -> dict[str, Any]:
    """The schema of a scene file (TOML, as the mapping it parses to)."""
    tables: dict[str, Any] = {
        "parameters": _parameters(),
        "fields": {
            "type": "object",
            "properties": {kind: _field_table() for kind in FIELD_KINDS},
            "additionalProperties": False,
        },
        "body": _open(
            "where elements may be placed (a region with shape), or the body to simulate "
            "(design = path, or inline charges/masses/dipoles)",
            {
                "shape": {"enum": list(BODY_SHAPES)},
                "radius": _POSITIVE,
                "height": _POSITIVE,
                "spacing": _POSITIVE,
                "n_points": {"type": "integer", "minimum": 1},
                "half_size": {"anyOf": [_POSITIVE, _VECTOR]},
                "size": {"anyOf": [_POSITIVE, _VECTOR]},
                "center": _VECTOR,
                "symmetric": {"type": "boolean"},
                "path": {"type": "string"},
                "scale": _POSITIVE,
                "design": {"type": "string"},
            },
        ),
        "design": _open(
            "design options (docs/design.md)",
            {
                "realise": {
                    "type": "array",
                    "items": {"enum": list(REALISABLE)},
                    "uniqueItems": True,
                },
                "objective": {"enum": list(OBJECTIVES)},
                "objectives": {
                    "type": "object",
                    "propertyNames": {"enum": list(SOURCES)},
                    "additionalProperties": {"enum": list(OBJECTIVES)},
                },
                "sparsity": {"enum": ["auto", "reweighted", "mip"]},
                "column_generation": {"type": "boolean"},
                "tol": _POSITIVE,
                "time_limit": _POSITIVE,
                "solver": {"type": "string"},
                "n_charges": {"type": "integer", "minimum": 1},
                "max_charge": _POSITIVE,
                "total_charge": _NUMBER,
                "total_mass": _NONNEG,
                "polish": {"type": "boolean"},
                "robust_weight": {"type": "number", "minimum": 0, "maximum": 1},
                "larmor": {
                    "enum": list(LARMOR_READINGS),
                    "description": "how n is realised: charges (the paper's (p6) second "
                    "moments) or frame (the body realises n = 0, read in axes turning at n); "
                    "default charges without [medium], frame with it",
                },
            },
        ),
        "simulation": _open(
            "integration options (docs/simulate.md); open: more keys are being added",
            {
                "effects": {"type": "array", "items": {"enum": list(EFFECTS)}},
                "t_end": _POSITIVE,
                "rtol": _POSITIVE,
                "atol": _POSITIVE,
                "method": {"type": "string"},
                "samples": {"type": "integer", "minimum": 2},
                "max_step": _POSITIVE,
                "step": _POSITIVE,
                "route": {"type": "string"},
                "gamma3_min": _NONNEG,
                "axes": {"enum": list(SIMULATION_AXES)},
            },
        ),
        "initial": _open(
            "initial state: omega and gamma, or level with gamma, p and q",
            {
                "omega": _VECTOR,
                "gamma": _VECTOR,
                "level": {"anyOf": [{"type": "string"}, _NUMBER]},
                "p": _NUMBER,
                "q": _NUMBER,
                "precession": _NUMBER,
            },
        ),
        "output": _open(
            "what a simulation writes",
            {"poincare_section": {"enum": list(STATE_NAMES)}},
        ),
        "medium": _medium(scene=True),
        "carriers": _open("the charge carriers (sizes, material)"),
        "magnets": _open("the magnets (sizes, material)"),
        "ballast": _open("the ballast masses (sizes, material or a list of materials)"),
        "tolerance": {
            "type": "object",
            "description": "the materials' relative property errors (one standard deviation, "
            "one draw per material) that tolerance analyses",
            "properties": {
                key: {"type": "number", "minimum": 0, "exclusiveMaximum": 1}
                for key in MATERIAL_ERROR_KEYS
            },
            "additionalProperties": False,
        },
        "testbed": testbed_table_schema(),
    }
    assert set(tables) == set(SCENE_TABLES)  # one list of tables: the vocabulary's
    return {
        "$schema": DRAFT,
        "$id": "chargedesign/schemas/scene.schema.json",
        "title": "chargedesign scene (TOML)",
        "description": "A scene: the theorem's parameters, the fields, where the body may be "
        "and what each stage should do. Every table is optional.",
        "type": "object",
        "properties": tables,
        "additionalProperties": False,
    }


def schema(name: str) -> dict[str, Any]:
    """The JSON Schema ``design`` (design.json), ``scene`` (scene files) or ``testbed``
    (testbed.json).

    Returns
    -------
    dict
        A JSON Schema (draft 2020-12).
    """
    from chargedesign.validation import input_error

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

    from chargedesign.errors import InputError

    validator = jsonschema.Draft202012Validator(schema(name))
    errors = sorted(validator.iter_errors(instance), key=lambda e: list(e.absolute_path))
    if errors:
        error = errors[0]
        where = ".".join(str(p) for p in error.absolute_path) or "(top level)"
        raise InputError(f"{name} schema: {where}: {error.message}")


__all__ = [
    "NAMES",
    "design_schema",
    "scene_schema",
    "schema",
    "schema_text",
    "shipped_schema_text",
    "validate",
]
