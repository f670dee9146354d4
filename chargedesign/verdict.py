"""The verdict on a design, reasoned in one place and recorded once (design.json ``verdict``).

A body is judged when its design is accepted (:func:`verdict_record`, called by
:func:`chargedesign.designer.design_from_scene`) and the record is stored in
``Design.verdict``; the report, the terminal, the API's ``repr`` and HTML, ``frontier`` and
the sweep's summary render that record (:func:`verdict_line`, :func:`verdict_table`) and never
reason on their own. ``chargedesign check`` is the independent route: it recomputes the limits
and the realised window's items from the written parts and judges them with the same
:func:`judge` (docs/check.md).

The states (docs/buildable.md):

- :data:`NOT_CHECKED`: a scene without ``[medium]`` (point elements, the mathematical case);
- :data:`NOT_BUILDABLE`: a part outside its limits (surface fields, overlaps, magnet volumes,
  field limits), or magnets smaller than the continuum size their material data hold for;
- :data:`NOT_REALISED`: the parts are within their limits, but a parasitic of the realised
  window's catalogue is above the stated fraction of the smallest realised term;
- :data:`REALISED`: within every limit, and every parasitic below the fraction.

The record (contract, "The verdict record")::

    {"state": str, "binding": str, "factor": float | None, "change": str,
     "support": {"style": str | None, "state": "included" | "open" | "none"},
     "items": [{"name", "value", "limit", "unit", "met"}],
     "rows": [{"state", "binding", "factor", "change"}]}

``factor`` is the binding item's value over its limit (None when no number binds, e.g. an
overlap); ``rows`` the verdict's short table as the report prints it (a second row when the
parts are not buildable as specified but would not be realised either, and the support as an
open item when it is).
"""

from __future__ import annotations

import math
import textwrap
from typing import Any

from chargedesign.body import Design
from chargedesign.formatting import PLAIN, ROUGH, fmt, fmt_length
from chargedesign.physical.limits import within_limits
from chargedesign.physical.window import RealisedWindow
from chargedesign.scene.design_realism import RealismRecord, WindowAtDesign, parasitic_text
from chargedesign.vocabulary import VERDICT_STATES

#: the verdict's four states (the contract's strings, ``vocabulary.VERDICT_STATES``)
REALISED, NOT_REALISED, NOT_BUILDABLE, NOT_CHECKED = VERDICT_STATES


def realised_window(design: Design) -> RealisedWindow | None:
    """The realised window design.json records (``frontier.realised``), read back as the
    frontier's own :class:`~chargedesign.physical.window.RealisedWindow` (None: not computed;
    :func:`recorded_window`)."""
    return recorded_window((design.frontier or {}).get("realised"))


def recorded_window(data: dict[str, Any] | None) -> RealisedWindow | None:
    """A realised window as design.json records it (the frontier's ``realised``, or a
    ``[case]`` record's), read back by :meth:`RealisedWindow.from_dict` (None: not computed)."""
    return RealisedWindow.from_dict(data) if data else None


def _what_changes(design: Design) -> str:
    """What would move the body into its realised window (from the frontier's record)."""
    window = realised_window(design)
    if window is None and design.general_case is not None:
        return (
            "the scene's field, materials or size (frontier --recommend varies the theorem's "
            "[parameters]: not a [case])"
        )
    if window is None:
        return "`chargedesign frontier SCENE --recommend PATH` searches field, materials, size"
    if window.empty:
        if design.parameters.K != 0:
            return (
                "nothing at this K: the size-free K law holds for any size and a2; K = 0 "
                "bodies can be realised (docs/buildable.md)"
            )
        return "`chargedesign frontier SCENE --recommend PATH`: no rate of this choice is realised"
    return (
        f"a rate s in [{fmt(window.s_low, ROUGH)}, {fmt(window.s_high, ROUGH)}] x the "
        "scene's (the realised window)"
    )


def _row(state: str, binding: str, factor: float | None, text: str, change: str) -> dict[str, Any]:
    return {
        "state": state,
        "binding": binding,
        "factor": factor,
        "factor_text": text,
        "change": change,
    }


def _item(name: str, value: Any, limit: Any, unit: str, met: bool) -> dict[str, Any]:
    return {"name": name, "value": value, "limit": limit, "unit": unit, "met": bool(met)}


def _limit_items(limits: dict[str, Any], ok: bool) -> list[dict[str, Any]]:
    """The limits check as items: the largest surface field, and the limits broken."""
    items = []
    top, safe = limits.get("largest_surface_field_V_per_m"), limits.get("safe_field_V_per_m")
    if top is not None and safe is not None:
        items.append(_item("largest carrier surface field", top, safe, "V/m", top <= safe))
    violations = list(limits.get("violations") or [])
    items.append(_item("limits broken", len(violations), 0, "count", ok and not violations))
    return items


