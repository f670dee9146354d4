"""The realism budget with every figure the report prints, as design.json records it.

:func:`realism_record` is the budget of :func:`chargedesign.physical.realism.realism_budget`
(its items: radiation, drag, balance, the field response, the size-free K law, ...) plus the
figure blocks :data:`~chargedesign.scene.design_realism.FIGURE_KEYS`: the part sizes, the
realisability map and the realised window's items at the design's own rate. The designer
writes it into ``design.realism`` (and again once the frontier is known: the K law and the
map's frontier columns are judged at its ``K_max``); the report reads it back through
:class:`~chargedesign.scene.design_realism.RealismRecord` and computes nothing. The forward
check (``chargedesign check``) does not read it: it re-derives the body's figures on its own.
"""

from __future__ import annotations

from typing import Any

from chargedesign.physical.limits import within_limits
from chargedesign.physical.realism import k_law, part_sizes, realisability_map, realism_budget
from chargedesign.physical.window import window_model
from chargedesign.results import json_ready
from chargedesign.scene.design_realism import K_LAW_KEY, MAP_KEY, PART_SIZES_KEY, WINDOW_KEY


def window_at_design(design: Any, parts_ok: bool | None = None) -> dict[str, Any] | None:
    """The realised window's items at the design's own rate (``s = 1``, the default fraction
    and 1 g), as the verdict reads them; None for a body whose parts are not within their
    limits (``parts_ok``; None: as its ``buildability`` record says)."""
    if not (within_limits(design.buildability) if parts_ok is None else parts_ok):
        return None
    model = window_model(design, 1.0)
    ratios = model.ratios(1.0)
    return {
        "fraction": model.fraction,
        "term_key": model.term_key,
        "items": [
            {"key": p.key, "label": p.label, "over_fraction": ratios[p.key] / model.fraction}
            for p in model.items
        ],
        "apparatus": model.apparatus.to_dict() if model.apparatus is not None else None,
        "apparatus_summary": (
            "; ".join(str(model.apparatus).splitlines()) if model.apparatus is not None else None
        ),
        "support": model.support,
    }


def report_figures(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """The figure blocks of the budget (JSON-ready, as design.json holds them: an infinite
    size is null, so the report renders the same from memory and from the file)."""
    return json_ready(
        {
            PART_SIZES_KEY: part_sizes(design),
            MAP_KEY: realisability_map(design, response),
            WINDOW_KEY: window_at_design(design),
        }
    )


def realism_record(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """design.json's ``realism``: the budget's items and the report's figures.

    ``response``: the design's :func:`~chargedesign.physical.realism.field_response` when
    already computed (the limits check computes it too).
    """
    budget = realism_budget(design, response)
    return budget | report_figures(design, response)


def judge_at_frontier(design: Any) -> None:
    """The budget's K law and the realisability map again, once ``design.frontier`` is known:
    the law and the map's frontier columns are judged at its ``K_max``. The part sizes and
    the window at the design's rate do not depend on it (the window's smallest term is chosen
    by the sizes here)."""
    realism = design.realism
    if not isinstance(realism, dict):
        return
    if K_LAW_KEY in realism:
        realism[K_LAW_KEY] = k_law(design)
    if MAP_KEY in realism:
        realism[MAP_KEY] = json_ready(realisability_map(design))
