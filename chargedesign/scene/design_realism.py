"""design.json's ``realism`` (the realism budget), read at the boundary: its keys, declared
once for the budget that writes them and the report that reads them, and the figures the
report prints read back as a typed record.

The budget (:func:`chargedesign.physical.budget.realism_record`) writes every figure the
report prints beside its items, so the report only renders: the items (``value``, ``unit``,
``verdict``, ``note``; the field response and the size-free K law among them) and three
figure blocks, :data:`FIGURE_KEYS`:

- ``part_sizes``: ``carriers`` and ``ballast`` (``count``, ``smallest_m``, ``largest_m``: a
  carrier's sphere radius, a ballast sphere's radius) and ``magnets`` (the magnets against
  their continuum size, :func:`chargedesign.physical.realism.magnet_continuum`); a kind the
  body has not is absent;
- ``realisability_map``: the rows of :func:`chargedesign.physical.realism.realisability_map`
  (an infinite size, a singular term that is present, is written as null);
- ``window_at_design``: the realised window's items at the design's own rate
  (:func:`chargedesign.physical.window.window_model` at ``s = 1``): ``fraction``,
  ``term_key``, ``items`` (``key``, ``label``, ``over_fraction``: the item's ratio to the
  smallest realised term over the fraction), ``apparatus`` and its one-line
  ``apparatus_summary``, ``support``; null for a body that is not buildable.

This module computes nothing: it names the keys and reads them back.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from chargedesign.errors import InputError
from chargedesign.formatting import PLAIN, ROUGH, fmt

#: a torque from the parts' materials below this fraction of the designed torques is negligible
RESPONSE_FRACTION = 1e-3
#: the budget's items for the applied field acting on the parts' materials
FIELD_RESPONSE_KEYS = ("induced_magnetisation_fraction", "eddy_torque_fraction")
#: the budget's item for the size-free K law (a law of matter at the K frontier, named as such)
K_LAW_KEY = "k_law_induced_ratio"
#: the induced magnetisation's one figure: the parts' induced-energy range over the smallest
#: realised term, at a named rate (:func:`chargedesign.physical.budget.induced_magnetisation`)
INDUCED_KEY = "induced_magnetisation"
#: its one name and its reference, as every output prints them
INDUCED_NAME = "induced magnetisation"
INDUCED_REFERENCE = "of the smallest realised term"
#: the figure blocks beside the budget's items (not rows of its table)
PART_SIZES_KEY = "part_sizes"
MAP_KEY = "realisability_map"
WINDOW_KEY = "window_at_design"
FIGURE_KEYS = (PART_SIZES_KEY, MAP_KEY, WINDOW_KEY)


def parasitic_text(value: float | None, term: str, s: float) -> str:
    """A parasitic's figure with its reference and its rate, as every output prints it:
    ``4.6e+12 of the smallest realised term (K2) at s = 1`` (None: unbounded)."""
    shown = "inf" if value is None else fmt(value, ROUGH)
    return f"{shown} {INDUCED_REFERENCE} ({term}) at s = {fmt(s, ROUGH)}"


def induced_text(figure: dict[str, Any]) -> str:
    """The induced magnetisation's one line, from its record (:data:`INDUCED_KEY`):
    ``induced magnetisation: 4.6e+12 of the smallest realised term (K2) at s = 1 (the
    design's rate; limit 0.001: NOT negligible)``."""
    value = parasitic_text(figure["value"], figure["term"], figure["s"])
    return (
        f"{INDUCED_NAME}: {value} ({figure['rate']}; limit {fmt(figure['limit'], PLAIN)}: "
        f"{figure['verdict']})"
    )


@dataclass(frozen=True)
class WindowAtDesign:
    """The realised window's items at the design's own rate, as the verdict reads them."""

    fraction: float
    term_key: str
    #: (key, label, ratio to the smallest realised term over the fraction), in the window's order
    items: tuple[tuple[str, str, float], ...]
    apparatus_summary: str | None
    support: dict[str, Any] | None

    @property
    def ratios(self) -> dict[str, float]:
        """Each item's ratio over the fraction, by key."""
        return {key: over for key, _, over in self.items}

    def label(self, key: str) -> str:
        return next(label for k, label, _ in self.items if k == key)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> WindowAtDesign:
        return cls(
            fraction=data["fraction"],
            term_key=data["term_key"],
            items=tuple((i["key"], i["label"], i["over_fraction"]) for i in data["items"]),
            apparatus_summary=data.get("apparatus_summary"),
            support=data.get("support"),
        )


@dataclass(frozen=True)
class RealismRecord:
    """design.json's ``realism`` read for the report: the budget's items and its figures."""

    #: the budget's rows and scalars as written (everything but the figure blocks)
    budget: dict[str, Any]
    part_sizes: dict[str, Any]
    realisability_map: list[dict[str, Any]]
    window: WindowAtDesign | None

    @property
    def response(self) -> dict[str, Any]:
        """The field response items (induced magnetisation, eddy currents), when written."""
        return {k: self.budget[k] for k in FIELD_RESPONSE_KEYS if k in self.budget}

    @property
    def induced(self) -> dict[str, Any]:
        """The induced magnetisation's one figure ({} when not recorded: no magnetic field,
        parts outside their limits, or a design.json written before it)."""
        return self.budget.get(INDUCED_KEY) or {}

    @property
    def law(self) -> dict[str, Any]:
        """The size-free K law's item ({} when the law does not apply)."""
        return self.budget.get(K_LAW_KEY) or {}

    @property
    def magnets(self) -> dict[str, Any]:
        """The magnets against their continuum size ({} without magnets)."""
        return self.part_sizes.get("magnets") or {}

    @classmethod
    def read(cls, realism: dict[str, Any] | None) -> RealismRecord:
        """The record of a physical design; one line naming the missing block for a
        design.json written before the budget recorded the report's figures."""
        realism = realism or {}
        missing = [k for k in FIGURE_KEYS if k not in realism]
        if missing:
            raise InputError(
                f"design realism.{missing[0]}: missing (a design.json written before the "
                "realism budget recorded the report's figures): design the scene again with "
                "`chargedesign design` to render its report"
            )
        window = realism[WINDOW_KEY]
        return cls(
            budget={k: v for k, v in realism.items() if k not in FIGURE_KEYS},
            part_sizes=realism[PART_SIZES_KEY] or {},
            realisability_map=list(realism[MAP_KEY] or []),
            window=WindowAtDesign.from_dict(window) if window else None,
        )
