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

import math
from typing import Any

from chargedesign.physical.limits import within_limits
from chargedesign.physical.realism import k_law, part_sizes, realisability_map, realism_budget
from chargedesign.physical.window import WindowModel, window_model
from chargedesign.results import json_ready
from chargedesign.scene.design_realism import (
    INDUCED_KEY,
    INDUCED_NAME,
    INDUCED_REFERENCE,
    K_LAW_KEY,
    MAP_KEY,
    PART_SIZES_KEY,
    WINDOW_KEY,
)

#: the window's item that is the induced magnetisation (:mod:`chargedesign.physical.window`)
INDUCED_ITEM = "induced"


def _model_at_design(design: Any, parts_ok: bool | None) -> WindowModel | None:
    """The window's laws of this body at its own rate (``s_ref = 1``), None for a body whose
    parts are not within their limits (the verdict judges no parasitic then). The rate-free
    factors are cached per body (physical/parasitics.py), so building it again is cheap."""
    if not (within_limits(design.buildability) if parts_ok is None else parts_ok):
        return None
    return window_model(design, 1.0)


def window_at_design(design: Any, parts_ok: bool | None = None) -> dict[str, Any] | None:
    """The realised window's items at the design's own rate (``s = 1``, the default fraction
    and 1 g), as the verdict reads them; None for a body whose parts are not within their
    limits (``parts_ok``; None: as its ``buildability`` record says)."""
    model = _model_at_design(design, parts_ok)
    if model is None:
        return None
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


def induced_magnetisation(
    design: Any, s: float = 1.0, parts_ok: bool | None = None
) -> dict[str, Any] | None:
    """The induced magnetisation's one figure: the range over orientations of the parts'
    induced energy ``-sum chi v |B|^2 / (2 mu0)`` over the smallest realised term of V or mu
    (the realisability map's smallest row that parts realise), at the rate ``s`` (a multiple of
    the design's rates; 1: the design's own).

    Computed in one place, the realised window's ``induced`` item
    (:func:`chargedesign.physical.window.window_model` of this body at ``s_ref = 1``, the
    verdict's), so the verdict, the report, design.json (``realism.induced_magnetisation``),
    ``design``'s terminal, ``frontier`` and ``check`` print one number under one name. At
    another rate the window's law carries it (the magnets' energy ~ s^2 like the terms, the
    other parts' fixed). The size-free K law (``realism.k_law_induced_ratio``) is a law of
    matter at the K frontier over ``C K_max^2``, not this figure.

    Parameters
    ----------
    design : Design
        A physical body (``medium``, ``materials``).
    s : float
        The rate, a multiple of the design's rates.
    parts_ok : bool, optional
        Whether its parts are within their limits (None: as its ``buildability`` says).

    Returns
    -------
    dict or None
        ``name``, ``value`` (the ratio; None: unbounded), ``unit`` (``"of the smallest
        realised term"``), ``term`` (its key in the map), ``term_N_m``, ``s``, ``rate`` (in
        words), ``limit`` (the realised fraction), ``verdict``, ``note``; None when the
        window is not judged (parts outside their limits) or has no such item (no magnetic
        field).
    """
    model = _model_at_design(design, parts_ok)
    value = _induced_ratio(model, s)
    if model is None or value is None:
        return None
    rate = "the design's rate" if s == 1.0 else f"{s:.6g} x the design's rates"
    return json_ready(
        {
            "name": INDUCED_NAME,
            "value": value,
            "unit": INDUCED_REFERENCE,
            "term": model.term_key,
            "term_N_m": model.term_size,
            "s": s,
            "rate": rate,
            "limit": model.fraction,
            "verdict": "negligible" if value <= model.fraction else "NOT negligible",
            "note": (
                f"range over orientations of the energy -chi v |B|^2 / (2 mu0) of the parts' "
                f"materials in the applied field, over the smallest realised term "
                f"({model.term_key}, {model.term_size:.3g} N m), at {rate} (s = {s:.6g}); "
                f"the verdict's item, held to the limit {model.fraction:g}"
                + (
                    f"; that needs the parts' chi-weighted dipole and quadrupole moments to "
                    f"cancel to 1 part in {value / model.fraction:.2g}"
                    if value > model.fraction and math.isfinite(value)
                    else ""
                )
            ),
        }
    )


