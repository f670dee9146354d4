"""The sources table: every physical figure the tool uses, with its source and whether it
was checked.

The figures live in one file, ``chargedesign/data/sources.toml`` (package data), one
``[[figure]]`` row each: ``key``, ``value`` (SI or the unit named), ``unit``, ``what``,
``source`` (title, author or maker, year), ``locator`` (DOI, URL, or document and page) and
``checked`` (true only when the figure was read in that source). The modules that use a
figure read it here by its key (:func:`value`), so the table is the one source of truth;
``chargedesign sources`` prints it (docs/sources.md says how to add a figure).

Outputs that rest on a figure cite its key with :func:`cite`: ``[key]`` for a checked
figure, ``[key, unverified]`` for the others.
"""

from __future__ import annotations

import html
import re
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import Any

from chargedesign.formatting import fmt

#: the mark an unchecked figure's citation carries
UNVERIFIED_MARK = "unverified"
#: the fields of a row, in the contract's order (``chargedesign sources --json``)
FIELDS = ("key", "value", "unit", "what", "source", "locator", "checked")
#: the widest line the text table prints
LINE_WIDTH = 160


@dataclass(frozen=True)
class SourceRow:
    """One physical figure: ``value`` in ``unit``, what it is, its source and locator, and
    whether it was checked (read in that source)."""

    key: str
    value: float
    unit: str
    what: str
    source: str
    locator: str
    checked: bool

    def to_dict(self) -> dict[str, Any]:
        return {f: getattr(self, f) for f in FIELDS}

    def cite(self) -> str:
        """``[key]`` when checked, ``[key, unverified]`` otherwise."""
        return f"[{self.key}]" if self.checked else f"[{self.key}, {UNVERIFIED_MARK}]"


def _load() -> tuple[SourceRow, ...]:
    text = resources.files("chargedesign").joinpath("data/sources.toml").read_text("utf-8")
    table = tomllib.loads(text)
    out = []
    for row in table.get("figure", []):
        out.append(
            SourceRow(
                key=str(row["key"]),
                value=float(row["value"]),
                unit=str(row["unit"]),
                what=str(row["what"]),
                source=str(row["source"]),
                locator=str(row["locator"]),
                checked=bool(row["checked"]),
            )
        )
    return tuple(out)


@lru_cache(maxsize=1)
def _by_key() -> dict[str, SourceRow]:
    rows = _load()
    table = {r.key: r for r in rows}
    if len(table) != len(rows):  # a packaging error, not a user's input
        raise ValueError("chargedesign/data/sources.toml: a key appears twice")
    return table


def rows() -> tuple[SourceRow, ...]:
    """Every row of the table, in the file's order."""
    return tuple(_by_key().values())


def source(key: str) -> SourceRow:
    """The row of ``key``.

    Raises
    ------
    KeyError
        When the table has no such key (a programming error: every figure the code reads
        is in the table; ``tests/physical/test_sources.py`` checks it).
    """
    try:
        return _by_key()[key]
    except KeyError:
        raise KeyError(f"sources: no figure {key!r} in chargedesign/data/sources.toml") from None


def value(key: str) -> float:
    """The figure of ``key`` (in the row's unit)."""
    return source(key).value


def checked(key: str) -> bool:
    """Whether the figure of ``key`` was read in its source."""
    return source(key).checked


def cite(key: str) -> str:
    """The citation an output carries: ``[key]``, or ``[key, unverified]`` when unchecked."""
    return source(key).cite()


def unchecked(keys: Iterable[str]) -> list[str]:
    """The keys among ``keys`` (in order, once each) whose figures are not checked."""
    seen: list[str] = []
    for k in keys:
        if k not in seen and not checked(k):
            seen.append(k)
    return seen


def rows_under(prefix: str) -> list[SourceRow]:
    """The rows whose key starts with ``prefix`` (e.g. ``actuators.``)."""
    return [r for r in rows() if r.key.startswith(prefix)]


