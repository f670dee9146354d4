"""The text of the linear conditions (what ``chargedesign conditions`` prints).

:func:`format_conditions` is ``str(LinearConditions)``; the command adds the scene's name.
"""

from __future__ import annotations

from typing import Any

from chargedesign.formatting import FULL, fmt
from chargedesign.moment_conditions.constants import SOURCES

PREFIX = {"charges": "I", "dipoles": "S", "masses": "M"}
PROVENANCE_WIDTH = 120


def _moment_name(source: str, key: str) -> str:
    """``I_xxz`` (charges), ``M_xx`` (masses), ``S_z:x`` = sum sigma_z x (dipoles)."""
    key = key.rstrip(":")
    return f"{PREFIX[source]}_{key}" if key else PREFIX[source]


def _number(value: float) -> str:
    return fmt(value, FULL)


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


def clean_number(value: float) -> str:
    """The shortest decimal (at most 12 significant digits) of a coefficient: products such as
    ``-4 n a2 / 5`` print as ``-0.392``, not ``-0.39199999999999996``."""
    return _number(float(value))


def field_notation(kind: str, coefficients: tuple[float, ...] | list[float]) -> str:
    """A field's coefficients as the user writes them.

    ``legendre = [f1, f2, ...]`` with clean numbers; a magnetic field of degree <= 2 also in the
    paper's notation, ``a1 = f1 T, a2 = f2 / 2 T/m`` (``Phi = a1 Z + a2 (3 Z^2 - R^2)``).
    """
    coeffs = [float(c) for c in coefficients]
    text = "[" + ", ".join(clean_number(c) for c in coeffs) + "]"
    if kind == "magnetic" and 1 <= len(coeffs) <= 2:
        a1 = coeffs[0]
        a2 = coeffs[1] / 2.0 if len(coeffs) == 2 else 0.0
        text += f" = a1 {clean_number(a1)} T, a2 {clean_number(a2)} T/m"
    return text


def _short(provenance: str) -> str:
    parts = provenance.split("; ")
    text = parts[0] + (f" (+{len(parts) - 1} more)" if len(parts) > 1 else "")
    return text if len(text) <= PROVENANCE_WIDTH else text[: PROVENANCE_WIDTH - 3] + "..."


def format_conditions(result: Any, scene_source: str | None = None) -> str:
    """The human text of a :class:`~chargedesign.moment_conditions.LinearConditions`."""

    where = f" for {scene_source}" if scene_source else ""
    lines = [f"conditions{where} (realise {', '.join(result.realise) or 'nothing'})"]
    lines.append("fields (legendre coefficients of Phi = sum_k f_k R^k P_k(Z/R)):")
    for kind, origin in result.field_origin.items():
        lines.append(f"  {kind:<9} {field_notation(kind, result.fields.get(kind, ()))}  ({origin})")
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


__all__ = ["clean_number", "field_notation", "format_conditions"]
