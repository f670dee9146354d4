"""The medium around the body: one type for the scene's ``[medium]`` and design.json.

A scene names a medium (``name = "air"``) or gives its breakdown field (``breakdown = V/m``,
then ``name`` is free and defaults to ``custom``); ``gas`` names whose density and viscosity
the realism budget's drag estimate uses (default: the name's when it names one). design.json
records the same :class:`Medium` under its contract keys ``name``, ``breakdown_V_per_m``,
``safety`` (and ``gas`` when the scene gave one).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from chargedesign.physical.materials import BREAKDOWN_V_PER_M, GAS_PROPERTIES
from chargedesign.scene.keys import check_table, check_value, default_of
from chargedesign.validation import as_finite_float, input_error

#: design.json's keys of a medium (the contract), ``gas`` optional
DESIGN_KEYS = ("name", "breakdown_V_per_m", "safety")
DEFAULT_SAFETY = default_of("medium", "safety")


@dataclass(frozen=True)
class Medium:
    """What surrounds the body.

    Attributes
    ----------
    name : str
        ``vacuum``, ``air``, ``sf6``, ``oil``, or the scene's name of a custom medium
        (``custom`` when it gives none).
    breakdown : float
        Breakdown field, V/m.
    safety : float
        In (0, 1]: every surface field stays at or below ``safety * breakdown``.
    gas : str or None
        The medium whose density and viscosity the drag estimate uses (None: the name's).
    """

    name: str
    breakdown: float
    safety: float = DEFAULT_SAFETY
    gas: str | None = None

    @property
    def safe_field(self) -> float:
        """The largest surface field a design may make, V/m."""
        return self.safety * self.breakdown

    @property
    def gas_properties(self) -> tuple[float, float] | None:
        """(density kg/m^3, viscosity Pa s) for the drag estimate; None when the medium
        names no known gas (a custom medium without ``gas``)."""
        return GAS_PROPERTIES.get(self.gas or self.name)

    def to_dict(self) -> dict[str, Any]:
        """design.json's ``medium`` object."""
        out: dict[str, Any] = {
            "name": self.name,
            "breakdown_V_per_m": self.breakdown,
            "safety": self.safety,
        }
        if self.gas is not None:
            out["gas"] = self.gas
        return out

    @classmethod
    def from_dict(cls, value: Any) -> Medium:
        """design.json's ``medium`` object (keys ``name``, ``breakdown_V_per_m``, ``safety``;
        ``gas`` optional)."""
        if isinstance(value, Medium):
            return value
        keys = set(value) - {"gas"} if isinstance(value, dict) else None
        if keys != set(DESIGN_KEYS):
            raise input_error("medium", "an object with keys " + ", ".join(DESIGN_KEYS), value)
        if not isinstance(value["name"], str):
            raise input_error("medium.name", "a name", value["name"])
        breakdown = as_finite_float(
            value["breakdown_V_per_m"], "medium.breakdown_V_per_m", positive=True
        )
        return cls(value["name"], breakdown, _safety(value["safety"]), _gas(value.get("gas")))


def _safety(value: Any) -> float:
    safety = as_finite_float(value, "medium.safety")
    if not 0.0 < safety <= 1.0:
        raise input_error("medium.safety", "a number in (0, 1]", safety)
    return safety


def _gas(value: Any) -> str | None:
    if value is not None and (not isinstance(value, str) or value not in GAS_PROPERTIES):
        raise input_error("medium.gas", "one of " + ", ".join(GAS_PROPERTIES), value)
    return value


def medium_from_table(table: Mapping[str, Any]) -> Medium:
    """``[medium]``: a named medium or a breakdown field, the safety factor, the gas."""
    check_table(table, "medium")
    if "breakdown" in table:
        breakdown = check_value("medium", "breakdown", table["breakdown"])
        name = table.get("name", "custom")
        if not isinstance(name, str):
            raise input_error("medium.name", "a name", name)
    else:
        name = table.get("name")
        if not isinstance(name, str) or name not in BREAKDOWN_V_PER_M:
            raise input_error(
                "medium.name", "one of " + ", ".join(BREAKDOWN_V_PER_M) + " (or breakdown)", name
            )
        breakdown = BREAKDOWN_V_PER_M[name]
    safety = _safety(table.get("safety", DEFAULT_SAFETY))
    return Medium(name=name, breakdown=breakdown, safety=safety, gas=_gas(table.get("gas")))