def _window_rows(design: Design, window: WindowAtDesign) -> tuple[dict[str, Any], list]:
    """Realised or not: the worst parasitic over the fraction at the design's rate; every
    parasitic of the window's catalogue as an item."""
    # an unbounded parasitic is written as null (JSON has no infinity): it is over the fraction
    ratios = {k: math.inf if v is None else float(v) for k, v in window.ratios.items()}
    items = [
        _item(
            f"{label} (of the {window.term_key} term)",
            _finite(ratios[key] * window.fraction),
            window.fraction,
            "of the smallest realised term",
            ratios[key] <= 1.0,
        )
        for key, label, _ in window.items
    ]
    worst = max(ratios, key=lambda k: ratios[k]) if ratios else None
    if worst is None:
        return _row(REALISED, "-", None, "-", "-"), items
    binding = f"{window.label(worst)} (of the {window.term_key} term)"
    over = ratios[worst]
    # the item's own figure (its reference and rate beside it: the one text every output
    # prints, chargedesign.scene.design_realism.parasitic_text) and the limit it is held to
    value = _finite(over * window.fraction)
    text = f"{parasitic_text(value, window.term_key, 1.0)}; limit {fmt(window.fraction, PLAIN)}"
    if over > 1.0:
        return _row(NOT_REALISED, binding, _finite(over), text, _what_changes(design)), items
    return _row(REALISED, binding, over, text, "-"), items


def _finite(x: float) -> float | None:
    """A number for design.json: None for an infinite one."""
    return x if math.isfinite(x) else None


def _support(
    design: Design, window: WindowAtDesign | None
) -> tuple[dict[str, Any], list[dict[str, Any]], list[dict[str, Any]]]:
    """What holds O: ``design.support`` when recorded, else the realised window's support
    record (an air bearing's film drag). Returns the support summary, its open rows and its
    items."""
    recorded = getattr(design, "support", None)  # the support record, when designed with one
    if isinstance(recorded, dict):
        items = [dict(i) for i in recorded.get("items") or []]
        unmet = [i for i in items if not i.get("met")]
        summary = {"style": recorded.get("style"), "state": "open" if unmet else "included"}
        rows = []
        if unmet:
            first = unmet[0]
            value, limit = first.get("value"), first.get("limit")
            factor = value / limit if _numbers(value, limit) and limit else None
            rows.append(
                _row(
                    "support: open (not counted)",
                    f"the {recorded.get('style')} support: {first.get('name')}",
                    factor,
                    f"{fmt(value)} {first.get('unit', '')} against {fmt(limit)}".strip(),
                    "a support that meets it (docs/flight.md)",
                )
            )
        return summary, rows, items
    support = window.support if window is not None else None
    if not support:
        return {"style": None, "state": "none"}, [], []
    assert window is not None  # a support is stated only with a window
    term, fraction = window.term_key, window.fraction
    over = support["drag_over_term"] / fraction
    item = _item(
        f"the {support['bearing']} air bearing's film drag",
        support["drag_over_term"],
        window.fraction,
        "of the smallest realised term",
        over <= 1.0,
    )
    summary = {"style": "air_bearing", "state": "open" if over > 1.0 else "included"}
    if over <= 1.0:
        return summary, [], [item]
    change = f"a support with every attitude free and {fmt(over, ROUGH)} x less drag" + (
        f"; {support['needs']}" if support.get("needs") else ""
    )
    row = _row(
        "support: open (not counted)",
        item["name"],
        over,
        f"{parasitic_text(support['drag_over_term'], term, 1.0)}; limit {fmt(fraction, PLAIN)}",
        change,
    )
    return summary, [row], [item]


def _numbers(*values: Any) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def judge(
    design: Design,
    *,
    limits: dict[str, Any],
    magnets: dict[str, Any],
    window: WindowAtDesign | None,
) -> dict[str, Any]:
    """The verdict of a physical body from its limits record (``buildability``'s mapping),
    its magnets against the continuum size and the realised window's items at its rate.

    Both routes call this: the design's record (:func:`verdict_record`) and the check's
    recomputation from the written parts."""
    ok = within_limits(limits)
    below = magnets.get("below", 0)
    rows: list[dict[str, Any]] = []
    items = _limit_items(limits, ok)
    if not ok:
        binding = (limits.get("violations") or ["a limit"])[0]
        rows.append(_row(NOT_BUILDABLE, binding, None, "-", "see the broken limit below"))
    if magnets:
        items.append(
            _item(
                "smallest magnet across",
                magnets["smallest_m"],
                magnets["continuum_size_m"],
                "m",
                not below,
            )
        )
    if ok and below:
        factor = magnets["continuum_size_m"] / magnets["smallest_m"]
        rows.append(
            _row(
                NOT_BUILDABLE,
                f"{below} of its magnets are smaller than the "
                f"{fmt_length(magnets['continuum_size_m'])} continuum size",
                factor,
                fmt(factor, ROUGH),
                "larger magnets: a slower rate, a weaker field, or a larger body",
            )
        )
    window = window if ok else None
    if window is not None:
        realised, window_items = _window_rows(design, window)
        items += window_items
        if not rows or realised["state"] != REALISED:
            rows.append(realised)
    support, support_rows, support_items = _support(design, window)
    rows += support_rows
    items += support_items
    if not rows:  # within every limit and no window recorded: nothing binds
        rows.append(_row(REALISED, "-", None, "-", "-"))
    first = rows[0]
    return {
        "state": first["state"],
        "binding": first["binding"],
        "factor": first["factor"],
        "change": first["change"],
        "support": support,
        "items": items,
        "rows": rows,
    }


