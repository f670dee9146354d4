"""The keys of every scene table, declared once: the validators refuse what is not listed
here and the JSON Schema (:mod:`chargedesign.schemas`) is generated from the same lists, so
the two cannot drift.

Each table is a tuple of :class:`Key` (name, JSON Schema of its value, one-line doc). The
order is the order the one-line errors list the keys in ("one of t_end, rtol, ...").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from chargedesign.validation import check_keys, input_error
from chargedesign.vocabulary import (
    BODY_SHAPES,
    EFFECTS,
    LARMOR_READINGS,
    MATERIAL_ERROR_KEYS,
    OBJECTIVES,
    REALISABLE,
    SIMULATION_AXES,
    SOURCES,
    STATE_NAMES,
)

NUMBER: dict[str, Any] = {"type": "number"}
NONNEG: dict[str, Any] = {"type": "number", "minimum": 0}
POSITIVE: dict[str, Any] = {"type": "number", "exclusiveMinimum": 0}
VECTOR: dict[str, Any] = {"type": "array", "items": NUMBER, "minItems": 3, "maxItems": 3}
POINTS: dict[str, Any] = {"type": "array", "items": VECTOR}
NUMBERS: dict[str, Any] = {"type": "array", "items": NUMBER}
BOOLEAN: dict[str, Any] = {"type": "boolean"}
STRING: dict[str, Any] = {"type": "string"}
TEXT_OR_NUMBER: dict[str, Any] = {"anyOf": [STRING, NUMBER]}


@dataclass(frozen=True)
class Key:
    """One key of a scene table: its name, the JSON Schema of its value and what it means."""

    name: str
    schema: Mapping[str, Any] = field(default_factory=dict)
    doc: str = ""

    def json_schema(self) -> dict[str, Any]:
        out = dict(self.schema)
        if self.doc:
            out["description"] = self.doc
        return out


def _enum(values: tuple[str, ...]) -> dict[str, Any]:
    return {"enum": list(values)}


_RESPONSE = (
    Key("susceptibility", {"type": "number", "exclusiveMinimum": -1}, "SI volume susceptibility"),
    Key("conductivity", NONNEG, "S/m"),
)
_MATERIAL_NAME = Key("material", STRING, "a named material (docs/buildable.md)")

MEDIUM = (
    Key("name", STRING, "vacuum, air, sf6, oil, or any name with breakdown"),
    Key("breakdown", POSITIVE, "breakdown field, V/m (replaces the named medium's)"),
    Key("safety", {"type": "number", "exclusiveMinimum": 0, "maximum": 1}, "default 0.5"),
    Key(
        "gas",
        _enum(("vacuum", "air", "sf6", "oil")),
        "whose density and viscosity the drag estimate uses (default: the name's, if it names one)",
    ),
)
CARRIERS = (
    _MATERIAL_NAME,
    Key("density", POSITIVE, "kg/m^3"),
    Key("shell_thickness", NONNEG, "m; 0 = solid"),
    Key(
        "samples",
        {"type": "integer", "minimum": 6, "maximum": 2000},
        "surface points per carrier in the design",
    ),
    *_RESPONSE,
)
MAGNETS = (
    _MATERIAL_NAME,
    Key("density", POSITIVE, "kg/m^3"),
    Key("magnetisation", POSITIVE, "remanent magnetisation, A/m"),
    Key("coercivity", POSITIVE, "intrinsic coercivity, A/m"),
    *_RESPONSE,
)
BALLAST = (
    Key(
        "material",
        {"anyOf": [STRING, {"type": "array", "items": STRING, "minItems": 1}]},
        "a material, or a list of materials of opposite susceptibilities",
    ),
    Key("density", POSITIVE, "kg/m^3"),
    *_RESPONSE,
)
TOLERANCE = tuple(
    Key(name, {"type": "number", "minimum": 0, "exclusiveMaximum": 1}, "relative error")
    for name in MATERIAL_ERROR_KEYS
)
DESIGN = (
    Key("objective", _enum(OBJECTIVES)),
    Key("solver", STRING, "auto or a cvxpy solver name"),
    Key("max_charge", POSITIVE, "C"),
    Key("total_charge", NUMBER, "C"),
    Key("n_charges", {"type": "integer", "minimum": 1}),
    Key("total_mass", POSITIVE, "kg"),
    Key("realise", {"type": "array", "items": _enum(REALISABLE), "uniqueItems": True}),
    Key("polish", BOOLEAN),
    Key("tol", {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1}),
    Key(
        "objectives",
        {
            "type": "object",
            "properties": {source: _enum(OBJECTIVES) for source in SOURCES},
            "additionalProperties": False,
        },
        "the objective per source",
    ),
    Key("column_generation", BOOLEAN),
    Key("sparsity", _enum(("auto", "reweighted", "mip"))),
    Key("time_limit", POSITIVE, "s"),
    Key("robust_weight", {"type": "number", "minimum": 0, "maximum": 1}),
    Key(
        "larmor",
        _enum(LARMOR_READINGS),
        "how n is realised: charges (the paper's (p6) second moments) or frame (the body "
        "realises n = 0, read in axes turning at n); default charges without [medium], frame "
        "with it",
    ),
)
SIMULATION = (
    Key("t_end", POSITIVE),
    Key("rtol", POSITIVE),
    Key("atol", POSITIVE),
    Key("method", STRING),
    Key("effects", {"type": "array", "items": _enum(EFFECTS)}),
    Key("max_step", POSITIVE),
    Key("step", POSITIVE),
    Key("samples", {"type": "integer", "minimum": 2}),
    Key("route", STRING),
    Key("gamma3_min", POSITIVE),
    Key("tol", POSITIVE, "tolerance of the taylor method"),
    Key("monitors", {"type": "array", "items": STRING}),
    Key("axes", _enum(SIMULATION_AXES)),
)
INITIAL = (
    Key("omega", VECTOR),
    Key("gamma", VECTOR),
    Key("level", TEXT_OR_NUMBER, "e.g. 'I3=0'"),
    Key("p", NUMBER),
    Key("q", NUMBER),
    Key("precession", NUMBER),
    Key("states", {"type": "array", "items": {**NUMBERS, "minItems": 6, "maxItems": 6}}),
    Key("file", STRING, "a .csv or .npy file of states"),
)
OUTPUT = (
    Key("dir", STRING, "a relative folder without '..'"),
    Key("trajectory", BOOLEAN),
    Key("plot", BOOLEAN),
    Key("poincare", BOOLEAN),
    Key("poincare_section", _enum(STATE_NAMES)),
    Key(
        "poincare_axes",
        {"type": "array", "items": _enum(STATE_NAMES), "minItems": 2, "maxItems": 2},
    ),
)
_SIZE = {"anyOf": [POSITIVE, VECTOR]}
#: a [body] region's keys (besides shape), by shape
REGION_KEYS: dict[str, tuple[str, ...]] = {
    "ball": ("radius", "spacing", "center", "symmetric"),
    "box": ("half_size", "size", "spacing", "center", "symmetric"),
    "cylinder": ("radius", "height", "spacing", "center", "symmetric"),
    "shell": ("radius", "n_points", "center", "symmetric"),
    "points": ("path", "scale", "center", "symmetric"),
    "mesh": ("path", "sample", "spacing", "scale", "center", "symmetric"),
}
_BLOCK = {"type": "object", "additionalProperties": False}
BODY = (
    Key("shape", _enum(BODY_SHAPES), "a region to design in"),
    Key("radius", POSITIVE, "m"),
    Key("height", POSITIVE, "m"),
    Key("spacing", POSITIVE, "m"),
    Key("n_points", {"type": "integer", "minimum": 1}),
    Key("half_size", _SIZE, "m"),
    Key("size", _SIZE, "m"),
    Key("center", VECTOR, "m"),
    Key("symmetric", BOOLEAN),
    Key("path", STRING),
    Key("scale", POSITIVE),
    Key("sample", _enum(("surface", "volume"))),
    Key("carrier_radius", POSITIVE, "m (physical parts)"),
    Key("design", STRING, "a design.json to simulate"),
    Key("charges", {**_BLOCK, "properties": {"positions": POINTS, "values": NUMBERS}}),
    Key("masses", {**_BLOCK, "properties": {"positions": POINTS, "values": NUMBERS}}),
    Key("dipoles", {**_BLOCK, "properties": {"positions": POINTS, "moments": POINTS}}),
)
#: the keys of a [body] that names the body to simulate (a design reference or inline elements)
BODY_REFERENCE_KEYS = ("design", "charges", "masses", "dipoles")

#: every table with a flat key list (parameters and fields have their own shapes)
TABLE_KEYS: dict[str, tuple[Key, ...]] = {
    "body": BODY,
    "design": DESIGN,
    "simulation": SIMULATION,
    "initial": INITIAL,
    "output": OUTPUT,
    "medium": MEDIUM,
    "carriers": CARRIERS,
    "magnets": MAGNETS,
    "ballast": BALLAST,
    "tolerance": TOLERANCE,
}


def key_names(table: str) -> tuple[str, ...]:
    """The names of a table's keys, in their declared order."""
    return tuple(key.name for key in TABLE_KEYS[table])


def check_table(table: Any, name: str, where: str | None = None) -> Mapping[str, Any]:
    """``table`` as a mapping whose keys are all ``name``'s (one-line error naming the
    first unknown key)."""
    where = where or name
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, key_names(name), where)
    return table


def table_schema(name: str, description: str) -> dict[str, Any]:
    """The closed JSON Schema of a table, generated from its key list."""
    return {
        "type": "object",
        "description": description,
        "properties": {key.name: key.json_schema() for key in TABLE_KEYS[name]},
        "additionalProperties": False,
    }