def induced_reference(design: Any, parts_ok: bool | None = None) -> dict[str, Any] | None:
    """The reference of the induced magnetisation's one figure: the smallest realised term at
    the design's own rate (``s = 1``), for analyses that compute the same energy by another
    route (the tolerance's Monte Carlo) and must state it over the same reference.

    Returns
    -------
    dict or None
        ``term`` (its key in the map), ``term_N_m``, ``s`` (1), ``unit`` (``"of the smallest
        realised term"``), ``limit`` (the realised fraction); None when the figure is not
        judged (as :func:`induced_magnetisation`).
    """
    model = _model_at_design(design, parts_ok)
    if model is None or _induced_ratio(model, 1.0) is None:
        return None
    return {
        "term": model.term_key,
        "term_N_m": float(model.term_size),
        "s": 1.0,
        "unit": INDUCED_REFERENCE,
        "limit": float(model.fraction),
    }


def _induced_ratio(model: WindowModel | None, s: float) -> float | None:
    """The window's induced item over its smallest realised term at rate ``s`` (None: no
    window judged, or no magnetic field): the one place the figure is computed."""
    if model is None or INDUCED_ITEM not in {p.key for p in model.items}:
        return None
    return float(model.ratios(s)[INDUCED_ITEM])


def map_figures(
    design: Any, response: dict[str, Any] | None = None, parts_ok: bool | None = None
) -> list[dict[str, Any]]:
    """The realisability map's rows (:func:`~chargedesign.physical.realism.realisability_map`)
    with their induced columns from the one figure's function: each term's induced
    magnetisation over it at the design's rate (``induced_over_term``) and at the K frontier
    (``frontier_induced_over_term``, the window's law at ``s = sqrt(frontier size / size)``:
    the magnets' energy grows like the terms, the other parts' does not), so over the smallest
    term the map says the figure's number at either rate. A body whose window is not judged
    keeps the map's own columns."""
    rows = realisability_map(design, response)
    model = _model_at_design(design, parts_ok)
    now = _induced_ratio(model, 1.0)
    if model is None or now is None:
        return rows
    out = []
    for row in rows:
        row = dict(row)
        size, front = row["size_N_m"], row["frontier_size_N_m"]
        if row["induced_over_term"] is not None and size and math.isfinite(size):
            per_term = model.term_size / size
            row["induced_over_term"] = now * per_term
            there = _induced_ratio(model, math.sqrt(front / size)) if front else None
            if there is not None and row["frontier_induced_over_term"] is not None:
                row["frontier_induced_over_term"] = there * per_term
        out.append(row)
    return out


def report_figures(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """The figure blocks of the budget (JSON-ready, as design.json holds them: an infinite
    size is null, so the report renders the same from memory and from the file)."""
    return json_ready(
        {
            PART_SIZES_KEY: part_sizes(design),
            MAP_KEY: map_figures(design, response),
            WINDOW_KEY: window_at_design(design),
        }
    )


def realism_record(design: Any, response: dict[str, Any] | None = None) -> dict[str, Any]:
    """design.json's ``realism``: the budget's items and the report's figures.

    ``response``: the design's :func:`~chargedesign.physical.realism.field_response` when
    already computed (the limits check computes it too).
    """
    budget = realism_budget(design, response)
    figure = induced_magnetisation(design)
    return budget | ({INDUCED_KEY: figure} if figure else {}) | report_figures(design, response)


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
        realism[MAP_KEY] = json_ready(map_figures(design))