def not_checked() -> dict[str, Any]:
    """The verdict of a scene without ``[medium]``: point elements, no physical limits."""
    return {
        "state": NOT_CHECKED,
        "binding": "the scene has no [medium]: point elements, the mathematical case",
        "factor": None,
        "change": "a [medium] table (docs/buildable.md)",
        "support": {"style": None, "state": "none"},
        "items": [],
        "rows": [],
    }


def verdict_record(design: Design) -> dict[str, Any]:
    """The verdict of a design as its record says (``buildability``, ``realism``,
    ``frontier``, ``support``): design.json's ``verdict``.

    Parameters
    ----------
    design : Design
        An accepted design; a physical one (with ``medium``) carries its limits report and
        realism budget.

    Returns
    -------
    dict
        ``state`` (one of :data:`~chargedesign.vocabulary.VERDICT_STATES`), ``binding``,
        ``factor``, ``change``, ``support`` (``style``, ``state``), ``items`` and ``rows``
        (module docstring).
    """
    if design.medium is None:
        return not_checked()
    record = RealismRecord.read(design.realism)
    return judge(
        design, limits=design.buildability or {}, magnets=record.magnets, window=record.window
    )


def recorded_verdict(design: Design) -> dict[str, Any]:
    """``design.verdict``, or (a design.json written before the record) the verdict its
    record gives, computed once here."""
    if isinstance(design.verdict, dict) and design.verdict.get("state") in VERDICT_STATES:
        return design.verdict
    return verdict_record(design)


# --------------------------------------------------------------------------- rendering
def _cell(text: Any, width: int = 110) -> str:
    """A table cell: one line, at most ``width`` characters (the detail follows the table)."""
    text = " ".join(str(text).split()).replace("|", "/")
    return text if len(text) <= width else text[: width - 3] + "..."


def verdict_state_line(verdict: dict[str, Any]) -> str:
    """The state as the first line says it (an open support named beside a realised body)."""
    state = verdict["state"]
    if state == REALISED and (verdict.get("support") or {}).get("state") == "open":
        return state + " (the body and its field; its support is open, see the table)"
    return state


def verdict_line(verdict: dict[str, Any]) -> str:
    """One line: ``Verdict: STATE; binding: ...`` (at most 160 characters)."""
    line = f"Verdict: {verdict['state']}"
    binding = verdict.get("binding")
    if binding and binding != "-" and verdict["state"] != NOT_CHECKED:
        line += f"; binding: {binding}"
    return _cell(line, 160)


def verdict_text_table(verdict: dict[str, Any]) -> list[str]:
    """The verdict's table for a terminal: the same rows as :func:`verdict_table`, each cell
    wrapped in its column, so no line passes 160 characters."""
    widths = (26, 52, 22, 52)
    heads = ("state", "binding item", "factor", "what would change it")
    keys = ("state", "binding", "factor_text", "change")
    rows = verdict.get("rows") or []
    if not rows:
        return [verdict_line(verdict)]
    out = ["  ".join(h.ljust(w) for h, w in zip(heads, widths, strict=True)).rstrip()]
    for row in rows:
        cells = [
            textwrap.wrap(" ".join(str(row[k]).split()), w) or [""]
            for k, w in zip(keys, widths, strict=True)
        ]
        for i in range(max(len(c) for c in cells)):
            out.append(
                "  ".join(
                    (c[i] if i < len(c) else "").ljust(w)
                    for c, w in zip(cells, widths, strict=True)
                ).rstrip()
            )
    return out


def verdict_table(verdict: dict[str, Any], width: int = 110) -> list[str]:
    """The verdict's short table (Markdown): state, binding item, factor, what would change it;
    each cell at most ``width`` characters (the detail follows the table)."""
    rows = verdict.get("rows") or []
    if not rows:
        return []
    return [
        "| state | binding item | factor | what would change it |",
        "|---|---|---|---|",
        *[
            "| "
            + " | ".join(_cell(r[k], width) for k in ("state", "binding", "factor_text", "change"))
            + " |"
            for r in rows
        ],
    ]
