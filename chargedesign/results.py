"""The one result protocol every result of the library follows.

A result (a :class:`~chargedesign.checker.CheckReport`, a
:class:`~chargedesign.designer.DesignResult`, a :class:`~chargedesign.body.Design`, the
verification report, ...) has

- ``to_dict()``: a JSON-ready mapping (``json.dumps(r.to_dict())`` works; no NaN, no arrays);
- ``str(r)``: the text the command line prints (the CLI formats nothing itself);
- ``repr(r)``: one short line (at most :data:`REPR_LIMIT` characters) naming the type and its
  main figures;
- ``r._repr_html_()``: a small HTML table for notebooks (with a picture where it helps).

:class:`Result` gives ``__repr__``, ``__str__``, ``_repr_html_`` and ``to_json`` from three
hooks a subclass fills in: :meth:`Result.to_dict`, :meth:`Result._text` and
:meth:`Result._summary` (the few ``name -> value`` pairs shown by ``repr`` and at the top of
the HTML table). A dataclass that uses it is declared with ``@dataclass(repr=False)`` so the
generated repr does not replace the compact one.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping
from typing import Any

from chargedesign.formatting import CELL, PRECISE, fmt
from chargedesign.vocabulary import VERDICT_STATES

#: the longest ``repr`` of any result, characters
REPR_LIMIT = 300
#: rows of nested mappings shown in the HTML table before "..."
HTML_ROWS = 40


def short_value(value: Any) -> str:
    """A value as it appears in a repr: floats to 4 significant digits, long lists counted."""
    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, float):
        return fmt(value, PRECISE)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):  # a verdict's state is said whole (its words are its meaning)
        return repr(value if len(value) <= 40 or value in VERDICT_STATES else value[:37] + "...")
    if isinstance(value, (list, tuple)):
        if len(value) <= 4 and all(isinstance(v, (int, float, str)) for v in value):
            inner = ", ".join(short_value(v) for v in value)
            return f"[{inner}]"
        return f"<{len(value)} items>"
    if isinstance(value, Mapping):
        return f"<{len(value)} keys>"
    shape = getattr(value, "shape", None)
    if shape is not None:
        return f"<array {tuple(shape)}>"
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def compact_repr(name: str, items: Mapping[str, Any], limit: int = REPR_LIMIT) -> str:
    """``name(k=v, ...)`` cut to ``limit`` characters."""
    text = f"{name}(" + ", ".join(f"{k}={short_value(v)}" for k, v in items.items()) + ")"
    if len(text) > limit:
        text = text[: limit - 4] + "...)"
    return text


def json_ready(value: Any) -> Any:
    """A copy of ``value`` that ``json.dumps(..., allow_nan=False)`` accepts.

    numpy arrays and scalars become lists and Python numbers; tuples become lists; NaN and
    infinities become None; other objects with ``to_dict`` are converted with it.
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):  # numpy's float64 too: a Python float out
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, Mapping):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [json_ready(v) for v in value]
    tolist = getattr(value, "tolist", None)
    if callable(tolist):  # numpy arrays and scalars
        return json_ready(tolist())
    to_dict = getattr(value, "to_dict", None)
    if callable(to_dict):
        return json_ready(to_dict())
    return str(value)


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return html.escape(fmt(value, CELL))
    if isinstance(value, (list, tuple)) and len(value) > 8:
        return html.escape(f"[{len(value)} items]")
    if isinstance(value, Mapping):
        return html.escape(short_value(value))
    return html.escape(str(value))


def html_table(title: str, rows: Mapping[str, Any], picture: str = "") -> str:
    """A small HTML table (``name | value``), with an optional picture (an HTML fragment)."""
    body = []
    for i, (key, value) in enumerate(rows.items()):
        if i >= HTML_ROWS:
            body.append("<tr><td colspan='2'>...</td></tr>")
            break
        body.append(
            f"<tr><th style='text-align:left'>{html.escape(str(key))}</th>"
            f"<td style='text-align:left'>{_cell(value)}</td></tr>"
        )
    table = (
        f"<table><caption style='text-align:left'><b>{html.escape(title)}</b></caption>"
        + "".join(body)
        + "</table>"
    )
    if picture:
        return f"<div style='display:flex;gap:1em;align-items:flex-start'>{table}{picture}</div>"
    return table


