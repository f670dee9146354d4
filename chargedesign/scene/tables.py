"""Typed forms of the scene tables that name no stage: ``[tolerance]`` and ``[body]``.

``[body]`` means one of two things: a region the design places elements in
(:class:`BodyRegion`, ``shape = ...``), or the body to simulate (:class:`BodyReference`, a
``design = PATH`` or inline ``charges``/``masses``/``dipoles``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from chargedesign.scene.keys import BODY_REFERENCE_KEYS, REGION_KEYS, check_table, check_value
from chargedesign.validation import check_keys, input_error
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS


def material_errors_from_table(table: Any, where: str = "tolerance") -> dict[str, float]:
    """``[tolerance]``: every material error (relative, in [0, 1); absent ones are 0)."""
    check_table(table, "tolerance", where)
    out = dict.fromkeys(MATERIAL_ERROR_KEYS, 0.0)
    for key, value in table.items():
        out[key] = check_value("tolerance", key, value, f"{where}.{key}")
    return out


@dataclass(frozen=True)
class BodyRegion:
    """``[body]`` with a shape: where the design may place elements (the raw keys, checked
    against the shape; sizes are read into points by :mod:`chargedesign.candidates`)."""

    table: Mapping[str, Any] = field(default_factory=dict)

    @property
    def shape(self) -> str:
        return str(self.table.get("shape", "ball"))


@dataclass(frozen=True)
class BodyReference:
    """``[body]`` naming the body to simulate: ``design = PATH`` or inline elements."""

    table: Mapping[str, Any] = field(default_factory=dict)

    @property
    def design_path(self) -> Any:
        return self.table.get("design")


def check_region_keys(table: Mapping[str, Any]) -> None:
    """Unknown keys of a ``[body]`` region (for its shape) are one-line errors naming the key.

    A missing or unknown shape is left to the candidate sets.
    """
    if not isinstance(table, Mapping):
        return
    shape = table.get("shape", "ball" if table else None)
    if not isinstance(shape, str) or shape not in REGION_KEYS:
        return
    # carrier_radius belongs to the physical parts (chargedesign.scene.physical)
    allowed = set(REGION_KEYS[shape]) | {"shape", "carrier_radius"}
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise input_error(
            f"body.{unknown[0]}",
            f"a key of shape {shape!r} (" + ", ".join(REGION_KEYS[shape]) + ")",
            unknown[0],
        )


def body_from_table(table: Any) -> BodyRegion | BodyReference | None:
    """``[body]`` as a region or a reference (None: the scene has no ``[body]``)."""
    if table is None:
        return None
    if not isinstance(table, Mapping):
        raise input_error("body", "a table", table)
    if "shape" in table or not set(table) & set(BODY_REFERENCE_KEYS):
        check_region_keys(table)
        return BodyRegion(dict(table))
    check_keys(table, BODY_REFERENCE_KEYS, "body")
    return BodyReference(dict(table))
