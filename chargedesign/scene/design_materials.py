"""design.json's ``materials`` (the parts' materials by role), read at the boundary: each key
declared once (its JSON Schema and what it means), from which the reader's checks and the
design schema's ``materials`` (:mod:`chargedesign.schemas`) both follow.

A role is ``carrier``, ``magnet`` or ``ballast``; ``ballast`` may be a list of materials,
and then ``masses.material`` names each ballast part's (:func:`check_mass_materials`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from chargedesign.errors import InputError
from chargedesign.scene.keys import NONNEG, POSITIVE, STRING, Key, check_declared
from chargedesign.validation import input_error

ROLES = ("carrier", "magnet", "ballast")
#: the keys of one material, in the order the errors list them
MATERIAL_KEYS = (
    Key("name", STRING, "the material's name"),
    Key("density_kg_per_m3", POSITIVE, "density", "kg/m^3"),
    Key("remanent_magnetisation_A_per_m", POSITIVE, "a magnet's remanent magnetisation", "A/m"),
    Key("intrinsic_coercivity_A_per_m", POSITIVE, "a magnet's intrinsic coercivity", "A/m"),
    Key("shell_thickness_m", POSITIVE, "a hollow carrier's wall", "m"),
    Key(
        "volume_susceptibility",
        {"type": "number", "exclusiveMinimum": -1},
        "SI volume susceptibility",
    ),
    Key("conductivity_S_per_m", NONNEG, "electrical conductivity", "S/m"),
)
_DECLARED = {key.name: key for key in MATERIAL_KEYS}


def materials_from_dict(value: Any) -> dict[str, Any]:
    """design.json ``materials``: role -> {name, density_kg_per_m3, ...} (validated copies)."""
    if not isinstance(value, dict):
        raise input_error("materials", "an object role -> material", value)
    out: dict[str, Any] = {}
    for role, spec in value.items():
        where = f"materials.{role}"
        if role not in ROLES:
            raise input_error("materials", "roles among " + ", ".join(ROLES), role)
        if role == "ballast" and isinstance(spec, list):
            if not spec:
                raise input_error(where, "a material or a non-empty list of materials", spec)
            items = [_material(x, f"{where}[{i}]") for i, x in enumerate(spec)]
            names = [x.get("name") for x in items]
            if None in names or len(set(names)) != len(names):
                raise input_error(where, "materials with distinct names", names)
            out[role] = items
        else:
            out[role] = _material(spec, where)
    if "magnet" in out and "remanent_magnetisation_A_per_m" not in out["magnet"]:
        raise InputError("materials.magnet: missing key 'remanent_magnetisation_A_per_m'")
    return out


def _material(spec: Any, where: str) -> dict[str, Any]:
    """One material (validated copy)."""
    if not isinstance(spec, dict) or "density_kg_per_m3" not in spec:
        raise input_error(where, "an object with density_kg_per_m3", spec)
    clean: dict[str, Any] = {}
    for key, item in spec.items():
        if key not in _DECLARED:
            raise input_error(f"{where}.{key}", "one of " + ", ".join(_DECLARED), key)
        if key == "name":
            if not isinstance(item, str):
                raise input_error(f"{where}.name", "a name", item)
            clean[key] = item
        else:  # a number within its declared range
            clean[key] = check_declared(_DECLARED[key], item, f"{where}.{key}")
    return clean


def check_mass_materials(
    materials: dict[str, Any], names: Sequence[str] | None, has_masses: bool
) -> None:
    """Several ballast materials: ``masses.material`` names each ballast part's, from the
    list (``names``: that list, None when the file gives none)."""
    ballast = materials.get("ballast")
    if isinstance(ballast, list) and len(ballast) > 1:
        if names is None and has_masses:
            raise InputError(
                "masses.material: several ballast materials need each ballast part's material"
            )
        known = {m["name"] for m in ballast}
        unknown = sorted(set(names or []) - known)
        if unknown:
            raise input_error(
                "masses.material", "names among " + ", ".join(sorted(known)), unknown[0]
            )
    elif names is not None:
        known = {ballast["name"]} if isinstance(ballast, dict) and "name" in ballast else set()
        if isinstance(ballast, list):
            known = {m.get("name") for m in ballast}
        unknown = sorted(set(names) - known)
        if unknown:
            raise input_error("masses.material", "the ballast material's name", unknown[0])
