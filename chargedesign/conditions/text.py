"""The text of the linear conditions (what ``chargedesign conditions`` prints).

:func:`format_conditions` is ``str(LinearConditions)``; the command adds the scene's name.
"""

from __future__ import annotations

from typing import Any

PREFIX = {"charges": "I", "dipoles": "S", "masses": "M"}
PROVENANCE_WIDTH = 120


def _moment_name(source: str, key: str) -> str:
    """``I_xxz`` (charges), ``M_xx`` (masses), ``S_z:x`` = sum sigma_z x (dipoles)."""
    key = key.rstrip(":")
    return f"{PREFIX[source]}_{key}" if key else PREFIX[source]


def _number(value: float) -> str:
    return f"{value:.12g}"


def _lhs(source: str, coefficients: dict[str, float]) -> str:
    terms = []
    for key, coef in coefficients.items():
        name = _moment_name(source, key)
        if coef == 1.0:
            terms.append(f"+ {name}")
        elif coef == -1.0:
            terms.append(f"- {name}")
        else:
            sign = "-" if coef < 0 else "+"
            terms.append(f"{sign} {_number(abs(coef))} {name}")
    text = " ".join(terms)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def _short(provenance: str) -> str:
    parts = provenance.split("; ")
    text = parts[0] + (f" (+{len(parts) - 1} more)" if len(parts) > 1 else "")
    return text if len(text) <= PROVENANCE_WIDTH else text[: PROVENANCE_WIDTH - 3] + "..."


def format_conditions(result: Any, scene_source: str | None = None) -> str:
    """The human text of a :class:`~chargedesign.conditions.LinearConditions`."""
    from chargedesign.conditions.constants import SOURCES

    where = f" for {scene_source}" if scene_source else ""
    lines = [f"conditions{where} (realise {', '.join(result.realise) or 'nothing'})"]
    lines.append("fields (legendre coefficients of Phi = sum_k f_k R^k P_k(Z/R)):")
    for kind, origin in result.field_origin.items():
        coeffs = ", ".join(_number(v) for v in result.fields.get(kind, ()))
        lines.append(f"  {kind:<9} [{coeffs}]  ({origin})")
    for source in SOURCES:
        rows = result.for_source(source)
        if not rows and source not in _present(result):
            continue
        lines.append("")
        lines.append(f"{source}: {len(rows)} condition{'s' if len(rows) != 1 else ''}")
        for row in rows:
            value = row.exact_value or _number(row.value)
            key = row.single_key
            if key is not None and row.coefficients[key] == 1.0:
                equation = f"{_moment_name(source, key)} = {value}"
            else:
                equation = f"{_lhs(source, row.coefficients)} = {value}"
            lines.append(f"  {equation}")
            lines.append(f"      <- {_short(row.provenance)}")
    if result.notes:
        lines.append("")
        lines.append("notes:")
        lines += [f"  - {note}" for note in result.notes]
    return "\n".join(lines)


def _present(result: Any) -> set[str]:
    present = set()
    if "mu" in result.realise or "V" in result.realise:
        present.add("charges")
    if "V" in result.realise:
        present.add("dipoles")
    if "inertia" in result.realise:
        present.add("masses")
    return present


__all__ = ["format_conditions"]