@dataclass(frozen=True)
class SourcesTable:
    """The table as a result: ``to_dict()`` is the contract's JSON list, ``str()`` the text
    table (lines of at most :data:`LINE_WIDTH` characters)."""

    rows: tuple[SourceRow, ...]

    def to_dict(self) -> list[dict[str, Any]]:
        return [r.to_dict() for r in self.rows]

    @property
    def checked_count(self) -> int:
        return sum(r.checked for r in self.rows)

    def __str__(self) -> str:
        lines = [
            f"{len(self.rows)} figures, {self.checked_count} checked (read in the source named); "
            "'no' marks the unverified ones. Full sources and locators: --json.",
            "",
        ]
        head = f"{'key':<52} {'value':>11} {'unit':<12} {'checked':<7} source"
        lines += [head, "-" * len(head)]
        for r in self.rows:
            start = (
                f"{_clip(r.key, 52):<52} {r.value:>11.4g} {_clip(r.unit, 12):<12} "
                f"{'yes' if r.checked else 'no':<7} "
            )
            lines.append(start + _clip(r.source, LINE_WIDTH - len(start)))
        return "\n".join(lines) + "\n"

    def __repr__(self) -> str:
        return f"SourcesTable({len(self.rows)} figures, {self.checked_count} checked)"

    def _repr_html_(self) -> str:
        cells = "".join(
            "<tr>"
            + "".join(
                f"<td>{html.escape(str(x))}</td>"
                for x in (r.key, f"{r.value:.4g}", r.unit, "yes" if r.checked else "no", r.source)
            )
            + "</tr>"
            for r in self.rows
        )
        return (
            "<table><tr><th>key</th><th>value</th><th>unit</th><th>checked</th><th>source</th>"
            f"</tr>{cells}</table>"
        )


def _clip(text: str, width: int) -> str:
    return text if len(text) <= width else text[: max(width - 3, 0)] + "..."


def table() -> SourcesTable:
    """The whole table as a result (what ``chargedesign sources`` prints)."""
    return SourcesTable(rows())


#: a figure's citation of its row in the table: ``[key]`` or ``[key, unverified ...]`` (keys
#: are dotted names; their parts may hold capitals and hyphens, as ``...fused-silica``, ``PTFE``)
CITATION = re.compile(
    r"\[([A-Za-z][A-Za-z0-9_\-]*(?:\.[A-Za-z0-9_\-]+)+)(, " + UNVERIFIED_MARK + r"[^\]]*)?\]"
)
#: a mark of an unchecked figure with no row in the table
UNCHECKED_MARK = re.compile(r"\[" + UNVERIFIED_MARK + r"[^\]]*\]")


def cited_keys(text: str) -> tuple[str, list[str]]:
    """``text`` with each citation reduced to its reference key ``[key]`` (the checked status
    goes to the sources section, not inline), and the keys cited, in order of first use.
    A mark ``[unverified ...]`` without a key becomes ``[unchecked]``."""
    keys: list[str] = []
    known = {row.key for row in rows()}

    def reference(match: re.Match[str]) -> str:
        if match[1] not in known and match[2] is None:
            return match[0]  # a bracketed dotted name that is no key (``[design.json]``)
        if match[1] not in keys:
            keys.append(match[1])
        return f"[{match[1]}]"

    text = CITATION.sub(reference, text)
    if UNCHECKED_MARK.search(text):
        text = UNCHECKED_MARK.sub("[unchecked]", text)
        keys.append("unchecked")
    return text, keys


def table_cell(text: str) -> str:
    """Text for a Markdown table cell: its ``|`` (as in ``|B|``) would end the cell."""
    return text.replace("|", "\\|")


def sources_table_lines(keys: list[str]) -> list[str]:
    """A report's sources table (the design's and the testbed's): each key cited above, its
    figure, its source and locator, and whether the figure was checked in that source."""
    if not keys:
        return []
    known = {row.key: row for row in rows()}
    unverified = sum(1 for k in keys if k not in known or not known[k].checked)
    lines = [
        "",
        "Figures cited above by their key (the sources table, `chargedesign sources`): "
        f"{len(keys)} cited, {unverified} of them unverified (not read in the source named).",
        "",
        "| key | figure | source | locator | checked |",
        "|---|---|---|---|---|",
    ]
    for key in keys:
        row = known.get(key)
        if key == "unchecked":
            lines.append("| unchecked | a figure with no row in the sources table | - | - | no |")
        elif row is None:
            lines.append(f"| {key} | not in the sources table | - | - | no |")
        else:
            figure = f"{fmt(row.value)} {row.unit}".strip()
            lines.append(
                f"| {key} | {figure} ({table_cell(row.what)}) | {table_cell(row.source)} | "
                f"{table_cell(row.locator)} | {'yes' if row.checked else 'no (unverified)'} |"
            )
    return lines


__all__ = [
    "CITATION",
    "FIELDS",
    "UNCHECKED_MARK",
    "UNVERIFIED_MARK",
    "SourceRow",
    "SourcesTable",
    "checked",
    "cite",
    "cited_keys",
    "rows",
    "rows_under",
    "source",
    "sources_table_lines",
    "table",
    "table_cell",
    "unchecked",
    "value",
]