class Result:
    """Mixin of the result protocol (see the module docstring).

    Subclasses define :meth:`to_dict` and :meth:`_text`, and usually :meth:`_summary`.
    """

    __slots__ = ()

    def to_dict(self) -> dict[str, Any]:  # pragma: no cover - every result overrides it
        raise NotImplementedError

    def to_json(self, **kwargs: Any) -> str:
        """``to_dict()`` as JSON text (``kwargs`` go to :func:`json.dumps`, default indent 2)."""
        kwargs.setdefault("indent", 2)
        return json.dumps(json_ready(self.to_dict()), allow_nan=False, **kwargs)

    def _summary(self) -> dict[str, Any]:
        """The main figures: ``name -> value`` pairs for ``repr`` and the HTML table."""
        data = self.to_dict()
        return {
            k: v for k, v in data.items() if isinstance(v, (bool, int, float, str)) or v is None
        }

    def _text(self) -> str:
        """The text the command line prints."""
        return "\n".join(f"{k}: {v}" for k, v in self._summary().items())

    def _html_rows(self) -> dict[str, Any]:
        """Rows of the HTML table (default: the summary)."""
        return self._summary()

    def _html_picture(self) -> str:
        """An HTML fragment (e.g. an inline PNG) shown beside the table; empty by default."""
        return ""

    def __str__(self) -> str:
        return self._text()

    def __repr__(self) -> str:
        return compact_repr(type(self).__name__, self._summary())

    def _repr_html_(self) -> str:
        return html_table(type(self).__name__, self._html_rows(), self._html_picture())


def png_bytes(image: Any) -> bytes:
    """``image`` (array, shape (h, w, 3), uint8) encoded as PNG."""
    import io

    import imageio.v3 as iio

    buffer = io.BytesIO()
    iio.imwrite(buffer, image, extension=".png")
    return buffer.getvalue()


def png_html(image: Any, width: int = 240) -> str:
    """An ``<img>`` tag with ``image`` (array, shape (h, w, 3), uint8) inlined as PNG."""
    import base64

    data = base64.b64encode(png_bytes(image)).decode("ascii")
    return f"<img width='{width}' src='data:image/png;base64,{data}'/>"


__all__ = [
    "HTML_ROWS",
    "REPR_LIMIT",
    "Result",
    "compact_repr",
    "design_summary",
    "design_text",
    "html_table",
    "json_ready",
    "png_bytes",
    "png_html",
    "short_value",
]


# ------------------------------------------------------------------ designs (body.Design)
def design_summary(design: Any) -> dict[str, Any]:
    """The main figures of a :class:`~chargedesign.body.Design` (for repr and notebooks)."""
    p = design.parameters.as_dict()
    verdict = getattr(design, "verdict", None)
    out: dict[str, Any] = {"verdict": verdict["state"]} if isinstance(verdict, dict) else {}
    out |= {
        "charges": len(design.charge_values),
        "dipoles": len(design.dipole_moments),
        "masses": len(design.mass_values),
    }
    if design.continuous:
        out["continuous"] = len(design.continuous)
    out["realises"] = list(design.realises)
    out["fields"] = ",".join(k for k, v in design.fields.items() if len(v))
    if design.is_physical:
        out["total_mass"] = design.total_mass
    out["parameters"] = " ".join(f"{k}={fmt(v)}" for k, v in p.items() if v != 0.0)
    return out


def design_text(design: Any) -> str:
    """The short text of a :class:`~chargedesign.body.Design`: its main figures, one a line
    (the full report is :func:`chargedesign.report.render_report`, or ``str`` of the
    :class:`~chargedesign.designer.DesignResult`)."""
    rows = design_summary(design)
    width = max(len(k) for k in rows)
    lines = [f"{type(design).__name__}:"]
    lines += [
        f"  {k:<{width}}  {short_value(v) if not isinstance(v, str) else v}"
        for k, v in rows.items()
    ]
    return "\n".join(lines)
